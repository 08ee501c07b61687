"""A real MLflow tracking server on a free port, and its REST API, for the tracking tests."""

from __future__ import annotations

import contextlib
import json
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def mlflow_server(cwd: Path, command: str = "server") -> Iterator[str]:
    """Serve ``cwd/mlflow.db`` (artifacts under ``cwd/mlartifacts``) by ``mlflow server`` (or
    ``command``, e.g. ``ui``); yields the server's URL."""
    port = free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "mlflow", command, "--backend-store-uri", "sqlite:///mlflow.db"]
        + ["--host", "127.0.0.1", "--port", str(port), "--workers", "1"],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.terminate()
        server.wait(timeout=30)


def rest(url: str, path: str, body: dict | None = None, wait_s: float = 120) -> dict:
    """GET (or POST ``body``) one REST call of ``url``'s API, waiting for the server to come up."""
    deadline = time.time() + wait_s
    data = json.dumps(body).encode() if body is not None else None
    while True:
        try:
            request = urllib.request.Request(
                f"{url}/api/2.0/mlflow/{path}", data=data, headers={"Content-Type": "application/json"}
            )
            with urllib.request.urlopen(request) as r:
                return json.load(r)
        except OSError:
            if time.time() > deadline:
                raise
            time.sleep(1)


def search_runs(url: str, experiment: str) -> list[dict]:
    """Every run of an experiment, as the REST API returns it."""
    experiment_id = rest(url, f"experiments/get-by-name?experiment_name={experiment}")["experiment"][
        "experiment_id"
    ]
    return rest(url, "runs/search", {"experiment_ids": [experiment_id]})["runs"]
