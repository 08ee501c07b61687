"""Isolation (timeouts that really stop, crashes contained) and resumable Dask runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from distributed import Client

from pipelines import zonegraphs
from pipelines.records import MAX_ATTEMPTS, RECORD_VERSION
from pipelines.runner import PROJECT, Job, records_frame, run_jobs
from zonegraph.errors import InputError
from zonegraph.isolation import run_isolated


def _sleep(seconds):
    time.sleep(seconds)
    return "woke"


def _die():
    os.kill(os.getpid(), signal.SIGKILL)  # what a segfaulting OpenCASCADE call looks like


def _bad_input(name):
    raise InputError(name, "corrupt")


def _square(x):
    return {"square": x * x}


def test_timeout_kills_the_child():
    t0 = time.perf_counter()
    out = run_isolated(_sleep, (30,), timeout=0.5)
    assert out.status == "timeout" and time.perf_counter() - t0 < 10


def test_crash_is_an_outcome():
    assert run_isolated(_die, (), timeout=10).status == "crash"


def test_user_error_keeps_its_status():
    out = run_isolated(_bad_input, ("x.step",), timeout=10)
    assert (out.status, out.reason) == ("invalid_input", "corrupt")


def test_value_comes_back():
    assert run_isolated(_sleep, (0,), timeout=10).value == "woke"


def test_run_jobs_resumes_and_records_failures(tmp_path):
    jobs = [Job(f"d{i}", f"v1-{i}", (i,)) for i in range(3)] + [Job("bad", "v1", ("bad.step",))]
    with Client(processes=False, dashboard_address=None) as client:
        first = run_jobs(_dispatch, jobs, tmp_path, client, 20, "test")
        assert [r["status"] for r in first] == ["ok", "ok", "ok", "invalid_input"]
        assert first[2]["square"] == 4
        stamp = (tmp_path / "d1.json").stat().st_mtime_ns
        changed = jobs[:1] + [Job("d1", "v2-1", (1,))] + jobs[2:]
        second = run_jobs(_dispatch, changed, tmp_path, client, 20, "test")
    assert [r["status"] for r in second] == [r["status"] for r in first]
    assert (tmp_path / "d1.json").stat().st_mtime_ns != stamp  # changed fingerprint: recomputed
    assert second[0] == first[0]  # unchanged fingerprint: the record was reused as is


def _dispatch(arg):
    return _bad_input(arg) if isinstance(arg, str) else _square(arg)


def _die_once(flag: str):
    """Crashes (SIGKILL) while ``flag`` exists: an environment failure that a later run survives."""
    if os.path.exists(flag):
        os.kill(os.getpid(), signal.SIGKILL)
    return {"square": 1}


def test_a_crash_is_retried_on_later_runs_and_a_design_status_is_final(tmp_path):
    flag = tmp_path / "crash"
    flag.touch()
    jobs = [Job("crashes", "v1", ("crashes", str(flag))), Job("bad", "v1", ("bad", "bad.step"))]
    with Client(processes=False, dashboard_address=None) as client:
        first = run_jobs(_by_key, jobs, tmp_path / "r", client, 20, "t")
        assert [(r["status"], r.get("attempts")) for r in first] == [("crash", 1), ("invalid_input", None)]
        flag.unlink()
        second = run_jobs(_by_key, jobs, tmp_path / "r", client, 20, "t")
    assert second[0]["status"] == "ok" and second[0]["square"] == 1
    assert second[1]["seconds"] == first[1]["seconds"]  # the design's own failure was reused


def _by_key(key: str, arg: str):
    return _die_once(arg) if key == "crashes" else _bad_input(arg)


def test_environment_failures_are_tried_a_bounded_number_of_runs(tmp_path):
    flag = tmp_path / "crash"
    flag.touch()
    job = Job("crashes", "v1", ("crashes", str(flag)))
    with Client(processes=False, dashboard_address=None) as client:
        seen = [run_jobs(_by_key, [job], tmp_path, client, 20, "t")[0] for _ in range(MAX_ATTEMPTS + 1)]
    assert [r["attempts"] for r in seen] == [*range(1, MAX_ATTEMPTS + 1), MAX_ATTEMPTS]
    assert seen[-1] == seen[-2]  # past the limit the crash stands as the final record


def _write(path: str) -> dict:
    Path(path).write_text("fresh")
    return {"wrote": 1}


def test_a_record_is_reused_only_while_its_outputs_are_intact(tmp_path):
    out = tmp_path / "out.txt"
    job = Job("d", "v1", (str(out),), outputs=(str(out),))
    with Client(processes=False, dashboard_address=None) as client:
        first = run_jobs(_write, [job], tmp_path / "r", client, 20, "t")[0]
        assert first["outputs"] == [{".": [5, first["outputs"][0]["."][1]]}]
        assert run_jobs(_write, [job], tmp_path / "r", client, 20, "t")[0] == first
        out.write_text("gar")  # truncated behind the record's back
        again = run_jobs(_write, [job], tmp_path / "r", client, 20, "t")[0]
    assert again["outputs"] == first["outputs"] and out.read_text() == "fresh" and again is not first


def test_a_first_format_record_is_reused_and_gets_its_hashes(tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("old run")
    records = tmp_path / "r"
    records.mkdir()
    old = {"design_id": "d", "fingerprint": "v1", "status": "ok", "reason": "", "seconds": 1.5, "wrote": 1}
    (records / "d.json").write_text(json.dumps(old))
    job = Job("d", "v1", (str(out),), outputs=(str(out),))
    with Client(processes=False, dashboard_address=None) as client:
        kept = run_jobs(_write, [job], records, client, 20, "t")[0]
    assert out.read_text() == "old run" and kept["seconds"] == 1.5 and kept["version"] == RECORD_VERSION
    assert json.loads((records / "d.json").read_text())["outputs"] == [{".": [7, kept["outputs"][0]["."][1]]}]


def test_an_input_missing_on_the_worker_is_an_environment_failure(tmp_path):
    job = Job("d", "v1", (str(tmp_path / "out.txt"),), inputs=(str(tmp_path / "absent.brep"),))
    with Client(processes=False, dashboard_address=None) as client:
        record = run_jobs(_write, [job], tmp_path / "r", client, 20, "t")[0]
    assert record["status"] == "worker_error" and "absent.brep not found on worker" in record["reason"]


def test_a_stage_whose_designs_all_failed_writes_its_metrics(tmp_path):
    records = [{"design_id": "a", "fingerprint": "f", "status": "invalid_input", "reason": "no such file"}]
    zonegraphs.write_metrics(
        records_frame(records, ("build_s", "zones")), tmp_path / "m.json", tmp_path / "d.json"
    )
    metrics = json.loads((tmp_path / "m.json").read_text())
    details = json.loads((tmp_path / "d.json").read_text())
    assert metrics == {"designs": 1, "ok": 0, "failed": 1, "seconds": None}
    assert (details["median_build_s"], details["by_status"]) == (None, {"invalid_input": 1})


def test_a_memory_hog_is_out_of_memory():
    out = run_isolated(_allocate, (2000,), timeout=30, memory_mb=1500)
    assert out.status == "out_of_memory", out


def _allocate(mb: int):
    return len(bytearray(mb << 20))


def _imports_build123d_on_first_use(path: str) -> dict:
    """A job that, like the ground truth's shape readers, imports build123d only when it runs."""
    import build123d  # noqa: F401

    return {}


def test_workers_import_the_shape_library_once_not_each_design(tmp_path):
    """A design's child is forked from the worker: what the job imports on first use is already
    there when the worker imported it before (`warm_worker`), so the child pays nothing for it."""
    script = (
        "import sys\n"
        "from pathlib import Path\n"
        "from distributed import Client\n"
        "from pipelines.runner import Job, run_jobs\n"
        "from tests.pipelines.test_runner import _imports_build123d_on_first_use as job\n"
        "with Client(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as c:\n"
        f"    run_jobs(job, [Job('a', 'f', ('a',))], Path({str(tmp_path)!r}), c, 60, 't')\n"
        "    print(c.run(lambda: 'build123d' in sys.modules).popitem()[1])\n"
    )
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, env=env, cwd=PROJECT, timeout=300
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "True"
    assert json.loads((tmp_path / "a.json").read_text())["status"] == "ok"
