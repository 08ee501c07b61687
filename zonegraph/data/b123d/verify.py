"""Verification of a conversion: the replay of our JSON against the part the script itself built.

build123d's Mode.ADD fuses everything into one part, while Fusion's NewBody keeps separate bodies
(and so does our replay), so the *union* of our bodies is compared with the script's part: Join,
Cut and Intersect all distribute over the union, so the union of a correct replay is the script's
point set exactly, while the body-summed volume double counts overlapping NewBody bodies.
build123d's ``volume``/``area`` integrate with a fixed Gauss order that is off by up to ~1e-4 on
faces trimmed by B-spline curves, so a replay that misses `REPLAY_RTOL` is re-measured
precisely (`zonegraph.geometry.occ`) and, failing that, by its symmetric difference with the
script's part before it is a mismatch.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from zonegraph.data.b123d.features import Plan
from zonegraph.data.b123d.reasons import one_line
from zonegraph.data.design import Design, design_to_json, parse_design
from zonegraph.errors import ZoneGraphError
from zonegraph.geometry.occ import precise_area, precise_volume
from zonegraph.geometry.shapes import symmetric_difference_volume
from zonegraph.status import Status
from zonegraph.verified import REPLAY_RTOL, Measured, relative_difference

SYMDIFF_AREA_RTOL = 1e-5  # area agreement required before a symmetric difference may settle volume


@dataclass(frozen=True)
class Check:
    """A replay compared with the script: union errors and the replay's own figures (bodies
    summed, as Fusion's ``properties`` are)."""

    status: Status
    reason: str
    volume_rel_error: float = math.nan
    area_rel_error: float = math.nan
    measured: Measured | None = None


def verify(plan: Plan, part: Any, replay: Callable[[Design], Any]) -> Check:
    """Replay ``plan`` and compare the union of its bodies with the script's ``part``."""
    try:
        design = parse_design(design_to_json(plan.design), plan.design.id)
        res = replay(design)
        bodies = list(res.bodies)
        union = bodies[0].fuse(*bodies[1:]).clean() if len(bodies) > 1 else bodies[0]
        dv, da, how = _union_errors(union, part)
    except ZoneGraphError as exc:
        return Check(Status.REPLAY_FAILED, f"{exc.status}: {one_line(exc)}")
    except Exception as exc:  # the design's geometry fails in OpenCASCADE or build123d
        return Check(Status.REPLAY_FAILED, f"{type(exc).__name__}: {one_line(exc)}")
    measured = Measured(float(res.volume), float(res.area), len(bodies), int(res.face_count))
    if dv > REPLAY_RTOL or da > REPLAY_RTOL:
        reason = f"replay differs from the script: volume {dv:.2e}, area {da:.2e} relative"
        return Check(Status.MISMATCH, reason, dv, da, measured)
    return Check(Status.OK, how, dv, da, measured)


def _union_errors(union: Any, part: Any) -> tuple[float, float, str]:
    """Relative volume and area errors of ``union`` against ``part``, and how they were settled."""
    dv = relative_difference(float(union.volume), float(part.volume))
    da = relative_difference(float(union.area), float(part.area))
    how = ""
    if dv > REPLAY_RTOL or da > REPLAY_RTOL:
        uv, pv = abs(precise_volume(union.wrapped)), abs(precise_volume(part.wrapped))
        if uv > 0 and pv > 0:  # a broken shell integrates to 0 (docs/results/evidence.md)
            dv = relative_difference(uv, pv)
            da = relative_difference(precise_area(union.wrapped), precise_area(part.wrapped))
            how = "adaptive integration"
    if dv > REPLAY_RTOL and da <= SYMDIFF_AREA_RTOL:
        sym = symmetric_difference_volume(union, part) / max(abs(precise_volume(part.wrapped)), 1e-300)
        if sym <= REPLAY_RTOL:
            how = f"symmetric difference {sym:.1e} (integrated volumes differ by {dv:.1e})"
            dv = sym
    return dv, da, how
