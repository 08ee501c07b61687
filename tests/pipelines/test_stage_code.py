"""One source of truth for what a stage's records depend on: its code deps in ``dvc.yaml``.

A record is reused only while the code it was made by and the files it read are unchanged; these
tests change a zone-graph module or a saved graph and check that the dependent records are
recomputed, not reused (the stale-results bug of the ``reconstruct`` stage)."""

from __future__ import annotations

import ast
import shlex
import shutil
from pathlib import Path

import yaml
from distributed import Client

from pipelines.runner import CODE_ROOTS, PROJECT, Job, code_fingerprint, fingerprint, run_jobs, stage_code

STAGES = yaml.safe_load((PROJECT / "dvc.yaml").read_text())["stages"]


def _copy_project(tmp: Path) -> Path:
    root = tmp / "project"
    root.mkdir()
    shutil.copy(PROJECT / "dvc.yaml", root)
    for folder in ("zonegraph", "pipelines"):
        shutil.copytree(PROJECT / folder, root / folder, ignore=shutil.ignore_patterns("__pycache__"))
    return root


def _load_graph(graph_dir: str) -> dict:
    """Stands for a reconstruct job: reads a saved graph, returns what it found."""
    return {"zones": len((Path(graph_dir) / "zones.parquet").read_bytes())}


def _module_file(name: str) -> Path | None:
    """The project file of a dotted module name (a module or a package), or None outside it."""
    if name.split(".")[0] not in CODE_ROOTS:
        return None
    base = PROJECT.joinpath(*name.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _module_name(path: Path) -> str:
    parts = path.relative_to(PROJECT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_type_checking(node: ast.AST) -> bool:
    test = node.test if isinstance(node, ast.If) else None
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _run_nodes(node: ast.AST) -> list[ast.AST]:
    """Every node of ``node`` that can run: all but the bodies of ``if TYPE_CHECKING:``."""
    nodes = [node]
    for child in ast.iter_child_nodes(node):
        if _is_type_checking(child):
            assert isinstance(child, ast.If)
            for other in child.orelse:
                nodes.extend(_run_nodes(other))
        else:
            nodes.extend(_run_nodes(child))
    return nodes


def _imported(path: Path) -> set[str]:
    """Every module ``path`` imports anywhere in its body (lazy imports inside functions too, not
    those for the type checker), with relative imports resolved and ``from package import module``
    naming the module."""
    here = _module_name(path)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    names: set[str] = set()
    for node in _run_nodes(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, node.module] if node.module else anchor)
            else:
                base = node.module or ""
            names.add(base)
            names.update(f"{base}.{alias.name}" for alias in node.names)
    return names


def _closure(entry: str) -> set[Path]:
    """The project files a ``python -m entry`` process runs: the modules it imports, directly or
    not, and the packages above each (a package's ``__init__`` runs on a submodule's import)."""
    seen: set[Path] = set()
    todo = [entry]
    while todo:
        name = todo.pop()
        parts = name.split(".")
        for i in range(1, len(parts) + 1):
            path = _module_file(".".join(parts[:i]))
            if path is not None and path not in seen:
                seen.add(path)
                todo.extend(_imported(path))
    return seen


def _entry_module(cmd: str) -> str:
    words = shlex.split(cmd)
    assert words[:2] == ["python", "-m"], f"{cmd!r}: a stage runs a module of the project"
    return words[2]


def test_every_code_dep_exists():
    for stage in STAGES:
        for path in stage_code(stage):
            assert Path(path).exists(), f"{stage}: code dep {path} does not exist"


def test_the_code_deps_cover_every_module_a_stage_imports():
    """``dvc.yaml``'s code deps are what DVC watches and what `code_fingerprint` hashes into
    every record: a module a stage imports but does not list would let stale records be reused."""
    for stage, spec in STAGES.items():
        listed = [Path(p) for p in stage_code(stage)]
        missing = sorted(
            str(f.relative_to(PROJECT))
            for f in _closure(_entry_module(spec["cmd"]))
            if not any(f == dep or dep in f.parents for dep in listed)
        )
        assert not missing, f"{stage}: imports code that dvc.yaml does not list: {missing}"


def test_the_import_walk_finds_lazy_and_relative_imports():
    files = {str(f.relative_to(PROJECT)) for f in _closure("pipelines.zonegraphs")}
    assert {"pipelines/runner.py", "pipelines/__init__.py", "zonegraph/isolation.py"} <= files
    assert "zonegraph/zones/build.py" in files  # imported inside a function of zonegraph.jobs


def test_the_code_deps_name_the_stage_code():
    zone_code = stage_code("zonegraphs")
    assert any(p.endswith("zonegraph/zones") for p in zone_code)
    assert any(p.endswith("zonegraph") for p in stage_code("reconstruct"))


def test_a_zone_graph_module_change_invalidates_graphs_and_reconstructions(tmp_path):
    root = _copy_project(tmp_path)
    before = {s: code_fingerprint(s, root) for s in ("replay", "zonegraphs", "reconstruct")}
    extension = root / "zonegraph" / "zones" / "extension.py"
    extension.write_text(extension.read_text() + "\n# a change in face extension\n")
    after = {s: code_fingerprint(s, root) for s in before}
    assert after["zonegraphs"] != before["zonegraphs"]
    assert after["reconstruct"] != before["reconstruct"]
    assert after["replay"] == before["replay"]  # replay does not read zone-graph code


def test_changed_code_or_saved_graph_recomputes_the_record(tmp_path):
    root = _copy_project(tmp_path)
    graph = tmp_path / "graphs" / "d0"
    graph.mkdir(parents=True)
    (graph / "zones.parquet").write_bytes(b"x" * 10)

    def jobs() -> list[Job]:
        code = code_fingerprint("reconstruct", root)
        return [Job("d0", fingerprint(code, files=(graph,)), (str(graph),))]

    records = tmp_path / "records"
    with Client(processes=False, dashboard_address=None) as client:
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 10
        (graph / "zones.parquet").write_bytes(b"x" * 12)  # the zonegraphs stage re-saved the graph
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 12
        stamp = (records / "d0.json").stat().st_mtime_ns
        assert run_jobs(_load_graph, jobs(), records, client, 20, "t")[0]["zones"] == 12
        assert (records / "d0.json").stat().st_mtime_ns == stamp  # nothing changed: reused
        model = root / "zonegraph" / "zones" / "model.py"
        model.write_text(model.read_text() + "\n# a change in the zone graph model\n")
        run_jobs(_load_graph, jobs(), records, client, 20, "t")
        assert (records / "d0.json").stat().st_mtime_ns != stamp  # new code: recomputed
