"""Why a reconstruction is not exact: the target's faces no extrusion can make, the zones no prism
holds, and how the search ended.

An extrusion along d makes two kinds of face: caps (planes normal to d) and side walls (surfaces
whose normals are all normal to d: planes containing d, cylinders and other extrusion surfaces
along d). The search extrudes only between parallel planes of the zone graph, so its directions
are the normals of those plane pairs; a target face whose normals fit no such direction (a sphere,
a torus, a cone, a free-form face, a cylinder across every direction) is beyond any program the
search can find, whatever its budget. A face is judged by its surface's normals sampled over the
face's parameter box, so a B-spline that is really an extruded profile still counts as makeable.

The zone graph's own limit is exact too: a prism's zones are a union of single-face sweeps (each
memoised by the generator and independent of the canvas), so an inside zone that no sweep holds can
never be added by any program on that graph.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepLProp import BRepLProp_SLProps
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_C0, GeomAbs_SurfaceType
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_ShapeEnum
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import AncestorMap, ancestors, shape_index, surface_props, xyz
from zonegraph.sequence.deadline import Deadline
from zonegraph.sequence.proposals import ProposalGenerator

NORMAL_TOL = 1e-6  # |cos| below this is normal to d, above 1 - this is along d
SAMPLES = 5  # surface normals sampled per parameter direction of a face
# GeomAbs surface types by name (the enum's names, lower-cased and without the prefix).
KIND_WORDS = {
    "plane": ("plane", "planes"),
    "cylinder": ("cylinder", "cylinders"),
    "cone": ("cone", "cones"),
    "sphere": ("sphere", "spheres"),
    "torus": ("torus", "tori"),
    "beziersurface": ("Bezier face", "Bezier faces"),
    "bsplinesurface": ("B-spline face", "B-spline faces"),
    "surfaceofrevolution": ("surface of revolution", "surfaces of revolution"),
    "surfaceofextrusion": ("extrusion surface", "extrusion surfaces"),
    "offsetsurface": ("offset surface", "offset surfaces"),
    "othersurface": ("free-form face", "free-form faces"),
}


@dataclass(frozen=True)
class TargetFace:
    """One face of the target: its surface type, area, and whether it is a blend."""

    kind: str  # a KIND_WORDS key
    area: float
    blend: str  # "fillet" (curved and tangent to two or more neighbours), "chamfer" or ""
    makeable: bool  # a cap or side wall of an extrusion along one of the search's directions
    side_only: bool  # a slanted plane: makeable only as a side wall (no plane pair along its normal)


@dataclass(frozen=True)
class FaceGroup:
    """Target faces of one kind and blend, summed."""

    kind: str
    blend: str
    count: int
    area_share: float  # of the target's whole area

    def describe(self) -> str:
        """E.g. "8 spheres (fillets, 2.4% of the area)"."""
        one, many = KIND_WORDS.get(self.kind, (self.kind, self.kind + "s"))
        blend = {"fillet": ("fillet", "fillets"), "chamfer": ("chamfer", "chamfers")}.get(self.blend)
        label = f"{blend[self.count != 1]}, " if blend else ""
        noun = one if self.count == 1 else many
        return f"{self.count} {noun} ({label}{self.area_share:.1%} of the area)"


@dataclass(frozen=True)
class Diagnosis:
    """What limits a reconstruction, for its ``reason``.

    ``uncovered`` is None when the sweeps could not all be checked within their time."""

    unmakeable: list[FaceGroup] = field(default_factory=list)
    side_only: list[FaceGroup] = field(default_factory=list)
    uncovered: int | None = 0  # inside zones no prism of the graph holds
    inside: int = 0
    uncovered_share: float = 0.0  # of the target's volume
    searches: list[str] = field(default_factory=list)  # e.g. "simplified graph: exhausted, 12 expansions"

    def reason(self) -> str:
        """One sentence: the faces, then the graph, then the search."""
        parts = []
        if self.unmakeable:
            faces = "; ".join(g.describe() for g in self.unmakeable)
            parts.append(f"no extrusion can make {faces}")
        else:
            parts.append("every target face can be made by some extrusion")
        if self.side_only:
            faces = "; ".join(g.describe() for g in self.side_only)
            parts.append(f"{faces} can only be side walls of extrusions (no plane pair lies along them)")
        if self.uncovered is None:
            parts.append("whether the zone graph can represent the target was not checked in time")
        elif self.uncovered:
            parts.append(
                f"the zone graph cannot represent the target ({self.uncovered} of {self.inside} "
                f"inside zones, {self.uncovered_share:.1%} of its volume, lie in no prism)"
            )
        else:
            parts.append("every inside zone lies in some prism of the zone graph")
        if self.searches:
            parts.append("the search " + "; ".join(self.searches))
        if not self.unmakeable and self.uncovered == 0 and all("exhausted" in s for s in self.searches):
            parts.append("so the proposal rules, not extrusion, fall short here")
        return "; ".join(parts)


def _normals(face: TopoDS_Face) -> np.ndarray:
    """Unit normals of the face's surface on a grid over its parameter box (singular points left
    out, as a sphere's poles have none)."""
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    surface = BRepAdaptor_Surface(face)
    props = BRepLProp_SLProps(surface, 1, 1e-9)
    out = []
    for u in np.linspace(u0, u1, SAMPLES):
        for v in np.linspace(v0, v1, SAMPLES):
            props.SetParameters(float(u), float(v))
            if props.IsNormalDefined():
                out.append(xyz(props.Normal()))
    return np.array(out).reshape(-1, 3)


