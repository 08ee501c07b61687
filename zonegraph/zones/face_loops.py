"""Face loops (paper sec. 3, supplement A): the side walls of an extrusion.

A face loop is a cycle of faces in which consecutive faces share an edge and all those shared edges
are parallel (the loop's extrusion direction). Walls only need extending along their extrusion
direction, which keeps the zone count down. Which faces may be walls is a rule:

- ``STRICT``: every face has exactly four edges in its outer wire, and a planar one only straight
  ones (planar faces with a curved edge are caps, "frames", and stop a loop).
- ``LOOSE``: curved walls (cylinders, extrusions) with any number of outer edges, as in the
  original implementation, and planar walls whose straight outer edges make four sides, some split
  where another face meets them. A planar face with more sides stays a cap: it is an extrusion's
  profile, and taking it as a wall crosses its loop's walls with a second strip (more zones). The
  looser rule's loops include the strict ones.

The looser rule's strips can leave a partition that misses part of the target, so the build checks
its graph and falls back to the strict rule (``zonegraph.zones.build``).
"""

from __future__ import annotations

import enum
from collections import defaultdict

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.GeomAbs import GeomAbs_Line, GeomAbs_Plane
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import ShapeIndex, make_compound, shape_index, sub_shapes, xyz

PARALLEL_TOL = 1e-9  # 1 - |cos| between edge directions

Loops = dict[int, list[np.ndarray]]


class LoopRule(str, enum.Enum):
    """Which faces may be walls of a face loop."""

    LOOSE = "loose"
    STRICT = "strict"


def _line_direction(edge: TopoDS_Shape) -> np.ndarray | None:
    curve = BRepAdaptor_Curve(TopoDS.Edge(edge))
    if curve.GetType() != GeomAbs_Line or BRep_Tool.Degenerated_s(TopoDS.Edge(edge)):
        return None
    d = xyz(curve.Line().Direction())
    return d / np.linalg.norm(d)


def _is_wall_candidate(face: TopoDS_Face, directions: list[np.ndarray | None], rule: LoopRule) -> bool:
    """Whether a face with these outer-edge directions (``None``: curved) may be a wall."""
    planar = BRepAdaptor_Surface(face).GetType() == GeomAbs_Plane
    if planar and any(d is None for d in directions):
        return False
    if rule is LoopRule.STRICT:
        return len(directions) == 4
    return not planar or _sides(face) == 4


def _sides(face: TopoDS_Face) -> int:
    """The number of sides of a face's outer wire of straight edges: runs of collinear edges in
    wire order count once."""
    explorer = BRepTools_WireExplorer(BRepTools.OuterWire_s(face), face)
    dirs = []
    while explorer.More():
        d = _line_direction(explorer.Current())
        if d is not None:
            dirs.append(d)
        explorer.Next()
    turns = [1 - abs(float(a @ b)) >= PARALLEL_TOL for a, b in zip(dirs, dirs[1:] + dirs[:1], strict=True)]
    return sum(turns)


def find_face_loops(faces: list[TopoDS_Face], rule: LoopRule = LoopRule.STRICT) -> Loops:
    """For each face index in a loop, the extrusion directions of the loops it belongs to."""
    loops = _loops_of(faces, rule)
    if rule is LoopRule.LOOSE:
        # A looser wall can join a strict loop's component with a third link and so hide that
        # cycle; the strict loops are added back so the looser rule never finds fewer.
        for f, dirs in _loops_of(faces, LoopRule.STRICT).items():
            have = loops.setdefault(f, [])
            have.extend(d for d in dirs if not any(1 - abs(float(d @ h)) < PARALLEL_TOL for h in have))
    return loops


def _loops_of(faces: list[TopoDS_Face], rule: LoopRule) -> Loops:
    edge_faces: dict[int, list[int]] = defaultdict(list)  # edge id -> candidate faces
    edge_dir: dict[int, np.ndarray] = {}
    all_edges = shape_index_of(faces)
    for i, face in enumerate(faces):
        outer = BRepTools.OuterWire_s(face)
        edges = sub_shapes(outer, TopAbs_EDGE) if not outer.IsNull() else []
        dirs = [_line_direction(e) for e in edges]
        if not _is_wall_candidate(face, dirs, rule):
            continue
        for e, d in zip(edges, dirs, strict=False):
            if d is None:
                continue
            eid = all_edges.FindIndex(e)
            edge_faces[eid].append(i)
            edge_dir[eid] = d
    # Group shared straight edges by direction; the cycles of each direction's face graph in which
    # every face has exactly two links are the loops (a four-edge face has at most two edges of
    # one direction, so under the strict rule every component is a path or a cycle).
    groups: list[tuple[np.ndarray, list[int]]] = []
    for eid, fs in edge_faces.items():
        if len(set(fs)) != 2:
            continue
        d = edge_dir[eid]
        for g_dir, members in groups:
            if 1 - abs(float(g_dir @ d)) < PARALLEL_TOL:
                members.append(eid)
                break
        else:
            groups.append((d, [eid]))
    loops: Loops = defaultdict(list)
    for d, eids in groups:
        pairs = [(min(edge_faces[e]), max(edge_faces[e])) for e in eids]  # two distinct faces each
        for component in _cycles(pairs):
            for f in component:
                loops[f].append(d)
    return dict(loops)


def shape_index_of(faces: list[TopoDS_Face]) -> ShapeIndex:
    """One edge index over all faces, so shared edges get one id."""
    return shape_index(make_compound(faces), TopAbs_EDGE)


def _cycles(pairs: list[tuple[int, int]]) -> list[set[int]]:
    """Connected components of the face graph in which every face has exactly two links."""
    links: dict[int, list[int]] = defaultdict(list)
    for a, b in pairs:
        links[a].append(b)
        links[b].append(a)
    seen: set[int] = set()
    out = []
    for start in links:
        if start in seen:
            continue
        component, stack = set(), [start]
        while stack:
            f = stack.pop()
            if f in component:
                continue
            component.add(f)
            stack.extend(links[f])
        seen |= component
        if len(component) >= 2 and all(len(links[f]) == 2 for f in component):
            out.append(component)
    return out
