"""Extrusion proposals from a zone graph (paper sec. 4.1, supplement Alg. 1).

For every ordered pair of parallel planes (start s, end e; d = the vector from s to e), the
partition faces on s are grouped by the zone just beyond them along d:

1. in the canvas but not the target: can start a subtraction;
2. in the target but not the canvas: can start a union;
3. in the target, or in neither: can start a union;
4. whose sweep to e (below) meets a zone in the canvas but not the target, and no zone in both:
   can start a subtraction that removes only what must go;
5. whose sweep to e meets a zone in the target but not the canvas: can start a union.

Groups 4 and 5 are where a sketch's extent is set by what its prism reaches rather than by the
zone next to the sketch plane: a through-cut or a boss drawn on the box face, whose first zones
lie outside both canvas and target, so groups 1-3 lump its faces with the whole face.

A sketch is a connected component of a group (faces sharing an edge on s), the union of the
group's components, or (proposal level k) any 1..k or N-k..N of them. Each sketch face is swept
along d to e through the zones it meets: from the face into the zone beyond it, then across that
zone's caps (planar faces facing along d, and curved faces not on a cylinder or extrusion along d),
never its side walls (cylinders and extrusions along d), until plane e. The zones swept must fill
the prism exactly (volume = face area x |d|, relative 1e-4) of the face or, where a curved cap
joins the columns of neighbouring faces (a cylinder lying across the sweep, tangent to s where
the columns meet), of every face on s under the zones swept; a sketch needs all the faces its
faces' sweeps lie on, and a face that fails rejects the whole sketch. A face inside one zone (a
face-loop strip or a kept freeform face that ends within the zone: the general fuse leaves it
dangling, with that zone on both sides) bounds nothing: a sweep passes it and no sketch uses it.
The geometry never changes during search, so sweeps are made once per plane pair, every face
on its start plane at once (with the pairs after it, in one breadth-first search over (pair,
zone) nodes), and kept.
"""

from __future__ import annotations

import enum
import itertools
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from zonegraph.sequence.deadline import Deadline
from zonegraph.sequence.memo import Memo
from zonegraph.zones.model import ZoneGraph

PARALLEL_TOL = 1e-9
MIN_DISTANCE = 1e-5  # normalised units: closer parallel planes are not an extrusion
PRISM_RTOL = 1e-4
SIDE_WALL_KINDS = ("cylinder", "extrusion")  # curved surfaces a sweep along their axis runs beside
# What the memos of one generator keep (bytes), the least recently used dropped first: the face
# groups' candidates, their components, and the components' sweeps.
MEMO_BYTES = {"groups": 256 * 2**20, "components": 32 * 2**20, "sweeps": 128 * 2**20}


_Swept = tuple[np.ndarray, set[int]]  # a component's swept zones (Z,) bool, the faces its sweeps need


@dataclass(frozen=True)
class Sweep:
    """The zones a face's prism from s to e is made of, and the faces on s they stand on.

    Kept as the zones' ids: a generator memoises every sweep it makes, and a (Z,) mask each held
    13 GB on a 16,500-zone graph.

    Shapes:
        members: (K,) int32, sorted; zones: (Z,) bool, made on each read.
    """

    members: np.ndarray
    faces: tuple[int, ...]  # the face swept, and the faces it shares its zones with (sorted)
    n_zones: int

    @property
    def zones(self) -> np.ndarray:
        """(Z,) bool: the swept zones as a mask over the graph's zones."""
        mask = np.zeros(self.n_zones, bool)
        mask[self.members] = True
        return mask


class Op(enum.IntEnum):
    UNION = 1
    SUBTRACT = -1


@dataclass(frozen=True, eq=False, repr=False)
class Proposal:
    """One candidate operation: extrude ``faces`` on plane ``start`` to plane ``end``.

    Two proposals are equal (and hash alike) when they do the same thing to any canvas: the same
    extrusion volume with the same operation, whichever sketch produced it (`key`).

    Shapes:
        zones: (Z,) bool over the zone graph's zones.
    """

    start: int  # surface index of the start plane
    end: int  # surface index of the end plane
    faces: tuple[int, ...]  # partition faces of the sketch (sorted)
    zones: np.ndarray  # bool (Z,): the extrusion volume X
    op: Op

    @cached_property
    def key(self) -> tuple[bytes, int]:
        """Identity of the operation on the canvas (the same volume from other sketches is equal)."""
        return np.packbits(self.zones).tobytes(), int(self.op)

    @cached_property
    def inverse_key(self) -> tuple[bytes, int]:
        """The key of the operation that undoes this one (the same volume, the other operation)."""
        return self.key[0], -int(self.op)

    def apply(self, canvas: np.ndarray) -> np.ndarray:
        """The canvas after this operation: (Z,) bool in, (Z,) bool out."""
        return canvas | self.zones if self.op is Op.UNION else canvas & ~self.zones

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Proposal) and self.key == other.key

    def __hash__(self) -> int:
        return hash(self.key)

    def __repr__(self) -> str:
        return (
            f"Proposal({self.op.name.lower()}, plane {self.start} -> {self.end}, "
            f"{len(self.faces)} sketch faces, {int(self.zones.sum())} zones)"
        )


