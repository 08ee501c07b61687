"""The scorer, its data and training on labels of real samples, MLflow tracking, the network guide."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
import torch
from torch_geometric.loader import DataLoader

from eval.heldout import held_out, trained_projects
from pipelines.ablations import default_specs, train_variant, variant, variants
from training.card import card
from training.data import LabelDataset
from training.loss import focal_loss
from training.train import TrainConfig, forward, train
from zonegraph.data.dataset import project_of
from zonegraph.data.design import load_design
from zonegraph.data.replay import replay
from zonegraph.jobs import label_and_save
from zonegraph.network.checkpoint import SHIPPED, load_scorer
from zonegraph.network.encoding import geometry_of, state_data
from zonegraph.network.model import ModelConfig, ProposalScorer
from zonegraph.sequence.best_first import SearchConfig, search
from zonegraph.sequence.ground_truth import ground_truth
from zonegraph.sequence.proposals import ProposalGenerator
from zonegraph.sequence.rankers import make_ranker, relative_rank
from zonegraph.testing import gt_rows, requires_samples
from zonegraph.testing.mlflow_server import mlflow_server, search_runs
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.storage import save_zone_graph

SAMPLES = [
    "Couch.json",
    "Pattern4-SteppedStartEndFace_17dd857d_0000.json",
    "Z0HexagonCutJoin_RootComponent.json",
]


def test_focal_loss_is_cross_entropy_at_gamma_zero_and_discounts_easy_examples():
    logits = torch.tensor([[2.0, -1.0], [0.1, 0.3], [-3.0, 3.0]])
    target = torch.tensor([0, 1, 1])
    ce = torch.nn.functional.cross_entropy(logits, target)
    assert torch.isclose(focal_loss(logits, target, 0.0), ce)
    assert focal_loss(logits, target, 2.0) < focal_loss(logits, target, 0.5) < ce
    sure = torch.tensor([[40.0, -40.0], [0.0, 1.0]], requires_grad=True)  # p of the first rounds to 1
    focal_loss(sure, torch.tensor([0, 1]), 0.5).backward()
    assert torch.isfinite(sure.grad).all()  # the slope of (1 - p)^0.5 at p = 1 made it NaN


def test_a_nan_score_ranks_last():
    assert relative_rank(np.array([np.nan, 0.2, 0.1]), np.array([True, False, False])) == 1.0
    assert relative_rank(np.array([0.5, np.nan, np.nan]), np.array([True, False, False])) == 1 / 3


def _quick(labelled, **overrides) -> TrainConfig:
    """A one-epoch CPU run on the labelled samples' shards, with ``overrides``."""
    settings = dict(
        labels_dir=str(labelled / "labels"),
        graphs_dir=str(labelled / "graphs"),
        epochs=1,
        val_fraction=0.34,
        points_per_zone=16,
        batch_states=4,
        device="cpu",
    )
    return TrainConfig(**{**settings, **overrides})


@pytest.fixture(scope="module")
def labelled(samples_dir, tmp_path_factory):
    """Zone graphs (32 samples per zone) and labels of three real samples, as the stages write them."""
    root = tmp_path_factory.mktemp("labelled")
    for name in SAMPLES:
        r = replay(load_design(samples_dir / name))
        graph = build_zone_graph(list(r.bodies), samples=32)
        design_id = name.split(".")[0]
        save_zone_graph(graph, root / "graphs" / design_id)
        gt = ground_truth(
            graph, [s.tool.wrapped for s in r.steps], [s["operation"] for s in r.summary()["steps"]]
        )
        rows = gt_rows(gt.steps)
        label_and_save(str(root / "graphs" / design_id), rows, design_id, "train", str(root / "labels"))
    return root


