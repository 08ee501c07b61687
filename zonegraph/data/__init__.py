"""Design data: the typed Fusion 360 Gallery JSON model, its exact build123d replay, data sets.

``schema`` describes the JSON and builds the model from it, ``design`` holds the model (read
and written as JSON), ``profiles`` turns sketch curves into faces, ``replay`` runs the timeline
with Fusion's Boolean semantics, ``synthetic`` generates seeded designs in the same format,
``dataset`` finds designs and their split, ``stats`` compares a data set with the published
r1.0.1 figures and ``targets`` reads any supported input (STEP, BREP, design JSON) as solids. The
replay function is `zonegraph.data.replay.replay` (the module keeps its name). Imports
only `zonegraph.geometry` and `zonegraph.errors`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

_EXPORTS = {
    "DesignRecord": "zonegraph.data.dataset",
    "read_dataset": "zonegraph.data.dataset",
    "Design": "zonegraph.data.design",
    "Extrude": "zonegraph.data.design",
    "Operation": "zonegraph.data.design",
    "design_to_json": "zonegraph.data.design",
    "load_design": "zonegraph.data.design",
    "parse_design": "zonegraph.data.design",
    "ReplayResult": "zonegraph.data.replay",
    "ReplayStep": "zonegraph.data.replay",
    "as_shape": "zonegraph.data.replay",
    "generate_design": "zonegraph.data.synthetic",
    "synthetic_design": "zonegraph.data.synthetic",
    "load_target": "zonegraph.data.targets",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.data.dataset import DesignRecord, read_dataset
    from zonegraph.data.design import Design, Extrude, Operation, design_to_json, load_design, parse_design
    from zonegraph.data.replay import ReplayResult, ReplayStep, as_shape
    from zonegraph.data.synthetic import generate_design, synthetic_design
    from zonegraph.data.targets import load_target

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, __all__)