def _kind(face: TopoDS_Face) -> str:
    name = GeomAbs_SurfaceType(BRepAdaptor_Surface(face).GetType()).name
    return name.removeprefix("GeomAbs_").lower()


def _distinct(shape: TopoDS_Shape, kind: TopAbs_ShapeEnum) -> list[TopoDS_Shape]:
    index = shape_index(shape, kind)
    return [index.FindKey(i) for i in range(1, index.Size() + 1)]


def _tangent_neighbours(face: TopoDS_Face, edge_faces: AncestorMap) -> int:
    """How many of the face's edges join it smoothly (G1 or better) to another face."""
    count = 0
    for edge in _distinct(face, TopAbs_EDGE):
        for other in edge_faces.FindFromKey(edge):
            other_face = TopoDS.Face(other)
            if other_face.IsSame(face):
                continue
            if BRep_Tool.Continuity_s(TopoDS.Edge(edge), face, other_face) != GeomAbs_C0:
                count += 1
    return count


def target_faces(shape: TopoDS_Shape, directions: np.ndarray) -> list[TargetFace]:
    """Every face of the target, judged against the search's extrusion directions (unit rows)."""
    edge_faces = ancestors(shape, TopAbs_EDGE, TopAbs_FACE)
    out = []
    for item in _distinct(shape, TopAbs_FACE):
        face = TopoDS.Face(item)
        kind = _kind(face)
        cos = np.abs(_normals(face) @ directions.T) if len(directions) else np.zeros((0, 0))
        cap = bool(cos.size) and bool((cos > 1 - NORMAL_TOL).all(axis=0).any())
        side = bool(cos.size) and bool((cos < NORMAL_TOL).all(axis=0).any())
        tangent = _tangent_neighbours(face, edge_faces) if kind != "plane" else 0
        slanted = kind == "plane" and not cap
        blend = "fillet" if tangent >= 2 else "chamfer" if slanted and side else ""
        out.append(TargetFace(kind, surface_props(face)[0], blend, cap or side, slanted and side))
    return out


def group_faces(faces: list[TargetFace], total_area: float) -> list[FaceGroup]:
    """Faces summed by kind and blend, the largest area first."""
    counts = Counter((f.kind, f.blend) for f in faces)
    areas: dict[tuple[str, str], float] = {}
    for f in faces:
        areas[(f.kind, f.blend)] = areas.get((f.kind, f.blend), 0.0) + f.area
    groups = [FaceGroup(k, b, counts[(k, b)], areas[(k, b)] / total_area) for k, b in counts]
    return sorted(groups, key=lambda g: -g.area_share)


def search_directions(generator: ProposalGenerator) -> np.ndarray:
    """The unit extrusion directions of the generator's plane pairs, one row per line."""
    normals = generator.graph.surface_normal
    lines = {tuple(np.round(normals[s] * np.sign(_first(normals[s])), 9)) for s, _ in generator.pairs}
    return np.array(sorted(lines), float).reshape(-1, 3)


def _first(v: np.ndarray) -> float:
    """The first clearly non-zero component, to give each line one sign."""
    return float(v[int(np.argmax(np.abs(v) > 1e-9))])


def uncovered_zones(generator: ProposalGenerator, deadline: Deadline) -> np.ndarray | None:
    """Inside zones that no single-face sweep of the graph holds, or None if ``deadline`` passed
    before every sweep was tried (the generator memoises them, so the search's own are free)."""
    g = generator.graph
    covered = np.zeros(g.n_zones, bool)
    for s, e in generator.pairs:
        for face in generator.faces_on[s].tolist():
            if deadline.passed():
                return None
            swept = generator.sweep(face, s, e)
            if swept is not None:
                covered[swept.members] = True
    return np.flatnonzero(g.zone_inside.astype(bool) & ~covered)


def diagnose(
    shape: TopoDS_Shape, generator: ProposalGenerator, searches: list[str], seconds: float
) -> Diagnosis:
    """The limits of a reconstruction on ``generator``'s graph; ``seconds`` bounds the sweeps."""
    faces = target_faces(shape, search_directions(generator))
    total = sum(f.area for f in faces) or 1.0
    uncovered = uncovered_zones(generator, Deadline.after(seconds))
    g = generator.graph
    inside = g.zone_inside.astype(bool)
    share = 0.0
    if uncovered is not None and len(uncovered):
        share = float(g.zone_volume[uncovered].sum() / g.zone_volume[inside].sum())
    return Diagnosis(
        unmakeable=group_faces([f for f in faces if not f.makeable], total),
        side_only=group_faces([f for f in faces if f.side_only], total),
        uncovered=None if uncovered is None else len(uncovered),
        inside=int(inside.sum()),
        uncovered_share=share,
        searches=searches,
    )
