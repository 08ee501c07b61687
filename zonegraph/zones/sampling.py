"""Zone surfaces as triangle meshes: the network's point samples and a mesh users can open.

Each zone's surface is the union of its partition faces' triangulations (normals outward). The
samples are area-uniform points on that surface with the normal of the triangle they fall on,
drawn from a seeded generator by trimesh's surface sampler's draws (a face by cumulative area,
then two uniform lengths folded into the triangle); the same meshes, one colour per zone, make
``zones.ply`` for a viewer. Both are a few lines of numpy here rather than trimesh's: importing
trimesh (and the scipy and networkx it loads) would cost every ``zonegraph build`` about 0.5 s
and 40 MB for these two calls; the tests check both against trimesh itself.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import face_triangles, make_compound, sub_shapes

if TYPE_CHECKING:
    from zonegraph.zones.model import ZoneGraph

ZoneTriangles = tuple[np.ndarray, np.ndarray, np.ndarray]  # corners (T, 3, 3), normals (T, 3), areas (T,)
EXPORT_DEFLECTION = 1e-3  # normalised units, as the build's own mesh
INSIDE_RGBA = (70, 120, 220, 255)
OUTSIDE_RGBA = (200, 200, 200, 60)


def _surface_samples(
    corners: np.ndarray, area: np.ndarray, count: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """``count`` points on triangles (T, 3, 3) weighted by ``area`` and the triangle of each: the
    draws of ``trimesh.sample.sample_surface`` (TrianglePointPicking), in its order."""
    weight_cum = np.cumsum(area)
    face = np.searchsorted(weight_cum, rng.random(count) * weight_cum[-1])
    origins = corners[:, 0][face]
    vectors = (corners[:, 1:] - corners[:, :1])[face]
    lengths = rng.random((count, 2, 1))
    lengths[lengths.sum(axis=1).reshape(-1) > 1.0] -= 1.0
    return (vectors * np.abs(lengths)).sum(axis=1) + origins, face


def sample_zone_surfaces(
    zone_tris: list[ZoneTriangles], count: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """``count`` area-uniform surface points per zone and their outward normals.

    Args:
        zone_tris: per zone, triangle corners (T, 3, 3), outward unit normals (T, 3), areas (T,).
        count: samples per zone (0: none).
        rng: the seeded generator; zones are sampled in order, so a seed fixes every sample.

    Returns:
        points and normals, both float32 (Z, count, 3); zeros for a zone without triangles.
    """
    points = np.zeros((len(zone_tris), count, 3), np.float32)
    normals = np.zeros_like(points)
    if count == 0:
        return points, normals
    for z, (corners, n, area) in enumerate(zone_tris):
        if not len(area):
            continue
        p, t = _surface_samples(corners, area, count, rng)
        points[z], normals[z] = p, n[t]
    return points, normals


def write_ply(path: Path, corners: np.ndarray, rgba: np.ndarray) -> None:
    """Triangles (T, 3, 3) with a colour each (T, 4) as binary PLY, the layout trimesh writes
    (float32 vertices, three per triangle, face order kept)."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {3 * len(corners)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(corners)}\nproperty list uchar int vertex_indices\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
        "end_header\n"
    )
    face = np.zeros(len(corners), [("n", "u1"), ("v", "<i4", 3), ("rgba", "u1", 4)])
    face["n"], face["v"], face["rgba"] = 3, np.arange(3 * len(corners)).reshape(-1, 3), rgba
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(corners.reshape(-1, 3).astype("<f4").tobytes())
        f.write(face.tobytes())


def _solid_triangles(solid: object) -> np.ndarray:
    corners = []
    for face in sub_shapes(solid, TopAbs_FACE):
        nodes, tris = face_triangles(face)
        if len(tris):
            c = nodes[tris]
            corners.append(c[:, ::-1] if face.Orientation() == TopAbs_REVERSED else c)
    return np.concatenate(corners) if corners else np.zeros((0, 3, 3))


def export_zone_mesh(graph: ZoneGraph, path: str | Path) -> Path:
    """Write every zone as coloured triangles (inside: blue, outside: translucent grey).

    The file is in the part's own coordinates and units (the graph's normalisation undone), so it
    overlays the input in a viewer; PLY keeps per-face RGBA colours and opens in MeshLab, Blender
    or any trimesh-based viewer. The triangles are the build's own (``ZoneGraph.zone_mesh``) where
    the graph holds them: reading a 627-zone graph's meshes back off its solids took 0.7 CPU s.
    A graph read from disk has its solids meshed again, at the build's deflection.

    Raises:
        ValueError: the graph was loaded without its zone solids.
    """
    if graph.zone_mesh is not None:
        triangles = graph.zone_mesh
    elif graph.solids is not None:
        BRepMesh_IncrementalMesh(make_compound(graph.solids), EXPORT_DEFLECTION, False, 0.5, False)
        triangles = [_solid_triangles(solid) for solid in graph.solids]
    else:
        raise ValueError("zone graph has no zone solids to mesh")
    corners, colours = [], []
    for tris, inside in zip(triangles, graph.zone_inside, strict=True):
        c = graph.normalization.to_original(tris.reshape(-1, 3)).reshape(-1, 3, 3)
        corners.append(c)
        colours.append(np.tile(INSIDE_RGBA if inside else OUTSIDE_RGBA, (len(c), 1)))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_ply(path, np.concatenate(corners), np.concatenate(colours))
    return path
