"""The test-support package: where it finds the data, and that the product never depends on it."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import zonegraph
from zonegraph.testing import locations

PACKAGE = Path(zonegraph.__file__).parent


def _shared_root(cwd: Path, env: str | None) -> Path:
    """``shared_root()`` in a fresh interpreter run from ``cwd`` with ``$ZONEGRAPH_SHARED``."""
    environ = {k: v for k, v in os.environ.items() if k != locations.ENV}
    if env is not None:
        environ[locations.ENV] = env
    environ["PYTHONPATH"] = os.pathsep.join([str(PACKAGE.parent), environ.get("PYTHONPATH", "")])
    code = "from zonegraph.testing.locations import shared_root; print(shared_root())"
    out = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=environ, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return Path(out.stdout.strip())


def test_the_environment_variable_wins(tmp_path):
    assert _shared_root(tmp_path, str(tmp_path / "elsewhere")) == tmp_path / "elsewhere"


def test_shared_beside_the_working_folder(tmp_path):
    (tmp_path / "shared").mkdir()
    (tmp_path / "checkout").mkdir()
    assert _shared_root(tmp_path / "checkout", None) == tmp_path / "shared"


def test_shared_beside_the_package_checkout_else(tmp_path):
    beside_package = PACKAGE.resolve().parents[1] / "shared"
    expected = beside_package if beside_package.is_dir() else tmp_path.parent / "shared"
    assert _shared_root(tmp_path, None) == expected


def test_import_zonegraph_testing_needs_no_pytest():
    code = (
        "import sys, zonegraph, zonegraph.testing; zonegraph.testing.SAMPLES; print('pytest' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False"]


def test_the_product_never_imports_its_test_support():
    bad = []
    for path in PACKAGE.rglob("*.py"):
        if "testing" in path.relative_to(PACKAGE).parts:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = (
                [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else []
            )
            found = [n for n in names if n.startswith("zonegraph.testing")]
            bad += [f"{path.relative_to(PACKAGE)} imports {n}" for n in found]
    assert not bad, "\n".join(bad)
