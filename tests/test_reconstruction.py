"""`zonegraph infer` on the real samples: exact, and the exported script and JSON rebuild the part."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

from zonegraph.configs import InferConfig
from zonegraph.data.design import load_design
from zonegraph.data.replay import as_shape, replay
from zonegraph.data.targets import load_target
from zonegraph.geometry.shapes import read_solids, write_brep
from zonegraph.reconstruction import infer
from zonegraph.sequence.program import brep_iou
from zonegraph.testing import CORPUS, requires_corpus, requires_samples, sample_paths

DISTINCT = [p for p in sample_paths() if not p.stem.startswith(("SingleSketchExtrude_", "Z0HexagonCutJoin"))]
SCRIPT = Path(sys.executable).parent / "zonegraph"


@pytest.fixture(scope="module")
def inferred(tmp_path_factory):
    """Every distinct sample inferred once (heuristic, 10 s budget)."""
    root = tmp_path_factory.mktemp("infer")
    return {
        p.stem: (p, root / p.stem, infer(str(p), str(root / p.stem), InferConfig(budget_s=10)))
        for p in DISTINCT
    }


@requires_samples
def test_every_distinct_sample_is_exact_within_10_s(inferred):
    assert len(inferred) == 18
    for name, (_, out, result) in inferred.items():
        assert result.exact and result.iou_brep >= 0.9999, name
        assert result.search_s <= 10.0, name
        assert json.loads((out / "result.json").read_text())["status"] == "exact"
        assert (out / "sequence.png").stat().st_size > 0 and (out / "steps/00.step").is_file()


@requires_samples
def test_anytime_trace_is_monotone_and_ends_at_the_returned_program(inferred):
    for name, (_, _, result) in inferred.items():
        times, ious = zip(*result.trace, strict=True)
        assert list(times) == sorted(times) and list(ious) == sorted(ious), name  # only improvements
        assert ious[-1] == result.iou_zone == 1.0 and times[-1] == result.time_to_best_s <= result.search_s
        assert len(result.step_zones) == result.steps == len(result.operations)
        assert all(zones and max(zones) < result.zones for zones in result.step_zones)


@requires_corpus
def test_the_full_graphs_trace_continues_the_simplified_ones(tmp_path):
    """A corpus part whose simplified graph has no exact program (its face-loop strips leave
    zones no prism holds): the full graph's search continues the anytime trace on one clock."""
    from zonegraph.data.b123d import convert_design

    converted = convert_design(CORPUS / "07_16to20ops/batch_003.py", "55341_a059c86e_0000")
    assert converted.ok and converted.design_json is not None, converted.reason
    path = tmp_path / "55341_a059c86e_0000.json"
    path.write_text(json.dumps(converted.design_json))
    result = infer(str(path), str(tmp_path / "out"), InferConfig(budget_s=20), render=False)
    assert result.exact and not result.simplified
    times, ious = zip(*result.trace, strict=True)
    assert list(times) == sorted(times) and list(ious) == sorted(ious)
    assert ious[-1] == result.iou_zone == 1.0 and times[-1] == result.time_to_best_s <= result.search_s


@requires_samples
def test_exported_scripts_rebuild_the_parts_in_a_fresh_process(inferred, tmp_path):
    runner = tmp_path / "run_all.py"
    runner.write_text(
        "import runpy, sys\n"
        "for script, out in zip(sys.argv[1::2], sys.argv[2::2]):\n"
        "    sys.argv = [script, out]\n"
        "    runpy.run_path(script, run_name='__main__')\n"
    )
    args = [
        a
        for name, (_, out, _) in inferred.items()
        for a in (str(out / "sequence.py"), str(tmp_path / f"{name}.step"))
    ]
    subprocess.run(
        [sys.executable, str(runner), *args], check=True, capture_output=True, text=True, timeout=600
    )
    for name, (path, _, _) in inferred.items():
        target = as_shape(load_target(path))
        rebuilt = as_shape(read_solids(tmp_path / f"{name}.step"))
        # The script's STEP is read back in millimetres; the design JSON is in centimetres.
        assert brep_iou(rebuilt.scale(0.1), target) >= 0.9999, name


@requires_samples
def test_exported_json_replays_to_the_same_solid(inferred):
    for name, (path, out, _) in inferred.items():
        replayed = replay(load_design(out / "sequence.json"))
        assert brep_iou(replayed.shape, as_shape(load_target(path))) >= 0.9999, name
        # the file carries its own replay's figures, so `zonegraph replay` verifies it by default
        assert replayed.design.properties is not None and replayed.disagreement() is None, name


