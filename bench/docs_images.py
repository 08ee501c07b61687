"""The pictures of the documentation, made from a part built here (no data set geometry).

    python -m bench.docs_images [--out docs/images]
    python -m bench.docs_images --mlflow PROJECT [--out docs/images]
    python -m bench.docs_images --site [--out docs/images]

A bracket (a plate with a slot and a bored boss) is built with build123d and written as STEP;
``zonegraph.infer`` runs on it as ``zonegraph infer bracket.step`` would, and its strip
(``sequence.png``), its editable script (``bracket_sequence.py``) and a picture of its zone graph
(``zones.png``) are copied into ``--out``. Re-run it when the renderer or the writer changes.

``--mlflow PROJECT`` instead photographs the MLflow dashboard of a project that trained (and
evaluated): ``mlflow ui`` on its ``mlflow.db``, as ``make ui`` serves it, opened in headless
Chromium at the experiments list, the newest training run, its metrics, its logged model and the
newest evaluation run with its metrics (``mlflow_*.png``, palette-reduced to stay small).

``--site`` builds the documentation site as ``make docs-build`` does (``mkdocs build --strict``),
serves the built pages over HTTP as ``make docs`` would, and photographs its getting-started page
and its API page (``site_*.png``): what a newcomer sees, rendered by a browser rather than read as
Markdown.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import os
import shutil
import subprocess
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from build123d import (
    Align,
    Box,
    BuildPart,
    BuildSketch,
    Circle,
    Locations,
    Mode,
    Plane,
    Rectangle,
    SlotCenterToCenter,
    export_step,
    extrude,
)

import zonegraph as zg
import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.export.render import render_zone_graph
from zonegraph.testing.mlflow_server import mlflow_server, rest


def bracket(path: Path) -> Path:
    """A 60 x 40 x 8 mm plate with a slot and a 24 mm boss bored through both."""
    with BuildPart() as part:
        Box(60, 40, 8, align=(Align.CENTER, Align.CENTER, Align.MIN))
        with BuildSketch(Plane.XY.offset(8)), Locations((-12, 0)):
            Rectangle(24, 24)
        extrude(amount=14)
        with BuildSketch(Plane.XY.offset(22)), Locations((-12, 0)):
            Circle(6)
        extrude(amount=-22, mode=Mode.SUBTRACT)
        with BuildSketch(Plane.XY.offset(8)), Locations((18, 0)):
            SlotCenterToCenter(14, 8, rotation=90)
        extrude(amount=-8, mode=Mode.SUBTRACT)
    export_step(part.part, str(path))
    return path


WIDTH = 1400
SHOTS = {  # file -> the dashboard's address (from the experiment and run ids) and the shot's height
    "mlflow_experiments.png": ("#/experiments/{train}/runs", 500),
    "mlflow_training_run.png": ("#/experiments/{train}/runs/{run}", 1100),
    "mlflow_training_metrics.png": ("#/experiments/{train}/runs/{run}/model-metrics", 1900),
    "mlflow_logged_model.png": ("#/experiments/{train}/models/{model}", 900),
    "mlflow_evaluation_overview.png": ("#/experiments/{evaluation}/runs/{eval_run}", 1100),
    "mlflow_evaluation_run.png": ("#/experiments/{evaluation}/runs/{eval_run}/model-metrics", 1500),
}


SITE_SHOTS = {  # file -> the built site's page and the shot's height
    "site_getting_started.png": ("getting-started/", 1800),
    "site_api.png": ("api/", 1800),
}


def _newest_run(url: str, experiment_id: str) -> dict:
    body = {"experiment_ids": [experiment_id], "max_results": 1, "order_by": ["start_time DESC"]}
    return rest(url, "runs/search", body)["runs"][0]


def _ids(url: str) -> dict[str, str]:
    """The experiments and newest runs the pictures show, and the training run's logged model;
    an experiment the project has not run yet is left out."""
    ids = {}
    for key, run, name in (("train", "run", "zonegraph-scorer"), ("evaluation", "eval_run", "evaluation")):
        try:
            found = rest(url, f"experiments/get-by-name?experiment_name={name}", wait_s=0)["experiment"]
        except OSError:
            continue
        ids[key] = found["experiment_id"]
        ids[run] = _newest_run(url, ids[key])["info"]["run_id"]
    if "run" in ids:
        models = rest(url, "logged-models/search", {"experiment_ids": [ids["train"]]})["models"]
        logged = [m["info"]["model_id"] for m in models if m["info"]["source_run_id"] == ids["run"]]
        ids |= {"model": logged[0]} if logged else {}
    return ids


def _shoot(address: str, height: int, path: Path) -> None:
    """One page in headless Chromium; the charts draw only with every compositor stage run."""
    subprocess.run(
        ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
        + ["--run-all-compositor-stages-before-draw", "--virtual-time-budget=60000"]
        + [f"--window-size={WIDTH},{height}", f"--screenshot={path}", address],
        check=True,
        capture_output=True,
        timeout=180,
    )
    from PIL import Image

    with Image.open(path) as image:  # a UI's few colours: a palette keeps a shot near 100 KB
        small = image.convert("RGB").quantize(colors=64)
    small.save(path, optimize=True)


def mlflow_shots(project: Path, out: Path) -> list[Path]:
    """Serve ``project``'s store with ``mlflow ui`` and photograph `SHOTS` into ``out``."""
    subprocess.run([sys.executable, "-m", "eval.tracking", "relocate"], cwd=project, check=True)
    with mlflow_server(project, command="ui") as base:
        rest(base, "experiments/search", {"max_results": 1})  # the server is up
        ids = _ids(base)
        paths = []
        for name, (address, height) in SHOTS.items():
            try:
                address = address.format(**ids)
            except KeyError as missing:
                print(f"{name}: skipped, the project has no {missing.args[0]} to show", flush=True)
                continue
            _shoot(f"{base}/{address}", height, out / name)
            paths.append(out / name)
            print(f"wrote {out / name} ({(out / name).stat().st_size // 1024} KB)", flush=True)
        return paths


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    """Serves files without a log line per request."""

    def log_message(self, format: str, *args: object) -> None:
        pass


