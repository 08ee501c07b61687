"""One source of truth for what a stage's records depend on: its code deps in ``dvc.yaml``.

A record is reused only while the code it was made by and the files it read are unchanged; these
tests change a zone-graph module or a saved graph and check that the dependent records are
recomputed, not reused (the stale-results bug of the ``reconstruct`` stage)."""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml
from distributed import Client

from pipelines.runner import PROJECT, Job, code_fingerprint, fingerprint, run_jobs, stage_code


def _copy_project(tmp: Path) -> Path:
    root = tmp / "project"
    root.mkdir()
    shutil.copy(PROJECT / "dvc.yaml", root)
    for folder in ("zonegraph", "pipelines"):
        shutil.copytree(PROJECT / folder, root / folder, ignore=shutil.ignore_patterns("__pycache__"))
    return root


def _load_graph(graph_dir: str) -> dict:
    """Stands for a reconstruct job: reads a saved graph, returns what it found."""
    return {"zones": len((Path(graph_dir) / "zones.parquet").read_bytes())}


def test_every_code_dep_exists_and_covers_the_imports():
    stages = yaml.safe_load((PROJECT / "dvc.yaml").read_text())["stages"]
    for stage in stages:
        for path in stage_code(stage):
            assert Path(path).exists(), f"{stage}: code dep {path} does not exist"
    zone_code = stage_code("zonegraphs")
    assert any(p.endswith("zonegraph/zones") for p in zone_code)
    assert any(p.endswith("zonegraph") for p in stage_code("reconstruct"))


def test_a_zone_graph_module_change_invalidates_graphs_and_reconstructions(tmp_path):
    root = _copy_project(tmp_path)
    before = {s: code_fingerprint(s, root) for s in ("replay", "zonegraphs", "reconstruct")}
    extension = root / "zonegraph" / "zones" / "extension.py"
    extension.write_text(extension.read_text() + "\n# a change in face extension\n")
    after = {s: code_fingerprint(s, root) for s in before}
    assert after["zonegraphs"] != before["zonegraphs"]
    assert after["reconstruct"] != before["reconstruct"]
    assert after["replay"] == before["replay"]  # replay does not read zone-graph code


def test_changed_code_or_saved_graph_recomputes_the_record(tmp_path):
    root = _copy_project(tmp_path)
    graph = tmp_path / "graphs" / "d0"
    graph.mkdir(parents=True)
    (graph / "zones.parquet").write_bytes(b"x" * 10)

    def jobs() -> list[Job]:
        code = code_fingerprint("reconstruct", root)
        return [Job("d0", fingerprint(code, files=(graph,)), (str(graph),))]

    records = tmp_path / "records"
    with Client(processes=False, dashboard_address=None) as client:
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 10
        (graph / "zones.parquet").write_bytes(b"x" * 12)  # the zonegraphs stage re-saved the graph
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 12
        stamp = (records / "d0.json").stat().st_mtime_ns
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 12
        assert (records / "d0.json").stat().st_mtime_ns == stamp  # nothing changed: reused
        model = root / "zonegraph" / "zones" / "model.py"
        model.write_text(model.read_text() + "\n# a change in the zone graph model\n")
        run_jobs(_load_graph, jobs(), records, client, 20, "t")
        assert (records / "d0.json").stat().st_mtime_ns != stamp  # new code: recomputed
