"""The corpus's designs, listed without running any of its code.

The corpus (``../shared/data/fusion360_b123d``, see its ``PROVENANCE.md``) holds each design as a
function ``model_<id>()`` in a ``batch_*.py`` file under a timeline folder (``01_2ops`` ...
``08_21plus``); each batch's literal ``MODELS`` dict records Fusion's volume and area.
"""

from __future__ import annotations

import ast
import contextlib
import re
from dataclasses import dataclass
from pathlib import Path

FOLDER_RE = re.compile(r"^\d\d_")


@dataclass(frozen=True)
class CorpusEntry:
    """One design of the corpus, found without running any code."""

    design_id: str
    folder: str
    batch: str
    function: str
    fusion_volume: float | None
    fusion_area: float | None


def list_corpus(root: str | Path) -> list[CorpusEntry]:
    """Every design under ``root`` (folders ``NN_*`` of ``batch_*.py``), read with ``ast`` only.

    Importing the batches would execute build123d for every model; parsing is ~100x faster and
    cannot be broken by a bad model. A batch that does not parse still lists its ``def model_*``
    functions (found by a regular expression) so that converting them reports ``syntax_error``.
    """
    root = Path(root)
    out: list[CorpusEntry] = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir() and FOLDER_RE.match(p.name)):
        for batch in sorted(folder.glob("batch_*.py")):
            out.extend(batch_entries(batch, folder.name))
    return out


def batch_entries(batch: Path, folder: str) -> list[CorpusEntry]:
    """The designs of one batch: ``def model_*`` at top level plus the literal ``MODELS`` block.

    Only the ``MODELS`` assignment goes through ``ast`` (the function bodies are ~99% of the text
    and parsing them all takes ~10 s for the corpus); whether the whole file is valid Python is
    the converter's business (``syntax_error``).
    """
    text = batch.read_text(encoding="utf-8", errors="replace")
    names = re.findall(r"^def (model_\w+)\s*\(", text, flags=re.M)
    measures: dict[str, tuple[float | None, float | None]] = {}
    m = re.search(r"^MODELS\s*=", text, flags=re.M)
    if m:
        tail = text[m.start() :]
        stop = re.search(r"^if __name__", tail, flags=re.M)
        with contextlib.suppress(SyntaxError, ValueError):
            measures = _models_measures(ast.parse(tail[: stop.start()] if stop else tail))
    return [
        CorpusEntry(n.removeprefix("model_"), folder, str(batch), n, *measures.get(n, (None, None)))
        for n in names
    ]


def _models_measures(tree: ast.Module) -> dict[str, tuple[float | None, float | None]]:
    """``MODELS`` -> {function: (volume, area)} from the literal dict (its ``func`` is a name)."""
    out: dict[str, tuple[float | None, float | None]] = {}
    for node in tree.body:
        if not (
            isinstance(node, ast.Assign)
            and any(isinstance(t, ast.Name) and t.id == "MODELS" for t in node.targets)
        ):
            continue
        if not isinstance(node.value, ast.Dict):
            continue
        for key, value in zip(node.value.keys, node.value.values, strict=True):
            if not (isinstance(key, ast.Constant) and isinstance(key.value, str)):
                continue
            if not isinstance(value, ast.Dict):
                continue
            fields: dict[str, float] = {}
            for k, v in zip(value.keys, value.values, strict=True):
                if (
                    isinstance(k, ast.Constant)
                    and isinstance(v, ast.Constant)
                    and isinstance(v.value, (int, float))
                ):
                    fields[str(k.value)] = float(v.value)
            out[key.value] = (fields.get("volume"), fields.get("area"))
    return out
