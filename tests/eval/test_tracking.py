"""The project's MLflow store keeps working when the project moves."""

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

from eval.tracking import metric_name, run_name

LOG_A_RUN = textwrap.dedent(
    """
    import mlflow
    mlflow.set_tracking_uri("sqlite:///mlflow.db")
    mlflow.set_experiment("evaluation")
    with mlflow.start_run() as run:
        open("report.md", "w").write("# report")
        mlflow.log_artifact("report.md")
    print(run.info.run_id)
    """
)

READ_IT_BACK = textwrap.dedent(
    """
    import sys, mlflow
    mlflow.set_tracking_uri("sqlite:///mlflow.db")
    path = mlflow.artifacts.download_artifacts(run_id=sys.argv[1], artifact_path="report.md", dst_path="back")
    print(open(path).read())
    """
)


def _python(code: str, cwd: Path, *args: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    env.pop("MLFLOW_TRACKING_URI", None)
    out = subprocess.run(
        [sys.executable, "-c", code, *args], cwd=cwd, env=env, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip().splitlines()[-1]


def test_a_moved_store_opens_its_artifacts_after_relocate(tmp_path):
    first = tmp_path / "first"
    first.mkdir()
    run = _python(LOG_A_RUN, first)
    moved = tmp_path / "moved"
    shutil.move(first, moved)
    _python("from eval.tracking import main; main()", moved, "relocate")
    assert _python(READ_IT_BACK, moved, run) == "# report"


def test_metric_names_are_grouped_and_runs_named():
    assert metric_name("rank.net:shipped") == "rank/net_shipped"
    assert metric_name("exact_at_1s.heuristic") == "exact_at_1s/heuristic"
    assert (
        run_name({"designs": "test", "budget": 2.0, "k": [1, 5], "seed": 0})
        == "evaluate test 2.0s k1-5 seed0"
    )
    assert (
        run_name({"designs": "parts", "budget_s": 2.0, "k": [5]}) == "evaluate parts 2.0s k5 seed0"
    )  # eval.report's
