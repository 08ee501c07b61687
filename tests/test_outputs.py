"""One writer per ``--out``; scratch folders of killed runs do not stay behind."""

from __future__ import annotations

import pytest

from zonegraph.errors import ZoneGraphError
from zonegraph.isolation import Outcome
from zonegraph.outputs import run_staged, writer_lock
from zonegraph.status import Status


def _writes(name: str):
    def run(scratch):
        (scratch / name).write_text(name)
        return Outcome(Status.OK)

    return run


def test_a_second_writer_of_the_same_out_is_refused(tmp_path):
    out = tmp_path / "out"
    with writer_lock(out):
        with pytest.raises(ZoneGraphError, match="another zonegraph run is writing this folder"):
            run_staged(_writes("b.txt"), out)
    assert not out.exists()  # the refused run wrote nothing
    assert run_staged(_writes("a.txt"), out).ok
    assert sorted(p.name for p in out.iterdir()) == [".zonegraph-outputs.json", "a.txt"]


def test_scratch_folders_of_killed_runs_are_removed(tmp_path):
    out = tmp_path / "out"
    stale = tmp_path / ".out.partial-dead1"
    stale.mkdir()
    (stale / "sequence.py").write_text("half")
    assert run_staged(_writes("a.txt"), out).ok
    assert not stale.exists() and not list(tmp_path.glob(".out.partial-*"))
