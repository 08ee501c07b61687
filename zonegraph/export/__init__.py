"""Export of a found program: an editable build123d script, Fusion-format JSON, STEP and PNG.

``writers`` maps the program back to the input's units and frame and writes every file;
``idioms`` chooses build123d's named planes and the sketch objects (Rectangle, Circle, ...) a
profile is;
``render`` draws the step strip (green: union, red: subtraction, grey: the shape so far);
``snap`` shortens the written numbers and ``verify`` keeps them only where the written files still
rebuild the part.
Imports :mod:`zonegraph.sequence`, :mod:`zonegraph.data` and :mod:`zonegraph.geometry`.
"""

from zonegraph.export.render import StripStep, render_sequence, render_strips
from zonegraph.export.snap import Snapper
from zonegraph.export.verify import Export, ExportCheck, verified_export
from zonegraph.export.writers import WrittenStep, program_design, program_script, write_outputs, written_steps

__all__ = [
    "Export",
    "ExportCheck",
    "Snapper",
    "StripStep",
    "WrittenStep",
    "program_design",
    "program_script",
    "render_sequence",
    "render_strips",
    "verified_export",
    "write_outputs",
    "written_steps",
]
