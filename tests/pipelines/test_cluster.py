"""A real Dask cluster, started with the ``dask`` command line as a user would: one scheduler and
two workers on 127.0.0.1, started in a folder other than the project's. A stage run through
``params.yaml: dask.scheduler`` gives the same outputs as a local run although one worker is
killed mid-stage, and a daemonic worker is refused before any design runs."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml

from zonegraph.testing.stages import run_stage, stage_command

pytestmark = pytest.mark.slow  # three stage runs and a cluster (about a minute on 2 busy cores)

DASK = Path(sys.executable).with_name("dask")
PROJECT = Path(__file__).resolve().parents[2]
DESIGNS = 6  # the worker is killed at the first record, with most of them still to run


def _params(scheduler: str | None) -> dict:
    return {
        "data": {"source": "synthetic", "split_seed": 0, "test_fraction": 0.35},
        "synthetic": {"count": DESIGNS, "seed": 2021, "timeout_s": 60},
        "dask": {"scheduler": scheduler, "n_workers": 2},
        "replay": {"timeout_s": 60},
    }


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _start(args: list[str], cwd: Path, daemon: bool = False) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(PROJECT), "DASK_DISTRIBUTED__WORKER__DAEMON": str(daemon)}
    return subprocess.Popen(
        [str(DASK), *args],
        cwd=cwd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # its own process group: killed as a whole, children included
    )


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait(10)


def _stage(project: Path) -> subprocess.Popen:
    words = stage_command("pipelines.replay", PROJECT)
    env = {**os.environ, "PYTHONPATH": str(PROJECT)}
    return subprocess.Popen(
        [sys.executable, *words[1:]],
        cwd=project,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_workers(address: str, n: int) -> None:
    from distributed import Client

    with Client(address, timeout=30) as client:
        client.wait_for_workers(n, timeout=60)


def _outputs(project: Path) -> pd.DataFrame:
    manifest = pd.read_parquet(project / "data/replay/manifest.parquet")
    hashes = {
        p.stem: json.loads(p.read_text())["outputs"] for p in (project / "data/replay/records").glob("*.json")
    }
    manifest["outputs"] = manifest["design_id"].map(lambda d: json.dumps(hashes[d], sort_keys=True))
    keep = ["design_id", "split", "status", "steps", "operations", "faces", "volume", "outputs"]
    return manifest[keep].sort_values("design_id").reset_index(drop=True)


@pytest.mark.skipif(not DASK.is_file(), reason="the dask command line is not installed")
def test_a_stage_on_a_real_cluster_survives_a_killed_worker(tmp_path):
    local, remote, elsewhere = tmp_path / "local", tmp_path / "remote", tmp_path / "workers"
    for folder in (local, remote, elsewhere):
        folder.mkdir()
    (local / "params.yaml").write_text(yaml.safe_dump(_params(None)))
    run_stage("pipelines.generate", local, PROJECT)
    run_stage("pipelines.replay", local, PROJECT)

    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    (remote / "params.yaml").write_text(yaml.safe_dump(_params(address)))
    shutil.copytree(local / "data/designs", remote / "data/designs")  # its index names local's files
    worker = ["worker", address, "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"]
    procs = [_start(["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"], elsewhere)]
    try:
        procs.append(_start(worker, elsewhere, daemon=True))
        _wait_for_workers(address, 1)
        refused = _stage(remote)
        _, err = refused.communicate(timeout=120)
        assert refused.returncode != 0 and "DASK_DISTRIBUTED__WORKER__DAEMON=False" in err
        assert len(err.strip().splitlines()) == 1 and not list(remote.glob("data/replay/records/*.json"))
        _kill(procs.pop())

        procs += [_start(worker, elsewhere), _start(worker, elsewhere)]
        _wait_for_workers(address, 2)
        stage = _stage(remote)
        records = remote / "data/replay/records"
        deadline = time.monotonic() + 120
        while not any(records.glob("*.json")) and time.monotonic() < deadline and stage.poll() is None:
            time.sleep(0.1)
        _kill(procs.pop())  # a worker dies mid-stage, its design child with it
        killed_at = len(list(records.glob("*.json")))
        out, err = stage.communicate(timeout=300)
        assert stage.returncode == 0, err[-3000:]
    finally:
        for proc in procs:
            _kill(proc)
    assert killed_at < DESIGNS  # the kill came before the stage was done
    pd.testing.assert_frame_equal(_outputs(remote), _outputs(local))
