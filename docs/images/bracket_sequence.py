"""bracket: 2 sketch + extrude steps found by `zonegraph infer`.

Lengths are in mm, the input's unit, and the part sits where the input's did. Run
`python sequence.py [out.step]` to write it as STEP (default: sequence.step beside this
file); with no argument it is also shown in the OCP CAD Viewer where ocp_vscode is installed.
"""

import sys
from pathlib import Path

from build123d import *

with BuildPart() as part:
    # Step 1: union: sketch on the plane z = 0 mm, extruded 8 mm along +z
    with BuildSketch(Plane.XY):
        Rectangle(60, 40)
        with Locations((18, 0)):
            SlotCenterToCenter(14, 8, rotation=90, mode=Mode.SUBTRACT)
        with Locations((-12, 0)):
            Circle(6, mode=Mode.SUBTRACT)
    extrude(amount=8, mode=Mode.ADD)

    # Step 2: union: sketch on the plane z = 22 mm, extruded 22 mm along -z
    with BuildSketch(Plane.XY.offset(22)):
        with Locations((-12, 0)):
            Rectangle(24, 24)
        with Locations((-12, 0)):
            Circle(6, mode=Mode.SUBTRACT)
    extrude(amount=-22, mode=Mode.ADD)

result = part.part

if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).with_suffix(".step"))
    export_step(result, out, unit=Unit.MM)
    print(f"wrote {out}")
    if len(sys.argv) == 1:
        try:
            from ocp_vscode import show
        except ImportError:
            pass
        else:
            show(result)