@contextmanager
def _served(folder: Path) -> Iterator[str]:
    """``folder`` served over HTTP on a free local port, for as long as the block runs."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def site_shots(out: Path) -> list[Path]:
    """Build the site with ``--strict`` into a temporary folder and photograph `SITE_SHOTS`."""
    paths = []
    with tempfile.TemporaryDirectory() as site:
        env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
        build = [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", site]
        subprocess.run(build, check=True, env=env)
        with _served(Path(site)) as base:
            for name, (page, height) in SITE_SHOTS.items():
                _shoot(f"{base}/{page}", height, out / name)
                paths.append(out / name)
                print(f"wrote {out / name} ({(out / name).stat().st_size // 1024} KB)", flush=True)
    return paths


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("docs/images"))
    ap.add_argument("--mlflow", type=Path, default=None, help="photograph this project's MLflow runs instead")
    ap.add_argument("--site", action="store_true", help="photograph the built documentation site instead")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.site:
        site_shots(args.out.resolve())
        return
    if args.mlflow is not None:
        mlflow_shots(args.mlflow.resolve(), args.out.resolve())
        return
    with tempfile.TemporaryDirectory() as work:
        step = bracket(Path(work) / "bracket.step")
        result = zg.infer(step, Path(work) / "out", zg.InferConfig(budget_s=10))
        print(f"bracket.step: {result.status}, {result.steps} steps, B-rep IoU {result.iou_brep:.6f}")
        shutil.copy(Path(work) / "out/sequence.png", args.out / "sequence.png")
        shutil.copy(Path(work) / "out/sequence.py", args.out / "bracket_sequence.py")
        target = zg.load_target(step)
        render_zone_graph(zg.build_zone_graph(target), args.out / "zones.png", target)
    print(f"wrote {args.out}/sequence.png, zones.png, bracket_sequence.py")


if __name__ == "__main__":
    main()
