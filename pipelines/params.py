"""The pipeline's sections of ``params.yaml`` (the single source of every seed, size and budget).

Each section a stage reads is one `Config`: the stage gets it with
`section`, which reads the file with the package's one reader and fails in one line naming
the file on a key that is not a field (a typo would otherwise leave a setting at its default).
The ``zonegraph`` and ``reconstruct`` sections are the CLI's `BuildConfig` and
`InferConfig` plus the stage's own keys; ``train`` is ``training.train.TrainConfig`` and
``evaluate`` is ``eval.report.EvalConfig``, read by those scripts themselves.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from zonegraph.configs import BuildConfig, C, Config, ConfigError, InferConfig, load_section

PARAMS_FILE = Path("params.yaml")


def section(cls: type[C], name: str, path: str | Path = PARAMS_FILE) -> C:
    """Section ``name`` of the params file as ``cls``; bad params exit with one line."""
    try:
        return load_section(cls, name, path)
    except ConfigError as exc:
        raise SystemExit(f"{exc}") from None


@dataclass(frozen=True)
class DataParams(Config):
    """``data``: where the designs come from and how they are split (the ``generate`` stage).

    Args:
        source: ``synthetic``, ``fusion_json`` (a folder of Fusion 360 Gallery JSON) or ``b123d``
            (a clone of Fusion360GalleryDataset-build123d, converted and verified).
        fusion_json_dir: the folder of a ``fusion_json`` source.
        b123d_dir: the clone of a ``b123d`` source.
        limit: a seeded sample of at most this many designs (None: all).
        limit_seed: seed of that sample.
        convert_timeout_s: per corpus design converted.
        split_seed: seed of the split by project, for sources without ``train_test.json``.
        test_fraction: share of the designs in the test split.
    """

    source: str = "synthetic"
    fusion_json_dir: str | None = None
    b123d_dir: str | None = None
    limit: int | None = None
    limit_seed: int = 0
    convert_timeout_s: float = 120.0
    split_seed: int = 0
    test_fraction: float = 0.35


@dataclass(frozen=True)
class SyntheticParams(Config):
    """``synthetic``: the seeded synthetic designs of a ``synthetic`` source.

    Args:
        count: designs generated.
        seed: base seed of the set.
        timeout_s: per design.
    """

    count: int = 150
    seed: int = 2021
    timeout_s: float = 120.0


@dataclass(frozen=True)
class DaskParams(Config):
    """``dask``: the cluster every stage's designs run on.

    Args:
        scheduler: address of an existing cluster (None: a local one).
        n_workers: workers of the local cluster.
        memory_mb: address space each design's child may add in MiB (None: no limit); past it a
            design is ``out_of_memory``. A worker's own memory monitor does not see its children.
    """

    scheduler: str | None = None
    n_workers: int = 2
    memory_mb: int | None = None


@dataclass(frozen=True)
class ReplayParams(Config):
    """``replay``: ``timeout_s`` per design (a hung OpenCASCADE call is killed)."""

    timeout_s: float = 120.0


@dataclass(frozen=True)
class ZoneGraphParams(BuildConfig):
    """``zonegraph``: the `BuildConfig` of every graph, and ``timeout_s`` per design."""

    timeout_s: float = 300.0


@dataclass(frozen=True)
class ReconstructParams(InferConfig):
    """``reconstruct``: the `InferConfig` of every search but its guide, searched once per
    guide of ``guides`` at the same budget, with ``timeout_s`` as the hard stop per design."""

    guides: tuple[str, ...] = ("heuristic", "random", "net")
    timeout_s: float = 60.0


@dataclass(frozen=True)
class GroundTruthParams(Config):
    """``ground_truth``: how each design's GT sequence is tested for capture.

    Args:
        levels: proposal levels at which capture is tested (paper supplement: 1 vs 3).
        full_graph: also measure the unsimplified graph.
        budget_s: heuristic search seconds for a design whose GT is not captured.
        timeout_s: per design.
    """

    levels: tuple[int, ...] = (1, 3)
    full_graph: bool = True
    budget_s: float = 2.0
    timeout_s: float = 300.0


@dataclass(frozen=True)
class LabelsParams(Config):
    """``labels``: which designs get training labels and how (paper sec. 4.2).

    Args:
        splits: splits labelled with completions.
        rank_splits: splits labelled rank-only (proposals and GT, no completions).
        limit: a seeded sample stratified by timeline folder (None: all).
        limit_seed: seed of that sample.
        level: proposal level (one of ``ground_truth.levels``).
        multiplier: completions per proposal = multiplier x remaining GT steps (at least 1).
        slack: a completion stops after remaining GT steps + slack proposals.
        seed: with the design id, seeds every random completion.
        timeout_s: per design.
    """

    splits: tuple[str, ...] = ("train",)
    rank_splits: tuple[str, ...] = ()
    limit: int | None = None
    limit_seed: int = 0
    level: int = 1
    multiplier: float = 1.0
    slack: int = 2
    seed: int = 0
    timeout_s: float = 600.0


# The sections the stage scripts under pipelines/ read, with the config each must fit.
SECTIONS: dict[str, type[Config]] = {
    "data": DataParams,
    "synthetic": SyntheticParams,
    "dask": DaskParams,
    "replay": ReplayParams,
    "zonegraph": ZoneGraphParams,
    "reconstruct": ReconstructParams,
    "ground_truth": GroundTruthParams,
    "labels": LabelsParams,
}
