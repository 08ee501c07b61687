"""What "verified" means for a design file: the one definition ``convert``, ``replay``, the
``generate`` and ``replay`` stages and the tests share.

A design file's ``properties`` (volume, area, body and face counts) are what replaying the file
measures, and a replay is verified when it reproduces them within `REPLAY_RTOL` (relative
volume and area) with the same number of bodies. For Fusion 360 Gallery's own JSON these are
Fusion's figures, which our replay reproduces to ~1e-16 on the samples. For a design converted
from the build123d corpus they are the converter's own replay of the file, measured the same way,
so every file ``convert`` calls ok replays with exit 0; Fusion's published volume and area are kept
beside them under `FUSION_FIELD` with their relative differences, because the two part by up
to ~1e-3 on some designs (build123d's fixed-order integration on spline-bounded faces, Fusion's own
tolerances), and that is worth knowing rather than hiding. Conversion itself compares our replay
with the script's part (`REPLAY_RTOL`, re-measured precisely before a mismatch) and with
Fusion's figures (`FUSION_RTOL`, the ``fusion_mismatch`` status).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

REPLAY_RTOL = 1e-6  # a replay vs the file's properties, and our replay vs the script's part
FUSION_RTOL = 0.01  # a converted design (or its script) vs Fusion's published volume and area
FUSION_FIELD = "fusion_properties"  # the converted file's record of Fusion's figures


def relative_difference(value: float, reference: float) -> float:
    return abs(value - reference) / max(abs(reference), 1e-300)


@dataclass(frozen=True)
class Measured:
    """A replay's figures, as `ReplayResult` measures them (bodies
    summed, as Fusion's ``properties`` are)."""

    volume: float
    area: float
    body_count: int
    face_count: int


def file_properties(measured: Measured) -> dict[str, Any]:
    """The ``properties`` block a converted design file carries: its replay's own figures."""
    return {
        "volume": measured.volume,
        "area": measured.area,
        "body_count": measured.body_count,
        "face_count": measured.face_count,
    }


def fusion_properties(volume: float, area: float, measured: Measured) -> dict[str, float]:
    """The `FUSION_FIELD` block: Fusion's published figures and how far our replay is."""
    return {
        "volume": volume,
        "area": area,
        "volume_rel_difference": relative_difference(measured.volume, volume),
        "area_rel_difference": relative_difference(measured.area, area),
    }


def disagreement(
    measured: Measured, volume: float, area: float, body_count: int | None, tolerance: float = REPLAY_RTOL
) -> str | None:
    """How a replay differs from a file's properties beyond ``tolerance`` (relative volume and
    area, and the body count when the file states it), or None when the replay is verified."""
    problems = [
        f"{what} differs by {error:.1e} relative"
        for what, error in (
            ("volume", relative_difference(measured.volume, volume)),
            ("area", relative_difference(measured.area, area)),
        )
        if not error <= tolerance
    ]
    if body_count is not None and measured.body_count != body_count:
        problems.append(f"{measured.body_count} bodies instead of {body_count}")
    if not problems:
        return None
    return f"replay disagrees with the file's properties: {', '.join(problems)} (tolerance {tolerance:g})"


__all__ = [
    "FUSION_FIELD",
    "FUSION_RTOL",
    "REPLAY_RTOL",
    "Measured",
    "disagreement",
    "file_properties",
    "fusion_properties",
    "relative_difference",
]
