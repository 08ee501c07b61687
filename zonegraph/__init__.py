"""zonegraph: recover editable sketch + extrude programs from B-rep solids with zone graphs.

After Xu et al., *Inferring CAD Modeling Sequences Using Zone Graphs* (CVPR 2021). The layers,
each a sub-package that imports only the ones before it:

- `zonegraph.geometry`: OCP/build123d helpers, B-rep I/O, normalisation;
- `zonegraph.data`: the Fusion 360 Gallery design model, exact replay, synthetic designs;
- `zonegraph.zones`: zone graphs (face extension, general fuse, the `ZoneGraph`);
- `zonegraph.sequence`: proposals, rankers, best-first search, programs;
- `zonegraph.export`: editable scripts, Fusion JSON, STEP and PNG;
- on top: `zonegraph.reconstruction` (`infer`), `zonegraph.cli`,
  `zonegraph.isolation` and `zonegraph.errors` (used by every layer).

Typical use::

    import zonegraph as zg
    graph = zg.build_zone_graph(zg.load_target("part.step"))
    result = zg.search(graph, zg.HeuristicRanker(), zg.SearchConfig(budget_s=10))
    answer = zg.infer("part.step", "out/", zg.InferConfig(budget_s=20))  # search ... export
    part = answer.to_part()      # the program as a build123d Part (answer.reason: why not exact)
    script, design = answer.to_script(), answer.to_json()  # sequence.py, sequence.json

The public names below are imported on first use, so ``import zonegraph`` stays cheap (the
geometry kernel loads only when a name that needs it is touched). There is no torch import here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from zonegraph.lazy import lazy_exports

__version__ = "0.1.0"

_EXPORTS = {
    "ZoneGraphError": "zonegraph.errors",
    "InputError": "zonegraph.errors",
    "DesignError": "zonegraph.errors",
    "UnsupportedFeatureError": "zonegraph.errors",
    "Design": "zonegraph.data",
    "load_design": "zonegraph.data",
    "replay": "zonegraph.data.replay",
    "load_target": "zonegraph.data",
    "ZoneGraph": "zonegraph.zones",
    "ZoneGraphBuildError": "zonegraph.zones",
    "build_zone_graph": "zonegraph.zones",
    "load_zone_graph": "zonegraph.zones",
    "save_zone_graph": "zonegraph.zones",
    "Op": "zonegraph.sequence",
    "Proposal": "zonegraph.sequence",
    "ProposalGenerator": "zonegraph.sequence",
    "Ranker": "zonegraph.sequence",
    "RandomRanker": "zonegraph.sequence",
    "HeuristicRanker": "zonegraph.sequence",
    "SearchConfig": "zonegraph.sequence",
    "SearchResult": "zonegraph.sequence",
    "search": "zonegraph.sequence",
    "InferConfig": "zonegraph.configs",
    "BuildConfig": "zonegraph.configs",
    "InferResult": "zonegraph.reconstruction",
    "Reconstruction": "zonegraph.reconstruction",
    "reconstruct": "zonegraph.reconstruction",
    "infer": "zonegraph.reconstruction",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from zonegraph.configs import BuildConfig, InferConfig
    from zonegraph.data import Design, load_design, load_target
    from zonegraph.data.replay import replay
    from zonegraph.errors import DesignError, InputError, UnsupportedFeatureError, ZoneGraphError
    from zonegraph.reconstruction import InferResult, Reconstruction, infer, reconstruct
    from zonegraph.sequence import (
        HeuristicRanker,
        Op,
        Proposal,
        ProposalGenerator,
        RandomRanker,
        Ranker,
        SearchConfig,
        SearchResult,
        search,
    )
    from zonegraph.zones import (
        ZoneGraph,
        ZoneGraphBuildError,
        build_zone_graph,
        load_zone_graph,
        save_zone_graph,
    )


__getattr__, _ = lazy_exports(__name__, _EXPORTS, __all__)


def __dir__() -> list[str]:
    """The public API only: not this module's own helpers (``TYPE_CHECKING``, ``lazy_exports``)."""
    return sorted([*__all__, "__version__"])
