"""The package's layers: imports run one way, the public API is where the README says it is."""

from __future__ import annotations

import ast
import pydoc
import subprocess
import sys
from pathlib import Path

import zonegraph

PACKAGE = Path(zonegraph.__file__).parent
# Each layer may import only layers of a lower rank (and itself); data and zones are siblings.
# errors, console (capturing native output) and plugins (entry-point groups) import nothing heavy
# and serve every layer.
RANK = {
    "errors": 0,
    "console": 0,
    "plugins": 0,
    "status": 0,
    "verified": 0,
    "geometry": 1,
    "data": 2,
    "zones": 2,
    "sequence": 3,
    "export": 4,
}
TOP = 5  # reconstruction, cli, batch, jobs, isolation, outputs, configs and the package root


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _rank(layer: str) -> int:
    return RANK.get(layer, TOP)


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return found


def test_imports_run_one_way():
    bad = []
    for path in PACKAGE.rglob("*.py"):
        module = ".".join(("zonegraph", *path.relative_to(PACKAGE).with_suffix("").parts))
        layer = _layer(module)
        for imported in _imports(path):
            if imported.split(".")[0] == "torch":
                bad.append(f"{module} imports torch")
            if not imported.startswith("zonegraph."):
                continue
            other = _layer(imported)
            upward = _rank(other) > _rank(layer)
            sideways = other != layer and _rank(other) == _rank(layer) < TOP  # data <-> zones
            if upward or sideways:
                bad.append(f"{module} imports {imported}")
    assert not bad, "imports against the layering:\n" + "\n".join(sorted(bad))


def test_package_root_is_light_and_lists_the_public_api():
    code = "import sys, zonegraph; print('build123d' in sys.modules, 'OCP' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]  # geometry loads on first use of a name, not on import
    doc = pydoc.render_doc(zonegraph, renderer=pydoc.plaintext)
    for name in ("build_zone_graph", "ZoneGraph", "search", "HeuristicRanker", "RandomRanker", "infer"):
        assert name in doc
        assert getattr(zonegraph, name) is not None
    assert set(zonegraph.__all__) <= set(dir(zonegraph))


def test_every_subpackage_declares_its_api():
    for init in PACKAGE.glob("*/__init__.py"):
        names = [n for n in ast.walk(ast.parse(init.read_text())) if isinstance(n, ast.Assign)]
        assert any(t.id == "__all__" for n in names for t in n.targets if isinstance(t, ast.Name)), init
