"""Zone surface samples: area-uniform on the zone's surface with outward normals, seeded, and the
zone mesh export."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from build123d import Box, Cylinder

from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.sampling import export_zone_mesh


def test_box_samples_match_the_analytic_surface_moments():
    g = build_zone_graph(Box(4, 2, 1), samples=40_000, seed=0)
    assert g.n_zones == 1
    p, n = g.zone_points[0].astype(float), g.zone_normals[0].astype(float)
    h = (g.box[3:] - g.box[:3]) / 2  # half extents in the normalised frame
    faces = np.array([h[1] * h[2], h[0] * h[2], h[0] * h[1]]) * 4  # area of one face normal to x, y, z
    total = 2 * faces.sum()
    assert np.abs(p.mean(axis=0)).max() < 0.01 * h.max()  # centred
    for axis in range(3):
        on_cap = 2 * faces[axis] / total  # share of the surface on the two faces normal to this axis
        expected = (on_cap * h[axis] ** 2) + (1 - on_cap) * h[axis] ** 2 / 3
        assert (p[:, axis] ** 2).mean() == pytest.approx(expected, rel=0.03)
        share = (np.abs(n[:, axis]) > 0.99).mean()
        assert share == pytest.approx(on_cap, abs=0.01)
    assert np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-3)
    assert ((p * n).sum(axis=1) > 0).all()  # outward: away from the centre on a box


def test_samples_are_seeded():
    part = Box(4, 4, 1) - Cylinder(1, 1)
    a, b, c = (build_zone_graph(part, samples=64, seed=s) for s in (3, 3, 4))
    assert np.array_equal(a.zone_points, b.zone_points) and np.array_equal(a.zone_normals, b.zone_normals)
    assert not np.array_equal(a.zone_points, c.zone_points)


def test_zone_mesh_export_opens_with_one_colour_per_side(tmp_path):
    g = build_zone_graph(Box(4, 4, 1) - Cylinder(1, 1), samples=0)
    mesh = trimesh.load(export_zone_mesh(g, tmp_path / "zones.ply"), process=False)
    assert len(mesh.faces) > 0
    colours = {tuple(c) for c in mesh.visual.face_colors.tolist()}
    assert len(colours) == 2  # inside and outside zones
    # in the part's own coordinates (a 4 x 4 x 1 box about the origin), not the graph's unit box
    assert mesh.bounds.tolist() == [
        pytest.approx([-2, -2, -0.5], abs=1e-6),
        pytest.approx([2, 2, 0.5], abs=1e-6),
    ]


def test_the_build_s_own_triangles_export_as_the_solids_meshed_again(tmp_path):
    """The viewer's file reuses the build's mesh; a graph without it meshes its solids: the same
    triangles, wound outward either way (the zones tile the 16 cm3 box)."""
    g = build_zone_graph(Box(4, 4, 1) - Cylinder(1, 1), samples=0)
    reused = trimesh.load(export_zone_mesh(g, tmp_path / "reused.ply"), process=False)
    g.zone_mesh = None
    meshed = trimesh.load(export_zone_mesh(g, tmp_path / "meshed.ply"), process=False)
    assert len(reused.faces) == len(meshed.faces)
    assert reused.volume == pytest.approx(16.0, rel=1e-6) and meshed.volume == pytest.approx(16.0, rel=1e-6)


def test_samples_are_trimeshs_surface_sampler_draws():
    """The numpy sampler keeps trimesh's draws, so a seed gives the samples it gave with trimesh."""
    from zonegraph.zones.sampling import _surface_samples

    rng = np.random.default_rng(5)
    corners = rng.normal(size=(30, 3, 3))
    area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1) / 2
    mesh = trimesh.Trimesh(vertices=corners.reshape(-1, 3), faces=np.arange(90).reshape(-1, 3), process=False)
    ours, ours_faces = _surface_samples(corners, area, 500, np.random.default_rng(9))
    seed = np.random.default_rng(9)
    theirs, their_faces = trimesh.sample.sample_surface(mesh, 500, face_weight=area, seed=seed)
    assert np.array_equal(ours_faces, their_faces)
    assert np.array_equal(ours, theirs)


def test_zone_mesh_file_reads_back_as_the_zone_triangles(tmp_path):
    g = build_zone_graph(Box(2, 1, 1), samples=0)
    mesh = trimesh.load(export_zone_mesh(g, tmp_path / "zones.ply"), process=False)
    assert len(mesh.vertices) == 3 * len(mesh.faces)  # three corners per triangle, none merged
    assert mesh.volume == pytest.approx(2.0, rel=1e-6)  # the box's, in its own units; outward
