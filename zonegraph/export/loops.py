"""Sketch loops as the files write them: edges in loop order, each starting where the last ended.

A sketch face cut from the zone graph's fuzzy partition is valid although the curves of two
neighbouring edges end up to the vertex tolerance apart (1.3e-5 cm on the corpus): the vertex's
tolerance covers the gap. Written as numbers, such a loop does not close (the script's
``make_face`` joins edges 1e-9 apart: "Face can only be created with closed wires"; the JSON
reader merges end points 1e-5 apart: "a profile loop does not close"). So each corner of a loop is
written as one point, its vertex, shared by the edge that ends there and the edge that starts
there, and an edge whose two corners (almost) coincide is left out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from build123d import Edge, Face, Wire
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopExp import TopExp

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.data.profiles import SNAP_TOL

# An open edge whose corners are closer than this is left out of a written loop: the JSON reader
# merges end points this close, so it could not build the edge, and leaving it out moves the
# part by no more than this.
MIN_EDGE = SNAP_TOL


@dataclass(frozen=True)
class LoopEdge:
    """An edge of a loop with the corners it is written between (world coordinates), in the
    loop's running order; ``reversed``: the edge runs against its curve in the loop."""

    edge: Edge
    reversed: bool
    start: np.ndarray
    end: np.ndarray


def _point(vertex: object) -> np.ndarray:
    p = BRep_Tool.Pnt_s(vertex)
    return np.array([p.X(), p.Y(), p.Z()])


def _explored(wire: Wire, face: Face) -> list[tuple[Edge, bool, np.ndarray]] | None:
    """(edge, reversed, corner at its start in loop order) by OpenCASCADE's wire explorer, which
    walks a loop through its shared vertices; None when it does not reach every edge (a wire
    whose edges share no vertices)."""
    out = []
    explorer = BRepTools_WireExplorer(wire.wrapped, face.wrapped)
    while explorer.More():
        edge = explorer.Current()
        start = _point(TopExp.FirstVertex_s(edge, True))
        out.append((Edge(edge), edge.Orientation() == TopAbs_REVERSED, start))
        explorer.Next()
    return out if len(out) == len(wire.edges()) else None


def _chained(wire: Wire) -> list[tuple[Edge, bool, np.ndarray]]:
    """The same by proximity: from the first edge, the edge with an end nearest the last end."""
    left = list(wire.edges())
    edge = left.pop(0)
    out = [(edge, False, np.array(tuple(edge.position_at(0))))]
    end = np.array(tuple(edge.position_at(1)))
    while left:
        gaps = [
            (float(np.linalg.norm(np.array(tuple(e.position_at(t))) - end)), i, t == 1)
            for i, e in enumerate(left)
            for t in (0, 1)
        ]
        _, i, flipped = min(gaps)
        edge = left.pop(i)
        out.append((edge, flipped, end))
        end = np.array(tuple(edge.position_at(0 if flipped else 1)))
    return out


def loop_edges(wire: Wire, face: Face, min_edge: float = MIN_EDGE) -> list[LoopEdge]:
    """The edges of one loop of ``face`` in running order, edge i written from corner i to
    corner i + 1 (the last back to the first), open edges shorter than ``min_edge`` left out."""
    walked = _explored(wire, face) or _chained(wire)
    if len(walked) == 1:
        edge, flipped, corner = walked[0]
        return [LoopEdge(edge, flipped, corner, corner)]
    kept = [w for i, w in enumerate(walked) if w[0].is_closed or _span(walked, i) >= min_edge]
    return [
        LoopEdge(edge, flipped, corner, kept[(i + 1) % len(kept)][2])
        for i, (edge, flipped, corner) in enumerate(kept)
    ]


def _span(walked: list[tuple[Edge, bool, np.ndarray]], i: int) -> float:
    return float(np.linalg.norm(walked[(i + 1) % len(walked)][2] - walked[i][2]))
