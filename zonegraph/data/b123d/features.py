"""Calls to features: the recorded ``extrude`` calls as our typed timeline, one Fusion feature each.

Each feature (a ``# Sketch -> Extrude (Op)`` comment in the source) becomes one ExtrudeFeature that
keeps Fusion's own operation. Semantics that differ between the two worlds, and how they are
bridged:

- build123d's ``both=True`` extrudes ``amount`` to each side: Fusion's Symmetric extent with
  ``is_full_length = False`` and the same distance (or ``True`` with twice the distance when the
  script's comment says Fusion used the full length).
- build123d's positive ``taper`` (degrees) closes the profile; Fusion's positive taper opens it, so
  the JSON holds ``-radians(taper)`` (the replay negates it again).
- Fusion's TwoSides extents are written as two ``extrude`` calls (the second on ``sk.sketch``);
  the pair is merged back into one TwoSides feature. The "offset" variant (Join the full depth,
  then Cut the trim depth) is merged into a TwoSides extent whose both ends lie on one side; where
  that differs from the script (its Cut also removes older material), the calls are written as
  separate features instead (``literal``).
"""

from __future__ import annotations

import math
import uuid
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from zonegraph.data.b123d.comments import FeatureComment
from zonegraph.data.b123d.curves import RecordedFace
from zonegraph.data.b123d.recording import RecordedCall
from zonegraph.data.design import (
    Design,
    Extent,
    ExtentType,
    Extrude,
    Frame,
    Operation,
    Profile,
    ProfileRef,
    Sketch,
)
from zonegraph.data.profiles import SNAP_TOL
from zonegraph.errors import UnsupportedFeatureError

SAME_TOL = 1e-9  # relative: two recorded face sets are the same profiles

OPERATIONS = {
    "NewBody": Operation.NEW_BODY,
    "Join": Operation.JOIN,
    "Cut": Operation.CUT,
    "Intersect": Operation.INTERSECT,
}
SHORT_NAMES = {v: k for k, v in OPERATIONS.items()}
# The script mode each Fusion operation should have been written with.
EXPECTED_MODE = {"NewBody": "ADD", "Join": "ADD", "Cut": "SUBTRACT", "Intersect": "INTERSECT"}
MODE_OPERATION = {"ADD": Operation.JOIN, "SUBTRACT": Operation.CUT, "INTERSECT": Operation.INTERSECT}


@dataclass(frozen=True)
class Feature:
    """The recorded calls of one Fusion feature (or of calls no comment names)."""

    comment: FeatureComment | None
    calls: tuple[RecordedCall, ...]


def group_calls(calls: list[RecordedCall], comments: list[FeatureComment]) -> list[Feature]:
    """Assign each call to the last feature comment above it (calls before any get their own)."""
    groups: list[Feature] = []
    for call in calls:
        owner = None
        for c in comments:
            if c.line < call.line:
                owner = c
        if groups and owner is not None and groups[-1].comment is owner:
            groups[-1] = Feature(owner, groups[-1].calls + (call,))
        else:
            groups.append(Feature(owner, (call,)))
    return groups


@dataclass
class _Writer:
    """Builds the typed timeline (sketches, extrudes) with deterministic ids."""

    design_id: str
    timeline: list[Sketch | Extrude] = field(default_factory=list)
    counter: int = 0

    def uid(self, kind: str) -> str:
        self.counter += 1
        return str(uuid.uuid5(uuid.NAMESPACE_URL, f"fusion360_b123d/{self.design_id}/{kind}/{self.counter}"))

    def sketches(self, call: RecordedCall, name: str) -> tuple[ProfileRef, ...]:
        """One sketch per distinct face frame; every face becomes one profile."""
        refs: list[ProfileRef] = []
        groups: list[tuple[Frame, list[RecordedFace]]] = []
        for face in call.faces:
            for frame, members in groups:
                if _same_frame(frame, face.frame):
                    members.append(face)
                    break
            else:
                groups.append((face.frame, [face]))
        for i, (frame, members) in enumerate(groups):
            sid = self.uid("sketch")
            profiles: dict[str, Profile] = {}
            for face in members:
                pid = self.uid("profile")
                profiles[pid] = Profile(pid, face.loops, face.area)
                refs.append(ProfileRef(sid, pid))
            self.timeline.append(Sketch(sid, name if i == 0 else f"{name}.{i + 1}", frame, profiles))
        return tuple(refs)

    def extrude(self, refs: tuple[ProfileRef, ...], name: str, op: Operation, **extent: Any) -> None:
        self.timeline.append(Extrude(self.uid("extrude"), name, refs, op, **extent))


def _same_frame(a: Frame, b: Frame) -> bool:
    return all(
        np.allclose(u, v, atol=1e-12)
        for u, v in ((a.origin, b.origin), (a.x_axis, b.x_axis), (a.z_axis, b.z_axis))
    )


def _fusion_taper(degrees: float) -> float:
    """build123d's taper (degrees, positive inward) as Fusion's (radians, positive outward)."""
    return -math.radians(degrees)


def _single_extent(call: RecordedCall, full_length: bool) -> dict[str, Any]:
    taper = _fusion_taper(call.taper)
    if call.both:
        d = abs(call.amount)
        if full_length:
            return dict(
                extent_type=ExtentType.SYMMETRIC, extent_one=Extent(2 * d, taper), symmetric_full_length=True
            )
        return dict(
            extent_type=ExtentType.SYMMETRIC, extent_one=Extent(d, taper), symmetric_full_length=False
        )
    return dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(call.amount, taper))


