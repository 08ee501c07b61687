"""Export of a found program: an editable build123d script, Fusion-format JSON, STEP and PNG.

``writers`` maps the program back to the input's units and frame and writes every file;
``idioms`` chooses build123d's named planes and the sketch objects (Rectangle, Circle, ...) a
profile is;
``render`` draws the step strip (green: union, red: subtraction, grey: the shape so far);
``snap`` shortens the written numbers and ``verify`` keeps them only where the written files still
rebuild the part.
Imports `zonegraph.sequence`, `zonegraph.data` and `zonegraph.geometry`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "StripStep": "zonegraph.export.render",
    "render_sequence": "zonegraph.export.render",
    "render_strips": "zonegraph.export.render",
    "Snapper": "zonegraph.export.snap",
    "Export": "zonegraph.export.verify",
    "ExportCheck": "zonegraph.export.verify",
    "verified_export": "zonegraph.export.verify",
    "WrittenStep": "zonegraph.export.writers",
    "program_design": "zonegraph.export.writers",
    "program_script": "zonegraph.export.writers",
    "write_outputs": "zonegraph.export.writers",
    "written_steps": "zonegraph.export.writers",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.export.render import StripStep, render_sequence, render_strips
    from zonegraph.export.snap import Snapper
    from zonegraph.export.verify import Export, ExportCheck, verified_export
    from zonegraph.export.writers import (
        WrittenStep,
        program_design,
        program_script,
        write_outputs,
        written_steps,
    )

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)
