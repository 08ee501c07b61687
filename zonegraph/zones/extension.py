"""Face extension: the target's faces become surfaces that partition its bounding box.

Rules (paper sec. 3, ``docs/algorithm.md`` sec. 1): planes become planes across the box (or, for
face-loop walls when simplifying, strips along the loop's extrusion direction); circular cylinders
become complete cylinders along their axis; other surfaces of linear extrusion are extended along
the extrusion direction only; spheres become complete spheres; anything else keeps the face itself.
Coincident surfaces are merged, planes on the box's own faces add nothing, and tiny faces are
skipped. Sheets are sized to just cover the box (the box lies in a ball of half its diagonal), which
keeps the general fuse's work inside the box.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy, BRepBuilderAPI_MakeFace
from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane, GeomAbs_Sphere, GeomAbs_SurfaceOfExtrusion
from OCP.gp import gp_Ax3, gp_Cylinder, gp_Pln
from OCP.TopAbs import TopAbs_FACE, TopAbs_VERTEX
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import direction, pnt, shape_index, sub_shapes, surface_props, xyz
from zonegraph.zones.face_loops import LoopRule, find_face_loops

GEOM_TOL = 1e-7  # normalised units: surfaces closer than this are the same surface
PARALLEL_TOL = 1e-9  # 1 - |cos| for parallel directions
STRIP_WIDEN = 0.1  # a face-loop strip is widened by this share of its width on each side
SHEET_MARGIN = 1.2  # sheets reach this share of the half-diagonal beyond the box centre


class SurfaceKind(str, enum.Enum):
    PLANE = "plane"
    CYLINDER = "cylinder"
    EXTRUSION = "extrusion"
    SPHERE = "sphere"
    FACE = "face"


CURVED = (SurfaceKind.CYLINDER, SurfaceKind.SPHERE, SurfaceKind.EXTRUSION)  # surfaces with anchors


@dataclass
class ExtendedSurface:
    """One distinct surface of the target, and the sheets that represent it in the fuse."""

    kind: SurfaceKind
    source_faces: list[int] = field(default_factory=list)
    normal: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))  # planes: n . x = offset
    offset: float = math.nan
    axis_point: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))  # nearest the centre
    axis_dir: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    radius: float = math.nan
    on_box: bool = False  # one of the six box faces
    strips: list[tuple[np.ndarray, float, float]] = field(default_factory=list)  # (direction, e0, e1)
    sheets: list[TopoDS_Shape] = field(default_factory=list)
    # The target's own faces on a curved surface, fed to the fuse beside its sheets on a retry
    # (``zonegraph.zones.build``): the general fuse can drop a full cylinder's split where it
    # meets the part's faces at a cusp, and the face itself pins it.
    anchors: list[TopoDS_Shape] = field(default_factory=list)

    @property
    def is_plane(self) -> bool:
        return self.kind is SurfaceKind.PLANE


def canonical(d: np.ndarray) -> np.ndarray:
    """A direction with its first clearly non-zero component positive (one sign per line)."""
    d = np.asarray(d, float) / np.linalg.norm(d)
    k = int(np.argmax(np.abs(d) > 1e-12))
    return -d if d[k] < 0 else d


def parallel(a: np.ndarray, b: np.ndarray) -> bool:
    return 1 - abs(float(a @ b)) < PARALLEL_TOL


def box_planes(box: np.ndarray) -> list[ExtendedSurface]:
    out = []
    for axis in range(3):
        n = np.eye(3)[axis]
        for value in (box[axis], box[axis + 3]):
            out.append(ExtendedSurface(SurfaceKind.PLANE, normal=n, offset=float(value), on_box=True))
    return out


class _Extender:
    def __init__(self, box: np.ndarray):
        self.box = box
        self.centre = (box[:3] + box[3:]) / 2
        self.half = SHEET_MARGIN * 0.5 * float(np.linalg.norm(box[3:] - box[:3]))
        self.surfaces: list[ExtendedSurface] = box_planes(box)

    # ------------------------------------------------------------------ finding or adding surfaces

    def plane(self, n: np.ndarray, offset: float, face: int) -> ExtendedSurface:
        for s in self.surfaces:
            if (
                s.is_plane
                and parallel(s.normal, n)
                and abs(s.offset - offset * float(s.normal @ n)) < GEOM_TOL
            ):
                s.source_faces.append(face)
                return s
        s = ExtendedSurface(SurfaceKind.PLANE, [face], normal=n, offset=offset)
        self.surfaces.append(s)
        return s

    def cylinder(self, point: np.ndarray, d: np.ndarray, r: float, face: int) -> None:
        p0 = point + d * float((self.centre - point) @ d)
        for s in self.surfaces:
            if (
                s.kind is SurfaceKind.CYLINDER
                and parallel(s.axis_dir, d)
                and abs(s.radius - r) < GEOM_TOL
                and np.linalg.norm(s.axis_point - p0) < GEOM_TOL
            ):
                s.source_faces.append(face)
                return
        s = ExtendedSurface(SurfaceKind.CYLINDER, [face], axis_point=p0, axis_dir=d, radius=r)
        ax = gp_Ax3(pnt(p0), direction(d))
        s.sheets.append(
            BRepBuilderAPI_MakeFace(gp_Cylinder(ax, r), 0, 2 * math.pi, -self.half, self.half).Face()
        )
        self.surfaces.append(s)

    def sphere(self, centre: np.ndarray, r: float, face: int) -> None:
        for s in self.surfaces:
            if (
                s.kind is SurfaceKind.SPHERE
                and abs(s.radius - r) < GEOM_TOL
                and np.linalg.norm(s.axis_point - centre) < GEOM_TOL
            ):
                s.source_faces.append(face)
                return
        s = ExtendedSurface(SurfaceKind.SPHERE, [face], axis_point=centre, radius=r)
        s.sheets.extend(sub_shapes(BRepPrimAPI_MakeSphere(pnt(centre), r).Shape(), TopAbs_FACE))
        self.surfaces.append(s)

    def extrusion(self, face: TopoDS_Face, adaptor: BRepAdaptor_Surface, index: int) -> None:
        """Extend along the extrusion direction only (the profile curve cannot be closed)."""
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        reach = 2 * self.half
        surface = BRep_Tool.Surface_s(face)
        sheet = BRepBuilderAPI_MakeFace(surface, u0, u1, v0 - reach, v1 + reach, GEOM_TOL).Face()
        self.surfaces.append(
            ExtendedSurface(
                SurfaceKind.EXTRUSION, [index], axis_dir=canonical(xyz(adaptor.Direction())), sheets=[sheet]
            )
        )

    def keep_face(self, face: TopoDS_Face, index: int) -> None:
        self.surfaces.append(
            ExtendedSurface(SurfaceKind.FACE, [index], sheets=[BRepBuilderAPI_Copy(face).Shape()])
        )

    # ------------------------------------------------------------------------------ plane sheets

    def on_box_face(self, n: np.ndarray, offset: float) -> bool:
        axis = int(np.argmax(np.abs(n)))
        if abs(abs(n[axis]) - 1) > PARALLEL_TOL:
            return False
        value = offset * n[axis]
        return min(abs(value - self.box[axis]), abs(value - self.box[axis + 3])) < GEOM_TOL

    def plane_sheets(
        self, s: ExtendedSurface, faces: list[TopoDS_Face], loops: dict[int, list[np.ndarray]] | None
    ) -> None:
        if s.on_box or self.on_box_face(s.normal, s.offset):
            s.on_box = True
            return
        origin = self.centre + s.normal * (s.offset - float(self.centre @ s.normal))
        if loops is not None and all(f in loops for f in s.source_faces):
            s.strips = self._strips(s, faces, loops, origin)
        if not s.strips:
            pln = gp_Pln(gp_Ax3(pnt(origin), direction(s.normal)))
            s.sheets.append(BRepBuilderAPI_MakeFace(pln, -self.half, self.half, -self.half, self.half).Face())
            return
        for d, e0, e1 in s.strips:
            pln = gp_Pln(gp_Ax3(pnt(origin), direction(s.normal), direction(d)))
            s.sheets.append(BRepBuilderAPI_MakeFace(pln, -self.half, self.half, e0, e1).Face())

    def _strips(
        self,
        s: ExtendedSurface,
        faces: list[TopoDS_Face],
        loops: dict[int, list[np.ndarray]],
        origin: np.ndarray,
    ) -> list[tuple[np.ndarray, float, float]]:
        """Per loop direction, the union of the walls' extents across it, widened a little."""
        spans: list[tuple[np.ndarray, list[tuple[float, float]]]] = []
        for f in s.source_faces:
            verts = np.array(
                [xyz(BRep_Tool.Pnt_s(TopoDS.Vertex(v))) for v in sub_shapes(faces[f], TopAbs_VERTEX)]
            )
            for d in loops[f]:
                group = next((g for g in spans if parallel(g[0], d)), None)
                if group is None:
                    group = (d, [])
                    spans.append(group)
                along = (verts - origin) @ np.cross(s.normal, group[0])
                group[1].append((float(along.min()), float(along.max())))
        strips = []
        for d, intervals in spans:
            for a, b in _merge(intervals):
                w = STRIP_WIDEN * (b - a)
                strips.append((d, a - w, b + w))
        return strips


