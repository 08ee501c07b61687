"""Importing a batch: once per process, shims installed, ``extrude`` replaced by the recorder."""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import sys
import types
from dataclasses import dataclass
from pathlib import Path

from zonegraph.data.b123d.reasons import one_line
from zonegraph.data.b123d.recording import recording_extrude
from zonegraph.data.b123d.shims import install_api_shims, install_ocp_shims


@dataclass
class _Batch:
    """An imported batch (or why it could not be imported) plus its source, parsed once."""

    path: str
    module: types.ModuleType | None
    error: str
    lines: list[str]
    spans: dict[str, tuple[int, int]]  # function name -> (first line, last line)


_BATCHES: dict[str, _Batch] = {}


def load_batch(batch_path: str | Path) -> _Batch:
    """Import a batch once per process (cached), with ``extrude`` replaced by the recorder."""
    key = str(Path(batch_path).resolve())
    if key in _BATCHES:
        return _BATCHES[key]
    lines: list[str] = []
    spans: dict[str, tuple[int, int]] = {}
    module: types.ModuleType | None = None
    error = ""
    try:
        text = Path(key).read_text(encoding="utf-8")
        lines = text.splitlines()
        tree = ast.parse(text, filename=key)
        spans = {
            n.name: (n.lineno, n.end_lineno or n.lineno) for n in tree.body if isinstance(n, ast.FunctionDef)
        }
        install_ocp_shims()
        name = "zonegraph_b123d_" + hashlib.sha1(key.encode()).hexdigest()[:16]
        spec = importlib.util.spec_from_file_location(name, key)
        if spec is None or spec.loader is None:
            raise ImportError("no loader for this path")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        real = getattr(module, "extrude", None)
        if not callable(real):
            raise ImportError("the batch does not import build123d's extrude")
        module.extrude = recording_extrude(real, key)  # type: ignore[attr-defined]
        install_api_shims(module)
    except SyntaxError as exc:
        module, error = None, f"SyntaxError: {exc.msg} (line {exc.lineno})"
    except (Exception, SystemExit) as exc:  # whatever the module's top level raises, sys.exit too
        module, error = None, f"import failed: {type(exc).__name__}: {one_line(exc)}"
    batch = _Batch(key, module, error, lines, spans)
    _BATCHES[key] = batch
    return batch
