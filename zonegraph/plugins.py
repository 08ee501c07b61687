"""The guides a search can rank proposals with: the built-in ones, the network guide zonegraph
ships, and those other packages add through an entry-point group.

Kept apart from `zonegraph.sequence.rankers` and free of heavy imports, so that the CLI can
reject an unknown guide before it loads the geometry kernel, and a batch can import a guide's
package once in the parent instead of once in every forked child. The network guide
(`zonegraph.network`) is named here by reference, as an entry point would be. Its shipped
weights run folded to numpy, so it needs nothing beyond the core; a guide that needs an extra
is offered only where its requirements can be found (decided without importing them), so an
install lists only the guides it can run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points
from importlib.util import find_spec
from typing import Any

RANKER_PLUGINS = "zonegraph.rankers"  # entry-point group of rankers other packages provide
BUILTIN_GUIDES = ("heuristic", "random")


@dataclass(frozen=True)
class ExtraGuide:
    """A guide zonegraph ships whose code needs an optional extra."""

    factory: str  # "module:attribute", imported only when the guide is used
    extra: str  # the extra of ``pyproject.toml`` that installs its requirements
    requires: tuple[str, ...]  # the top-level modules it imports

    def installed(self) -> bool:
        """Whether every requirement can be imported (found, not imported: no torch loads)."""
        return all(find_spec(name) is not None for name in self.requires)


PYTORCH = ExtraGuide("zonegraph.network.checkpoint:read_checkpoint", "train", ("torch", "torch_geometric"))
"""What reading a PyTorch checkpoint (``--model X.pt``) needs; the shipped weights, folded to
numpy (``.npz``), need none of it."""

EXTRA_GUIDES = {
    # PyTorch checkpoints (--model X.pt) need the train extra: zonegraph.cli checks those
    "net": ExtraGuide("zonegraph.network.ranker:NetworkRanker", "train", ()),
}


def _plugins() -> dict[str, EntryPoint]:
    """Guides installed packages register, by name; they cannot replace zonegraph's own."""
    own = {*BUILTIN_GUIDES, *EXTRA_GUIDES}
    return {e.name: e for e in entry_points(group=RANKER_PLUGINS) if e.name not in own}


def available_guides() -> list[str]:
    """The guides this installation can run: built-in, shipped (with their extra installed, where
    they need one), and registered by installed packages."""
    shipped = [name for name, guide in EXTRA_GUIDES.items() if guide.installed()]
    return [*BUILTIN_GUIDES, *shipped, *sorted(_plugins())]


def missing_extra(guide: str) -> str | None:
    """The extra a guide zonegraph ships needs and this installation lacks, or None."""
    shipped = EXTRA_GUIDES.get(guide)
    return shipped.extra if shipped is not None and not shipped.installed() else None


def model_problem(model: str) -> str | None:
    """Why the network guide cannot read checkpoint ``model`` here, in one line, or None."""
    if model.endswith(".npz") or PYTORCH.installed():
        return None
    needs = " and ".join(PYTORCH.requires)
    install = f"pip install 'zonegraph[{PYTORCH.extra}]'"
    return f"{model}: a PyTorch checkpoint needs {needs}: {install} (the shipped weights need neither)"


def guide_problem(guide: str) -> str | None:
    """Why ``guide`` cannot run here, in one line, or None if it can."""
    extra = missing_extra(guide)
    if extra is not None:
        needs = " and ".join(EXTRA_GUIDES[guide].requires)
        return f"the {guide} guide needs {needs}: pip install 'zonegraph[{extra}]'"
    guides = available_guides()
    return None if guide in guides else f"unknown guide {guide!r}: {', '.join(guides)}"


def guide_factory(guide: str) -> Callable[..., Any] | None:
    """The factory of a shipped or plugin guide (importing its package), or None for a built-in
    guide and for one this installation cannot run."""
    shipped = EXTRA_GUIDES.get(guide)
    if shipped is not None:
        entry = EntryPoint(guide, shipped.factory, RANKER_PLUGINS) if shipped.installed() else None
    else:
        entry = _plugins().get(guide)
    if entry is None:
        return None
    factory: Callable[..., Any] = entry.load()
    return factory
