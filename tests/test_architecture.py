"""The package's layers: imports run one way, the public API is where the docs say it is."""

from __future__ import annotations

import ast
import pydoc
import re
import subprocess
import sys
from pathlib import Path

import zonegraph

PACKAGE = Path(zonegraph.__file__).parent
# Each layer may import only layers of a lower rank (and itself); data and zones are siblings, as
# are export and network.
# errors, console (capturing native output), plugins (the guides, by name) and configs (the Config
# idiom every layer's settings use) import nothing heavy and serve every layer; status, the
# vocabulary of outcomes, sits below them all (errors name theirs).
RANK = {
    "status": -1,
    "errors": 0,
    "console": 0,
    "plugins": 0,
    "configs": 0,
    "lazy": 0,
    "verified": 0,
    "geometry": 1,
    "data": 2,
    "zones": 2,
    "sequence": 3,
    "export": 4,
    "network": 4,  # the network guide at inference: model, encoding, checkpoint, ranker
}
TOP = 5  # reconstruction, cli, batch, jobs, build_job, isolation, outputs and the package root
# The one layer that may import these, and which no other imports at module level: the rest reach
# the network guide through zonegraph.plugins, by reference, so a core install never needs torch.
TORCH = ("torch", "torch_geometric")
TORCH_LAYER = "network"


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _rank(layer: str) -> int:
    return RANK.get(layer, TOP)


def _names(node: ast.AST) -> set[str]:
    if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
        return {node.module}
    if isinstance(node, ast.Import):
        return {a.name for a in node.names}
    return set()


def _imports(path: Path) -> set[str]:
    return {name for node in ast.walk(ast.parse(path.read_text())) for name in _names(node)}


def _eager_imports(path: Path) -> set[str]:
    """The imports that run when the module is imported: module level, outside functions and
    ``if TYPE_CHECKING:`` blocks."""
    found: set[str] = set()
    pending: list[ast.AST] = list(ast.parse(path.read_text()).body)
    while pending:
        node = pending.pop()
        found |= _names(node)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            pending.extend(node.orelse)
        elif not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            pending.extend(ast.iter_child_nodes(node))
    return found


def _modules() -> list[tuple[str, Path]]:
    return [
        (".".join(("zonegraph", *path.relative_to(PACKAGE).with_suffix("").parts)), path)
        for path in PACKAGE.rglob("*.py")
    ]


def test_only_the_network_layer_imports_torch_and_nothing_imports_it_eagerly():
    bad = []
    for module, path in _modules():
        if _layer(module) == TORCH_LAYER:
            continue
        for imported in _imports(path):
            if imported.split(".")[0] in TORCH:
                bad.append(f"{module} imports {imported}")
        for imported in _eager_imports(path):
            if imported == f"zonegraph.{TORCH_LAYER}" or imported.startswith(f"zonegraph.{TORCH_LAYER}."):
                bad.append(f"{module} imports {imported} at module level")
    assert not bad, "torch outside zonegraph.network:\n" + "\n".join(sorted(bad))


def test_the_package_the_cli_help_and_the_shipped_network_guide_load_no_torch():
    code = (
        "import sys, contextlib, io, zonegraph, zonegraph.network, zonegraph.plugins, zonegraph.cli\n"
        "zonegraph.plugins.available_guides()\n"
        "import zonegraph.sequence.rankers as r; r.make_ranker('net')\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    zonegraph.cli.main(['infer', '--help'])\n"
        "print(sorted(m for m in ('torch', 'torch_geometric') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["[]"]


def test_every_module_that_imports_the_kernel_holds_its_thread_pool_first():
    """A parallel Boolean before the pool is held would hang every forked child's first one."""
    kernel = "zonegraph.geometry.kernel"
    bad = [
        module
        for module, path in _modules()
        if module != kernel
        and any(i.split(".")[0] in ("OCP", "build123d") for i in _eager_imports(path))
        and kernel not in _eager_imports(path)
    ]
    assert not bad, f"import {kernel} in:\n" + "\n".join(sorted(bad))


def test_imports_run_one_way():
    bad = []
    for module, path in _modules():
        layer = _layer(module)
        for imported in _imports(path):
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


def test_the_layout_page_names_every_module():
    """The docs' code layout page matches the tree: every sub-package and every module of the
    package (a sub-package's modules by their own name) is named there."""
    layout = (PACKAGE.parent / "docs" / "layout.md").read_text()
    named = set(re.findall(r"`([\w/.]+?)/?`", layout))
    missing = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        name = parts[-2] if parts[-1] == "__init__" and len(parts) > 1 else parts[-1]
        if name != "__init__" and name not in named and f"zonegraph/{name}" not in named:
            missing.append("/".join(parts))
    assert not missing, f"modules docs/layout.md does not name: {missing}"


def test_docstrings_are_markdown():
    """The API pages render docstrings as Markdown (mkdocstrings): a Sphinx role such as
    ``:func:`name``` shows up on the site as raw text, so names are written as code spans."""
    role = re.compile(r":(?:func|class|meth|attr|data|mod|exc|obj):`")
    found = [
        f"{path.relative_to(PACKAGE.parent)}:{n}"
        for root in ("zonegraph", "training", "eval", "pipelines", "bench")
        for path in sorted((PACKAGE.parent / root).rglob("*.py"))
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if role.search(line)
    ]
    assert not found, f"Sphinx roles in docstrings: {found}"


def test_the_docs_snippets_name_files_that_exist():
    """A snippet line the Markdown extension cannot parse is printed on the page as it is; every
    line that starts like one is well formed and names a file."""
    docs = PACKAGE.parent / "docs"
    bad = []
    for page in sorted(docs.rglob("*.md")):
        for n, line in enumerate(page.read_text().splitlines(), 1):
            if line.lstrip().startswith("--8"):
                match = re.fullmatch(r'\s*--8<-- "([^"]+)"', line)
                if match is None or not (PACKAGE.parent / match.group(1)).is_file():
                    bad.append(f"{page.relative_to(docs)}:{n}: {line.strip()}")
    assert not bad, f"malformed snippets: {bad}"
