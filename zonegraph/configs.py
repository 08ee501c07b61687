"""Typed settings of the commands and stages, built by keyword or from a mapping.

This module imports nothing heavy (and nothing else of the package), so that the CLI can take its
defaults from these dataclasses (never copying them by hand) without loading the geometry kernel
before a command runs, and so that every layer can declare its settings as a `Config`.
It also holds the one reader of ``params.yaml`` (`load_params`, `load_section`),
which the stage scripts, the training loop and the report share.
"""

from __future__ import annotations

import types
import typing
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, TypeVar

C = TypeVar("C", bound="Config")


class ConfigError(ValueError):
    """A mapping that does not fit a config: an unknown key or a value of the wrong kind."""


class Config:
    """Mixin for frozen dataclass configs: `from_mapping` and `defaults`."""

    @classmethod
    def from_mapping(cls: type[C], values: Mapping[str, Any], strict: bool = False) -> C:
        """The config from a mapping such as a ``params.yaml`` section or parsed CLI arguments.

        Each value is converted to its field's annotated type (YAML may give ``2`` for ``2.0``, a
        list for a tuple), so that a reordered or renamed field can never swap two values. None
        keeps a field's default unless the field is optional. Unknown keys are ignored, as a CLI
        namespace or a wider config holds other settings too, unless ``strict``: a section of
        ``params.yaml`` must fit its config exactly, so that a typo'd key cannot pass unnoticed.

        Raises:
            ConfigError: an unknown key (when strict) or a value that does not convert.
        """
        hints = typing.get_type_hints(cls)
        names = [f.name for f in fields(cls)]  # type: ignore[arg-type]
        unknown = sorted(set(values) - set(names))
        if strict and unknown:
            raise ConfigError(f"unknown key(s) {', '.join(unknown)} (known: {', '.join(names)})")
        chosen = {}
        for name in names:
            if name not in values or (values[name] is None and not _optional(hints[name])):
                continue
            try:
                chosen[name] = _convert(hints[name], values[name])
            except (TypeError, ValueError) as exc:
                raise ConfigError(f"{name}: {values[name]!r} is not {_describe(hints[name])}") from exc
        return cls(**chosen)

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Field defaults by name (the CLI's defaults)."""
        return {f.name: f.default for f in fields(cls)}  # type: ignore[arg-type]


def _optional(kind: Any) -> bool:
    return type(None) in typing.get_args(kind) and _is_union(kind)


def _is_union(kind: Any) -> bool:
    return typing.get_origin(kind) in (typing.Union, types.UnionType)


def _convert(kind: Any, value: Any) -> Any:
    """``value`` as the annotated type ``kind``: a scalar, ``X | None``, ``tuple[X, ...]``,
    ``tuple[X, Y]`` or ``list[X]``."""
    if _is_union(kind):
        if value is None:
            return None
        (inner,) = [k for k in typing.get_args(kind) if k is not type(None)]
        return _convert(inner, value)
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (tuple, list):
        if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Iterable):
            raise TypeError("not a sequence")
        items = list(value)
        if origin is tuple and not (len(args) == 2 and args[1] is Ellipsis):
            if len(items) != len(args):
                raise ValueError(f"{len(args)} items expected")
            return tuple(_convert(a, v) for a, v in zip(args, items, strict=True))
        return origin(_convert(args[0], v) for v in items)
    if kind is bool:
        if not isinstance(value, (bool, int)) or value not in (0, 1):
            raise TypeError("not a boolean")  # bool("false") would be True
        return bool(value)
    if kind in (int, float) and isinstance(value, bool):
        raise TypeError("a boolean is not a number")
    if kind is int and float(value) != int(value):
        raise ValueError("not a whole number")
    return kind(value)


def _describe(kind: Any) -> str:
    return "of type " + (kind.__name__ if isinstance(kind, type) else str(kind))


def load_params(path: str | Path = "params.yaml") -> dict[str, dict[str, Any]]:
    """The sections of a params file: the one reader of ``params.yaml``.

    Raises:
        ConfigError: the file is missing, not YAML, or not a mapping of sections (named in the
            message, so that a caller can print it as the one line of a bad-input exit).
    """
    import yaml  # only the pipeline and train extras install PyYAML

    try:
        params = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"{path}: cannot read params: {exc}") from exc
    if not isinstance(params, dict) or not all(isinstance(s, dict) for s in params.values()):
        raise ConfigError(f"{path}: not a mapping of sections (section: {{key: value}})")
    return params


def load_section(cls: type[C], name: str, path: str | Path = "params.yaml") -> C:
    """Section ``name`` of a params file as its config, strictly (every key a field).

    Raises:
        ConfigError: the file cannot be read, lacks the section, or the section does not fit.
    """
    params = load_params(path)
    if name not in params:
        raise ConfigError(f"{path}: no section {name!r}")
    try:
        return cls.from_mapping(params[name], strict=True)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {name}: {exc}") from exc


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


# The guides zonegraph itself offers (``zonegraph.plugins`` runs them; it is not imported here, as
# reading entry points costs ``zonegraph --help`` a tenth of a second), and those that take no model.
GUIDES = ("heuristic", "random", "net")
MODELLESS_GUIDES = ("heuristic", "random")


@dataclass(frozen=True)
class InferConfig(Config):
    """Search settings of one reconstruction (``zonegraph infer``, the ``reconstruct`` stage).

    Args:
        guide: proposal ranking: ``heuristic``, ``random``, ``net`` (the shipped network, behind
            the ``train`` extra) or a ranker plugin another package registers.
        budget_s: search seconds over both graphs (zone-graph build excluded, as in the paper).
        k: proposals kept per state (top-k).
        k_decay: decrease of k per depth level (the paper's harder runs: k 15, decay 0.5).
        max_depth: longest program searched.
        seed: seed of the random guide.
        level: proposal level: sketches of 1..level and N-level..N components.
        model: the network guide's checkpoint (None: the shipped one); the built-in guides use
            none, so the CLI refuses one with them.
        max_expansions: a work bound per graph searched (states expanded), None for none; with an
            infinite ``budget_s`` it makes a reconstruction the same on any machine and load.
    """

    guide: str = "heuristic"
    budget_s: float = 10.0
    k: int = 5
    k_decay: float = 0.0
    max_depth: int = 20
    seed: int = 0
    level: int = 1
    model: str | None = None
    max_expansions: int | None = None