@requires_samples
def test_both_fusions_score_and_eval_scores_do_not_depend_on_the_batch(labelled):
    data = LabelDataset(labelled / "labels", labelled / "graphs", mode="rank", points_per_zone=16)
    assert len(data) >= 3 and all(int(d.is_gt.sum()) == 1 for d in data)
    state = max(data.states, key=lambda s: len(s.labels))
    geometry = data.geometry[state.design_id]
    canvas = torch.from_numpy(state.canvas)

    def batch(rows: slice):
        zones, ops = torch.from_numpy(state.zones[rows]), torch.from_numpy(state.ops[rows])
        return next(iter(DataLoader([state_data(geometry, canvas, zones, ops)], batch_size=1)))

    for fusion in ("late", "early", "factored"):
        torch.manual_seed(0)
        model = ProposalScorer(ModelConfig(fusion=fusion))
        assert forward(model, batch(slice(None))).shape == (len(state.labels), 2)
        model.eval()  # the original scored in training mode: a score depended on its batch
        with torch.no_grad():
            together = forward(model, batch(slice(None))).softmax(1)[:, 1]
            alone = forward(model, batch(slice(0, 1))).softmax(1)[:, 1]
        assert torch.allclose(together[0], alone[0], atol=1e-5)


@requires_samples
def test_a_training_state_keeps_a_seeded_sample_of_its_negatives_or_every_proposal(labelled):
    every = LabelDataset(labelled / "labels", labelled / "graphs", points_per_zone=16, max_proposals=None)
    state = max(range(len(every)), key=lambda i: len(every.states[i].labels))
    negatives = int((every.states[state].labels == -1).sum())
    assert negatives > 4
    sampled = LabelDataset(labelled / "labels", labelled / "graphs", points_per_zone=16, max_proposals=4)
    assert len(sampled.get(state).y) == 4 and int(sampled.get(state).y.sum()) == 1
    assert len(every.get(state).y) == negatives + 1
    zones = every.states[state].zones.shape[1]
    bounded = LabelDataset(
        labelled / "labels", labelled / "graphs", points_per_zone=16, max_proposals=None, max_nodes=3 * zones
    )
    assert len(bounded.get(state).y) == 3 and int(bounded.get(state).y.sum()) == 1  # 3 copies of the graph


