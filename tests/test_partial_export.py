"""A program that is not exact has its files checked against its own rebuild within a thousandth.

The search can stop with a partial program whose rebuild and whose written files measure a little
apart (0.42279 against 0.42258 on a 20-step synthetic part). Held to a millionth, no script style
and no pass ever qualified and verification tried them all, snapped and raw: 47 s for a 1.6 s
rebuild. Here a real partial program (a plate, of a plate with a tower) is verified with its
rebuild's IoU a little above what its files reach: within `PARTIAL_SLACK` one pass is enough; past
it, the raw pass still runs.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest
from build123d import Face, Plane, Pos, Rectangle, Shape, Unit

import zonegraph.export.verify as verify
from zonegraph.export.verify import PARTIAL_SLACK, verified_export
from zonegraph.reconstruction import EXACT_IOU
from zonegraph.sequence.program import ProgramStep, brep_iou, execute
from zonegraph.sequence.proposals import Op


def face(plane: Plane, sketch: object) -> Face:
    return (plane * sketch).face()  # type: ignore[operator]


UP = (0.0, 0.0, 1.0)
TOP = Plane.XY.offset(6)
# 40.0000013 is written as 40: the snapped pass changes numbers, so a raw pass can follow it.
BASE = face(Plane.XY, Pos(10, 5) * Rectangle(40.0000013, 20))
PLATE = ProgramStep(Op.UNION, (BASE,), (0.0, 0.0, 0.0), UP, 6.0)
TOWER = ProgramStep(Op.UNION, (face(TOP, Pos(10, 5) * Rectangle(10, 10)),), (0.0, 0.0, 6.0), UP, 10.0)


@pytest.fixture
def passes(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """Each verification pass run, as whether its snapper changed any number (the real passes)."""
    seen: list[bool] = []
    real: Callable[..., verify.Export] = verify._pass

    def counted(*args: object, **kwargs: object) -> verify.Export:
        result = real(*args, **kwargs)
        seen.append(result.snapped)
        return result

    monkeypatch.setattr(verify, "_pass", counted)
    return seen


def partial() -> tuple[list[ProgramStep], Shape, float]:
    target = execute([PLATE, TOWER])[-1]
    rebuilt = execute([PLATE])[-1]
    assert target is not None and rebuilt is not None
    return [PLATE], target, brep_iou(rebuilt, target)


def test_files_within_a_thousandth_of_a_partial_rebuild_take_one_pass(passes: list[bool]) -> None:
    program, target, iou = partial()
    assert 0.8 < iou < 0.85  # the plate is 4,800 of the 5,800 mm3
    export = verified_export(program, "part", Unit.MM, target, iou + PARTIAL_SLACK / 2, EXACT_IOU)
    assert passes == [True]
    assert export.snapped and export.design_snapped
    assert "Rectangle(40, 20)" in export.script
    assert export.check.iou == pytest.approx(iou, abs=1e-6)


def test_files_further_from_a_partial_rebuild_are_checked_raw_as_well(passes: list[bool]) -> None:
    program, target, iou = partial()
    export = verified_export(program, "part", Unit.MM, target, iou + 2 * PARTIAL_SLACK, EXACT_IOU)
    assert passes == [True, False]
    assert export.check.iou == pytest.approx(iou, abs=1e-6)
