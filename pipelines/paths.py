"""The paths a stage's ``dvc.yaml`` command passes it: declared there once, parsed here.

Every stage reads the folders of the stages before it and writes its own folder and metrics
file; DVC's example projects pass these on the command line, so ``dvc.yaml`` is the one place
they are written down and a stage can run on any other layout (the tests run them in a
temporary folder).
"""

from __future__ import annotations

import argparse
from pathlib import Path

UPSTREAM = {  # the folders stages read, by the name of their flag
    "designs": "the generate stage's folder",
    "replay": "the replay stage's folder",
    "zonegraphs": "the zonegraphs stage's folder",
    "gt": "the ground_truth stage's folder",
}


def stage_paths(doc: str, inputs: tuple[str, ...], **outputs: str) -> argparse.Namespace:
    """Parse a stage's command line: the upstream folders ``inputs`` (names of `UPSTREAM`)
    and its ``outputs`` (flag name -> what it is), all required paths, made absolute: job paths
    built from them name the same files on a Dask worker started in any folder."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    for name in inputs:
        parser.add_argument(f"--{name}", type=Path, required=True, help=UPSTREAM[name])
    for name, what in outputs.items():
        parser.add_argument(f"--{name}", type=Path, required=True, help=what)
    args = parser.parse_args()
    for name in (*inputs, *outputs):
        setattr(args, name, getattr(args, name).resolve())
    return args