@requires_samples
def test_step_input_in_millimetres(samples_dir, tmp_path):
    result = infer(str(samples_dir / "Couch.step"), str(tmp_path / "couch"))
    assert result.exact
    target = read_solids(samples_dir / "Couch.step")[0]
    rebuilt = as_shape(read_solids(tmp_path / "couch" / "steps" / f"{result.steps - 1:02d}.step"))
    assert brep_iou(rebuilt, target) >= 0.9999  # same units and position as the input


@pytest.mark.skipif(not SCRIPT.exists(), reason=f"console script not installed at {SCRIPT}")
def test_cli_infer_bad_input_is_one_line(tmp_path):
    proc = subprocess.run(
        [str(SCRIPT), "infer", str(tmp_path / "absent.step"), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "no such file" in proc.stderr


@pytest.mark.skipif(not SCRIPT.exists(), reason=f"console script not installed at {SCRIPT}")
def test_cli_infer_writes_result(samples_dir, tmp_path):
    out = tmp_path / "o"
    proc = subprocess.run(
        [
            str(SCRIPT),
            "infer",
            str(samples_dir / "Pattern2_6c40bf33_0000.json"),
            "--out",
            str(out),
            "--guide",
            "random",
            "--budget",
            "5",
            "--seed",
            "1",
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    result = json.loads((out / "result.json").read_text())
    assert set(result) >= {
        "status",
        "exact",
        "iou_zone",
        "iou_brep",
        "steps",
        "time_to_best_s",
        "build_s",
        "search_s",
        "rebuild_s",
        "verify_s",
        "zones",
        "expansions",
    }
    assert result["config"]["guide"] == "random"


def test_brep_iou_is_a_fraction_even_where_volume_integration_overshoots():
    from build123d import Box, Cylinder, Pos

    part = Cylinder(3.7, 2.9) - Pos(1, 0, 0) * Cylinder(0.9, 3)
    assert 0.999999 <= brep_iou(part, part) <= 1.0
    volume = math.pi * (3.7**2 - 0.9**2) * 2.9
    upper = Pos(0, 0, 0.725) * Box(10, 10, 1.45)  # holds the upper half of the part
    assert brep_iou(part, upper) == pytest.approx((volume / 2) / (145 - volume / 2 + volume), rel=1e-6)
    assert brep_iou(part, Pos(20, 0, 0) * Box(1, 1, 1)) == 0.0  # disjoint: an empty common is real


def test_a_spline_profile_is_exported_so_that_our_json_replays_it(tmp_path):
    """A free-form outline: written as a B-spline close enough that the profile's area check passes."""
    from build123d import BuildLine, BuildPart, BuildSketch, Line, Spline, extrude, make_face

    with BuildPart() as part:
        with BuildSketch():
            with BuildLine():
                Spline((0, 0), (1.0, 0.7), (2.2, 0.2), (3.0, 1.1))
                Line((3.0, 1.1), (3.0, 2.0))
                Line((3.0, 2.0), (0, 2.0))
                Line((0, 2.0), (0, 0))
            make_face()
        extrude(amount=0.8)
    target = tmp_path / "spline.brep"
    write_brep(part.part, target)
    result = infer(str(target), str(tmp_path / "out"), InferConfig(budget_s=5), render=False)
    assert result.exact
    replayed = replay(load_design(tmp_path / "out" / "sequence.json"))
    assert brep_iou(replayed.shape, part.part) >= 0.9999


@requires_samples
def test_a_graph_without_face_loops_gets_the_whole_budget(samples_dir):
    from zonegraph.reconstruction import FIRST_SHARE, budget_share
    from zonegraph.zones.build import build_zone_graph

    def graph(name: str, simplify: bool = True):
        return build_zone_graph(list(replay(load_design(samples_dir / name)).bodies), simplify=simplify)

    assert budget_share(graph("Couch.json"), simplified=True) == 1.0  # no face loop
    assert budget_share(graph("Hexagon.json"), simplified=True) == FIRST_SHARE  # the full graph may follow
    assert budget_share(graph("Hexagon.json", simplify=False), simplified=False) == 1.0


@requires_samples
def test_exported_scripts_write_no_float_noise_around_zero(inferred):
    for name, (_, out, _) in inferred.items():
        text = (out / "sequence.py").read_text()
        assert not re.search(r"\de-(1\d|[2-9]\d)\b", text), name  # nothing from 1e-10 down
        assert not re.search(r"[(, ]-0[,)]", text), name  # no negative zero