@requires_samples
def test_training_reads_only_the_shards_the_labels_records_list_as_ok_and_intact(labelled, tmp_path):
    import shutil

    from pipelines.records import hash_output
    from training.shards import label_shards

    labels = tmp_path / "labels"
    shutil.copytree(labelled / "labels", labels)
    ok, damaged, failed = (name.split(".")[0] for name in SAMPLES)
    shards = {d: [labels / k / f"{d}.parquet" for k in ("proposals", "steps")] for d in (ok, damaged, failed)}
    (labels / "records").mkdir()
    for d, status in ((ok, "ok"), (damaged, "ok"), (failed, "timeout")):
        record = {"design_id": d, "status": status, "outputs": [hash_output(p) for p in shards[d]]}
        (labels / "records" / f"{d}.json").write_text(json.dumps(record))
    steps = shards[damaged][1]
    steps.write_bytes(steps.read_bytes()[: steps.stat().st_size // 2])  # a half-written shard
    for kind in ("proposals", "steps"):  # a stray shard of an earlier run, without a record
        shutil.copy(labels / kind / f"{ok}.parquet", labels / kind / "stray.parquet")
    with pytest.warns(UserWarning, match="6 label shards left out"):
        found = label_shards(labels)
    assert found.design_ids == [ok]
    assert (
        found.left_out[f"steps/{damaged}.parquet"]
        == f"steps/{damaged}.parquet differs from its record (size or SHA-1)"
    )
    assert found.left_out[f"proposals/{failed}.parquet"] == "its record is not ok (timeout)"
    assert found.left_out["steps/stray.parquet"] == "no readable record in records/"
    with pytest.warns(UserWarning):
        data = LabelDataset(labels, labelled / "graphs", mode="rank", points_per_zone=16)
    assert {s.design_id for s in data.states} == {ok}

    shutil.rmtree(labels / "records")  # shards written without the stage: each must read
    with pytest.warns(UserWarning, match="2 label shards left out"):
        found = label_shards(labels)
    assert found.design_ids == sorted([ok, failed, "stray"])
    assert (
        found.left_out[f"steps/{damaged}.parquet"]
        == f"steps/{damaged}.parquet is not a readable Parquet file"
    )


@pytest.mark.slow
@requires_samples
def test_training_logs_to_mlflow_and_the_network_guides_search(labelled, tmp_path, monkeypatch, samples_dir):
    monkeypatch.chdir(tmp_path)
    config = _quick(labelled, out_dir="models", epochs=2, seed=0)
    best = train(config)
    metrics = json.loads((tmp_path / "models" / "best.json").read_text())
    assert metrics["epoch"] == best["epoch"] and 0 < metrics["val_rank"] <= 1
    shared = json.loads((tmp_path / "models" / "metrics.json").read_text())
    assert set(shared) == {"designs", "seconds", "rank"} and shared["rank"] == round(best["val_rank"], 3)
    assert (tmp_path / "models" / "curve.png").stat().st_size > 1000
    assert load_scorer(tmp_path / "models" / "scorer.pt").training is False
    checkpoint = torch.load(tmp_path / "models" / "scorer.pt", weights_only=True)
    assert checkpoint["provenance"]["run_id"] == metrics["run_id"]
    text = card(checkpoint, tmp_path / "models" / "scorer.pt", {"heuristic": 0.3})
    assert f"validation relative GT rank **{metrics['val_rank']:.4f}**" in text
    assert checkpoint["provenance"]["data_version"] in text and "heuristic 0.3000" in text
    # The checkpoint names the projects it trained on, and evaluation leaves their designs out.
    seen, silent = trained_projects([tmp_path / "models" / "scorer.pt"])
    ids = [name.split(".")[0] for name in SAMPLES]
    assert not silent and seen == {project_of(i) for i in ids}
    assert held_out([*ids, "unseen_project_0000"], seen) == ["unseen_project_0000"]
    # The run is visible through a real MLflow server's REST API.
    with mlflow_server(tmp_path) as url:
        runs = search_runs(url, "zonegraph-scorer")
    run = next(r for r in runs if r["info"]["run_id"] == metrics["run_id"])
    names = {m["key"] for m in run["data"]["metrics"]}
    assert {"loss/train", "loss/val", "val/rank", "val/normalised", "best/val_rank"} <= names
    assert run["info"]["run_name"].startswith("late focal")
    tags = {t["key"]: t["value"] for t in run["data"]["tags"]}
    assert len(tags["data_version"]) == 12 and tags["git_commit"]
    # The network guide: a ranker the core reaches by reference, without importing torch.
    ranker = make_ranker("net", model=str(tmp_path / "models" / "scorer.pt"))
    graph = build_zone_graph(list(replay(load_design(samples_dir / "Couch.json")).bodies), samples=128)
    proposals = ProposalGenerator(graph).proposals(np.zeros(graph.n_zones, bool))
    scores = ranker.score(graph, np.zeros(graph.n_zones, bool), proposals)
    assert scores.shape == (len(proposals),) and ((scores >= 0) & (scores <= 1)).all()
    result = search(graph, ranker, SearchConfig(budget_s=float("inf"), max_expansions=30))
    assert result.expansions > 0 and result.iou > 0


def test_geometry_of_keeps_seeded_samples_and_both_edge_directions(samples_dir):
    graph = build_zone_graph(list(replay(load_design(samples_dir / "Couch.json")).bodies), samples=64)
    a, b = geometry_of(graph, 16, seed=1), geometry_of(graph, 16, seed=1)
    assert a.points.shape == (graph.n_zones, 6, 16) and torch.equal(a.points, b.points)
    assert a.edge_index.shape == (2, 2 * len(graph.edges))


@requires_samples
@pytest.mark.parametrize("fusion", ["early", "late"])
def test_a_state_scored_in_chunks_scores_as_in_one_pass(samples_dir, monkeypatch, fusion):
    from zonegraph.network import scoring

    graph = build_zone_graph(list(replay(load_design(samples_dir / "Couch.json")).bodies), samples=16)
    canvas = np.zeros(graph.n_zones, bool)
    proposals = ProposalGenerator(graph).proposals(canvas)
    zones = torch.from_numpy(np.stack([p.zones for p in proposals]))
    ops = torch.tensor([int(p.op) for p in proposals])
    torch.manual_seed(0)
    model = ProposalScorer(ModelConfig(fusion)).eval()
    args = (model, geometry_of(graph, 16), torch.from_numpy(canvas), zones, ops, torch.device("cpu"))
    whole = scoring.score_state(*args)
    monkeypatch.setattr(scoring, "MAX_POINTS", graph.n_zones * 16 * 2)  # two proposals per pass
    monkeypatch.setattr(scoring, "MAX_NODES", graph.n_zones * 2)
    assert scoring.chunk_size(model, geometry_of(graph, 16)) == 2 < len(proposals)
    assert np.allclose(scoring.score_state(*args), whole, atol=1e-6)


@requires_samples
def test_the_shipped_checkpoint_guides_without_a_model_path_and_has_its_card(samples_dir):
    checkpoint = torch.load(SHIPPED, weights_only=True)
    assert SHIPPED.stat().st_size < 5e6
    card_text = (SHIPPED.parent / "MODEL_CARD.md").read_text()
    assert (
        f"{checkpoint['metrics']['val_rank']:.4f}" in card_text
        and checkpoint["provenance"]["run_id"] in card_text
    )
    ranker = make_ranker("net")  # no --model: the shipped weights
    assert ranker.samples == checkpoint["train"]["points_per_zone"]
    graph = build_zone_graph(
        list(replay(load_design(samples_dir / "Couch.json")).bodies), samples=ranker.samples
    )
    result = search(graph, ranker, SearchConfig(budget_s=float("inf"), max_expansions=50))
    assert result.exact  # Couch: a box and a cut


@requires_samples
def test_an_ablation_variant_trains_once_then_is_reused(labelled, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = _quick(labelled, experiment="ablations")
    configs = variants(base, [0])
    assert list(configs) == ["rounds0", "rounds3_no_points"] and not configs["rounds3_no_points"].use_points
    path = train_variant("rounds0", configs["rounds0"], tmp_path / "out")
    assert torch.load(path, weights_only=True)["model"]["rounds"] == 0
    written = path.stat().st_mtime_ns
    assert train_variant("rounds0", configs["rounds0"], tmp_path / "out").stat().st_mtime_ns == written
    other = train_variant(
        "rounds0", replace(configs["rounds0"], lr=configs["rounds0"].lr * 10), tmp_path / "out"
    )
    assert other.stat().st_mtime_ns != written  # another config: trained again
    stamp = path.parent / "config.json"
    older = {k: v for k, v in json.loads(stamp.read_text()).items() if k != "context"}
    stamp.write_text(json.dumps({**older, "lr": configs["rounds0"].lr}))  # before `context` existed
    written = path.stat().st_mtime_ns
    assert train_variant("rounds0", configs["rounds0"], tmp_path / "out").stat().st_mtime_ns == written


def test_an_ablation_variant_is_the_base_with_its_changes_each_alone_and_combined():
    from zonegraph.sequence.features import FEATURES, PROPOSAL_FEATURES

    base = TrainConfig(loss="focal", features=(), fusion="late", use_points=True, rounds=3)
    combined = variant(base, "listwise+features+early+no_points+rounds1")
    assert (combined.loss, combined.features, combined.fusion) == ("listwise", PROPOSAL_FEATURES, "early")
    assert variant(base, "state_features").features == FEATURES
    assert variant(base, "context").model.context and not base.model.context
    assert (combined.use_points, combined.rounds) == (False, 1)
    assert variant(base, "base") == base and variant(combined, "focal").neutral_credit is None
    specs = default_specs(base, [1, 3])
    assert specs[:6] == ["base", "listwise", "features", "early", "no_points", "rounds1"]
    assert "listwise+features+early" in specs and "rounds3" not in specs
    with pytest.raises(SystemExit, match="unknown change 'deep'"):
        variant(base, "listwise+deep")
    student = variant(base, "listwise+hidden48+teacher", teacher=("teacher.pt",))
    assert (student.hidden, student.teacher, student.model.hidden) == (48, ("teacher.pt",), 48)
    with pytest.raises(SystemExit, match="--teacher"):
        variant(base, "listwise+teacher")


def test_listwise_loss_is_a_softmax_over_each_state_with_the_gt_as_target():
    from training.loss import listwise_loss

    logits = torch.tensor([[0.0, 2.0], [0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [0.0, 0.0]], requires_grad=True)
    state = torch.tensor([0, 0, 0, 1, 1])
    gt = torch.tensor([1.0, 0, 0, 0, 1])
    loss = listwise_loss(logits, state, gt)
    score = logits[:, 1] - logits[:, 0]
    expected = -(torch.log_softmax(score[:3], 0)[0] + torch.log_softmax(score[3:], 0)[1]) / 2
    assert torch.allclose(loss, expected)
    loss.backward()
    assert logits.grad[0, 1] < 0 < logits.grad[1, 1]  # the GT's score goes up, the others' down
    credit = listwise_loss(logits, state, torch.tensor([1.0, 0.5, 0, 0, 1]))
    assert credit > loss  # a neutral sharing the target: the GT alone on top is no longer ideal
    assert (
        listwise_loss(logits, state, torch.tensor([0.0, 0, 0, 0, 1])) == -torch.log_softmax(score[3:], 0)[1]
    )


def test_a_distilled_target_mixes_the_gt_with_the_teachers_softmax_per_state():
    from training.loss import distilled_weight, listwise_loss

    state = torch.tensor([0, 0, 0, 1, 1])
    teacher = torch.tensor([[0.0, 2.0], [0.0, 0.0], [0.0, 1.0], [0.0, 3.0], [0.0, 1.0]])
    gt = torch.tensor([0.0, 1, 0, 0, 0])  # the second state has no GT among its proposals
    target = distilled_weight(gt, teacher, state, 0.25, 2.0)
    taught = torch.cat(
        [torch.softmax(torch.tensor([2.0, 0, 1]) / 2, 0), torch.softmax(torch.tensor([3.0, 1]) / 2, 0)]
    )
    assert torch.allclose(target, 0.75 * torch.tensor([0.0, 1, 0, 0, 0]) + 0.25 * taught)
    assert torch.allclose(distilled_weight(gt, teacher, state, 0.0, 2.0), torch.tensor([0.0, 1, 0, 0, 0]))
    logits = torch.zeros(5, 2, requires_grad=True)
    listwise_loss(logits, state, target).backward()
    assert logits.grad[3, 1] < 0 < logits.grad[4, 1]  # a state without a GT learns the teacher's order


@requires_samples
def test_a_narrow_student_learns_from_a_teacher_folds_and_owns_its_projects(labelled, tmp_path, monkeypatch):
    from zonegraph.network.checkpoint import fold_checkpoint, read_checkpoint
    from zonegraph.sequence.features import FEATURES

    monkeypatch.chdir(tmp_path)
    common = dict(loss="listwise", features=FEATURES, use_points=False)
    train(_quick(labelled, **common, out_dir="teacher"))
    teacher = read_checkpoint(tmp_path / "teacher" / "scorer.pt")
    teacher["provenance"]["train_projects"].append("elsewhere")  # a project only the teacher saw
    torch.save(teacher, tmp_path / "teacher" / "scorer.pt")
    train(_quick(labelled, **common, out_dir="second", seed=1))
    second = read_checkpoint(tmp_path / "second" / "scorer.pt")
    second["provenance"]["train_projects"].append("only-the-second")
    torch.save(second, tmp_path / "second" / "scorer.pt")
    teachers = (str(tmp_path / "teacher" / "scorer.pt"), str(tmp_path / "second" / "scorer.pt"))
    train(_quick(labelled, **common, out_dir="student", hidden=16, teacher=teachers))
    student = read_checkpoint(tmp_path / "student" / "scorer.pt")
    assert student["model"]["hidden"] == 16 and list(student["train"]["teacher"]) == list(teachers)
    assert {"elsewhere", "only-the-second"} <= set(student["provenance"]["train_projects"])
    folded = fold_checkpoint(student)
    assert folded.rounds[0][0].weight.shape == (32, 16)
    with pytest.raises(SystemExit, match="loss listwise"):
        _quick(
            labelled, **{**common, "loss": "focal"}, teacher=teachers
        ).check()
    one = TrainConfig.from_mapping({"teacher": teachers[0]}, strict=True)  # params.yaml: one path
    assert one.teacher == (teachers[0],)

    # an ensemble teaches its mean logits, so its log-odds are the mean of its members'
    from torch_geometric.loader import DataLoader

    from training.train import forward, load_teacher, teach

    (first, other), _ = load_teacher(_quick(labelled, **common, teacher=teachers), torch.device("cpu"))
    data = LabelDataset(labelled / "labels", labelled / "graphs", mode="train", points_per_zone=16)
    batch = next(iter(DataLoader(data, batch_size=4)))
    with torch.no_grad():
        one, two = forward(first, batch), forward(other, batch)
    assert torch.allclose(teach((first,), batch), one) and torch.allclose(teach((first, first), batch), one)
    assert torch.allclose(teach((first, other), batch), (one + two) / 2) and not torch.allclose(one, two)


@requires_samples
def test_proposal_features_reach_the_scorer_and_change_its_scores(labelled):
    from zonegraph.sequence.features import FEATURES

    data = LabelDataset(labelled / "labels", labelled / "graphs", mode="rank", points_per_zone=16)
    assert data.has_features
    state = max(data.states, key=lambda s: len(s.labels))
    assert state.features.shape == (len(state.labels), len(FEATURES)) and state.features.any()
    batch = next(iter(DataLoader([data.get(data.states.index(state))], batch_size=1)))
    torch.manual_seed(0)
    model = ProposalScorer(ModelConfig(features=FEATURES)).eval()
    with torch.no_grad():
        plain = forward(model, batch)
        batch.feat = batch.feat + 1.0
        shifted = forward(model, batch)
    assert not torch.allclose(plain, shifted)
    with pytest.raises(ValueError, match="unknown proposal feature"):
        ProposalScorer(ModelConfig(features=("nope",)))


@pytest.mark.slow
@requires_samples
def test_a_stopped_run_resumes_from_its_last_epoch_in_the_same_mlflow_run(labelled, tmp_path, monkeypatch):
    import mlflow

    from zonegraph.sequence.features import FEATURES

    monkeypatch.chdir(tmp_path)
    base = _quick(
        labelled, epochs=2, batch_states=2, loss="listwise", neutral_credit=0.3, features=FEATURES, rounds=1
    )
    train(replace(base, out_dir="broken", epochs=1))
    after_one = torch.load(tmp_path / "broken" / "last.pt", weights_only=True)
    train(replace(base, out_dir="broken"))  # the same settings, more epochs: continues
    broken = torch.load(tmp_path / "broken" / "last.pt", weights_only=True)
    assert broken["epoch"] == 2 and broken["run_id"] == after_one["run_id"]
    assert broken["curve"][0] == after_one["curve"][0] and [r["epoch"] for r in broken["curve"]] == [1, 2]
    # Two unbroken CPU runs already differ by ~1e-2 (threaded float reductions, amplified by Adam),
    # so the weights cannot be compared with an unbroken run's; the resumed epoch trained on them.
    moved = max(
        float((broken["model"][k].float() - t.float()).abs().max()) for k, t in after_one["model"].items()
    )
    assert moved > 1e-3
    client = mlflow.tracking.MlflowClient(tracking_uri="sqlite:///mlflow.db")
    history = client.get_metric_history(broken["run_id"], "val/normalised")
    assert sorted(m.step for m in history) == [1, 2]  # one MLflow run across the interruption
    assert json.loads((tmp_path / "broken" / "best.json").read_text())["run_id"] == broken["run_id"]
    train(replace(base, out_dir="broken", lr=0.01), fresh=False)  # other settings: a new run
    assert torch.load(tmp_path / "broken" / "last.pt", weights_only=True)["run_id"] != broken["run_id"]


@requires_samples
def test_a_cosine_rate_ends_at_rest_and_resumes_where_a_killed_run_stopped(labelled, tmp_path, monkeypatch):
    import training.train as training_run

    monkeypatch.chdir(tmp_path)
    config = _quick(labelled, epochs=2, batch_states=1, loss="listwise", rounds=1, lr_schedule="cosine")
    ranked = training_run.rank_places
    calls = []

    def killed_in_epoch_two(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt  # a kill after epoch 1's state was saved
        return ranked(*args, **kwargs)

    monkeypatch.setattr(training_run, "rank_places", killed_in_epoch_two)
    with pytest.raises(KeyboardInterrupt):
        train(config)
    stopped = torch.load(tmp_path / "models" / "last.pt", weights_only=True)
    batches = stopped["scheduler"]["last_epoch"]
    assert stopped["epoch"] == 1 and batches > 1
    assert 0.4 * config.lr < stopped["optimiser"]["param_groups"][0]["lr"] < config.lr  # half way down
    train(config)  # resumes epoch 2 on the saved schedule
    done = torch.load(tmp_path / "models" / "last.pt", weights_only=True)
    assert done["epoch"] == 2 and done["run_id"] == stopped["run_id"]
    assert done["scheduler"]["last_epoch"] == 2 * batches
    assert done["optimiser"]["param_groups"][0]["lr"] < 1e-9  # at rest after the last batch
    train(replace(config, epochs=3))  # the epoch count shapes the schedule: a new run, not more of this one
    assert torch.load(tmp_path / "models" / "last.pt", weights_only=True)["run_id"] != done["run_id"]
    with pytest.raises(SystemExit, match="lr_schedule"):
        train(replace(config, lr_schedule="step"))


@requires_samples
def test_a_holdout_of_training_projects_is_never_trained_on_and_is_what_the_bench_searches(
    labelled, tmp_path, monkeypatch
):
    import pandas as pd

    from bench.guide_cost_bench import chosen_designs
    from eval.heldout import holdout_projects
    from eval.rank import main as rank_main
    from zonegraph.network.checkpoint import fold_checkpoint, read_checkpoint
    from zonegraph.network.folded import FoldedScorer

    monkeypatch.chdir(tmp_path)
    config = _quick(labelled, out_dir="held", loss="listwise", use_points=False)
    train(replace(config, holdout_fraction=0.34, holdout_seed=3))
    checkpoint = read_checkpoint(tmp_path / "held" / "scorer.pt")
    provenance = checkpoint["provenance"]
    everything = {project_of(d.stem) for d in (labelled / "graphs").iterdir()}
    held, seen = set(provenance["holdout_projects"]), set(provenance["train_projects"])
    assert len(held) == 1 and not held & seen and held | seen == everything
    assert provenance["holdout_designs"] == 1 and "held out of training" in card(checkpoint, tmp_path)
    fold_checkpoint(checkpoint).save(tmp_path / "held.npz")
    assert FoldedScorer.load(tmp_path / "held.npz").holdout_projects == tuple(held)
    assert holdout_projects([tmp_path / "held.npz"]) == held

    designs = sorted(d.name for d in (labelled / "graphs").iterdir())
    gt = tmp_path / "gt"
    gt.mkdir()
    table = {"design_id": designs, "split": "train", "folder": "samples", "steps": 2}
    pd.DataFrame(table).to_parquet(gt / "designs.parquet")
    chosen = chosen_designs(gt, labelled / "graphs", [str(tmp_path / "held.npz")], 10, 0, split="holdout")
    assert [project_of(d) for d in chosen["design_id"]] == sorted(held)
    assert chosen_designs(gt, labelled / "graphs", [], 10, 0, min_gt=3).empty
    rank_main(
        ["--labels", str(labelled / "labels"), "--graphs", str(labelled / "graphs"), "--split", "holdout"]
        + ["--guides", "heuristic", "--model", str(tmp_path / "held.npz"), "--out", str(tmp_path / "rank")]
    )
    ranked = pd.read_parquet(tmp_path / "rank" / "ranks.parquet")
    assert {project_of(d) for d in ranked["design_id"]} == held

    train(replace(config, out_dir="whole"))  # no holdout: nothing to evaluate on, said in one line
    with pytest.raises(SystemExit, match="no held-out projects"):
        holdout_projects([tmp_path / "whole" / "scorer.pt"])
    taught = replace(config, out_dir="student", teacher=(str(tmp_path / "whole" / "scorer.pt"),))
    with pytest.raises(SystemExit, match="teacher trained on 1 of the held-out projects"):
        train(replace(taught, holdout_fraction=0.34, holdout_seed=3))


def test_a_run_records_the_commit_of_its_code_wherever_it_runs_from(tmp_path, monkeypatch):
    import subprocess

    from training.train import git_commit

    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True)
    monkeypatch.chdir(tmp_path)  # no git checkout here
    assert git_commit() == head.stdout.strip()


def test_holdouts_drawn_with_two_seeds_are_independent_draws_of_about_their_share():
    from training.train import held_out_project

    rng = np.random.default_rng(0)
    projects = [f"{rng.integers(10**5)}_{rng.integers(2**32):08x}" for _ in range(4000)]
    first = {p for p in projects if held_out_project(p, 2718, 0.15)}
    second = {p for p in projects if held_out_project(p, 3737, 0.15)}
    assert 0.13 < len(first) / len(projects) < 0.17 and 0.13 < len(second) / len(projects) < 0.17
    expected = len(first) * len(second) / len(projects)  # a CRC's draws shared none
    assert 0.6 * expected < len(first & second) < 1.4 * expected


@requires_samples
@pytest.mark.parametrize(
    ("use_points", "rows", "context"), [(False, 2_000_000, False), (True, 40, False), (False, 40, True)]
)
def test_validation_ranks_with_the_numpy_fold_as_with_the_pytorch_forward(
    labelled, tmp_path, monkeypatch, use_points, rows, context
):
    from training.train import rank_metrics, rank_places
    from zonegraph.sequence.features import FEATURES

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("training.train.RANK_ROWS", rows)  # 40: a state's proposals a few at a time
    train(_quick(labelled, loss="listwise", features=FEATURES, use_points=use_points, context=context))
    model = load_scorer(tmp_path / "models" / "scorer.pt")
    data = LabelDataset(labelled / "labels", labelled / "graphs", mode="rank", points_per_zone=16)
    cpu = torch.device("cpu")
    folded, forward = rank_places(model, data, cpu), rank_places(model, data, cpu, numpy=False)
    assert len(folded) == len(forward) > 5
    assert [p.proposals for p in folded] == [p.proposals for p in forward]
    assert [(p.above, p.ties) for p in folded] == [(p.above, p.ties) for p in forward]
    assert rank_metrics(folded) == rank_metrics(forward)
