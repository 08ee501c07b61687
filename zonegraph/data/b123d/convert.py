"""One corpus design converted: its script run, its extrudes turned into our JSON, verified.

We *run* ``model_<id>()`` with ``extrude`` replaced by a recorder (`.recording`), turn each
recorded face back into profile curves (`.curves`) and each Fusion feature into one extrude
(`.features`), replay the JSON and compare it with the script's own part and Fusion's figures
(`.verify`, `zonegraph.verified`). Nothing a design does can escape as an exception:
every failure of the design becomes a `ConvertedDesign` with a status and a one-line reason;
a failure of our own code raises (its traceback is kept). A design's endless or crashing C call
is stopped by running it in a killable child (`zonegraph.jobs.convert_isolated`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from zonegraph.data.b123d.comments import feature_comments
from zonegraph.data.b123d.features import Plan, build_design, group_calls
from zonegraph.data.b123d.loading import load_batch
from zonegraph.data.b123d.reasons import one_line
from zonegraph.data.b123d.recording import recording
from zonegraph.data.b123d.reference import reference_part
from zonegraph.data.b123d.verify import verify
from zonegraph.data.design import design_to_json
from zonegraph.errors import UnsupportedFeatureError
from zonegraph.status import Status
from zonegraph.verified import (
    FUSION_FIELD,
    FUSION_RTOL,
    Measured,
    file_properties,
    fusion_properties,
    relative_difference,
)


@dataclass(frozen=True)
class ConvertedDesign:
    """The outcome of converting one design: its JSON (when built) and how well it replays.

    ``volume_rel_error``/``area_rel_error``: union of our replayed bodies vs the script's part.
    ``fusion_*``: our replay (bodies summed, as Fusion's ``properties`` are) vs Fusion's MODELS;
    ``script_fusion_*``: the script's part vs Fusion's MODELS.
    """

    design_id: str
    folder: str
    design_json: dict | None
    status: Status
    reason: str
    steps: int = 0
    operations: list[str] = field(default_factory=list)
    mode_disagreements: int = 0
    volume_rel_error: float | None = None
    area_rel_error: float | None = None
    fusion_volume_rel_error: float | None = None
    fusion_area_rel_error: float | None = None
    script_fusion_volume_rel_error: float | None = None
    script_fusion_area_rel_error: float | None = None
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status == Status.OK


def convert_design(
    batch_path: str | Path,
    design_id: str,
    fusion_volume: float | None = None,
    fusion_area: float | None = None,
) -> ConvertedDesign:
    """Run ``model_<design_id>`` of a batch, convert its extrudes to our JSON and verify the replay.

    Fusion's volume/area default to the batch's ``MODELS`` entry. Never raises for a bad design;
    runs in this process with no time limit (see `zonegraph.jobs.convert_isolated`).
    """
    t0 = time.perf_counter()
    path = Path(batch_path)

    def result(status: Status, reason: str, **kw: Any) -> ConvertedDesign:
        design_json = kw.pop("design_json", None)
        seconds = time.perf_counter() - t0
        return ConvertedDesign(
            design_id, path.parent.name, design_json, status, reason, seconds=seconds, **kw
        )

    return _convert(path, design_id, fusion_volume, fusion_area, result)


def _convert(  # noqa: C901 - the steps of one conversion, in order
    path: Path,
    design_id: str,
    fusion_volume: float | None,
    fusion_area: float | None,
    result: Callable[..., ConvertedDesign],
) -> ConvertedDesign:
    from build123d import Shape

    from zonegraph.data.replay import replay

    batch = load_batch(path)
    if batch.module is None:
        return result(Status.SYNTAX_ERROR, batch.error)
    fname = f"model_{design_id}"
    func = getattr(batch.module, fname, None)
    if not callable(func):
        return result(Status.SYNTAX_ERROR, f"the batch has no function {fname}")
    if fusion_volume is None or fusion_area is None:
        info = getattr(batch.module, "MODELS", {}).get(fname, {})
        fusion_volume = fusion_volume if fusion_volume is not None else info.get("volume")
        fusion_area = fusion_area if fusion_area is not None else info.get("area")

    # 1. run the script, recording its extrudes
    try:
        with recording() as calls:
            part = func()
    except MemoryError:
        raise  # the memory limit's outcome (out_of_memory, zonegraph.isolation), not the model's
    except (Exception, SystemExit, KeyboardInterrupt) as exc:  # whatever the script raises, sys.exit too
        return result(Status.MODEL_RAISED, f"{type(exc).__name__}: {one_line(exc)}")
    if not isinstance(part, Shape) or part.wrapped is None or not part.solids():
        return result(Status.NO_SHAPE, f"the model returned {type(part).__name__} without a solid")
    reference = reference_part(part)
    part = reference.shape
    script_volume, script_area = float(part.volume), float(part.area)  # build123d's own measure
    if script_volume <= 0:
        return result(Status.NO_SHAPE, f"the model's part has volume {script_volume:.3g}")
    script_fv = relative_difference(script_volume, fusion_volume) if fusion_volume else None
    script_fa = relative_difference(script_area, fusion_area) if fusion_area else None

    # 2. the recorded calls as our timeline
    start, end = batch.spans.get(fname, (0, 0))
    comments = feature_comments(batch.lines, start, end)
    features = group_calls(calls, comments)
    notes: list[str] = [reference.note] if reference.note else []
    used = {id(f.comment) for f in features if f.comment is not None}
    idle = [f"{c.sketch} -> {c.name}" for c in comments if id(c) not in used]
    if idle:  # its sketch's faces stay pending and are extruded by the next call with the next ones
        notes.append(
            f"{len(comments)} feature comments, {len(idle)} without an extrude call: " + ", ".join(idle[:4])
        )
    unnamed = sum(1 for f in features if f.comment is None)
    if unnamed:
        notes.append(f"{unnamed} extrude call(s) before any feature comment")
    try:
        plan = build_design(design_id, features)
    except UnsupportedFeatureError as exc:
        return result(
            Status.UNSUPPORTED,
            exc.reason,
            script_fusion_volume_rel_error=script_fv,
            script_fusion_area_rel_error=script_fa,
            notes=notes,
        )

    # 3. replay it and compare; a merged TwoSides that differs is retried call by call
    check = verify(plan, part, replay)
    if check.status != Status.OK and len(plan.operations) < len(calls):
        literal = build_design(design_id, features, literal=True)
        retry = verify(literal, part, replay)
        if retry.status == Status.OK:
            plan, check = literal, retry
    notes += list(plan.notes)
    if check.status == Status.OK and check.reason:
        notes.append(f"verified by {check.reason}")
    common: dict[str, Any] = dict(
        steps=len(plan.operations),
        operations=list(plan.operations),
        mode_disagreements=plan.mode_disagreements,
        script_fusion_volume_rel_error=script_fv,
        script_fusion_area_rel_error=script_fa,
        notes=notes,
    )
    if check.measured is None:  # the replay failed
        invalid = " (the script's own part is an invalid solid too)" if not part.is_valid else ""
        design_json = _to_json(plan, path, None, None, None)
        return result(check.status, check.reason + invalid, design_json=design_json, **common)
    measured = check.measured
    fv = relative_difference(measured.volume, fusion_volume) if fusion_volume else None
    fa = relative_difference(measured.area, fusion_area) if fusion_area else None
    common.update(
        volume_rel_error=check.volume_rel_error,
        area_rel_error=check.area_rel_error,
        fusion_volume_rel_error=fv,
        fusion_area_rel_error=fa,
    )
    design_json = _to_json(plan, path, measured, fusion_volume, fusion_area)
    if check.status == Status.MISMATCH:
        reason = check.reason
        if fv is not None and fa is not None and script_fv is not None and script_fa is not None:
            reason += (
                f"; vs Fusion: replay {fv:.1e}/{fa:.1e}, script {script_fv:.1e}/{script_fa:.1e} (volume/area)"
            )
        if not part.is_valid:
            reason += "; the script's own part is an invalid solid"
        return result(check.status, reason, design_json=design_json, **common)
    if fv is not None and fa is not None and script_fv is not None and script_fa is not None:
        if min(max(fv, fa), max(script_fv, script_fa)) > FUSION_RTOL:
            return result(
                Status.FUSION_MISMATCH,
                f"volume/area differ from Fusion's by {fv:.3%}/{fa:.3%} (script: "
                f"{script_fv:.3%}/{script_fa:.3%})",
                design_json=design_json,
                **common,
            )
    return result(Status.OK, "", design_json=design_json, **common)


def _to_json(
    plan: Plan, path: Path, measured: Measured | None, fusion_volume: float | None, fusion_area: float | None
) -> dict:
    """Fusion-format JSON whose ``properties`` are our replay's own figures (what ``zonegraph
    replay`` checks), with Fusion's published volume and area beside them."""
    metadata = {
        "parent_project": plan.design.id,
        "source": "fusion360_b123d",
        "batch": f"{path.parent.name}/{path.name}",
        "function": f"model_{plan.design.id}",
        "properties_source": f"zonegraph replay; Fusion's volume and area (MODELS): {FUSION_FIELD}",
    }
    properties = None if measured is None else file_properties(measured)
    out = design_to_json(plan.design, properties=properties, metadata=metadata)
    if measured is not None and fusion_volume is not None and fusion_area is not None:
        out[FUSION_FIELD] = fusion_properties(fusion_volume, fusion_area, measured)
    return out
