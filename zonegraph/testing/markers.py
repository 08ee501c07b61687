"""Skip markers for tests that need the real data: the only module here that imports pytest.

pytest is in the ``test`` extra, not the core install, so `zonegraph.testing` loads this
module only when a marker is first asked for; ``import zonegraph`` never imports pytest.
"""

from __future__ import annotations

import pytest

from zonegraph.testing.locations import CORPUS, CORPUS_SKIP_REASON, SAMPLES, SKIP_REASON

requires_samples = pytest.mark.skipif(not SAMPLES.is_dir(), reason=SKIP_REASON)
requires_corpus = pytest.mark.skipif(not CORPUS.is_dir(), reason=CORPUS_SKIP_REASON)
