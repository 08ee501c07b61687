"""The scorer folded to numpy scores every proposal of real states as the PyTorch forward does."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
import torch

from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.network.checkpoint import SHIPPED, fold, fold_checkpoint, read_checkpoint
from zonegraph.network.folded import (
    SHIPPED_FOLDED,
    CodeMemo,
    FoldedScorer,
    State,
    _max_elsewhere,
    zone_samples,
)
from zonegraph.network.model import ModelConfig, ProposalScorer
from zonegraph.network.ranker import NetworkRanker, NumpyScorer, open_scorer
from zonegraph.network.scoring import TorchScorer
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.features import FEATURES, proposal_features
from zonegraph.sequence.proposals import Op, ProposalGenerator
from zonegraph.sequence.rankers import HeuristicRanker
from zonegraph.testing import requires_samples
from zonegraph.zones.build import build_zone_graph


def _trained_like(config: ModelConfig) -> ProposalScorer:
    """A model with seeded weights and BatchNorm statistics far from the identity, so that a
    fold that dropped or misplaced one would show."""
    torch.manual_seed(0)
    model = ProposalScorer(config)
    for module in model.modules():
        if isinstance(module, torch.nn.BatchNorm1d):
            module.running_mean.normal_(0.0, 0.1)
            module.running_var.uniform_(0.5, 2.0)
            module.weight.data.uniform_(0.5, 1.5)
            module.bias.data.normal_(0.0, 0.1)
    return model.eval()


@pytest.fixture(scope="module")
def states(samples_dir):
    """Two real graphs, each at its empty canvas and after its first proposal."""
    found = []
    for name in ("Couch.json", "Z0HexagonCutJoin_RootComponent.json"):
        graph = build_zone_graph(list(replay(load_design(samples_dir / name)).bodies), samples=64)
        generator = ProposalGenerator(graph)
        canvas = np.zeros(graph.n_zones, bool)
        for _ in range(2):
            proposals = generator.proposals(canvas)
            found.append((graph, canvas, proposals))
            canvas = proposals[0].apply(canvas)
    return found


def _both(checkpoint: dict, graph, canvas, proposals) -> tuple[np.ndarray, np.ndarray]:
    zones = np.stack([p.zones for p in proposals]).astype(bool)
    ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals])
    features = proposal_features(graph, canvas, proposals, 1)
    folded = NumpyScorer(fold_checkpoint(checkpoint)).score(graph, canvas, zones, ops, features)
    reference = TorchScorer(checkpoint).score(graph, canvas, zones, ops, features)
    return folded, reference


def _forced_within_reach(self, state, zones, fresh=False):
    """`FoldedScorer._reach` without its cost test: the within-reach path whatever it costs."""
    return self._spread(state, zones)


def _never(self, state, zones, fresh=False):
    return None


@requires_samples
@pytest.mark.parametrize(
    "config",
    [
        ModelConfig(use_points=False, features=FEATURES),
        ModelConfig(use_points=True, features=("depth", "union", "step")),
        ModelConfig(use_points=True, rounds=2),
        ModelConfig(use_points=False, features=FEATURES, context=True),
    ],
    ids=["flags+features", "points+features", "points", "flags+features+context"],
)
@pytest.mark.parametrize("path", ["within reach", "every zone"])
def test_a_folded_scorer_scores_real_states_as_pytorch(states, config, path, monkeypatch):
    monkeypatch.setattr(FoldedScorer, "_reach", _forced_within_reach if path == "within reach" else _never)
    monkeypatch.setattr("zonegraph.network.scoring.MAX_NODES", 100)  # PyTorch embeds in chunks, reads whole
    model = _trained_like(config)
    checkpoint = {
        "model": config.__dict__,
        "state_dict": model.state_dict(),
        "train": {"points_per_zone": 16},
    }
    for graph, canvas, proposals in states:
        folded, reference = _both(checkpoint, graph, canvas, proposals)
        assert folded.shape == (len(proposals),)
        error = np.abs(folded - reference).max()
        assert error < 2e-5 and error < 0.01 * np.ptp(reference)  # well below what tells proposals apart


@requires_samples
def test_the_shipped_folded_weights_are_the_shipped_checkpoint_folded(states):
    checkpoint = read_checkpoint(SHIPPED)
    shipped, fresh = FoldedScorer.load(SHIPPED_FOLDED), fold_checkpoint(checkpoint)
    assert shipped.config == fresh.config and shipped.search == fresh.search == checkpoint["search"]
    assert shipped.points_per_zone == checkpoint["train"]["points_per_zone"]
    for mine, theirs in zip(shipped._chains().values(), fresh._chains().values(), strict=True):
        for a, b in zip(sum(mine, ()), sum(theirs, ()), strict=True):
            # torch's float32 BatchNorm arithmetic may round a last bit differently on another CPU
            np.testing.assert_allclose(a.weight, b.weight, rtol=1e-6, atol=1e-7)
            np.testing.assert_allclose(a.bias, b.bias, rtol=1e-6, atol=1e-7)
            assert a.activation == b.activation
    for graph, canvas, proposals in states:
        folded, reference = _both(checkpoint, graph, canvas, proposals)
        np.testing.assert_allclose(folded, reference, atol=2e-5)


def test_what_does_not_fold_stays_on_pytorch(tmp_path):
    with pytest.raises(ValueError, match="only late fusion"):
        fold(_trained_like(ModelConfig(fusion="early")))
    path = tmp_path / "early.pt"
    model = _trained_like(ModelConfig(fusion="factored"))
    torch.save({"model": model.config.__dict__, "state_dict": model.state_dict(), "train": {}}, path)
    assert isinstance(open_scorer(path), TorchScorer)
    assert isinstance(open_scorer(SHIPPED), NumpyScorer)
    assert isinstance(open_scorer(SHIPPED_FOLDED), NumpyScorer)


@requires_samples
def test_a_state_where_a_proposal_completes_the_target_is_ranked_by_the_network_itself(states):
    """The search takes a completing step without asking a ranker (tests/sequence/test_search.py),
    so where the guide ranks such a state (the relative GT rank) its order is the network's own,
    as the paper's: not the heuristic's, which puts every completing proposal first."""
    graph = states[0][0]  # Couch: a box, then a cut
    found = search(graph, HeuristicRanker(), SearchConfig(budget_s=float("inf"), max_expansions=50))
    assert found.exact and len(found.steps) >= 2
    canvas = np.zeros(graph.n_zones, bool)
    for step in found.steps[:-1]:
        canvas = step.apply(canvas)
    proposals = ProposalGenerator(graph).proposals(canvas)
    target = graph.zone_inside.astype(bool)
    assert any(np.array_equal(p.apply(canvas), target) for p in proposals)
    ranker = NetworkRanker(top_m=0)
    scores = ranker.score_at(graph, canvas, proposals, len(found.steps) - 1)
    zones = np.stack([p.zones for p in proposals]).astype(bool)
    ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals])
    features = proposal_features(graph, canvas, proposals, len(found.steps) - 1)
    own = ranker.scorer.score(graph, canvas, zones, ops, features)
    np.testing.assert_allclose(scores, own, rtol=1e-6)
    assert np.all((scores >= 0) & (scores <= 1))


@requires_samples
def test_computing_only_the_zones_within_reach_scores_as_computing_every_zone(states, monkeypatch):
    folded = fold(_trained_like(ModelConfig(use_points=False, features=FEATURES)))
    scorer, paths = NumpyScorer(folded), []
    for graph, canvas, proposals in states:
        zones = np.stack([p.zones for p in proposals]).astype(bool)
        ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals])
        features = proposal_features(graph, canvas, proposals, 0)
        chosen = scorer.score(graph, canvas, zones, ops, features)
        paths.append(folded._reach(scorer._state, zones) is not None)
        with monkeypatch.context() as patch:
            patch.setattr(FoldedScorer, "_reach", _never)
            every = scorer.score(graph, canvas, zones, ops, features)
        np.testing.assert_allclose(chosen, every, atol=1e-6)
    assert any(paths), "no state took the within-reach path: the comparison tests nothing"


@requires_samples
@pytest.mark.parametrize("dense_zones", [0, 10_000], ids=["sparse", "dense"])
def test_the_sparse_and_the_dense_neighbour_mean_score_as_pytorch(states, monkeypatch, dense_zones):
    monkeypatch.setattr("zonegraph.network.folded.DENSE_ZONES", dense_zones)
    config = ModelConfig(use_points=False, features=FEATURES)
    model = _trained_like(config)
    checkpoint = {"model": config.__dict__, "state_dict": model.state_dict(), "train": {}}
    for graph, canvas, proposals in states:
        folded, reference = _both(checkpoint, graph, canvas, proposals)
        assert np.abs(folded - reference).max() < 2e-5


@requires_samples
def test_a_scorer_reading_some_features_scores_without_them_as_pytorch_with_zeros(states):
    config = ModelConfig(use_points=False, features=("depth", "step"))
    model = _trained_like(config)
    checkpoint = {"model": config.__dict__, "state_dict": model.state_dict(), "train": {}}
    graph, canvas, proposals = states[2]
    zones = np.stack([p.zones for p in proposals]).astype(bool)
    ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals])
    folded = NumpyScorer(fold_checkpoint(checkpoint)).score(graph, canvas, zones, ops, None)
    reference = TorchScorer(checkpoint).score(graph, canvas, zones, ops, None)
    np.testing.assert_allclose(folded, reference, atol=2e-5)


@requires_samples
def test_top_m_and_margin_leave_the_network_only_the_heuristics_best_proposals(states):
    graph, canvas, proposals = states[0]  # Couch's empty canvas: no proposal completes it
    heuristic = HeuristicRanker().score(graph, canvas, proposals)
    assert heuristic.max() < 1.0 and len(proposals) > 8
    alone = NetworkRanker(top_m=0).score_at(graph, canvas, proposals, 0)
    assert (alone >= 0).all()  # top_m 0: every proposal scored (None: the checkpoint's own 8)
    top = NetworkRanker(top_m=4).score_at(graph, canvas, proposals, 0)
    best4 = np.argsort(-heuristic, kind="stable")[:4]
    assert set(np.flatnonzero(top >= 0)) == set(best4)
    np.testing.assert_allclose(top[best4], alone[best4], atol=1e-6)  # the same network scores
    margin = float(np.sort(heuristic)[-1] - np.sort(heuristic)[-3]) + 1e-9  # the best three
    within = NetworkRanker(top_m=0, margin=margin).score_at(graph, canvas, proposals, 0)
    assert (within >= 0).sum() == 3
    lone = NetworkRanker(top_m=0, margin=0.0).score_at(graph, canvas, proposals, 0)
    np.testing.assert_array_equal(np.argsort(-lone, kind="stable"), np.argsort(-heuristic, kind="stable"))


@requires_samples
def test_a_deferring_guide_scores_a_state_only_when_the_search_comes_back_for_a_second_choice(states):
    graph, canvas, proposals = states[0]  # Couch's empty canvas: no proposal completes it
    heuristic = HeuristicRanker().score(graph, canvas, proposals)
    ranker = NetworkRanker(defer=True)
    order = ranker.order_at(graph, canvas, proposals, 0, 5)
    assert next(order) == int(np.argmax(heuristic))
    assert not ranker.scorer.loaded, "the heuristic's first choice waited for the network"
    rest = list(order)
    assert ranker.scorer.loaded and len(rest) == 4 and int(np.argmax(heuristic)) not in rest
    scores = NetworkRanker().score_at(graph, canvas, proposals, 0)
    eager = [i for i in np.argsort(-scores, kind="stable") if i != int(np.argmax(heuristic))]
    assert rest == eager[:4]  # the others in the network's order, as the guide without defer
    solved = search(graph, NetworkRanker(defer=True), SearchConfig(budget_s=30.0), ProposalGenerator(graph))
    plain = search(graph, HeuristicRanker(), SearchConfig(budget_s=30.0), ProposalGenerator(graph))
    assert solved.exact and [p.key for p in solved.steps] == [p.key for p in plain.steps]


@requires_samples
def test_a_waking_guide_orders_every_state_by_the_network_once_the_search_backtracked(states):
    graph, canvas, proposals = states[0]
    first_choice = int(np.argmax(HeuristicRanker().score(graph, canvas, proposals)))
    scores = NetworkRanker().score_at(graph, canvas, proposals, 1)
    eager = [int(i) for i in np.argsort(-scores, kind="stable")]
    ranker = NetworkRanker(defer=True, wake=True)
    calls = []
    scorer_score = ranker.scorer.score
    ranker.scorer.score = lambda *args: calls.append(1) or scorer_score(*args)  # type: ignore[method-assign]
    root = ranker.order_at(graph, canvas, proposals, 0, 5)
    assert next(root) == first_choice
    assert next(ranker.order_at(graph, canvas, proposals, 1, 5)) == first_choice and not calls, "asleep"
    next(root)  # the search came back to its first state: it backtracked
    assert len(calls) == 1
    awake = ranker.order_at(graph, canvas, proposals, 1, 5)
    assert next(awake) == eager[0] and len(calls) == 2, "scored before its first choice"
    assert list(awake) == eager[1:5]
    again = ranker.order_at(graph, canvas, proposals, 0, 5)
    assert next(again) == first_choice and len(calls) == 2, "a new search starts asleep"


@requires_samples
def test_a_relaying_guide_orders_by_the_heuristic_and_hands_the_search_the_network(states):
    graph, canvas, proposals = states[0]
    heuristic = np.argsort(-HeuristicRanker().score(graph, canvas, proposals), kind="stable").tolist()
    scores = NetworkRanker().score_at(graph, canvas, proposals, 1)
    eager = [int(i) for i in np.argsort(-scores, kind="stable")]
    ranker = NetworkRanker(relay=7)
    calls = []
    scorer_score = ranker.scorer.score
    ranker.scorer.score = lambda *args: calls.append(1) or scorer_score(*args)  # type: ignore[method-assign]
    assert list(ranker.order_at(graph, canvas, proposals, 1, 5)) == heuristic[:5] and not calls
    after, make = ranker.relay()
    second = make()
    assert after == 7 and second.scorer is ranker.scorer and second.relay() is None
    assert list(second.order_at(graph, canvas, proposals, 1, 5)) == eager[:5] and calls
    assert NetworkRanker().relay() is None  # the shipped guide does not relay


@requires_samples
def test_the_shipped_weights_are_read_on_the_first_state_the_network_scores(states):
    ranker = NetworkRanker()
    assert not ranker.scorer.loaded and ranker.top_m == FoldedScorer.load(SHIPPED_FOLDED).search["top_m"]
    graph = states[0][0]  # Couch: the heuristic's box, then the completing cut, taken unscored
    found = search(graph, ranker, SearchConfig(budget_s=30.0), ProposalGenerator(graph))
    assert found.exact and not ranker.scorer.loaded, "a search that never asked the network read its weights"
    canvas = np.zeros(graph.n_zones, bool)
    proposals = ProposalGenerator(graph).proposals(canvas)
    scores = ranker.score_at(graph, canvas, proposals, 0)
    assert ranker.scorer.loaded
    np.testing.assert_array_equal(scores, NetworkRanker().score_at(graph, canvas, proposals, 0))


def test_a_folded_scorer_missing_its_arrays_is_refused_when_opened(tmp_path):
    path = tmp_path / "cut.npz"
    with np.load(SHIPPED_FOLDED) as data:
        kept = {k: data[k] for k in data.files}
    meta = json.loads(str(kept["meta"]))
    meta["arrays"] = {k: v for k, v in meta["arrays"].items() if not k.startswith("rounds.")}
    np.savez(path, **kept | {"meta": np.array(json.dumps(meta))})
    with pytest.raises(ValueError, match="cut.npz: a folded scorer without the arrays of rounds"):
        NetworkRanker(path)
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(ValueError, match="text.npz: not a folded scorer"):
        NetworkRanker(tmp_path / "text.npz")


def test_the_training_projects_are_kept_beside_a_small_header(tmp_path):
    """A guide reads only the header when it is made; the projects an evaluation must leave out
    (thousands of ids) are their own member, and files that kept them in the header still load."""
    shipped = FoldedScorer.load(SHIPPED_FOLDED)
    assert len(shipped.train_projects) > 1000
    assert "train_projects" not in FoldedScorer.header(SHIPPED_FOLDED)
    with np.load(SHIPPED_FOLDED) as data:
        arrays = {k: data[k] for k in data.files if k != "train_projects"}
    meta = json.loads(str(arrays["meta"])) | {"train_projects": list(shipped.train_projects)}
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "older.npz", **arrays)
    assert FoldedScorer.load(tmp_path / "older.npz").train_projects == shipped.train_projects


def test_the_layers_are_one_member_and_files_of_one_member_per_array_still_load(tmp_path):
    """A guide reads the weights while it searches: one flat member instead of one per array
    (a zip lookup and a header parse each). Files saved before keep loading to the same scorer."""
    shipped = FoldedScorer.load(SHIPPED_FOLDED)
    with np.load(SHIPPED_FOLDED) as data:
        assert set(data.files) == {"meta", "weights", "train_projects"}
        meta = json.loads(str(data["meta"]))
        weights, projects = data["weights"], data["train_projects"]
    per_array = {}
    for name, (offset, shape) in meta.pop("arrays").items():
        per_array[name] = weights[offset : offset + int(np.prod(shape))].reshape(shape)
    np.savez(tmp_path / "older.npz", meta=np.array(json.dumps(meta)), train_projects=projects, **per_array)
    older = FoldedScorer.load(tmp_path / "older.npz")
    for a, b in zip(_layers(shipped), _layers(older), strict=True):
        assert np.array_equal(a.weight, b.weight) and np.array_equal(a.bias, b.bias)
    assert older.train_projects == shipped.train_projects
    assert FoldedScorer.load(SHIPPED_FOLDED, projects=False).train_projects == ()


def _layers(scorer: FoldedScorer) -> list:
    return [layer for chains in scorer._chains().values() for chain in chains for layer in chain]


@requires_samples
def test_a_guide_with_a_call_budget_takes_the_heuristics_order_once_it_is_spent(states):
    graph, canvas, proposals = states[0]
    heuristic = np.argsort(-HeuristicRanker().score(graph, canvas, proposals), kind="stable").tolist()

    def eager(step: int) -> list[int]:
        scores = NetworkRanker().score_at(graph, canvas, proposals, step)
        return [int(i) for i in np.argsort(-scores, kind="stable")][:5]

    assert eager(1) != heuristic[:5], "the network's order is the heuristic's: the test tells nothing"
    ranker = NetworkRanker(defer=False, calls=2)
    calls = []
    scorer_score = ranker.scorer.score
    ranker.scorer.score = lambda *args: calls.append(1) or scorer_score(*args)  # type: ignore[method-assign]
    assert list(ranker.order_at(graph, canvas, proposals, 0, 5)) == eager(0)
    assert list(ranker.order_at(graph, canvas, proposals, 1, 5)) == eager(1) and len(calls) == 2
    assert list(ranker.order_at(graph, canvas, proposals, 1, 5)) == heuristic[:5] and len(calls) == 2
    assert list(ranker.order_at(graph, canvas, proposals, 0, 5)) == eager(0), "a new search scores again"
    deferring = NetworkRanker(defer=True, calls=0)  # the heuristic's order throughout: no call at all
    assert list(deferring.order_at(graph, canvas, proposals, 0, 5)) == heuristic[:5]
    assert not deferring.scorer.loaded


@requires_samples
def test_a_state_s_codes_updated_from_the_last_state_are_its_codes_computed_afresh(states, monkeypatch):
    monkeypatch.setattr(FoldedScorer, "_reach", _forced_within_reach)
    folded = fold(_trained_like(ModelConfig(use_points=False, features=FEATURES)))
    updated = 0
    for graph, canvas, proposals in states:
        state = State.of(graph.zone_inside, canvas, graph.edges.astype(np.int64))
        walk = [canvas] + [p.apply(canvas) for p in proposals[:6]] + [canvas, canvas]
        zones = np.stack([p.zones for p in proposals[:4]]).astype(bool)
        ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals[:4]], np.float32)
        memo = CodeMemo()
        for before, after in itertools.pairwise(walk):
            folded.score(state.with_canvas(before), zones, ops, memo=memo)
            last = memo.last
            assert last is not None
            updated += folded._update_reach(state.with_canvas(after), last) is not None
            kept = folded.score(state.with_canvas(after), zones, ops, memo=memo)
            fresh_memo = CodeMemo()
            fresh = folded.score(state.with_canvas(after), zones, ops, memo=fresh_memo)
            np.testing.assert_allclose(kept, fresh, atol=1e-6)
            assert memo.last is not None and fresh_memo.last is not None
            for mine, theirs in zip(memo.last.layers, fresh_memo.last.layers, strict=True):
                np.testing.assert_allclose(mine, theirs, atol=1e-6)
    assert updated, "every step computed every zone: the update was never tested"


def test_the_greatest_code_a_proposal_left_untouched_is_found_among_each_channels_best_zones():
    rng = np.random.default_rng(0)
    codes = rng.normal(size=(40, 6)).astype(np.float32)
    reached = rng.random((30, 40)) < np.linspace(0.0, 1.0, 30)[:, None]  # none reached ... all
    reached[-1] = True
    reached[5, np.argsort(-codes[:, 2])[:20]] = True  # every one of channel 2's best 16 zones
    expected = np.stack([codes[~r].max(axis=0) if (~r).any() else np.full(6, -np.inf) for r in reached])
    for top in (1, 16, 40):
        np.testing.assert_array_equal(_max_elsewhere(codes, reached, top), expected)


def _seeded(config: ModelConfig, seed: int) -> FoldedScorer:
    model, generator = _trained_like(config), torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for parameter in model.parameters():  # members of one recipe, other seeds
            parameter.add_(0.2 * torch.randn(parameter.shape, generator=generator))
    return fold(model)


@requires_samples
@pytest.mark.parametrize(
    "config",
    [
        ModelConfig(use_points=False, features=FEATURES, hidden=16),
        ModelConfig(use_points=True, features=("depth", "union"), hidden=16, context=True),
        ModelConfig(use_points=True, rounds=2, hidden=16),
    ],
    ids=["flags+features", "points+features+context", "points"],
)
def test_an_ensemble_side_by_side_scores_the_mean_log_odds_of_its_members(states, config):
    from zonegraph.network.ensemble import side_by_side

    members = [_seeded(config, seed) for seed in range(3)]
    ensemble = side_by_side(members)
    assert ensemble.config["hidden"] == 48 and ensemble.config["members"] == 3
    for graph, canvas, proposals in states:
        zones = np.stack([p.zones for p in proposals]).astype(bool)
        ops = np.array([1 if p.op is Op.UNION else -1 for p in proposals], np.float32)
        features = proposal_features(graph, canvas, proposals, 1)
        state = State.of(graph.zone_inside, canvas, graph.edges.astype(np.int64))
        samples = zone_samples(graph, 16) if config.use_points else None
        geometry = [None if samples is None else m.encode_geometry(samples) for m in [*members, ensemble]]
        log_odds = [
            m.log_odds(m.embed(state, zones, ops, codes, features))
            for m, codes in zip([*members, ensemble], geometry, strict=True)
        ]
        assert np.abs(np.mean(log_odds[:3], axis=0) - log_odds[3]).max() < 1e-4 * np.abs(log_odds[3]).max()
        assert np.abs(log_odds[0] - log_odds[1]).max() > 0.01  # the members disagree: the mean is tested


def test_members_of_different_architectures_make_no_ensemble():
    from zonegraph.network.ensemble import side_by_side

    flags = _seeded(ModelConfig(use_points=False, hidden=16), 0)
    with pytest.raises(ValueError, match="use_points"):
        side_by_side([flags, _seeded(ModelConfig(use_points=True, hidden=16), 1)])
    with pytest.raises(ValueError, match="two members"):
        side_by_side([flags])


def test_fold_writes_one_checkpoint_or_several_as_one_ensemble(tmp_path, capsys):
    from training.fold import main

    config = ModelConfig(use_points=False, features=FEATURES, hidden=16)
    paths = []
    for seed in range(2):
        model, generator = _trained_like(config), torch.Generator().manual_seed(seed)
        with torch.no_grad():
            for parameter in model.parameters():
                parameter.add_(0.2 * torch.randn(parameter.shape, generator=generator))
        paths.append(tmp_path / f"seed{seed}" / "scorer.pt")
        paths[-1].parent.mkdir()
        torch.save({"model": config.__dict__, "state_dict": model.state_dict()}, paths[-1])
    main([str(paths[0])])
    assert FoldedScorer.load(paths[0].with_suffix(".npz")).config["hidden"] == 16
    with pytest.raises(SystemExit, match="needs --out"):
        main([str(p) for p in paths])
    main([*map(str, paths), "--out", str(tmp_path / "ensemble" / "scorer.npz")])
    ensemble = FoldedScorer.load(tmp_path / "ensemble" / "scorer.npz")
    assert (ensemble.config["hidden"], ensemble.config["members"]) == (32, 2)
    assert "seed0/scorer.pt + " in capsys.readouterr().out
