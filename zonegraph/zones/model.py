"""The zone graph (paper sec. 3): zones partitioning the target's bounding box, and their contacts.

Everything is stored as flat numpy arrays in the normalised frame (see ``normalize.py``) so the
search can work on indices and bit vectors; the zone solids themselves are kept alongside for
export and rendering. Faces are the partition faces of the general fuse: a face between two zones
is a graph edge, a face on the box boundary has ``-1`` as its second zone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from zonegraph.errors import ZoneGraphError
from zonegraph.geometry.normalize import Normalization
from zonegraph.status import Status

BOX_VOLUME_RTOL = 1e-6
TARGET_VOLUME_RTOL = 1e-4
# With a second measure (a shared triangulation: see ``build._mesh_volume_ratios``) a graph passes
# when either measure is within these of the box and of the target.
MESH_BOX_RTOL = 1e-5
MESH_TARGET_RTOL = 1e-3


class ZoneGraphBuildError(ZoneGraphError):
    """A zone graph could not be built or broke an invariant; ``status`` says which."""

    def __init__(self, status: Status, source: str, reason: str):
        super().__init__(source, reason)
        self.status = status


@dataclass(repr=False)
class ZoneGraph:
    """Zones partitioning the target's box, their faces, links and extended surfaces.

    Everything is in the normalised frame (centred, unit box diagonal; ``normalization`` maps back
    to the input's units). Faces are the general fuse's partition faces; a face between two zones
    is a graph edge, one on the box boundary has ``-1`` as its second zone.

    Shapes:
        Z zones, F partition faces, L face links, S extended surfaces, P samples per zone; the
        shape of every array is given beside its field.
    """

    normalization: Normalization
    box: np.ndarray  # (6,) normalised AABB of the target
    target_volume: float  # normalised units
    # zones (Z)
    zone_volume: np.ndarray
    zone_centroid: np.ndarray  # (Z, 3); may lie outside a non-convex zone
    zone_bbox: np.ndarray  # (Z, 6)
    zone_interior: np.ndarray  # (Z, 3) verified interior points
    zone_inside: np.ndarray  # (Z,) bool: inside the target
    zone_points: np.ndarray  # (Z, P, 3) float32 surface samples
    zone_normals: np.ndarray  # (Z, P, 3) float32 outward normals
    # partition faces (F)
    face_zones: np.ndarray  # (F, 2) int32; second is -1 on the box boundary
    face_area: np.ndarray
    face_centroid: np.ndarray  # (F, 3)
    face_normal: np.ndarray  # (F, 3) from zone 0 towards zone 1 (planar faces; NaN otherwise)
    face_surface: np.ndarray  # (F,) int32 index into the surfaces (-1: unknown)
    face_links: np.ndarray  # (L, 2) int32: faces sharing an edge on the same surface
    # extended surfaces (S)
    surface_kind: np.ndarray  # (S,) str: plane, cylinder, extrusion, sphere, face
    surface_normal: np.ndarray  # (S, 3) planes
    surface_offset: np.ndarray  # (S,) planes: n . x = offset
    surface_axis: np.ndarray  # (S, 6) cylinders/spheres: point, direction
    surface_radius: np.ndarray  # (S,)
    surface_on_box: np.ndarray  # (S,) bool
    surface_strip: np.ndarray  # (S,) bool: plane extended as face-loop strips only
    plane_side: np.ndarray  # (S, Z) int8: +1/-1 side of each plane, 0 straddles (or not a plane)
    solids: list | None = None  # zone solids (TopoDS_Solid), in zone order
    # (T, 3, 3) triangle corners per zone, wound outward: the build's own mesh, kept with the solids for
    # viewers (``sampling.export_zone_mesh``) so that they need not mesh the zones again; not saved
    zone_mesh: list | None = None
    info: dict = field(default_factory=dict)  # status, simplified, target faces, timings

    def __repr__(self) -> str:
        simplified = self.info.get("simplified")
        return (
            f"ZoneGraph({self.n_zones} zones ({int(self.zone_inside.sum())} inside), {self.n_faces} faces, "
            f"{len(self.edges)} edges, {self.n_surfaces} surfaces, simplified={simplified})"
        )

    @property
    def n_zones(self) -> int:
        return len(self.zone_volume)

    @property
    def n_faces(self) -> int:
        return len(self.face_area)

    @property
    def n_surfaces(self) -> int:
        return len(self.surface_kind)

    @property
    def edges(self) -> np.ndarray:
        """Distinct zone pairs sharing at least one face, (E, 2) with the smaller index first."""
        inner = self.face_zones[self.face_zones[:, 1] >= 0]
        return np.unique(np.sort(inner, axis=1), axis=0) if len(inner) else np.zeros((0, 2), np.int32)

    @property
    def box_volume(self) -> float:
        return float(np.prod(self.box[3:] - self.box[:3]))

    @property
    def inside_volume(self) -> float:
        return float(self.zone_volume[self.zone_inside].sum())

    @property
    def planes(self) -> np.ndarray:
        return np.flatnonzero(self.surface_kind == "plane")

    def check(self, source: str = "target") -> None:
        """Raise ZoneGraphBuildError unless every invariant of a usable zone graph holds."""
        box_ratio = float(self.zone_volume.sum()) / self.box_volume
        if not _close(box_ratio, self.info.get("mesh_box_ratio"), BOX_VOLUME_RTOL, MESH_BOX_RTOL):
            raise ZoneGraphBuildError(
                Status.FUSE_FAILED, source, f"zone volumes sum to {box_ratio:.9f} of the box"
            )
        if not np.isfinite(self.zone_interior).all():
            missing = int((~np.isfinite(self.zone_interior).all(axis=1)).sum())
            raise ZoneGraphBuildError(
                Status.NO_INTERIOR_POINT, source, f"{missing} zones have no interior point"
            )
        target_ratio = self.inside_volume / self.target_volume
        if not _close(target_ratio, self.info.get("mesh_target_ratio"), TARGET_VOLUME_RTOL, MESH_TARGET_RTOL):
            raise ZoneGraphBuildError(
                Status.TARGET_MISMATCH,
                source,
                f"inside zones hold {target_ratio:.6f} of the target volume",
            )
        if self.n_zones > 1:
            n = component_count(self.n_zones, self.edges)
            if n != 1:
                raise ZoneGraphBuildError(Status.DISCONNECTED, source, f"zone graph has {n} components")

    def summary(self) -> dict:
        return {
            "zones": self.n_zones,
            "faces": self.n_faces,
            "edges": len(self.edges),
            "surfaces": self.n_surfaces,
            "inside_zones": int(self.zone_inside.sum()),
            **self.info,
        }


def component_count(n: int, edges: np.ndarray) -> int:
    """Connected components of ``n`` nodes joined by ``edges`` (E, 2), by union-find: the one
    graph question of every build, not worth scipy's 0.3 s import in each process."""
    parent = list(range(n))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    count = n
    for a, b in edges.tolist():
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[ra] = rb
            count -= 1
    return count


def _close(exact: float, meshed: float | None, rtol: float, mesh_rtol: float) -> bool:
    """A volume ratio is 1 by the exact integral, or by the mesh when there is one."""
    return abs(exact - 1) <= rtol or (meshed is not None and abs(meshed - 1) <= mesh_rtol)