def _merge(intervals: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[list[float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1] + GEOM_TOL:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def extend_faces(
    target: TopoDS_Shape,
    box: np.ndarray,
    rule: LoopRule | None = LoopRule.STRICT,
    min_area_fraction: float = 1e-7,
) -> tuple[list[ExtendedSurface], int]:
    """Distinct extended surfaces of ``target`` (box planes first) and the number of target faces;
    ``rule``: which faces may be face-loop walls (``None``: no simplification, every plane whole)."""
    faces = [TopoDS.Face(f) for f in _distinct_faces(target)]
    areas = [surface_props(f)[0] for f in faces]
    min_area = min_area_fraction * sum(areas)
    ext = _Extender(box)
    loops = find_face_loops(faces, rule) if rule is not None else None
    planes: dict[int, ExtendedSurface] = {}
    for i, (face, area) in enumerate(zip(faces, areas, strict=False)):
        if area < min_area:
            continue
        adaptor = BRepAdaptor_Surface(face)
        kind = adaptor.GetType()
        if kind == GeomAbs_Plane:
            ax = adaptor.Plane().Position()
            n = canonical(xyz(ax.Direction()))
            s = ext.plane(n, float(n @ xyz(ax.Location())), i)
            planes[id(s)] = s
        elif kind == GeomAbs_Cylinder:
            cyl = adaptor.Cylinder()
            ax = cyl.Axis()
            ext.cylinder(xyz(ax.Location()), canonical(xyz(ax.Direction())), cyl.Radius(), i)
        elif kind == GeomAbs_Sphere:
            sph = adaptor.Sphere()
            ext.sphere(xyz(sph.Location()), sph.Radius(), i)
        elif kind == GeomAbs_SurfaceOfExtrusion:
            ext.extrusion(face, adaptor, i)
        else:
            ext.keep_face(face, i)
    for s in planes.values():
        ext.plane_sheets(s, faces, loops)
    for s in ext.surfaces:
        if s.kind in CURVED:
            s.anchors = [BRepBuilderAPI_Copy(faces[i]).Shape() for i in s.source_faces]
    return ext.surfaces, len(faces)


def same_extension(a: list[ExtendedSurface], b: list[ExtendedSurface]) -> bool:
    """Whether two extensions of one target give every surface the same strips (the same sheets)."""
    return len(a) == len(b) and all(_same_strips(s.strips, t.strips) for s, t in zip(a, b, strict=True))


def _same_strips(a: list[tuple[np.ndarray, float, float]], b: list[tuple[np.ndarray, float, float]]) -> bool:
    return len(a) == len(b) and all(
        parallel(d, e) and abs(a0 - b0) < GEOM_TOL and abs(a1 - b1) < GEOM_TOL
        for (d, a0, a1), (e, b0, b1) in zip(a, b, strict=True)
    )


def _distinct_faces(shape: TopoDS_Shape) -> list[TopoDS_Shape]:
    index = shape_index(shape, TopAbs_FACE)
    return [index.FindKey(i) for i in range(1, index.Size() + 1)]
