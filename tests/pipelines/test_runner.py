"""Isolation (timeouts that really stop, crashes contained) and resumable Dask runs."""

from __future__ import annotations

import os
import signal
import time

from distributed import Client

from pipelines.runner import Job, run_jobs
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