@dataclass(frozen=True)
class _Reach:
    """The zones every face on one plane pair's start plane sweeps, flattened (canvas-independent).

    Shapes:
        ok: (F_s,) bool, the face's sweep fills its prism; zones: (N,) int, the swept zones of
        all faces in order (one placeholder zone for a face whose sweep fails); starts: (F_s,)
        int, where each face's zones begin in ``zones``.
    """

    ok: np.ndarray
    zones: np.ndarray
    starts: np.ndarray

    def meets(self, need: np.ndarray, avoid: np.ndarray) -> np.ndarray:
        """(F_s,) bool: the faces whose sweep fills its prism, holds a zone of ``need`` (Z,) bool
        and none of ``avoid`` (Z,) bool."""
        if not len(self.ok):
            return self.ok
        hits = np.logical_or.reduceat(need[self.zones], self.starts)
        return self.ok & hits & ~np.logical_or.reduceat(avoid[self.zones], self.starts)


@dataclass(frozen=True)
class _Candidates:
    """The extrusions of one face group on one plane pair, as a union and a subtraction each.

    Shapes:
        volumes: (K, Z) bool, one row per sketch whose prism the zones fill exactly.
    """

    volumes: np.ndarray
    union: tuple[Proposal, ...]
    subtract: tuple[Proposal, ...]

    @property
    def nbytes(self) -> int:
        """About what keeping it costs: the volumes twice (the matrix, each proposal's row) and
        the proposal objects."""
        return 2 * self.volumes.nbytes + 600 * len(self.union) + 200

    @cached_property
    def rows(self) -> tuple[np.ndarray, tuple[Proposal, ...]]:
        """Each volume as a union then a subtraction: (2K, bytes) packed keys and the proposals."""
        packed = np.packbits(self.volumes, axis=1)
        keys = np.repeat(packed, 2, axis=0)
        ops = np.tile(np.array([Op.UNION, Op.SUBTRACT], np.int8).view(np.uint8), len(self.volumes))
        interleaved = tuple(p for pair in zip(self.union, self.subtract, strict=True) for p in pair)
        return np.concatenate([keys, ops[:, None]], axis=1), interleaved


@dataclass(frozen=True)
class _Slab:
    """A plane pair's sweep direction and length, which zones lie between its planes, and which
    faces a sweep crosses out of their first and their second zone.

    Shapes:
        inside: (Z + 1,) bool, the last entry (no zone: a face on the box) False; from_a,
        from_b: (F,) bool.
    """

    d: np.ndarray
    length: float
    inside: np.ndarray
    from_a: np.ndarray
    from_b: np.ndarray


@dataclass(frozen=True)
class _Floods:
    """Every face on one plane pair's start plane swept to its end plane (canvas-independent).

    Shapes:
        members: (N,) int32, the swept zones of each face in turn (sorted), none for a face whose
        sweep fails; starts: (F_s + 1,) int64, where each face's zones begin, then the end;
        fills: (F_s,) int8, `OWN` where the zones fill the face's own prism, `SHARED` where they
        fill the prism of every face on s under them, 0 where the sweep fails.
    """

    members: np.ndarray
    starts: np.ndarray
    fills: np.ndarray


OWN, SHARED = 1, 2
FLOOD_CELLS = 2**22  # faces x (zones + 1) flooded at once: the visited mask's bytes


