"""Export of a found program: an editable build123d script, Fusion-format JSON, STEP and PNG.

``writers`` maps the program back to the input's units and frame and writes every file;
``render`` draws the step strip (green: union, red: subtraction, grey: the shape so far).
Imports :mod:`zonegraph.sequence`, :mod:`zonegraph.data` and :mod:`zonegraph.geometry`.
"""

from zonegraph.export.render import StripStep, render_sequence, render_strips
from zonegraph.export.writers import program_design, program_script, write_outputs

__all__ = [
    "StripStep",
    "program_design",
    "program_script",
    "render_sequence",
    "render_strips",
    "write_outputs",
]
