"""Face loops (paper sec. 3, supplement A): the side walls of an extrusion.

A face loop is a cycle of faces in which consecutive faces share an edge, all those shared edges are
parallel (the loop's extrusion direction) and every face has exactly four edges in its outer wire.
Planar faces with a curved edge are caps ("frames"), not walls, so they stop a loop. Walls only need
extending along their extrusion direction, which keeps the zone count down.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Line, GeomAbs_Plane
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

from zonegraph.geometry.occ import ShapeIndex, make_compound, shape_index, sub_shapes, xyz

PARALLEL_TOL = 1e-9  # 1 - |cos| between edge directions


def _line_direction(edge: TopoDS_Shape) -> np.ndarray | None:
    curve = BRepAdaptor_Curve(TopoDS.Edge(edge))
    if curve.GetType() != GeomAbs_Line or BRep_Tool.Degenerated_s(TopoDS.Edge(edge)):
        return None
    d = xyz(curve.Line().Direction())
    return d / np.linalg.norm(d)


def _is_wall_candidate(face: TopoDS_Face, directions: list[np.ndarray | None]) -> bool:
    """Four outer edges; a planar face must have only straight ones."""
    if len(directions) != 4:
        return False
    planar = BRepAdaptor_Surface(face).GetType() == GeomAbs_Plane
    return not planar or all(d is not None for d in directions)


def find_face_loops(faces: list[TopoDS_Face]) -> dict[int, list[np.ndarray]]:
    """For each face index in a loop, the extrusion directions of the loops it belongs to."""
    edge_faces: dict[int, list[int]] = defaultdict(list)  # edge id -> candidate faces
    edge_dir: dict[int, np.ndarray] = {}
    all_edges = shape_index_of(faces)
    for i, face in enumerate(faces):
        outer = BRepTools.OuterWire_s(face)
        edges = sub_shapes(outer, TopAbs_EDGE) if not outer.IsNull() else []
        dirs = [_line_direction(e) for e in edges]
        if not _is_wall_candidate(face, dirs):
            continue
        for e, d in zip(edges, dirs, strict=False):
            if d is None:
                continue
            eid = all_edges.FindIndex(e)
            edge_faces[eid].append(i)
            edge_dir[eid] = d
    # Group shared straight edges by direction; within one direction every face has at most two
    # such edges, so the face graph is a union of paths and cycles, and the cycles are the loops.
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
    loops: dict[int, list[np.ndarray]] = defaultdict(list)
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