def _spans(begins: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """The indices ``begins[i] .. begins[i] + counts[i] - 1`` of every i, concatenated."""
    return np.arange(int(counts.sum())) + np.repeat(begins - (np.cumsum(counts) - counts), counts)


def _reached(
    sources: np.ndarray, targets: np.ndarray, inside: np.ndarray, starts: np.ndarray, width: int
) -> tuple[np.ndarray, np.ndarray]:
    """For each of R rows the nodes reached from its start node (-1: none) along the edges
    ``sources`` -> ``targets``, leaving only nodes that are ``inside``: (row, node % width) pairs
    (nodes are pair * width + zone), by row, then column. One breadth-first search for all rows:
    each round expands every row's frontier at once. A (R, width) mask says what was seen; the
    pairs are collected as they are found (reading them back from the mask scanned all of it,
    most of a batch's time on graphs of ten thousand zones)."""
    order = np.argsort(sources, kind="stable")
    successors = targets[order]
    bounds = np.concatenate(([0], np.cumsum(np.bincount(sources, minlength=len(inside)))))
    seen = np.zeros((len(starts), width), bool)
    rows = np.flatnonzero(starts >= 0)
    nodes = starts[rows]
    seen[rows, nodes % width] = True
    found = [rows * width + nodes % width]
    while len(rows):
        go = inside[nodes]
        rows, nodes = rows[go], nodes[go]
        counts = bounds[nodes + 1] - bounds[nodes]
        rows = np.repeat(rows, counts)
        nodes = successors[_spans(bounds[nodes], counts)]
        fresh = ~seen[rows, nodes % width]
        codes, first = np.unique(rows[fresh] * width + nodes[fresh] % width, return_index=True)
        rows, nodes = rows[fresh][first], nodes[fresh][first]
        seen[rows, nodes % width] = True
        found.append(codes)
    codes = np.sort(np.concatenate(found))
    return codes // width, codes % width


class ProposalGenerator:
    """Proposals for any canvas of one zone graph, with every canvas-independent part precomputed."""

    def __init__(self, graph: ZoneGraph, level: int = 1):
        self.graph = graph
        self.level = level
        self.target = graph.zone_inside.astype(bool)
        self.internal = self._internal_faces()
        planes = graph.planes
        self.pairs = self._plane_pairs(planes)
        self.faces_on = {int(s): np.flatnonzero(graph.face_surface == s) for s in planes}
        self._links_on = self._links_by_plane(planes)
        self._local_links = self._local_links_by_plane()
        self._sweeps: dict[tuple[int, int, int], Sweep | None] = {}
        self._groups: Memo[_Candidates] = Memo(MEMO_BYTES["groups"], lambda c: c.nbytes)
        self._comps: Memo[list[list[int]]] = Memo(
            MEMO_BYTES["components"], lambda comps: 100 + sum(60 + 8 * len(c) for c in comps)
        )
        self._swept_comps: Memo[_Swept | None] = Memo(
            MEMO_BYTES["sweeps"], lambda swept: 100 if swept is None else 200 + swept[0].nbytes
        )
        self._reach: dict[tuple[int, int], _Reach] = {}
        self._all_reach: _Reach | None = None
        self._slabs: dict[tuple[int, int], _Slab] = {}
        self._floods: dict[tuple[int, int], _Floods] = {}
        self._beyond = {(s, e): self._zones_beyond(s, e) for s, e in self.pairs}
        self._pair_index = {pair: i for i, pair in enumerate(self.pairs)}
        self._flatten_pairs()

    # ------------------------------------------------------------------ static structure

    def _plane_pairs(self, planes: np.ndarray) -> list[tuple[int, int]]:
        g = self.graph
        pairs = []
        for s, e in itertools.permutations(planes.tolist(), 2):
            ns, ne = g.surface_normal[s], g.surface_normal[e]
            if 1 - abs(float(ns @ ne)) > PARALLEL_TOL:
                continue
            if abs(g.surface_offset[e] * float(ns @ ne) - g.surface_offset[s]) > MIN_DISTANCE:
                pairs.append((s, e))
        return pairs

    def _internal_faces(self) -> np.ndarray:
        """(F,) bool: faces with one zone that are not on the box, so that zone lies on both sides."""
        g = self.graph
        surface = g.face_surface
        on_box = (surface >= 0) & g.surface_on_box[np.maximum(surface, 0)]
        return (g.face_zones[:, 1] < 0) & (surface >= 0) & ~on_box

    def _links_by_plane(self, planes: np.ndarray) -> dict[int, list[tuple[int, int]]]:
        """Face links (edge-sharing faces, always on one surface) grouped by their plane."""
        out: dict[int, list[tuple[int, int]]] = {int(s): [] for s in planes}
        for a, b in self.graph.face_links.tolist():
            plane = int(self.graph.face_surface[a])
            if plane in out:
                out[plane].append((a, b))
        return out

    def _local_links_by_plane(self) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """Each plane's face links as positions in ``faces_on[plane]``: a face group's links are
        then one mask away, where walking every link of the plane per group was the largest cost
        of an expansion on graphs of hundreds of zones."""
        out = {}
        for s, links in self._links_on.items():
            faces = self.faces_on[s]
            ends = np.array(links, np.int64).reshape(-1, 2)
            pos = np.minimum(np.searchsorted(faces, ends), max(len(faces) - 1, 0))
            on_plane = (faces[pos] == ends).all(axis=1) if len(faces) else np.zeros(len(ends), bool)
            out[s] = (pos[on_plane, 0], pos[on_plane, 1])
        return out

    def _flatten_pairs(self) -> None:
        """Every pair's start-plane faces in one array, so a canvas is classified in one pass."""
        beyond = [self._beyond[pair] for pair in self.pairs]
        lengths = np.array([len(b) for b in beyond], np.int64)
        self._ends = np.cumsum(lengths)
        self._starts = self._ends - lengths
        self._faced = lengths > 0  # the pairs with faces on their start plane
        flat = np.concatenate(beyond) if beyond else np.zeros(0, np.int64)
        self._flat_valid = flat >= 0
        self._flat_zone = np.where(self._flat_valid, flat, 0)
        self._flat_in_t = self.target[self._flat_zone] & self._flat_valid

    def direction(self, s: int, e: int) -> np.ndarray:
        """The extrusion vector d from plane s to plane e."""
        g = self.graph
        n = g.surface_normal[s]
        return n * (g.surface_offset[e] * float(n @ g.surface_normal[e]) - g.surface_offset[s])

    def _zones_beyond(self, s: int, e: int) -> np.ndarray:
        """For each face on s: the zone on its d side (-1 if none)."""
        g = self.graph
        d = self.direction(s, e)
        faces = self.faces_on[s]
        forward = g.face_normal[faces] @ d > 0
        beyond = np.where(forward, g.face_zones[faces, 1], g.face_zones[faces, 0])
        return beyond

    # -------------------------------------------------------------------------- sweeping

    def sweep(self, face: int, s: int, e: int) -> Sweep | None:
        """The prism over ``face`` (a face on s) from s to e, or None if its zones do not fill it
        exactly."""
        key = (face, s, e)
        if key not in self._sweeps:
            self._sweeps[key] = self._sweep(face, s, e)
        return self._sweeps[key]

    def _slab(self, s: int, e: int) -> _Slab:
        """What every sweep from s to e shares (memoised per pair)."""
        key = (s, e)
        slab = self._slabs.get(key)
        if slab is None:
            g = self.graph
            d = self.direction(s, e)
            side_s = 1 if float(g.surface_normal[s] @ d) > 0 else -1
            side_e = 1 if float(g.surface_normal[e] @ d) > 0 else -1
            length = float(np.linalg.norm(d))
            between = (g.plane_side[s] == side_s) & (g.plane_side[e] == -side_e)
            from_a, from_b = self._crossings(d, length)
            slab = self._slabs[key] = _Slab(d, length, np.append(between, False), from_a, from_b)
        return slab

    def _sweep(self, face: int, s: int, e: int) -> Sweep | None:
        floods = self._floods_of(s, e)
        i = int(np.searchsorted(self.faces_on[s], face))
        fill = int(floods.fills[i])
        if not fill:
            return None
        members = floods.members[floods.starts[i] : floods.starts[i + 1]]
        if fill == OWN:
            return Sweep(members, (face,), self.graph.n_zones)
        zones = np.zeros(self.graph.n_zones, bool)
        zones[members] = True
        return Sweep(members, tuple(self._faces_under(zones, s, e)), self.graph.n_zones)

    def _floods_of(self, s: int, e: int) -> _Floods:
        """The pair's `_Floods` (memoised), made with the pairs after it that are not made yet
        as far as `FLOOD_CELLS` allows."""
        floods = self._floods.get((s, e))
        if floods is None:
            width = self.graph.n_zones + 1
            batch: list[tuple[int, int]] = []
            cells = 0
            for pair in self.pairs[self._pair_index[(s, e)] :]:
                if pair in self._floods:
                    continue
                cells += len(self.faces_on[pair[0]]) * width
                if batch and cells > FLOOD_CELLS:
                    break
                batch.append(pair)
            self._floods.update(zip(batch, self._flood(batch), strict=True))
            floods = self._floods[(s, e)]
        return floods

    def _flood(self, pairs: list[tuple[int, int]]) -> list[_Floods]:
        """Every face on each pair's start plane swept at once: from the zone beyond the face, on
        through the faces the sweep crosses (`_crossings`; not those on e) of every zone reached,
        all faces of all the pairs as one breadth-first search over (pair, zone) nodes. A sweep
        fails where it reaches a zone outside the slab between s and e, or crosses a face with
        no zone behind it; else it must fill the face's prism exactly, or the prism of every
        face on s under its zones.

        One Python walk per face was most of a first expansion on graphs of a thousand zones
        (37,000 sweeps of 9 zones on average at the root of a 1,544-zone graph)."""
        g = self.graph
        width = g.n_zones + 1  # a node per zone, and one for no zone
        slabs = [self._slab(s, e) for s, e in pairs]
        first, second = g.face_zones[:, 0], g.face_zones[:, 1]
        crossable = (g.face_surface[None, :] != np.array([e for _, e in pairs])[:, None]) & (first >= 0)
        pair_a, out_a = np.nonzero(np.stack([sl.from_a for sl in slabs]) & crossable)  # (B, F) masks
        pair_b, out_b = np.nonzero(np.stack([sl.from_b for sl in slabs]) & crossable & (second >= 0))
        behind = np.where(second[out_a] >= 0, second[out_a], g.n_zones)
        inside = np.concatenate([sl.inside for sl in slabs])
        faces = np.concatenate([self.faces_on[s] for s, _ in pairs])
        pair_of_row = np.repeat(np.arange(len(pairs)), [len(self.faces_on[s]) for s, _ in pairs])
        beyond = np.concatenate([self._beyond[pair] for pair in pairs])
        starts = np.where(beyond >= 0, beyond + pair_of_row * width, -1)
        row, zone = _reached(
            np.concatenate([first[out_a] + pair_a * width, second[out_b] + pair_b * width]),
            np.concatenate([behind + pair_a * width, first[out_b] + pair_b * width]),
            inside,
            starts,
            width,
        )
        on = starts >= 0
        area_under = np.bincount(starts[on], g.face_area[faces[on]], minlength=len(inside))
        lengths = np.array([sl.length for sl in slabs])[pair_of_row]
        node = pair_of_row[row] * width + zone
        n_rows = len(starts)
        outside = np.bincount(row, ~inside[node], minlength=n_rows) > 0
        volume = np.bincount(row, np.append(g.zone_volume, 0.0)[zone], minlength=n_rows)
        prism = g.face_area[faces] * lengths
        shared = np.bincount(row, area_under[node], minlength=n_rows) * lengths
        fills = np.where(
            np.abs(volume - prism) <= PRISM_RTOL * prism,
            OWN,
            np.where(np.abs(volume - shared) <= PRISM_RTOL * shared, SHARED, 0),
        ).astype(np.int8)
        fills[outside | ~on] = 0
        kept = fills[row] > 0
        bounds = np.concatenate(([0], np.cumsum(np.bincount(row[kept], minlength=n_rows))))
        members = zone[kept].astype(np.int32)
        out, lo = [], 0
        for s, _ in pairs:
            hi = lo + len(self.faces_on[s])
            begin, end = bounds[lo], bounds[hi]
            out.append(_Floods(members[begin:end], bounds[lo : hi + 1] - begin, fills[lo:hi]))
            lo = hi
        return out

    def _reach_of(self, s: int, e: int, deadline: Deadline | None) -> _Reach | None:
        """The sweep of every face on s whose zone beyond it (towards e) lies outside the target,
        on the pair (s, e) (memoised), or None when ``deadline`` passes first. A face next to a
        target zone is left out (groups 1-3 place it by that zone): a placeholder zone, not ok."""
        hit = self._reach.get((s, e))
        if hit is None:
            if (s, e) not in self._floods and deadline is not None and deadline.passed():
                return None
            floods = self._floods_of(s, e)
            beyond = self._beyond[(s, e)]
            ok = (beyond >= 0) & ~self.target[np.maximum(beyond, 0)] & (floods.fills > 0)
            counts = np.where(ok, np.diff(floods.starts), 1)
            at = _spans(floods.starts[:-1], counts)
            members = floods.members if len(floods.members) else np.zeros(1, np.int32)
            zones = np.where(np.repeat(ok, counts), members[np.minimum(at, len(members) - 1)], 0)
            starts = (np.cumsum(counts) - counts).astype(np.int64)
            hit = self._reach[(s, e)] = _Reach(ok, zones.astype(np.int32), starts)
        return hit

    def _faces_under(self, zones: np.ndarray, s: int, e: int) -> list[int]:
        """The faces on s whose zone along d (from s to e) is one of ``zones``, sorted."""
        beyond = self._beyond[(s, e)]
        valid = beyond >= 0
        return self.faces_on[s][valid & zones[np.where(valid, beyond, 0)]].tolist()

    @cached_property
    def _face_frames(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """What `_crossings` reads of every face, whatever the direction: (F,) bool planar,
        (F, 3) its normal (0 where curved), (F,) bool on a side-wall surface, (F, 3) that
        surface's axis. Made once: per plane pair they were most of `_crossings`' time."""
        g = self.graph
        planar = np.isfinite(g.face_normal[:, 0])
        surface = g.face_surface
        wall = (surface >= 0) & np.isin(g.surface_kind[np.maximum(surface, 0)], SIDE_WALL_KINDS)
        normals = np.where(planar[:, None], g.face_normal, 0.0)
        return planar, normals, wall, np.ascontiguousarray(g.surface_axis[np.maximum(surface, 0), 3:])

    def _crossings(self, d: np.ndarray, length: float) -> tuple[np.ndarray, np.ndarray]:
        """For every face, whether a sweep along d (of ``length``) goes on through it out of its
        first zone, and out of its second (kept per plane pair by `_slab`): a planar face
        when it faces along d (a cap); a curved face unless it lies on a cylinder or extrusion
        along d (a side wall); never a face inside one zone (the sweep is on both of its sides
        already). Classifying all faces at once replaced a per-face test that was half a sweep's
        cost on graphs of thousands of zones."""
        planar, normals, wall, axes = self._face_frames
        along = normals @ d  # face normals point a -> b
        curved = ~wall | (1 - np.abs(axes @ d) / length >= PARALLEL_TOL)
        from_a = np.where(planar, along > PARALLEL_TOL * length, curved) & ~self.internal
        from_b = np.where(planar, -along > PARALLEL_TOL * length, curved) & ~self.internal
        return from_a, from_b

    # ------------------------------------------------------------------------ proposals

    def sketches(self, faces: np.ndarray, s: int) -> list[tuple[int, ...]]:
        """Candidate sketches from one group of faces on plane s (components, their unions)."""
        comps = self._components(np.isin(self.faces_on[s], faces), s)
        return [tuple(sorted(f for c in combo for f in comps[c])) for combo in self._combos(len(comps))]

    def _combos(self, n: int) -> list[tuple[int, ...]]:
        """The components a sketch takes, of n: any 1..level of them or all but 0..level, by size."""
        if not n:
            return []
        sizes = set(range(1, min(self.level, n) + 1)) | set(range(max(n - self.level, 1), n + 1))
        return [combo for size in sorted(sizes) for combo in itertools.combinations(range(n), size)]

    def _components(self, mask: np.ndarray, s: int) -> list[list[int]]:
        """Edge-connected components of the faces ``mask`` selects of plane s's faces, each
        sorted, ordered by first face.

        A union-find over the group's own links (found with one mask over the plane's): this runs
        for every new group of every state, and building a sparse matrix per call cost more than
        the rest of an expansion."""
        la, lb = self._local_links[s]
        keep = mask[la] & mask[lb]
        members = np.flatnonzero(mask).tolist()
        parent = {i: i for i in members}

        def root(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for a, b in zip(la[keep].tolist(), lb[keep].tolist(), strict=True):
            parent[root(a)] = root(b)
        comps: dict[int, list[int]] = {}
        for i in members:  # ascending: each component's faces come out sorted
            comps.setdefault(root(i), []).append(i)
        faces = self.faces_on[s]
        return sorted(faces[c].tolist() for c in comps.values())

    def _components_memo(self, mask: np.ndarray, s: int) -> list[list[int]]:
        """`_components`, kept per (plane, group) while recent: a group on s recurs with every
        plane parallel to s as its end."""
        key = (s, mask.tobytes())
        comps = self._comps.get(key)
        if comps is None:
            comps = self._comps[key] = self._components(mask, s)
        return comps

    def _component_sweep(self, faces: list[int], s: int, e: int) -> _Swept | None:
        """The zones a component's faces sweep from s to e and the faces on s its shared sweeps
        stand on, or None when a face's prism is not filled: what `extrusion` finds for any
        sketch holding the component, computed once for all of them (and kept while recent: one
        component recurs in the groups of many canvases)."""
        key = (s, e, tuple(faces))
        if key in self._swept_comps:
            return self._swept_comps[key]
        swept = self._swept_comps[key] = self._sweep_faces(faces, s, e)
        return swept

    def _sweep_faces(self, faces: list[int], s: int, e: int) -> _Swept | None:
        """The faces' sweeps joined (the zones, and the faces on s their shared sweeps stand on),
        or None when a face's prism is not filled: a component's, or a whole sketch's."""
        floods = self._floods_of(s, e)
        at = np.searchsorted(self.faces_on[s], faces)
        fills = floods.fills[at]
        if not fills.all():
            return None
        volume = np.zeros(self.graph.n_zones, bool)
        volume[floods.members[_spans(floods.starts[at], floods.starts[at + 1] - floods.starts[at])]] = True
        needs: set[int] = set()
        for i in np.flatnonzero(fills == SHARED).tolist():
            swept = self.sweep(faces[i], s, e)
            assert swept is not None
            needs.update(swept.faces)
        return volume, needs

    def extrusion(self, faces: tuple[int, ...], s: int, e: int) -> np.ndarray | None:
        """The zones of the sketch ``faces`` extruded from s to e, or None when a face's prism is
        not filled exactly or stands on zones that faces outside the sketch stand on too."""
        swept = self._sweep_faces(list(faces), s, e)
        if swept is None:
            return None
        volume, needs = swept
        return volume if needs.issubset(faces) else None

    def _candidates(
        self, s: int, e: int, mask: np.ndarray, deadline: Deadline | None = None
    ) -> _Candidates | None:
        """The sketches of the faces ``mask`` selects on plane s, swept to e (memoised), or None
        when ``deadline`` passes first (an unfinished group is not memoised).

        A group's candidates depend only on which faces are in it, not on the rest of the
        canvas, and the same groups recur across the canvases of a search and of random
        completions: generating them once per group is what makes an expansion cheap."""
        key = (s, e, mask.tobytes())
        hit = self._groups.get(key)
        if hit is not None:
            return hit
        comps = self._components_memo(mask, s)
        parts: list[_Swept | None] = []
        for comp in comps:
            if deadline is not None and deadline.passed():
                return None
            parts.append(self._component_sweep(comp, s, e))
        volumes, union, subtract = [], [], []
        for combo in self._combos(len(comps)):
            swept = [part for part in (parts[c] for c in combo) if part is not None]
            if len(swept) < len(combo):
                continue  # a face's prism is not filled
            faces = comps[combo[0]] if len(combo) == 1 else sorted(f for c in combo for f in comps[c])
            sketch = tuple(faces)
            needed = set().union(*(needs for _, needs in swept))
            if needed and not needed.issubset(sketch):
                continue  # a shared sweep stands on faces outside the sketch
            volume = swept[0][0] if len(swept) == 1 else np.logical_or.reduce([v for v, _ in swept])
            if not volume.any():
                continue
            volumes.append(volume)
            union.append(Proposal(s, e, sketch, volume, Op.UNION))
            subtract.append(Proposal(s, e, sketch, volume, Op.SUBTRACT))
        matrix = np.array(volumes, bool).reshape(len(volumes), self.graph.n_zones)
        hit = _Candidates(matrix, tuple(union), tuple(subtract))
        self._groups[key] = hit
        return hit

    def proposals(self, canvas: np.ndarray, deadline: Deadline | None = None) -> list[Proposal]:
        """Every distinct (volume, operation) reachable from ``canvas`` by one extrusion; once
        ``deadline`` passes, those of the face groups finished by then (a search stops anyway).

        Shapes:
            canvas: (Z,) bool. A union is proposed when the volume has zones outside the canvas,
            a subtraction when it has zones inside it, so no proposal leaves the canvas unchanged.
        """
        in_c = canvas[self._flat_zone] & self._flat_valid  # every pair's faces at once
        groups = (
            in_c & ~self._flat_in_t,
            self._flat_in_t & ~in_c,
            self._flat_valid & (self._flat_in_t | ~in_c),
        )
        counts = [np.concatenate(([0], np.cumsum(g))) for g in groups]
        filled = [c[self._ends] > c[self._starts] for c in counts]  # a group has faces on the pair
        found: list[_Candidates] = []
        masks = [
            (i, [mask[self._starts[i] : self._ends[i]] for g, mask in enumerate(groups) if filled[g][i]])
            for i in np.flatnonzero(filled[0] | filled[1] | filled[2]).tolist()
        ]
        if not self._extend(found, masks, deadline):
            return self._distinct(found, canvas) if found else []
        # Groups 4 and 5 after every pair's groups 1-3: their sweeps are the costly part of a first
        # expansion, and a deadline that passes during them leaves the proposals of groups 1-3.
        nothing = np.zeros_like(canvas)
        needs = ((canvas & ~self.target, canvas & self.target), (self.target & ~canvas, nothing))
        every = self._every_reach()
        if every is None:
            self._reach_pair_by_pair(found, groups[1], needs, deadline)
            return self._distinct(found, canvas) if found else []
        cuts, joins = every.meets(*needs[0]), every.meets(*needs[1])
        cut_any, join_any = self._any_per_pair(cuts), self._any_per_pair(joins)
        for i in np.flatnonzero(cut_any | join_any).tolist():
            span = slice(self._starts[i], self._ends[i])
            extra = [cuts[span]] if cut_any[i] else []
            extra += [joins[span] | groups[1][span]] if join_any[i] else []
            if not self._extend(found, [(i, extra)], deadline):
                break
        return self._distinct(found, canvas) if found else []

    def _reach_pair_by_pair(
        self,
        found: list[_Candidates],
        joined: np.ndarray,
        needs: tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
        deadline: Deadline | None,
    ) -> None:
        """Groups 4 and 5 while some pair's sweeps are still to be made (a graph's first
        expansions): each pair's reach made, under ``deadline``, as the pair's turn comes."""
        for i, (s, e) in enumerate(self.pairs):
            reach = self._reach_of(s, e, deadline)
            if reach is None:
                return
            cut, join = reach.meets(*needs[0]), reach.meets(*needs[1])
            extra = [cut] if cut.any() else []
            extra += [join | joined[self._starts[i] : self._ends[i]]] if join.any() else []
            if not self._extend(found, [(i, extra)], deadline):
                return

    def _every_reach(self) -> _Reach | None:
        """Every pair's reach in one, its faces laid out as the pairs' flattened faces, once all
        are made (else None): testing a canvas on all pairs at once, where a test per pair was a
        fifth of an expansion's time on graphs of hundreds of zones."""
        if self._all_reach is None and len(self._reach) == len(self.pairs):
            empty = _Reach(np.zeros(0, bool), np.zeros(0, np.int32), np.zeros(0, np.int64))
            reaches = [empty] + [self._reach[pair] for pair in self.pairs]
            offsets = np.cumsum([len(r.zones) for r in reaches])  # where each pair's zones begin
            starts = [empty.starts] + [r.starts + o for r, o in zip(reaches[1:], offsets, strict=False)]
            self._all_reach = _Reach(
                np.concatenate([r.ok for r in reaches]),
                np.concatenate([r.zones for r in reaches]),
                np.concatenate(starts),
            )
        return self._all_reach

    def _any_per_pair(self, flags: np.ndarray) -> np.ndarray:
        """(pairs,) bool: whether any of a pair's faces is set in ``flags`` (the flattened faces)."""
        out = np.zeros(len(self.pairs), bool)
        if self._faced.any():
            out[self._faced] = np.logical_or.reduceat(flags, self._starts[self._faced])
        return out

    def _extend(
        self, found: list[_Candidates], masks: list[tuple[int, list[np.ndarray]]], deadline: Deadline | None
    ) -> bool:
        """Append to ``found`` the candidates of each (pair index, face masks on its start plane)
        that have any; False when ``deadline`` passed first."""
        for i, pair_masks in masks:
            s, e = self.pairs[i]
            for mask in pair_masks:
                cand = self._candidates(s, e, mask, deadline)
                if cand is None:
                    return False
                if cand.union:
                    found.append(cand)
        return True

    @staticmethod
    def _distinct(found: list[_Candidates], canvas: np.ndarray) -> list[Proposal]:
        """The proposals of ``found`` that change ``canvas``, the first of each key, in order.

        All candidates at once: a union must add a zone, a subtraction remove one; duplicates
        (the same volume from another sketch or plane pair) are dropped by their packed key."""
        volumes = np.concatenate([c.volumes for c in found])
        adds = (volumes & ~canvas).any(axis=1)
        removes = (volumes & canvas).any(axis=1)
        valid = np.stack([adds, removes], axis=1).ravel()
        keys = np.concatenate([c.rows[0] for c in found])[valid]
        props = [p for c in found for p in c.rows[1]]
        index = np.flatnonzero(valid)
        rows = np.ascontiguousarray(keys).view(np.dtype((np.void, keys.shape[1]))).ravel()
        _, first = np.unique(rows, return_index=True)
        return [props[index[i]] for i in np.sort(first)]
