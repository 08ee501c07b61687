"""Recording what build123d extrudes: ``extrude`` replaced by a wrapper that snapshots its faces.

We do not parse the scripts into geometry ourselves: we *run* each model with the recorder in
place, so the faces we convert are exactly the faces build123d extrudes, whatever sketch API made
them (``BuildLine`` + ``make_face``, ``Circle`` under ``Locations``, OCP B-splines, booleans
between sketch faces). A ``BuildSketch`` not followed by ``extrude`` leaves its faces pending and
the next ``extrude`` sweeps them too; recording what is actually extruded keeps that behaviour.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from zonegraph.data.b123d.curves import RecordedFace, face_record
from zonegraph.data.b123d.reasons import one_line
from zonegraph.errors import UnsupportedFeatureError

_ACTIVE: list[list[RecordedCall]] = []  # the recorder of the model now running (a stack of one)


@dataclass(frozen=True)
class RecordedCall:
    """One ``extrude(...)`` call, in timeline order, with everything needed to rebuild it."""

    line: int  # source line of the call inside the batch
    faces: tuple[RecordedFace, ...]
    amount: float
    both: bool
    taper: float  # build123d degrees (positive closes the profile)
    mode: str  # ADD / SUBTRACT / INTERSECT / ...
    explicit: bool  # the call named its sketch (``extrude(sk.sketch, ...)``)
    error: str = ""  # why the call cannot be expressed in our JSON (the call itself still ran)


def recording_extrude(real: Callable[..., Any], path: str) -> Callable[..., Any]:
    """A drop-in ``extrude`` that records its faces and arguments, then runs the real one."""

    def extrude(
        to_extrude: Any = None,
        amount: float | None = None,
        dir: Any = None,  # noqa: A002
        until: Any = None,
        target: Any = None,
        both: bool = False,
        taper: float = 0.0,
        clean: bool = True,
        mode: Any = None,
    ) -> Any:
        if _ACTIVE:
            frame = sys._getframe(1)
            line = frame.f_lineno if frame.f_code.co_filename == path else -1
            _ACTIVE[-1].append(_record(to_extrude, amount, dir, until, both, taper, mode, line))
        kwargs: dict[str, Any] = dict(
            amount=amount, dir=dir, until=until, target=target, both=both, taper=taper, clean=clean
        )
        if mode is not None:
            kwargs["mode"] = mode
        return real(to_extrude, **kwargs)

    return extrude


def _record(
    to_extrude: Any,
    amount: float | None,
    direction: Any,
    until: Any,
    both: bool,
    taper: float,
    mode: Any,
    line: int,
) -> RecordedCall:
    """Snapshot the faces ``extrude`` is about to consume (it clears the pending list itself)."""
    from build123d import BuildPart, Plane

    mode_name = "ADD" if mode is None else str(getattr(mode, "name", mode))
    base = dict(
        line=line,
        amount=float(amount or 0.0),
        both=bool(both),
        taper=float(taper or 0.0),
        mode=mode_name,
        explicit=to_extrude is not None,
    )
    try:
        if amount is None or until is not None or direction is not None:
            raise UnsupportedFeatureError("", None, "extrude with until/dir (only distances)")
        if to_extrude is None:
            context = BuildPart._get_context("extrude", log=False)
            if context is None or not context.pending_faces:
                return RecordedCall(faces=(), error="extrude without pending faces", **base)  # type: ignore[arg-type]
            pairs = list(zip(context.pending_faces, context.pending_face_planes, strict=True))
        else:
            faces = list(to_extrude) if isinstance(to_extrude, (tuple, list)) else to_extrude.faces()
            pairs = [(f, Plane(f)) for f in faces]
        recorded = tuple(face_record(face, plane) for face, plane in pairs)
        return RecordedCall(faces=recorded, **base)  # type: ignore[arg-type]
    except UnsupportedFeatureError as exc:
        return RecordedCall(faces=(), error=exc.reason, **base)  # type: ignore[arg-type]
    except Exception as exc:  # a face we cannot read: say why, let the real extrude run
        reason = f"cannot read profile: {type(exc).__name__}: {one_line(exc)}"
        return RecordedCall(faces=(), error=reason, **base)  # type: ignore[arg-type]


@contextlib.contextmanager
def recording() -> Iterator[list[RecordedCall]]:
    """Collect the ``extrude`` calls of the model run inside the block (batches from load_batch)."""
    calls: list[RecordedCall] = []
    _ACTIVE.append(calls)
    try:
        yield calls
    finally:
        _ACTIVE.pop()
