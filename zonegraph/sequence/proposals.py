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
Sweeps are memoised per (face, s, e): the geometry never changes during search.
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
    """A plane pair's sweep direction and length, the planes' zone sides as lists, and which faces
    a sweep crosses out of their first and their second zone."""

    d: np.ndarray
    length: float
    side_s: int
    side_e: int
    on_s: list[int]
    on_e: list[int]
    from_a: list[bool]
    from_b: list[bool]


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
        self._zone_faces = self._faces_of_zones()
        self._sweeps: dict[tuple[int, int, int], Sweep | None] = {}
        self._face_zone_list = [tuple(pair) for pair in graph.face_zones.tolist()]
        self._face_surface_list = graph.face_surface.tolist()
        self._zone_face_lists = [faces.tolist() for faces in self._zone_faces]
        self._side_lists: dict[int, list[int]] = {}
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
        self._beyond = {(s, e): self._zones_beyond(s, e) for s, e in self.pairs}
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

    def _faces_of_zones(self) -> list[np.ndarray]:
        fz = self.graph.face_zones
        out: list[list[int]] = [[] for _ in range(self.graph.n_zones)]
        for f, (a, b) in enumerate(fz):
            out[a].append(f)
            if b >= 0:
                out[b].append(f)
        return [np.array(x, np.int64) for x in out]

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
        """The prism over ``face`` from s to e, or None if its zones do not fill it exactly."""
        key = (face, s, e)
        if key not in self._sweeps:
            self._sweeps[key] = self._sweep(face, s, e)
        return self._sweeps[key]

    def _slab(self, s: int, e: int) -> _Slab:
        """What every sweep from s to e shares (memoised per pair): a root expansion sweeps
        hundreds of faces per pair, and computing these per sweep was half of a small sweep's
        cost."""
        key = (s, e)
        slab = self._slabs.get(key)
        if slab is None:
            g = self.graph
            d = self.direction(s, e)
            side_s = 1 if float(g.surface_normal[s] @ d) > 0 else -1
            side_e = 1 if float(g.surface_normal[e] @ d) > 0 else -1
            length = float(np.linalg.norm(d))
            from_a, from_b = self._crossings(d, length)
            slab = self._slabs[key] = _Slab(
                d, length, side_s, side_e, self._sides(s), self._sides(e), from_a, from_b
            )
        return slab

    def _sweep(self, face: int, s: int, e: int) -> Sweep | None:
        g = self.graph
        slab = self._slab(s, e)
        a, b = self._face_zone_list[face]
        start = b if float(g.face_normal[face] @ slab.d) > 0 else a
        if start < 0:
            return None
        on_s, on_e, side_s, side_e = slab.on_s, slab.on_e, slab.side_s, -slab.side_e
        crossed_from_a, crossed_from_b = slab.from_a, slab.from_b
        face_zones, face_surface = self._face_zone_list, self._face_surface_list
        seen: set[int] = set()
        stack = [int(start)]
        while stack:
            z = stack.pop()
            if z in seen:
                continue
            if on_s[z] != side_s or on_e[z] != side_e:
                return None  # the zone reaches outside the slab between s and e
            seen.add(z)
            for f in self._zone_face_lists[z]:
                if face_surface[f] == e:
                    continue
                fa, fb = face_zones[f]
                from_first = fa == z
                if not (crossed_from_a[f] if from_first else crossed_from_b[f]):
                    continue
                other = fb if from_first else fa
                if other < 0:
                    return None
                stack.append(other)
        members = np.sort(np.fromiter(seen, np.int32, len(seen)))  # summed in the zones' order
        volume = float(g.zone_volume[members].sum())
        prism = g.face_area[face] * slab.length
        if abs(volume - prism) <= PRISM_RTOL * prism:
            return Sweep(members, (face,), g.n_zones)
        zones = np.zeros(g.n_zones, bool)
        zones[members] = True
        under = self._faces_under(zones, s, e)
        area = float(g.face_area[under].sum())
        if face not in under or abs(volume - area * slab.length) > PRISM_RTOL * area * slab.length:
            return None
        return Sweep(members, tuple(under), g.n_zones)

    def _reach_of(self, s: int, e: int, deadline: Deadline | None) -> _Reach | None:
        """The sweep of every face on s whose zone beyond it (towards e) lies outside the target,
        on the pair (s, e) (memoised), or None when ``deadline`` passes. Only those faces are
        swept: every face on every pair is most of a many-zone graph's setup, and a face next to
        a target zone needs none (groups 1-3 place it by that zone). The sweeps are kept as zone
        indices, not memoised as sweeps: a (Z,) array for every face of every pair of a
        many-zone graph is more memory than the graph."""
        hit = self._reach.get((s, e))
        if hit is None:
            beyond = self._beyond[(s, e)]
            outside = (beyond >= 0) & ~self.target[np.maximum(beyond, 0)]
            ok: list[bool] = []
            zones: list[int] = []
            starts: list[int] = []
            for face, swept_needed in zip(self.faces_on[s].tolist(), outside.tolist(), strict=True):
                if deadline is not None and deadline.passed():
                    return None
                swept = self._sweep(face, s, e) if swept_needed else None
                starts.append(len(zones))
                ok.append(swept is not None)
                zones.extend(swept.members.tolist() if swept is not None else [0])
            hit = self._reach[(s, e)] = _Reach(
                np.array(ok, bool), np.array(zones, np.int32), np.array(starts, np.int64)
            )
        return hit

    def _faces_under(self, zones: np.ndarray, s: int, e: int) -> list[int]:
        """The faces on s whose zone along d (from s to e) is one of ``zones``, sorted."""
        beyond = self._beyond[(s, e)]
        valid = beyond >= 0
        return self.faces_on[s][valid & zones[np.where(valid, beyond, 0)]].tolist()

    def _sides(self, plane: int) -> list[int]:
        """Each zone's side of a plane (``plane_side`` row) as a list: a sweep reads it zone by
        zone, and indexing a NumPy row one zone at a time dominated a sweep's cost."""
        if plane not in self._side_lists:
            self._side_lists[plane] = self.graph.plane_side[plane].tolist()
        return self._side_lists[plane]

    def _crossings(self, d: np.ndarray, length: float) -> tuple[list[bool], list[bool]]:
        """For every face, whether a sweep along d (of ``length``) goes on through it out of its
        first zone, and out of its second (kept per plane pair by `_slab`): a planar face
        when it faces along d (a cap); a curved face unless it lies on a cylinder or extrusion
        along d (a side wall); never a face inside one zone (the sweep is on both of its sides
        already). Classifying all faces at once replaced a per-face test that was half a sweep's
        cost on graphs of thousands of zones."""
        g = self.graph
        planar = np.isfinite(g.face_normal[:, 0])
        along = np.where(planar[:, None], g.face_normal, 0.0) @ d  # face normals point a -> b
        surface = g.face_surface
        wall = (surface >= 0) & np.isin(g.surface_kind[np.maximum(surface, 0)], SIDE_WALL_KINDS)
        axis = g.surface_axis[np.maximum(surface, 0), 3:] @ d
        curved = ~wall | (1 - np.abs(axis) / length >= PARALLEL_TOL)
        from_a = np.where(planar, along > PARALLEL_TOL * length, curved) & ~self.internal
        from_b = np.where(planar, -along > PARALLEL_TOL * length, curved) & ~self.internal
        return from_a.tolist(), from_b.tolist()

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
        volume = np.zeros(self.graph.n_zones, bool)
        needs: set[int] = set()
        for f in faces:
            swept = self.sweep(f, s, e)
            if swept is None:
                return None
            if len(swept.faces) > 1:
                needs.update(swept.faces)
            volume[swept.members] = True
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
            sketch = tuple(sorted(f for c in combo for f in comps[c]))
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
