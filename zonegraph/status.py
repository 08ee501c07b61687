"""The one vocabulary of outcomes: every manifest row, stage record, CLI message and ``result.json``.

A status is a plain string on disk (Parquet, JSON), so that tables stay readable without this
package; in code it is a member of `Status`, so that a misspelt status fails at import
instead of silently counting as a failure. This module imports nothing and serves every layer,
`zonegraph.errors` included (each error class names its status).
"""

from __future__ import annotations

import enum


class Status(str, enum.Enum):
    """What became of one design, part or step (the value is what files store)."""

    # success
    OK = "ok"
    EXACT = "exact"  # infer: the rebuilt program equals the target (B-rep IoU >= 0.9999)
    PARTIAL = "partial"  # infer: the best program found is not exact

    # the input's fault (exit 2 on the command line, a final row in the pipeline)
    INVALID_INPUT = "invalid_input"  # missing, empty, corrupt or unreadable file
    INVALID_DESIGN = "invalid_design"  # design JSON that breaks its schema
    UNSUPPORTED = "unsupported"  # a feature outside sketch + extrude
    REPLAY_FAILED = "replay_failed"  # the design's own geometry fails in OpenCASCADE
    REPLAY_MISMATCH = "replay_mismatch"  # the replay disagrees with the file's properties
    KERNEL_ERROR = "kernel_error"  # OpenCASCADE raised on this input's geometry
    NOT_A_SOLID = "not_a_solid"
    FUSE_FAILED = "fuse_failed"  # the general fuse lost or duplicated volume
    TARGET_MISMATCH = "target_mismatch"  # the inside zones do not make the target
    NO_INTERIOR_POINT = "no_interior_point"
    DISCONNECTED = "disconnected"
    REBUILD_FAILED = "rebuild_failed"  # infer: the program's Booleans give no valid part

    # corpus conversion (build123d scripts to design JSON)
    SYNTAX_ERROR = "syntax_error"
    MODEL_RAISED = "model_raised"
    NO_SHAPE = "no_shape"
    MISMATCH = "mismatch"  # our replay differs from the script's part
    FUSION_MISMATCH = "fusion_mismatch"  # the script's part differs from Fusion's figures
    NOTHING_CONVERTED = "nothing_converted"  # convert: no design of the batches converted

    # the environment's fault
    TIMEOUT = "timeout"
    CRASH = "crash"  # the process died (a signal, a lost worker)
    OUT_OF_MEMORY = "out_of_memory"  # the job passed its memory limit (params.yaml / --memory)
    WORKER_ERROR = "worker_error"  # the worker could not run it (an input missing there, daemonic)

    # ours
    BUG = "bug"  # an exception of our own code: its traceback is kept

    def __str__(self) -> str:
        return self.value


def plural(count: int, noun: str, many: str = "") -> str:
    """``1 expansion``, ``2 expansions``, ``3 bodies``: the counts every message of an outcome gives."""
    return f"{count} {noun if count == 1 else many or noun + 's'}"
