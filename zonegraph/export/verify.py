"""Rebuild what is written, and write snapped numbers only where they rebuild the part as well.

Snapping moves each number by at most a millionth of the part, but a moved vertex can still close a
gap, merge two edges or tip a Boolean, so nothing is assumed: the texts that go to disk are run
themselves. The script is executed in a fresh namespace (its ``result``), the JSON is parsed and
replayed by the project's own reader, and both are measured against the target with B-rep IoU. The
snapped texts are kept when they are exact wherever the program was (or as good as the program's
own rebuild); otherwise each file is chosen apart, its snapped text where it is at least as good as
its raw twin, else the raw numbers, and the IoU recorded is always that of the texts written. The
script's idioms (sketch objects, holes) are guarded the same way: each pass writes the most
idiomatic script that rebuilds as well, dropping holes, then objects, then build123d's own
Booleans (for checked fuzzy ones) where it does not.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import numpy as np
from build123d import Shape, Unit

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.data.design import parse_design
from zonegraph.data.replay import ReplayResult, cells_last, replay
from zonegraph.export.snap import REL_TOL, Snapper
from zonegraph.export.writers import (
    IDIOMATIC,
    LITERAL,
    ScriptStyle,
    WrittenStep,
    design_text,
    program_script,
    written_steps,
)
from zonegraph.geometry.cells import FUZZY_SHARES
from zonegraph.sequence.program import ProgramStep, brep_iou
from zonegraph.verified import file_properties

IOU_SLACK = 1e-6  # volume-integration noise between two rebuilds of the same part
# How far a program that is not exact may have its files fall short of its own rebuild. The two
# can differ by more than integration noise (0.42279 against 0.42258 on a 20-step partial
# program), and under IOU_SLACK no style and no pass qualified, so every one was tried: 47 s of
# verification for a 1.6 s rebuild. A thousandth is far below what a failed idiom costs (0.351).
PARTIAL_SLACK = 1e-3
# Written files are measured with faces closer than this fraction of the part's diagonal taken as
# one: ten times what snapping may move (REL_TOL), far below any real change. Without it the
# common of a snapped part and the target, faces 1e-6 apart, came back with 3e-7 of the volume.
FUZZY_REL = 10 * REL_TOL


@dataclass(frozen=True)
class ExportCheck:
    """B-rep IoU against the target of the written script and of the written JSON's replay
    (faces closer than ``FUZZY_REL`` of the part's diagonal taken as one)."""

    script_iou: float
    json_iou: float
    error: str = ""  # why a written file did not rebuild ("" when both did)

    @property
    def iou(self) -> float:
        return min(self.script_iou, self.json_iou)


@dataclass(frozen=True)
class Export:
    """The texts of sequence.py and sequence.json, whether their numbers were snapped, and how
    they rebuild."""

    script: str
    design: str
    snapped: bool  # the script carries snapped numbers
    snapped_numbers: int  # numbers whose written text snapping changed (0 when neither file is snapped)
    check: ExportCheck
    style: ScriptStyle = IDIOMATIC  # the idioms the script uses
    design_snapped: bool = False  # the JSON carries snapped numbers


# The styles a script is tried in, most idiomatic first; the literal loops are the last resort of
# build123d's own Booleans, after which the steps are combined by fuzzy Booleans
# (`fuzzy_styles`).
STYLES = (IDIOMATIC, ScriptStyle(holes=False), LITERAL)


def fuzzy_styles(target: Shape) -> tuple[ScriptStyle, ...]:
    """The checked styles for a part, sketch objects kept: each step's Boolean at the fuzzy values
    of the program's own rebuild (``FUZZY_SHARES`` of the part's diagonal), then the point set of
    all the tools at those values, as the rebuild's own last resort."""
    diag = float(target.bounding_box().diagonal)
    fuzzy = tuple(share * diag for share in FUZZY_SHARES)
    return ScriptStyle(holes=False, fuzzy=fuzzy), ScriptStyle(holes=False, fuzzy=fuzzy, cells=True)


def export_texts(
    program: list[ProgramStep], name: str, unit: Unit, snap: Snapper, style: ScriptStyle = IDIOMATIC
) -> tuple[str, str]:
    """The script and JSON texts of a program, both from one pass of ``snap`` over its numbers."""
    steps = written_steps(program, snap)
    return program_script(steps, name, unit, style), design_text(steps, name)


def run_script(text: str) -> Shape:
    """The ``result`` of a written script, executed as a module that is not ``__main__``."""
    namespace: dict[str, Any] = {"__name__": "zonegraph_written_script"}
    exec(compile(text, "sequence.py", "exec"), namespace)
    result = namespace.get("result")
    if not isinstance(result, Shape):
        raise ValueError("the script left no shape in `result`")
    return result


def _measure(build: Callable[[], Shape], target: Shape, fuzzy: float, label: str) -> tuple[float, str]:
    """IoU of ``build()`` against the target; any failure to rebuild is an IoU of 0 and its reason
    (OCP's exceptions share no base class, so none is let through)."""
    try:
        return brep_iou(build(), target, fuzzy), ""
    except Exception as exc:
        return 0.0, f"{label}: {type(exc).__name__}: {exc}"


def _fuzzy(target: Shape) -> float:
    return FUZZY_REL * target.bounding_box().diagonal


def check_export(script: str, design: str, name: str, target: Shape) -> ExportCheck:
    """Run the written script and replay the written JSON; measure both against the target, faces
    closer than ``FUZZY_REL`` of its diagonal taken as one."""
    fuzzy = _fuzzy(target)
    script_iou, script_error = _measure(lambda: run_script(script), target, fuzzy, "sequence.py")
    json_iou, json_error = _measure(
        lambda: replay(parse_design(json.loads(design), name)).shape, target, fuzzy, "sequence.json"
    )
    return ExportCheck(script_iou, json_iou, "; ".join(e for e in (script_error, json_error) if e))


def _styled_script(
    steps: list[WrittenStep], name: str, unit: Unit, target: Shape, bar: float
) -> tuple[str, ScriptStyle, float, str]:
    """The most idiomatic script of ``steps`` that rebuilds as well as the program (to ``bar``,
    its rebuild's IoU less the slack `verified_export` allows): an idiom may not spend the margin
    between the program and the exactness bar. Where none rebuilds to ``bar``, the best of all
    styles (the more idiomatic within ``IOU_SLACK``). Returns the text, its style, IoU and error."""
    tried: list[tuple[str, ScriptStyle, float, str]] = []
    for style in (*STYLES, *fuzzy_styles(target)):
        script = program_script(steps, name, unit, style)
        if any(script == t[0] for t in tried):
            continue
        iou, error = _measure(partial(run_script, script), target, _fuzzy(target), "sequence.py")
        tried.append((script, style, iou, error))
        if not error and iou >= bar:
            return tried[-1]
    best = max(t[2] for t in tried)
    return next(t for t in tried if t[2] >= best - IOU_SLACK)


def _pass(
    program: list[ProgramStep],
    name: str,
    unit: Unit,
    target: Shape,
    snap: Snapper,
    bar: float,
) -> Export:
    """The files of one pass of ``snap`` over the program's numbers, the script in its best style."""
    steps = written_steps(program, snap)
    script, style, script_iou, script_error = _styled_script(steps, name, unit, target, bar)
    design, json_iou, json_error = _design_file(steps, name, target, bar)
    error = "; ".join(e for e in (script_error, json_error) if e)
    return Export(
        script, design, snap.changed > 0, snap.changed, ExportCheck(script_iou, json_iou, error), style
    )


def _design_file(steps: list[WrittenStep], name: str, target: Shape, good: float) -> tuple[str, float, str]:
    """``sequence.json``'s text, its IoU and error: the file carries its own replay's figures as
    ``properties``, so that replaying it verifies by default (`zonegraph.verified`). Where
    that replay falls short of ``good`` and the cells of all its tools come closer, the file
    carries the cells' figures instead, with which its replay takes the last step from them
    (``CELLS_RETRY_RTOL``); that text is replayed again and kept if it measures better."""
    plain = design_text(steps, name)
    try:
        result = replay(parse_design(json.loads(plain), name))
    except Exception as exc:  # OCP's exceptions share no base class (as in _measure)
        return plain, 0.0, f"sequence.json: {type(exc).__name__}: {exc}"
    fuzzy = _fuzzy(target)
    text = design_text(steps, name, file_properties(result.measured()))
    iou = brep_iou(result.shape, target, fuzzy)
    retried = None if iou >= good else cells_last(result.steps)
    if retried is None or brep_iou(retried[-1].shape, target, fuzzy) <= iou:
        return text, iou, ""
    cells_text = design_text(steps, name, file_properties(ReplayResult(result.design, retried).measured()))
    again, error = _measure(
        lambda: replay(parse_design(json.loads(cells_text), name)).shape, target, fuzzy, "sequence.json"
    )
    return (cells_text, again, error) if not error and again > iou else (text, iou, "")


def _snapper(target: Shape, rel: float) -> Snapper:
    """A snapper for the target's size: its farthest point from the origin is a corner of its box."""
    box = target.bounding_box()
    corner = np.maximum(np.abs(tuple(box.min)), np.abs(tuple(box.max)))
    return Snapper.for_part(box.diagonal, float(np.linalg.norm(corner)), rel)


def as_good(snapped: ExportCheck, floor: float, raw: ExportCheck | None = None) -> bool:
    """Whether snapped files may be written: each rebuilds to ``floor`` (exact wherever the
    program was), or, measured beside the raw files, each is no worse than its raw twin."""
    if snapped.error:
        return False
    pairs = [
        (snapped.script_iou, raw.script_iou if raw else 1.0),
        (snapped.json_iou, raw.json_iou if raw else 1.0),
    ]
    return all(_no_worse(iou, other, floor) for iou, other in pairs)


def _no_worse(snapped: float, raw: float, floor: float) -> bool:
    return snapped >= min(floor, raw - IOU_SLACK)


def _file_error(error: str, label: str) -> str:
    """The part of an ExportCheck's error about one file (its messages start with its name)."""
    return "; ".join(e for e in error.split("; ") if e.startswith(label))


def _mixed(snapped: Export, raw: Export, floor: float) -> Export:
    """Each file from the pass that rebuilds it better: the snapped text where it fails no worse
    than the raw one (as `as_good` asks of both), else the raw text. The two files are two
    rebuilds with their own Booleans, and snapping helps one while it breaks the other (a corpus
    part whose snapped script was exact and raw one 0.03, its snapped JSON 0.03 and raw 0.95)."""
    files = []
    for label, field in (("sequence.py", "script_iou"), ("sequence.json", "json_iou")):
        s_iou, r_iou = getattr(snapped.check, field), getattr(raw.check, field)
        s_error = _file_error(snapped.check.error, label)
        files.append(not s_error and _no_worse(s_iou, r_iou, floor))
    script_from, design_from = (snapped if use else raw for use in files)
    errors = (
        _file_error(script_from.check.error, "sequence.py"),
        _file_error(design_from.check.error, "sequence.json"),
    )
    error = "; ".join(filter(None, errors))
    check = ExportCheck(script_from.check.script_iou, design_from.check.json_iou, error)
    return Export(
        script_from.script,
        design_from.design,
        snapped=files[0],
        snapped_numbers=snapped.snapped_numbers if any(files) else 0,
        check=check,
        style=script_from.style,
        design_snapped=files[1],
    )


def verified_export(
    program: list[ProgramStep],
    name: str,
    unit: Unit,
    target: Shape,
    reference_iou: float,
    exact_iou: float,
    rel_tol: float = REL_TOL,
) -> Export:
    """The texts to write: each snapped where its rebuild is as good as the unsnapped, else raw.

    Args:
        program: the found program, in the input's units.
        name: the design's name (script docstring, JSON id).
        unit: what the input's numbers mean.
        target: the input's shape, in its units.
        reference_iou: the B-rep IoU of the program's own rebuild.
        exact_iou: the IoU from which a part counts as exact.
        rel_tol: how far snapping may move a number, as a fraction of the part's diagonal.
    """
    bar = reference_iou - (IOU_SLACK if reference_iou >= exact_iou else PARTIAL_SLACK)
    floor = min(bar, exact_iou)
    snapped = _pass(program, name, unit, target, _snapper(target, rel_tol), bar)
    if not snapped.snapped or as_good(snapped.check, floor):
        return replace(snapped, design_snapped=snapped.snapped)
    raw = _pass(program, name, unit, target, Snapper.raw(), bar)
    return _mixed(snapped, raw, floor)
