"""The generate stage's user errors: a source folder that is not there stops it with one line
naming the parameter and the folder, not a traceback."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from zonegraph.testing.stages import stage_command


@pytest.mark.parametrize(("source", "key"), [("b123d", "b123d_dir"), ("fusion_json", "fusion_json_dir")])
def test_a_missing_source_folder_is_one_line(tmp_path, source, key):
    project = Path.cwd().resolve()
    data = {"source": source, key: "../nowhere/fusion360", "split_seed": 0, "test_fraction": 0.2}
    dask = {"scheduler": None, "n_workers": 1}
    (tmp_path / "params.yaml").write_text(yaml.safe_dump({"data": data, "dask": dask}))
    proc = subprocess.run(
        [sys.executable, *stage_command("pipelines.generate", project)[1:]],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(project)},
    )
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert f"data.{key}" in lines[0] and str((tmp_path / "../nowhere/fusion360").resolve()) in lines[0]
