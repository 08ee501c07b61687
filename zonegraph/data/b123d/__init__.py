"""Fusion 360 Gallery designs written as build123d scripts -> our reconstruction JSON, verified.

The corpus (``../shared/data/fusion360_b123d``) holds each design as a function ``model_<id>()``
whose body replays Fusion's sketch + extrude timeline with build123d. One module per step:

- `.listing`: the designs and Fusion's figures, found without running any code;
- `.comments`: where each Fusion feature starts in the source, and its operation;
- `.shims` and `.loading`: importing a batch written for build123d 0.10;
- `.recording`: the ``extrude`` calls a model makes, with the faces they sweep;
- `.curves`: each face as sketch-local loops of exact profile curves;
- `.features`: the calls as our typed timeline, one extrude per Fusion feature;
- `.verify`: our replay against the script's own part;
- `.convert`: one design through all of it (in a killable child:
  `zonegraph.jobs.convert_isolated`).

The package keeps the ``b123d`` name of the data source (``params.yaml``'s ``data.source: b123d``)
and of the module it replaces, so that every ``zonegraph.data.b123d`` import still holds.
"""

from zonegraph.data.b123d.comments import FeatureComment, feature_comments
from zonegraph.data.b123d.convert import ConvertedDesign, convert_design
from zonegraph.data.b123d.curves import RecordedFace, edge_curve, face_record
from zonegraph.data.b123d.listing import CorpusEntry, batch_entries, list_corpus
from zonegraph.data.b123d.loading import load_batch
from zonegraph.data.b123d.recording import RecordedCall, recording
from zonegraph.data.b123d.shims import install_ocp_shims

__all__ = [
    "ConvertedDesign",
    "CorpusEntry",
    "FeatureComment",
    "RecordedCall",
    "RecordedFace",
    "batch_entries",
    "convert_design",
    "edge_curve",
    "face_record",
    "feature_comments",
    "install_ocp_shims",
    "list_corpus",
    "load_batch",
    "recording",
]
