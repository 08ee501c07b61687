"""The pictures of the documentation, made from a part built here (no data set geometry).

    python -m bench.docs_images [--out docs/images]

A bracket (a plate with a slot and a bored boss) is built with build123d and written as STEP;
``zonegraph.infer`` runs on it as ``zonegraph infer bracket.step`` would, and its strip
(``sequence.png``), its editable script (``bracket_sequence.py``) and a picture of its zone graph
(``zones.png``) are copied into ``--out``. Re-run it when the renderer or the writer changes.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

from build123d import (
    Align,
    Box,
    BuildPart,
    BuildSketch,
    Circle,
    Locations,
    Mode,
    Plane,
    Rectangle,
    SlotCenterToCenter,
    export_step,
    extrude,
)

import zonegraph as zg
from zonegraph.export.render import render_zone_graph


def bracket(path: Path) -> Path:
    """A 60 x 40 x 8 mm plate with a slot and a 24 mm boss bored through both."""
    with BuildPart() as part:
        Box(60, 40, 8, align=(Align.CENTER, Align.CENTER, Align.MIN))
        with BuildSketch(Plane.XY.offset(8)), Locations((-12, 0)):
            Rectangle(24, 24)
        extrude(amount=14)
        with BuildSketch(Plane.XY.offset(22)), Locations((-12, 0)):
            Circle(6)
        extrude(amount=-22, mode=Mode.SUBTRACT)
        with BuildSketch(Plane.XY.offset(8)), Locations((18, 0)):
            SlotCenterToCenter(14, 8, rotation=90)
        extrude(amount=-8, mode=Mode.SUBTRACT)
    export_step(part.part, str(path))
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("docs/images"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        step = bracket(Path(work) / "bracket.step")
        result = zg.infer(step, Path(work) / "out", zg.InferConfig(budget_s=10))
        print(f"bracket.step: {result.status}, {result.steps} steps, B-rep IoU {result.iou_brep:.6f}")
        shutil.copy(Path(work) / "out/sequence.png", args.out / "sequence.png")
        shutil.copy(Path(work) / "out/sequence.py", args.out / "bracket_sequence.py")
        target = zg.load_target(step)
        render_zone_graph(zg.build_zone_graph(target), args.out / "zones.png", target)
    print(f"wrote {args.out}/sequence.png, zones.png, bracket_sequence.py")


if __name__ == "__main__":
    main()
