"""Design data: the typed Fusion 360 Gallery JSON model, its exact build123d replay, data sets.

``schema`` describes the JSON and builds the model from it, ``design`` holds the model (read
and written as JSON), ``profiles`` turns sketch curves into faces, ``replay`` runs the timeline
with Fusion's Boolean semantics, ``synthetic`` generates seeded designs in the same format,
``dataset`` finds designs and their split, ``stats`` compares a data set with the published
r1.0.1 figures and ``targets`` reads any supported input (STEP, BREP, design JSON) as solids. The
replay function is :func:`zonegraph.data.replay.replay` (the module keeps its name). Imports
only :mod:`zonegraph.geometry` and :mod:`zonegraph.errors`.
"""

from zonegraph.data.dataset import DesignRecord, read_dataset
from zonegraph.data.design import Design, Extrude, Operation, design_to_json, load_design, parse_design
from zonegraph.data.replay import ReplayResult, ReplayStep, as_shape
from zonegraph.data.synthetic import generate_design, synthetic_design
from zonegraph.data.targets import load_target

__all__ = [
    "Design",
    "DesignRecord",
    "Extrude",
    "Operation",
    "ReplayResult",
    "ReplayStep",
    "as_shape",
    "design_to_json",
    "generate_design",
    "load_design",
    "load_target",
    "parse_design",
    "read_dataset",
    "synthetic_design",
]
