"""Real corpus designs for tests: converted from ``../shared/data/fusion360_b123d`` and replayed.

The corpus is never copied into the repository; tests that use it skip when it is absent.
"""

from __future__ import annotations

import functools

from build123d import Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.data.b123d import convert_design
from zonegraph.data.design import parse_design
from zonegraph.data.replay import replay
from zonegraph.testing.locations import CORPUS

__all__ = ["corpus_shape"]


@functools.cache
def corpus_shape(batch: str, design_id: str) -> Shape:
    """The final shape of one corpus design (``batch`` relative to the corpus root)."""
    converted = convert_design(CORPUS / batch, design_id)
    assert converted.ok and converted.design_json is not None, converted.reason
    return replay(parse_design(converted.design_json, design_id)).shape
