"""Shared fixtures. The data locations, skip markers and helpers the tests import live in
`zonegraph.testing`: a test module never imports this file or another test module."""

from __future__ import annotations

from pathlib import Path

import pytest

import zonegraph.geometry.kernel  # noqa: F401 - before any test's Boolean, as the package does
from zonegraph.testing import SAMPLES, SKIP_REASON


@pytest.fixture(scope="session")
def samples_dir() -> Path:
    """The real Fusion 360 Gallery samples (the test is skipped when they are absent)."""
    if not SAMPLES.is_dir():
        pytest.skip(SKIP_REASON)
    return SAMPLES
