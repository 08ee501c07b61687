"""Guides named on a command line: ``heuristic``, ``random``, or a network with its search knobs.

``net=PATH@top_m=M,blend=B,margin=D,defer=1`` is the `NetworkRanker` of
the checkpoint at PATH (the shipped scorer when PATH is empty) with those knobs, so the rank
evaluation and the search benchmarks compare the same network under several settings.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from zonegraph.sequence.rankers import Ranker, make_ranker

# NetworkRanker's keyword arguments
KNOBS = {
    "top_m": int,
    "blend": float,
    "margin": float,
    "defer": int,
    "wake": int,
    "relay": int,
    "calls": int,
}


@dataclass(frozen=True)
class GuideSpec:
    """One guide: its label in tables, its name, and for a network its checkpoint and knobs."""

    label: str
    name: str
    model: str | None = None
    knobs: tuple[tuple[str, float], ...] = ()

    @classmethod
    def parse(cls, spec: str) -> GuideSpec:
        """From ``heuristic``, ``random`` or ``net=PATH@knob=value,...`` (one line if it is wrong)."""
        name, _, rest = spec.partition("=")
        if name != "net":
            return cls(spec, spec)
        model, _, settings = rest.partition("@")
        options = dict(kv.split("=", 1) for kv in settings.split(",") if kv)
        unknown = set(options) - set(KNOBS)
        if unknown:
            raise SystemExit(f"{spec}: unknown option {sorted(unknown)} ({', '.join(KNOBS)})")
        knobs = tuple((k, KNOBS[k](v)) for k, v in sorted(options.items()))
        path = Path(model)
        shipped = not model or (path.stem == "scorer" and path.parent.name == "checkpoints")
        short = "shipped" if shipped else path.parent.name or model
        label = f"net:{short}" + (f"@{settings}" if settings else "")
        return cls(label, "net", model or None, knobs)

    @property
    def checkpoint(self) -> str | None:
        """The network's weights (the shipped scorer's when no path was given), None for the
        other guides: an evaluation leaves out the designs of the projects they trained on."""
        if self.name != "net":
            return None
        from zonegraph.network.folded import SHIPPED_FOLDED

        return self.model or str(SHIPPED_FOLDED)

    def ranker(self, seed: int) -> Ranker:
        """A fresh ranker of this guide (a network loads its checkpoint)."""
        if self.name != "net":
            return make_ranker(self.name, seed)
        from zonegraph.network.ranker import NetworkRanker

        return NetworkRanker(self.model, seed, **dict(self.knobs))  # type: ignore[arg-type]
