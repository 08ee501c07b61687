"""Zone graph storage round trip and the ``zonegraph build`` command."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from build123d import Box, Rectangle, export_step

from zonegraph.data.targets import load_target
from zonegraph.errors import InputError
from zonegraph.geometry.occ import volume_props
from zonegraph.jobs import build_and_save
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.model import ZoneGraphBuildError
from zonegraph.zones.storage import load_zone_graph, save_zone_graph

SCRIPT = Path(sys.executable).parent / "zonegraph"


def test_round_trip_is_equal(samples_dir, tmp_path):
    graph = build_zone_graph(load_target(samples_dir / "Pattern2_6c40bf33_0000.json"), samples=64, seed=3)
    loaded = load_zone_graph(save_zone_graph(graph, tmp_path / "g"))
    for f in dataclasses.fields(graph):
        a, b = getattr(graph, f.name), getattr(loaded, f.name)
        if f.name in ("zone_points", "zone_normals"):  # stored as float16: network inputs, not geometry
            np.testing.assert_allclose(a, b, atol=2e-3)
        elif f.name == "solids":
            assert [volume_props(s)[0] for s in a] == pytest.approx(
                [volume_props(s)[0] for s in b], rel=1e-12
            )
        elif f.name == "zone_mesh":  # the build's own triangles, for viewers: not saved
            assert a is not None and b is None
        elif isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)
        else:
            assert a == b, f.name


def test_graph_without_surface_samples_round_trips(tmp_path):
    graph = build_zone_graph(Box(2, 1, 1) - Box(1, 1, 1), samples=0)
    loaded = load_zone_graph(save_zone_graph(graph, tmp_path / "g"))
    assert loaded.zone_points.shape == (graph.n_zones, 0, 3) == loaded.zone_normals.shape
    np.testing.assert_array_equal(loaded.zone_inside, graph.zone_inside)


def test_round_off_below_zero_loads_and_a_negative_volume_does_not(tmp_path):
    graph = build_zone_graph(Box(2, 1, 1) - Box(1, 1, 1), samples=0)
    graph.zone_volume[0], graph.face_area[0] = -5.5e-16, -1.9e-11  # as the fuse measures slivers
    assert load_zone_graph(save_zone_graph(graph, tmp_path / "g")).zone_volume[0] == -5.5e-16
    sliver = -1.0e-5 * graph.box_volume  # a 2,589-zone corpus part's
    graph.zone_volume[0] = sliver
    assert load_zone_graph(save_zone_graph(graph, tmp_path / "s")).zone_volume[0] == sliver
    graph.zone_volume[0] = -1e-3
    with pytest.raises(InputError, match="negative zone volume"):
        load_zone_graph(save_zone_graph(graph, tmp_path / "h"))


def test_samples_are_seeded(samples_dir):
    target = load_target(samples_dir / "Couch.json")
    a, b = (build_zone_graph(target, samples=32, seed=s) for s in (1, 1))
    c = build_zone_graph(target, samples=32, seed=2)
    np.testing.assert_array_equal(a.zone_points, b.zone_points)
    assert not np.array_equal(a.zone_points, c.zone_points)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        build_and_save(str(tmp_path / "absent.step"), str(tmp_path / "out"))


def test_empty_and_corrupt_step(tmp_path):
    empty, corrupt = tmp_path / "empty.step", tmp_path / "corrupt.step"
    empty.write_text("")
    corrupt.write_text("ISO-10303-21;\nthis is not STEP\n")
    with pytest.raises(InputError, match="empty"):
        load_target(empty)
    with pytest.raises(InputError, match="corrupt"):
        load_target(corrupt)


def test_sheet_or_wire_is_not_a_solid(tmp_path):
    sheet = tmp_path / "sheet.step"
    export_step(Rectangle(2, 1).faces()[0], str(sheet))
    with pytest.raises(InputError, match="not a solid"):
        load_target(sheet)
    with pytest.raises(ZoneGraphBuildError) as err:
        build_zone_graph(Rectangle(2, 1).faces()[0])
    assert err.value.status == "not_a_solid"
    with pytest.raises(ZoneGraphBuildError) as err:
        build_zone_graph(Rectangle(2, 1).wire())
    assert err.value.status == "not_a_solid"


@pytest.mark.skipif(not SCRIPT.exists(), reason=f"console script not installed at {SCRIPT}")
def test_cli_build_prints_counts_and_writes_the_graph(tmp_path):
    part = tmp_path / "plate.step"
    export_step(Box(4, 4, 1) - Box(1, 1, 1), str(part))
    out = tmp_path / "graph"
    proc = subprocess.run(
        [str(SCRIPT), "build", str(part), "--out", str(out)], capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    assert "status ok, 2 zones (1 inside)" in proc.stdout  # the through hole is one face loop
    graph = load_zone_graph(out)
    assert graph.zone_inside.sum() >= 1 and (out / "zones.brep").stat().st_size > 0


@pytest.mark.skipif(not SCRIPT.exists(), reason=f"console script not installed at {SCRIPT}")
@pytest.mark.parametrize(
    "args, message",
    [
        (["absent.step"], "no such file"),
        (["sheet.step"], "not a solid"),
        (["plate.step", "--timeout", "0.01"], "timeout"),
    ],
)
def test_cli_build_errors_are_one_line(tmp_path, args, message):
    export_step(Rectangle(2, 1).faces()[0], str(tmp_path / "sheet.step"))
    export_step(Box(4, 4, 1) - Box(1, 1, 1), str(tmp_path / "plate.step"))
    args = [str(tmp_path / args[0]), *args[1:]]
    proc = subprocess.run(
        [str(SCRIPT), "build", *args, "--out", str(tmp_path / "o")], capture_output=True, text=True
    )
    assert proc.returncode == 2
    lines = [line for line in proc.stderr.splitlines() if line.startswith("zonegraph:")]
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in proc.stderr


def test_a_step_target_is_read_by_the_kernel_alone_as_build123d_reads_it(samples_dir, tmp_path):
    """``zonegraph build PART.step`` loads neither build123d nor trimesh nor scipy (each costs a
    short command seconds and tens of MB) nor the search, and reads the same solids as build123d's
    importer."""
    from build123d import import_step

    from zonegraph.data.targets import load_kernel_target

    step = samples_dir / "Couch.step"
    ours = load_kernel_target(step)
    theirs = import_step(str(step)).solids()
    assert [volume_props(s)[0] for s in ours] == pytest.approx([s.volume for s in theirs], rel=1e-12)
    code = (
        "import sys; from zonegraph.cli import _build_job; from zonegraph.configs import BuildConfig\n"
        "_build_job(BuildConfig(), 60, None)\n"  # what the command imports before its child
        "from zonegraph.build_job import build_and_save\n"
        f"build_and_save({str(step)!r}, {str(tmp_path / 'g')!r}, mesh=True)\n"
        "heavy = ('build123d', 'trimesh', 'scipy', 'zonegraph.sequence', 'zonegraph.jobs')\n"
        "print(sorted(m for m in heavy if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["[]"]


def test_component_count_joins_edges_in_any_order():
    from zonegraph.zones.model import component_count

    assert component_count(5, np.array([[3, 4], [0, 1], [4, 1]])) == 2  # {0, 1, 3, 4} and {2}
    assert component_count(3, np.zeros((0, 2), int)) == 3


def _saved_l_shape(tmp_path: Path) -> Path:
    from build123d import Pos

    part = Box(2, 1, 1) + Pos(0.5, 0.5, 0.5) * Box(1, 1, 1)
    return save_zone_graph(build_zone_graph(list(part.solids()), samples=4), tmp_path / "g")


def _garble(path: Path, offset: int, n: int = 64) -> None:
    data = bytearray(path.read_bytes())
    rng = np.random.default_rng(0)
    at = min(offset, len(data) - n)
    data[at : at + n] = rng.integers(0, 256, n, dtype=np.uint8).tobytes()
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("name", ["zones.parquet", "faces.parquet", "links.parquet", "surfaces.parquet"])
def test_garbled_or_truncated_tables_are_invalid_input(tmp_path, name):
    """Bytes changed on disk are a clear bad-input error, never a bug or numbers read as garbage."""
    folder = _saved_l_shape(tmp_path)
    size = (folder / name).stat().st_size
    for damage in ("truncate", "garble"):
        original = (folder / name).read_bytes()
        if damage == "truncate":
            (folder / name).write_bytes(original[: size // 2])
        else:
            _garble(folder / name, 4)
        with pytest.raises(InputError, match="corrupt zone graph"):
            load_zone_graph(folder)
        (folder / name).write_bytes(original)
    assert load_zone_graph(folder).n_zones > 0


def test_a_truncated_zones_brep_is_invalid_input(tmp_path):
    folder = _saved_l_shape(tmp_path)
    brep = folder / "zones.brep"
    brep.write_bytes(brep.read_bytes()[: brep.stat().st_size // 2])
    with pytest.raises(InputError, match="corrupt zone graph"):
        load_zone_graph(folder)
    assert load_zone_graph(folder, solids=False).n_zones > 0
