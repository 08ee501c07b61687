"""Entry-point groups through which installed packages extend zonegraph (the network guide).

Kept apart from :mod:`zonegraph.sequence.rankers` and free of heavy imports, so that the CLI can
reject an unknown guide before it loads the geometry kernel, and a batch can import a plugin's
package once in the parent instead of once in every forked child.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib.metadata import entry_points
from typing import Any

RANKER_PLUGINS = "zonegraph.rankers"  # entry-point group of rankers other packages provide
BUILTIN_GUIDES = ("heuristic", "random")


def available_guides() -> list[str]:
    """The built-in guides and those installed packages register (the network: ``net``)."""
    return [*BUILTIN_GUIDES, *sorted(e.name for e in entry_points(group=RANKER_PLUGINS))]


def guide_factory(guide: str) -> Callable[..., Any] | None:
    """The factory a plugin registers for ``guide`` (importing its package), or None if no
    installed package provides it."""
    for entry in entry_points(group=RANKER_PLUGINS):
        if entry.name == guide:
            factory: Callable[..., Any] = entry.load()
            return factory
    return None
