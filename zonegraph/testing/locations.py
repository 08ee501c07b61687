"""Where the real data lives: the one definition the tests and the benchmarks read.

The data (the Fusion 360 Gallery samples and the build123d script corpus) sits in a ``shared``
folder beside the project checkout, never inside it (its licence forbids copying it into the
repository). The package may be installed in site-packages, where ``__file__`` says nothing about
the checkout, so the folder is looked for in this order:

1. ``$ZONEGRAPH_SHARED``, when set: an explicit choice always wins (CI, a data folder elsewhere);
2. ``Path.cwd().parent / "shared"``: ``make test``, ``pytest`` and ``python -m bench...`` all run
   from the checkout's root, so this finds it whether the package is installed or not;
3. the folder beside the checkout that holds this package (``zonegraph/``'s parent's parent),
   when it exists: an editable install or ``PYTHONPATH=.`` run from a sub-folder of the checkout.

When none exists, the cwd-based folder is named (what a user who cloned the data would create),
and the tests that need it are skipped with that path in the reason.
"""

from __future__ import annotations

import os
from pathlib import Path

ENV = "ZONEGRAPH_SHARED"
HINT = "clone the data with ../shared beside the repo, or set ZONEGRAPH_SHARED"


def shared_root() -> Path:
    """The ``shared`` folder (see the module docstring for the order it is looked for in)."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser()
    beside_cwd = Path.cwd().parent / "shared"
    beside_package = Path(__file__).resolve().parents[2].parent / "shared"
    if not beside_cwd.is_dir() and beside_package.is_dir():
        return beside_package
    return beside_cwd


def samples_root() -> Path:
    """The real Fusion 360 Gallery design JSON (and a few STEP files) used by the tests."""
    return shared_root() / "data" / "fusion360_samples"


def corpus_root() -> Path:
    """The build123d script corpus (Fusion360GalleryDataset-build123d)."""
    return shared_root() / "data" / "fusion360_b123d"


SAMPLES = samples_root()
CORPUS = corpus_root()
SKIP_REASON = f"real Fusion 360 Gallery samples not found at {SAMPLES} ({HINT})"
CORPUS_SKIP_REASON = f"build123d script corpus not found at {CORPUS} ({HINT})"


def sample_paths() -> list[Path]:
    """Every sample design JSON, sorted; empty when the samples are absent."""
    return sorted(SAMPLES.glob("*.json")) if SAMPLES.is_dir() else []
