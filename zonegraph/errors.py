"""Typed errors that name the input and the reason.

Every user-facing failure derives from `ZoneGraphError`, so the CLI and the pipeline can
turn it into a one-line message or a manifest row without a traceback, while programming errors
(any other exception) still surface loudly. OpenCASCADE's own exceptions are the third kind: the
kernel failing on this input's geometry (`is_kernel_error`), not a bug of ours.
"""

from __future__ import annotations

from pathlib import Path

from zonegraph.status import Status


class ZoneGraphError(Exception):
    """A failure caused by the input, not by a bug: carries the source and a short reason.

    Raised as it is (not as a subclass), it says that the input cannot be used at all, as a batch
    path that names nothing: ``invalid_input``, the input's fault like every status here. A status
    of its own (it was ``error``) read as a failure of ours, which is ``bug`` and keeps a traceback."""

    status: Status = Status.INVALID_INPUT

    def __init__(self, source: str, reason: str):
        super().__init__(f"{source}: {reason}")
        self.source = source
        self.reason = reason

    def explain(self) -> str:
        """The reason as a message that already names the source shows it (no source)."""
        return self.reason


class InputError(ZoneGraphError):
    """The file cannot be read: missing, corrupt, empty, or of the wrong kind."""

    status = Status.INVALID_INPUT


def file_problem(path: Path) -> str | None:
    """Why ``path`` is not a file to read, or None; a folder is named as one (a folder reported
    as "no such file" sent users looking for a typo)."""
    if path.is_dir():
        return "is a folder, not a file"
    return None if path.is_file() else "no such file"


def require_file(path: Path) -> None:
    """Raise InputError unless ``path`` is a file (`file_problem`)."""
    problem = file_problem(path)
    if problem:
        raise InputError(str(path), problem)


class DesignError(ZoneGraphError):
    """A design file is readable but inconsistent (a missing entity, a loop that does not close)."""

    status = Status.INVALID_DESIGN

    def __init__(self, design: str, entity: str | None, reason: str):
        where = f"{design} [{entity}]" if entity else design
        super().__init__(where, reason)
        self.design = design
        self.entity = entity

    def explain(self) -> str:
        """The reason with the entity it is about: a design has many, all alike but for the uuid."""
        return f"[{self.entity}] {self.reason}" if self.entity else self.reason


class UnsupportedFeatureError(DesignError):
    """The design uses something outside the sketch + extrude subset we replay exactly."""

    status = Status.UNSUPPORTED


class ReplayError(DesignError):
    """OpenCASCADE could not build a step (a Boolean failed or produced no solid)."""

    status = Status.REPLAY_FAILED


class ReplayMismatchError(DesignError):
    """The replay ran, but its result disagrees with the design file's own ``properties``."""

    status = Status.REPLAY_MISMATCH


def is_kernel_error(exc: BaseException) -> bool:
    """Whether OpenCASCADE raised ``exc``: the one test of kernel failure versus our own bug.

    OCP binds each OCCT exception class as its own subclass of ``Exception``, without OCCT's
    hierarchy (``StdFail_NotDone``, which a Boolean or sweep not done raises, does not derive
    from ``Standard_Failure``), so the test is where the class is defined, not its base. Such an
    exception is a failure of the kernel on the input (e.g. ``Standard_DomainError`` from a
    Boolean on a part at 1e12 cm); anything else is ours and keeps its traceback."""
    return any(c.__module__.startswith("OCP") for c in type(exc).__mro__)