def _along(first: RecordedCall, second: RecordedCall) -> float | None:
    """``second``'s amount measured along ``first``'s normal if both extrude the same faces."""
    if len(first.faces) != len(second.faces) or not first.faces:
        return None
    sign = 0.0
    for a, b in zip(first.faces, second.faces, strict=True):
        scale = max(math.sqrt(a.quick_area), 1e-9)
        if (
            abs(a.quick_area - b.quick_area) > SAME_TOL * max(a.quick_area, 1e-12)
            or np.linalg.norm(np.subtract(a.center, b.center)) > SAME_TOL * 1e3 * scale
        ):
            return None
        dot = float(np.dot(a.normal, b.normal))
        if abs(abs(dot) - 1) > 1e-9 or (sign and sign != math.copysign(1.0, dot)):
            return None
        sign = math.copysign(1.0, dot)
    return sign * second.amount


def merge_pair(first: RecordedCall, second: RecordedCall) -> dict[str, Any] | None:
    """The extent of a Fusion TwoSides feature written as two calls, or None if not a pair.

    Both calls sweep from the sketch plane, so with amounts ``a`` and ``b`` (along the first
    normal) the swept region is [0, a] U [0, b]; for the Join-then-Cut "offset" variant it is
    [0, a] minus [0, b]. TwoSides covers [-d2, d1] (our replay sweeps each tapered side from the
    profile plane, as build123d does).
    """
    if first.both or second.both or first.error or second.error:
        return None
    b = _along(first, second)
    if b is None:
        return None
    a = first.amount
    if first.mode == second.mode and first.mode in ("ADD", "SUBTRACT"):
        if a * b < 0:
            return dict(
                extent_type=ExtentType.TWO_SIDES,
                extent_one=Extent(a, _fusion_taper(first.taper)),
                extent_two=Extent(-b, _fusion_taper(second.taper)),
            )
        if first.taper == 0 and second.taper == 0:  # one side twice: the longer one wins
            return dict(extent_type=ExtentType.ONE_SIDE, extent_one=Extent(a if abs(a) >= abs(b) else b))
        return None
    if (
        (first.mode, second.mode) == ("ADD", "SUBTRACT")
        and a * b > 0
        and abs(b) < abs(a)
        and first.taper == 0
        and second.taper == 0
    ):
        return dict(extent_type=ExtentType.TWO_SIDES, extent_one=Extent(a), extent_two=Extent(-b))
    return None


@dataclass(frozen=True)
class Plan:
    """A timeline built from the recorded calls, with what was decided along the way."""

    design: Design
    operations: tuple[str, ...]
    mode_disagreements: int
    notes: tuple[str, ...]


def build_design(design_id: str, features: list[Feature], literal: bool = False) -> Plan:
    """Our typed design for the recorded features.

    Each Fusion feature keeps the operation of its comment. ``literal`` writes every call of a
    multi-call feature as its own extrude (the exact script) instead of merging it into one.
    """
    w = _Writer(design_id)
    ops: list[str] = []
    notes: list[str] = []
    disagreements = 0
    for k, feature in enumerate(features):
        for call in feature.calls:
            if call.error:
                raise UnsupportedFeatureError(design_id, None, f"line {call.line}: {call.error}")
        c = feature.comment
        name = c.name if c else f"Extrude{k + 1}"
        sketch_name = c.sketch if c else f"Sketch{k + 1}"
        fusion_op = c.operation if c else None
        modes = [call.mode for call in feature.calls]
        if fusion_op is not None and EXPECTED_MODE[fusion_op] != modes[0]:
            disagreements += 1
            notes.append(f"{name}: Fusion says {fusion_op}, script mode {modes[0]}")
        first_op = OPERATIONS[fusion_op] if fusion_op else MODE_OPERATION.get(modes[0], Operation.JOIN)
        if modes[0] not in MODE_OPERATION:
            raise UnsupportedFeatureError(design_id, None, f"{name}: script mode {modes[0]}")
        calls = feature.calls
        dropped = sum(f.dropped for call in calls for f in call.faces)
        if dropped:
            notes.append(f"{name}: left out {dropped} profile line(s) shorter than {SNAP_TOL:g} cm")
        extent = merge_pair(calls[0], calls[1]) if len(calls) == 2 and not literal else None
        if len(calls) == 1 or extent is not None:
            refs = w.sketches(calls[0], sketch_name)
            w.extrude(refs, name, first_op, **(extent or _single_extent(calls[0], bool(c and c.full_length))))
            ops.append(SHORT_NAMES[first_op])
            continue
        notes.append(f"{name}: {len(calls)} calls written as {len(calls)} extrudes")
        for i, call in enumerate(calls):
            op = first_op if i == 0 else MODE_OPERATION.get(call.mode)
            if op is None:
                raise UnsupportedFeatureError(design_id, None, f"{name}: script mode {call.mode}")
            suffix = "" if i == 0 else f".{i + 1}"
            refs = w.sketches(call, sketch_name + suffix)
            w.extrude(refs, name + suffix, op, **_single_extent(call, False))
            ops.append(SHORT_NAMES[op])
    if not w.timeline:
        raise UnsupportedFeatureError(design_id, None, "no extrude was recorded")
    return Plan(Design(design_id, tuple(w.timeline)), tuple(ops), disagreements, tuple(notes))
