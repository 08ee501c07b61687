"""Fusion 360 Gallery designs written as build123d scripts -> our reconstruction JSON, verified."""

from zonegraph.data.b123d.convert import (
    ConvertedDesign,
    CorpusEntry,
    FeatureComment,
    RecordedCall,
    RecordedFace,
    convert_batch,
    convert_design,
    edge_curve,
    face_record,
    feature_comments,
    install_ocp_shims,
    list_corpus,
    load_batch,
    recording,
)

__all__ = [
    "ConvertedDesign",
    "CorpusEntry",
    "FeatureComment",
    "RecordedCall",
    "RecordedFace",
    "convert_batch",
    "convert_design",
    "edge_curve",
    "face_record",
    "feature_comments",
    "install_ocp_shims",
    "list_corpus",
    "load_batch",
    "recording",
]
