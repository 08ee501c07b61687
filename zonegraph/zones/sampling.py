"""Zone surfaces as triangle meshes: the network's point samples and a mesh users can open.

Each zone's surface is the union of its partition faces' triangulations (normals outward). The
samples are area-uniform points on that surface with the normal of the triangle they fall on,
drawn by trimesh's surface sampler from a seeded generator; the same meshes, one colour per zone,
make ``zones.ply`` for a viewer.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import trimesh
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED

from zonegraph.geometry.occ import face_triangles, make_compound, sub_shapes

if TYPE_CHECKING:
    from zonegraph.zones.model import ZoneGraph

ZoneTriangles = tuple[np.ndarray, np.ndarray, np.ndarray]  # corners (T, 3, 3), normals (T, 3), areas (T,)
EXPORT_DEFLECTION = 1e-3  # normalised units, as the build's own mesh
INSIDE_RGBA = (70, 120, 220, 255)
OUTSIDE_RGBA = (200, 200, 200, 60)


def triangle_mesh(corners: np.ndarray, rgba: tuple[int, int, int, int] | None = None) -> trimesh.Trimesh:
    """Triangles given by their corners (T, 3, 3) as a trimesh, face order kept (no merging)."""
    faces = np.arange(3 * len(corners)).reshape(-1, 3)
    colours = np.tile(rgba, (len(corners), 1)) if rgba is not None else None
    return trimesh.Trimesh(
        vertices=corners.reshape(-1, 3), faces=faces, face_colors=colours, process=False, validate=False
    )


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
        p, t = trimesh.sample.sample_surface(triangle_mesh(corners), count, face_weight=area, seed=rng)
        points[z], normals[z] = p, n[t]
    return points, normals


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
    or any trimesh-based viewer.

    Raises:
        ValueError: the graph was loaded without its zone solids.
    """
    if graph.solids is None:
        raise ValueError("zone graph has no zone solids to mesh")
    BRepMesh_IncrementalMesh(make_compound(graph.solids), EXPORT_DEFLECTION, False, 0.5, False)
    meshes = []
    for solid, inside in zip(graph.solids, graph.zone_inside, strict=True):
        corners = graph.normalization.to_original(_solid_triangles(solid).reshape(-1, 3)).reshape(-1, 3, 3)
        meshes.append(triangle_mesh(corners, INSIDE_RGBA if inside else OUTSIDE_RGBA))
    mesh = trimesh.util.concatenate(meshes)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    mesh.export(path)
    return path
