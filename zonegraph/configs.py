"""Typed settings of the commands and stages, built by keyword or from a mapping.

This module imports nothing heavy, so that the CLI can take its defaults from these dataclasses
(never copying them by hand) without loading the geometry kernel before a command runs.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any, TypeVar

C = TypeVar("C", bound="Config")


class Config:
    """Mixin for frozen dataclass configs: :meth:`from_mapping` and :meth:`defaults`."""

    @classmethod
    def from_mapping(cls: type[C], values: Mapping[str, Any]) -> C:
        """The config from a mapping such as a ``params.yaml`` section or parsed CLI arguments.

        Unknown keys are ignored; known ones are converted to the field's type (YAML may give
        ``2`` for ``2.0``), so that a reordered or renamed field can never swap two values."""
        kinds: dict[str, Callable[[Any], Any]] = {
            f.name: str if f.default is None else type(f.default)  # optional fields hold paths
            for f in fields(cls)  # type: ignore[arg-type]
        }
        return cls(**{k: kinds[k](v) for k, v in values.items() if k in kinds and v is not None})

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Field defaults by name (the CLI's defaults)."""
        return {f.name: f.default for f in fields(cls)}  # type: ignore[arg-type]


@dataclass(frozen=True)
class BuildConfig(Config):
    """How a zone graph is built (``zonegraph build``, the ``zonegraphs`` stage).

    Args:
        simplify: face-loop simplification (paper sec. 3).
        samples: surface samples per zone, for the network (0: none).
        seed: seed of the surface samples.
    """

    simplify: bool = True
    samples: int = 512
    seed: int = 0


@dataclass(frozen=True)
class InferConfig(Config):
    """Search settings of one reconstruction (``zonegraph infer``, the ``reconstruct`` stage).

    Args:
        guide: proposal ranking, ``heuristic``, ``random`` or an installed plugin (``net``).
        budget_s: search seconds over both graphs (zone-graph build excluded, as in the paper).
        k: proposals kept per state (top-k).
        k_decay: decrease of k per depth level (the paper's harder runs: k 15, decay 0.5).
        max_depth: longest program searched.
        seed: seed of the random guide.
        level: proposal level: sketches of 1..level and N-level..N components.
        model: the network guide's checkpoint (None: the shipped one).
    """

    guide: str = "heuristic"
    budget_s: float = 10.0
    k: int = 5
    k_decay: float = 0.0
    max_depth: int = 20
    seed: int = 0
    level: int = 1
    model: str | None = None
