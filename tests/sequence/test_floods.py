"""The batched sweeps (every face of many plane pairs in one breadth-first search) against the
sweep as the proposals module states it, walked one face at a time."""

from __future__ import annotations

import numpy as np
import pytest
from build123d import Align, Box, Cylinder, Pos, Rot

from zonegraph.sequence import proposals
from zonegraph.sequence.proposals import PRISM_RTOL, ProposalGenerator
from zonegraph.zones.build import build_zone_graph
from zonegraph.zones.model import ZoneGraph


def walked(
    graph: ZoneGraph, generator: ProposalGenerator, face: int, s: int, e: int
) -> tuple[list[int], tuple[int, ...]] | None:
    """(zones, faces) of one face's sweep from s to e, or None: into the zone beyond the face,
    across the caps of each zone reached (not faces on e), failing outside the slab or past a
    face with nothing behind it; then the face's prism, or that of every face under the zones."""
    d = generator.direction(s, e)
    length = float(np.linalg.norm(d))
    side_s = np.sign(graph.surface_normal[s] @ d)
    side_e = -np.sign(graph.surface_normal[e] @ d)
    from_a, from_b = generator._crossings(d, length)
    a, b = graph.face_zones[face]
    start = b if graph.face_normal[face] @ d > 0 else a
    reached: set[int] = set()
    stack = [int(start)]
    while stack:
        z = stack.pop()
        if z < 0 or graph.plane_side[s, z] != side_s or graph.plane_side[e, z] != side_e:
            return None
        if z in reached:
            continue
        reached.add(z)
        for f in np.flatnonzero((graph.face_zones == z).any(axis=1)):
            if graph.face_surface[f] == e:
                continue
            fa, fb = graph.face_zones[f]
            if (from_a[f] and fa == z) or (from_b[f] and fb == z):
                stack.append(int(fb if fa == z else fa))
    members = sorted(reached)
    volume = graph.zone_volume[members].sum()
    on_s = generator.faces_on[s]
    beyond = generator._zones_beyond(s, e)
    under = [int(f) for f, z in zip(on_s, beyond, strict=True) if z in reached]
    for faces in ((face,), tuple(under)):
        prism = graph.face_area[list(faces)].sum() * length
        if abs(volume - prism) <= PRISM_RTOL * prism:
            return members, faces
    return None


def test_every_batched_sweep_is_the_walked_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """A plate with a boss, a through hole, a blind pocket and a cylinder lying across its top:
    caps, side walls, a curved cap that joins columns, sweeps that leave the slab. Made in small
    batches (a few pairs each) and all at once, every face of every pair sweeps as walked."""
    plate = Box(6, 4, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    boss = Pos(-1.5, 0, 1) * Cylinder(0.8, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    hole = Pos(1.5, 1, 0) * Cylinder(0.4, 1, align=(Align.CENTER, Align.CENTER, Align.MIN))
    pocket = Pos(1.5, -1, 0.5) * Box(1, 1, 0.5, align=(Align.CENTER, Align.CENTER, Align.MIN))
    across = Pos(0, 0, 1) * Rot(0, 90, 0) * Cylinder(0.3, 6)
    graph = build_zone_graph([plate + boss - hole - pocket - across], samples=0)
    for cells in (8 * (graph.n_zones + 1), proposals.FLOOD_CELLS):
        monkeypatch.setattr(proposals, "FLOOD_CELLS", cells)
        generator = ProposalGenerator(graph)
        outcomes = set()
        for s, e in generator.pairs:
            for face in generator.faces_on[s].tolist():
                swept = generator.sweep(face, s, e)
                expected = walked(graph, generator, face, s, e)
                got = None if swept is None else (swept.members.tolist(), swept.faces)
                assert got == expected, (face, s, e)
                outcomes.add("fails" if got is None else "own" if len(got[1]) == 1 else "shared")
        assert outcomes == {"fails", "own", "shared"}  # every kind of sweep occurs
