"""The warm server: calls handed to it behave as cold calls do, on real parts, through real sockets."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from zonegraph.testing import SAMPLES

COUCH = SAMPLES / "Couch.step"
CLI = [sys.executable, "-m", "zonegraph"]  # as the console script: a call is handed to a server


@pytest.fixture(scope="module")
def folder() -> Iterator[Path]:
    """A short private folder (a socket's path is limited to about 100 bytes)."""
    path = Path(tempfile.mkdtemp(prefix="zgs"))
    yield path / "servers"
    shutil.rmtree(path, ignore_errors=True)


def _env(folder: Path, **extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "ZONEGRAPH_NO_SERVER"}
    return {**env, "ZONEGRAPH_SERVER_DIR": str(folder), **extra}


def _zonegraph(
    folder: Path, *args: str, cwd: Path | None = None, **extra: str
) -> subprocess.CompletedProcess:
    env = _env(folder, **extra)
    return subprocess.run([*CLI, *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=300)


def _status(folder: Path) -> dict | None:
    proc = _zonegraph(folder, "server", "status", "--json")
    assert proc.stdout, proc.stderr
    return json.loads(proc.stdout)


@pytest.fixture(scope="module")
def server(folder: Path) -> Iterator[dict]:
    started = _zonegraph(folder, "server", "start", "--json")
    assert started.returncode == 0, started.stderr
    yield json.loads(started.stdout)
    _zonegraph(folder, "server", "stop")


def _wait(condition, seconds: float = 30.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.1)
    return False


def test_a_warm_build_writes_what_a_cold_one_does(folder: Path, server: dict, tmp_path: Path) -> None:
    before = _status(folder)
    warm = _zonegraph(folder, "build", str(COUCH), "--out", "warm", cwd=tmp_path)
    cold = _zonegraph(folder, "build", str(COUCH), "--out", "cold", cwd=tmp_path, ZONEGRAPH_NO_SERVER="1")
    assert warm.returncode == cold.returncode == 0, warm.stderr + cold.stderr
    assert warm.stdout.splitlines()[0] == cold.stdout.splitlines()[0]  # zones, faces, edges, surfaces
    assert sorted(p.name for p in (tmp_path / "warm").iterdir()) == sorted(
        p.name for p in (tmp_path / "cold").iterdir()
    )
    for table in ("zones.parquet", "faces.parquet", "links.parquet", "samples.parquet"):
        assert pq.read_table(tmp_path / "warm" / table).equals(pq.read_table(tmp_path / "cold" / table))
    after = _status(folder)
    assert before is not None and after is not None
    assert after["served"] == before["served"] + 1 and after["pid"] == server["pid"]
    assert after["children_cpu_s"] > before["children_cpu_s"]


def test_a_user_error_is_the_same_one_line_and_status(folder: Path, server: dict, tmp_path: Path) -> None:
    warm = _zonegraph(folder, "build", "missing.step", "--out", "o", cwd=tmp_path)
    cold = _zonegraph(folder, "build", "missing.step", "--out", "o", cwd=tmp_path, ZONEGRAPH_NO_SERVER="1")
    assert warm.returncode == cold.returncode == 2
    assert warm.stderr == cold.stderr and len(warm.stderr.strip().splitlines()) == 1
    assert "missing.step" in warm.stderr


def test_a_warm_infer_exports_its_program(folder: Path, server: dict, tmp_path: Path) -> None:
    proc = _zonegraph(folder, "infer", str(COUCH), "--out", "out", "--budget", "5", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "exact" in proc.stdout
    assert (tmp_path / "out" / "sequence.py").is_file()
    assert json.loads((tmp_path / "out" / "result.json").read_text())["status"] == "exact"


def _long_call(folder: Path, tmp_path: Path) -> subprocess.Popen:
    """A search that runs for its whole budget: the random guide on a part with many zones."""
    args = ["infer", str(COUCH), "--out", "out", "--guide", "random", "--budget", "60", "--k", "50"]
    return subprocess.Popen([*CLI, *args], env=_env(folder), cwd=tmp_path, stderr=subprocess.PIPE, text=True)


def _running(folder: Path) -> int:
    state = _status(folder)
    return -1 if state is None else state["running"]


def test_ctrl_c_reaches_the_call(folder: Path, server: dict, tmp_path: Path) -> None:
    call = _long_call(folder, tmp_path)
    assert _wait(lambda: _running(folder) == 1)
    time.sleep(1.0)  # into the search
    call.send_signal(signal.SIGINT)
    assert call.wait(timeout=30) != 0
    assert _wait(lambda: _running(folder) == 0)


def test_a_killed_caller_takes_its_call_down(folder: Path, server: dict, tmp_path: Path) -> None:
    call = _long_call(folder, tmp_path)
    assert _wait(lambda: _running(folder) == 1)
    time.sleep(1.0)
    call.kill()
    call.wait()
    assert _wait(lambda: _running(folder) == 0, 10.0)  # long before the 60 s search would end
    assert _status(folder)["pid"] == server["pid"]  # and the server serves on


def test_a_socket_nobody_listens_on_means_a_cold_call(tmp_path: Path) -> None:
    folder = Path(tempfile.mkdtemp(prefix="zgs")) / "stale"
    try:
        folder.mkdir(mode=0o700)
        probe = subprocess.run(
            [sys.executable, "-c", "from zonegraph.handoff import socket_path; print(socket_path())"],
            env=_env(folder),
            capture_output=True,
            text=True,
            check=True,
        )
        stale = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        stale.bind(probe.stdout.strip())
        stale.close()  # the file stays, nothing listens
        proc = _zonegraph(folder, "build", str(COUCH), "--out", "o", cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        assert (tmp_path / "o" / "zones.parquet").is_file()
        assert _status(folder) is None
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)


def test_a_folder_others_can_enter_is_refused(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir(mode=0o755)
    shared.chmod(0o755)
    proc = _zonegraph(shared, "server", "start")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "not a private folder" in proc.stderr


def test_status_and_stop_without_a_server(tmp_path: Path) -> None:
    folder = tmp_path / "none"
    status = _zonegraph(folder, "server", "status")
    assert status.returncode == 1 and "none of this code runs" in status.stdout
    stop = _zonegraph(folder, "server", "stop")
    assert stop.returncode == 0 and "nothing to stop" in stop.stdout


def test_stop_also_stops_a_server_of_other_code(tmp_path: Path) -> None:
    """A server left from an older install answers on another socket name in the same folder:
    status says it runs, and stop stops it too instead of leaving it to idle out."""
    folder = Path(tempfile.mkdtemp(prefix="zgs")) / "mixed"
    try:
        folder.mkdir(mode=0o700)
        older = folder / "0123456789abcdef.sock"
        serve = [sys.executable, "-m", "zonegraph.server", str(older), "60"]
        proc = subprocess.Popen(serve, env=_env(folder))
        assert _wait(lambda: older.exists(), 120.0)
        status = _zonegraph(folder, "server", "status")
        assert status.returncode == 1 and "1 of other code still running" in status.stdout
        stop = _zonegraph(folder, "server", "stop")
        assert stop.returncode == 0 and "1 of other code stopped" in stop.stdout
        assert proc.wait(timeout=30) == 0 and not older.exists()
    finally:
        shutil.rmtree(folder.parent, ignore_errors=True)
