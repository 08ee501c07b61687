"""Profile faces from the curves of a Fusion profile that build123d 0.13 will not close.

Two kinds of profile reach ``make_face()`` as curves that build123d 0.13 refuses ("Face can only be
created with closed wires", where 0.10 built *some* face from the open wire):

- a hole joined to its outer boundary (or to another hole) by a construction line: a slit of zero
  width that Fusion's loop walks out and back, listed once among its curves;
- end points apart by Fusion's float32 noise (~1e-6 cm at 20 cm), more than build123d's 1e-9.

The region Fusion meant is bounded by the loops left once every bridge (an edge on no cycle: the
slit, a line ending inside another curve) is dropped, joined at the replay's own snap tolerance.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

import numpy as np

from zonegraph.data.profiles import SNAP_TOL

VERTEX_TOL = SNAP_TOL  # cm: end points closer than the replay snaps together are one sketch point


class NotAProfile(ValueError):
    """The edges do not bound one region once their bridges are dropped."""


def slit_profile_faces(edges: list[Any]) -> list[Any]:
    """The faces the closed loops of ``edges`` bound (bridges dropped), or `NotAProfile`.

    Each loop inside no other is an outer boundary and the loops directly inside it its holes
    (two holes joined by a slit are two holes); an island inside a hole is not a profile.
    """
    from build123d import Face, Wire

    kept = _without_bridges(edges)
    if not kept:
        raise NotAProfile("every curve is a bridge")
    wires = Wire.combine(kept, tol=VERTEX_TOL)
    if not all(w.is_closed for w in wires):
        raise NotAProfile("the loops left do not close")
    filled = sorted(((Face(w), w) for w in wires), key=lambda fw: -fw[0].area)
    outers: list[tuple[Any, Any, list[Any]]] = []  # (filled face, wire, holes)
    for face, wire in filled:
        container = next((o for o in reversed(outers) if _inside(face, o[0])), None)
        if container is None:
            if any(_inside(face, h) for o in outers for h in o[2]):
                raise NotAProfile("a loop lies inside a hole")
            outers.append((face, wire, []))
        else:
            container[2].append(wire)
    return [Face(wire, holes) for _, wire, holes in outers]


def _inside(face: Any, container: Any) -> bool:
    """Whether ``face`` lies within ``container`` (their common area is all of ``face``)."""
    from build123d import Face

    container = container if isinstance(container, Face) else Face(container)
    common: Any = container.intersect(face) or []
    inside = sum(f.area for f in common.faces()) if hasattr(common, "faces") else 0.0
    return abs(inside - face.area) <= 1e-9 * max(container.area, 1.0)


def _without_bridges(edges: list[Any]) -> list[Any]:
    """``edges`` less every edge that lies on no cycle of their end-point graph."""
    ends = [(_point(e @ 0), _point(e @ 1)) for e in edges]
    ids = _vertex_ids([p for pair in ends for p in pair])
    links = [(ids[2 * i], ids[2 * i + 1]) for i in range(len(edges))]
    return [e for i, e in enumerate(edges) if not _is_bridge(i, links)]


def _point(v: Any) -> np.ndarray:
    return np.array([float(v.X), float(v.Y), float(v.Z)])


def _vertex_ids(points: list[np.ndarray]) -> list[int]:
    """Each point's vertex number; points within `VERTEX_TOL` share one."""
    reps: list[np.ndarray] = []
    out = []
    for p in points:
        for k, r in enumerate(reps):
            if np.linalg.norm(p - r) <= VERTEX_TOL:
                out.append(k)
                break
        else:
            reps.append(p)
            out.append(len(reps) - 1)
    return out


def _is_bridge(i: int, links: list[tuple[int, int]]) -> bool:
    """Whether edge ``i``'s end points are disconnected once it is removed (a loop never is)."""
    a, b = links[i]
    if a == b:
        return False
    graph: dict[int, set[int]] = defaultdict(set)
    for j, (u, v) in enumerate(links):
        if j != i:
            graph[u].add(v)
            graph[v].add(u)
    seen, stack = {a}, [a]
    while stack:
        for n in graph[stack.pop()]:
            if n not in seen:
                seen.add(n)
                stack.append(n)
    return b not in seen
