"""Zone graphs on disk: Parquet tables plus one BREP file with the zone solids.

``zones.parquet`` (per zone; the graph's metadata rides in its schema), ``faces.parquet``
(partition faces: the zones on each side, area, normal, surface), ``links.parquet`` (faces sharing
an edge on one surface), ``surfaces.parquet`` (extended surfaces and each plane's zone sides),
``samples.parquet`` (surface samples, float16: they are network inputs, not geometry) and
``zones.brep`` (the zone solids in zone order, sharing their faces).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from numpy.typing import DTypeLike
from OCP.BRep import BRep_Builder
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_SOLID
from OCP.TopoDS import TopoDS, TopoDS_Shape

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.errors import InputError
from zonegraph.geometry.normalize import Normalization
from zonegraph.geometry.occ import make_compound, sub_shapes
from zonegraph.zones.model import ZoneGraph

META_KEY = b"zonegraph"

# Sliver zones and faces of the fuse measure slightly below zero: the kernel's round-off, not a
# corrupt file. Seen from 1e-16 to 1e-11 (normalised units) on a 627-zone corpus part, and on 24
# of the whole corpus's graphs down to -1.0e-5 of the box's volume (a 2,589-zone part) and -1.4e-8
# of its squared diagonal for a face; the build's checks accept them and so must the load.
ROUND_OFF = 1e-4  # share of the box's volume (zones) or its squared diagonal (faces)


def _arrow(values: np.ndarray | list[str]) -> pa.Array:
    """A column as an Arrow array built from its buffers. ``pa.array`` and ``pa.table`` on numpy
    arrays first import pandas, to ask whether they were given a Series: 0.3 CPU s (profiled in
    one ``zonegraph build``) in a process that never uses it."""
    arr = np.ascontiguousarray(values)
    if arr.dtype.kind in "US":
        encoded = [str(v).encode() for v in arr]
        offsets = np.cumsum([0] + [len(e) for e in encoded], dtype=np.int32)
        return pa.Array.from_buffers(
            pa.string(), len(arr), [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded))]
        )
    if arr.dtype == bool:
        bits = np.packbits(arr, bitorder="little")
        return pa.Array.from_buffers(pa.bool_(), len(arr), [None, pa.py_buffer(bits)])
    return pa.Array.from_buffers(pa.from_numpy_dtype(arr.dtype), len(arr), [None, pa.py_buffer(arr)])


def _fixed(arr: np.ndarray, dtype: DTypeLike | None = None) -> pa.Array:
    """One fixed-width list per row; rows of width 0 (a graph built without surface samples)
    become empty lists, which Arrow's fixed-size lists cannot hold."""
    arr = np.asarray(arr, dtype=dtype)
    width = int(np.prod(arr.shape[1:])) if arr.ndim > 1 else 1
    if width == 0:
        offsets = _arrow(np.zeros(len(arr) + 1, np.int32))
        return pa.ListArray.from_arrays(offsets, _arrow(np.zeros(0, arr.dtype)))
    return pa.FixedSizeListArray.from_arrays(_arrow(arr.reshape(-1)), width)


def _table(columns: dict[str, np.ndarray | pa.Array]) -> pa.Table:
    return pa.table({k: v if isinstance(v, pa.Array) else _arrow(v) for k, v in columns.items()})


def _unfixed(column: pa.ChunkedArray, shape: tuple[int, ...], dtype: DTypeLike = float) -> np.ndarray:
    flat = column.combine_chunks().flatten().to_numpy(zero_copy_only=False)
    return flat.astype(dtype).reshape((len(column),) + shape)


def save_zone_graph(graph: ZoneGraph, folder: str | Path) -> Path:
    """Write a graph as Parquet tables plus ``zones.brep`` (see the module docstring); returns
    the folder."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    meta = {
        "center": graph.normalization.center,
        "scale": graph.normalization.scale,
        "box": graph.box.tolist(),
        "target_volume": graph.target_volume,
        "info": graph.info,
        "samples": int(graph.zone_points.shape[1]),
    }
    zones = _table(
        {
            "volume": graph.zone_volume,
            "centroid": _fixed(graph.zone_centroid),
            "bbox": _fixed(graph.zone_bbox),
            "interior": _fixed(graph.zone_interior),
            "inside": graph.zone_inside,
        }
    ).replace_schema_metadata({META_KEY: json.dumps(meta)})
    pq.write_table(zones, folder / "zones.parquet")
    pq.write_table(
        _table(
            {
                "zone_a": graph.face_zones[:, 0],
                "zone_b": graph.face_zones[:, 1],
                "area": graph.face_area,
                "centroid": _fixed(graph.face_centroid),
                "normal": _fixed(graph.face_normal),
                "surface": graph.face_surface,
            }
        ),
        folder / "faces.parquet",
    )
    pq.write_table(
        _table({"face_a": graph.face_links[:, 0], "face_b": graph.face_links[:, 1]}),
        folder / "links.parquet",
    )
    pq.write_table(
        _table(
            {
                "kind": _arrow(list(graph.surface_kind)),
                "normal": _fixed(graph.surface_normal),
                "offset": graph.surface_offset,
                "axis": _fixed(graph.surface_axis),
                "radius": graph.surface_radius,
                "on_box": graph.surface_on_box,
                "strip": graph.surface_strip,
                "plane_side": _fixed(graph.plane_side.reshape(graph.n_surfaces, -1), np.int8),
            }
        ),
        folder / "surfaces.parquet",
    )
    pq.write_table(
        _table(
            {
                "points": _fixed(graph.zone_points, np.float16),
                "normals": _fixed(graph.zone_normals, np.float16),
            }
        ),
        folder / "samples.parquet",
        compression="zstd",
    )
    if graph.solids is not None:
        BRepTools.Write_s(make_compound(graph.solids), str(folder / "zones.brep"))
    return folder


def saved_zone_count(folder: str | Path) -> int:
    """The zones of a graph saved by `save_zone_graph`, from its Parquet footer (nothing else is
    read: benchmarks and data summaries size thousands of graphs this way)."""
    return int(pq.ParquetFile(Path(folder) / "zones.parquet").metadata.num_rows)


def load_zone_graph(folder: str | Path, solids: bool = True) -> ZoneGraph:
    """Read a saved graph back, equal to the one saved.

    Args:
        folder: written by `save_zone_graph`.
        solids: also read the zone solids (``zones.brep``); skip them for array-only work.

    Raises:
        InputError: no graph in the folder, or one whose files are unreadable or inconsistent
            (garbled or truncated bytes are bad input, never read as numbers).
    """
    folder = Path(folder)
    if not (folder / "zones.parquet").is_file():
        raise InputError(str(folder), "no zone graph here (zones.parquet missing)")
    try:
        graph = _read(folder, solids)
    except (OSError, ValueError, KeyError, TypeError, IndexError, pa.ArrowException) as exc:
        raise InputError(str(folder), f"corrupt zone graph ({type(exc).__name__}: {_one_line(exc)})") from exc
    problem = _inconsistency(graph)
    if problem:
        raise InputError(str(folder), f"corrupt zone graph: {problem}")
    return graph


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:200] or "no message"


def _inconsistency(graph: ZoneGraph) -> str | None:
    """What in a read graph cannot come from `save_zone_graph`, or None: non-finite or
    negative measures (normals and offsets are NaN off planes), indices out of range, a zone
    solid per zone missing."""
    measures = {  # always finite
        "zone volumes": graph.zone_volume,
        "zone centroids": graph.zone_centroid,
        "zone boxes": graph.zone_bbox,
        "face areas": graph.face_area,
        "face centroids": graph.face_centroid,
    }
    planar = {  # NaN where the face or surface is not a plane
        "face normals": graph.face_normal,
        "surface offsets": graph.surface_offset,
        "surface normals": graph.surface_normal,
    }
    for name, values in measures.items():
        if not np.isfinite(values).all() or (np.abs(values) > 1e6).any():
            return f"{name} not finite or out of range"
    for name, values in planar.items():
        if np.isinf(values).any() or (np.abs(np.nan_to_num(values)) > 1e6).any():
            return f"{name} out of range"
    scale = float(np.sum((graph.box[3:] - graph.box[:3]) ** 2))
    if (graph.zone_volume < -ROUND_OFF * graph.box_volume).any() or (
        graph.face_area < -ROUND_OFF * scale
    ).any():
        return "negative zone volume or face area"
    n_zones, n_faces, n_surfaces = graph.n_zones, len(graph.face_area), len(graph.surface_offset)
    if graph.face_zones.size and (graph.face_zones.min() < -1 or graph.face_zones.max() >= n_zones):
        return "a face names a zone that does not exist"
    if graph.face_surface.size and (graph.face_surface.min() < 0 or graph.face_surface.max() >= n_surfaces):
        return "a face names a surface that does not exist"
    if graph.face_links.size and (graph.face_links.min() < 0 or graph.face_links.max() >= n_faces):
        return "a link names a face that does not exist"
    if not np.isin(graph.plane_side, (-1, 0, 1)).all():
        return "plane sides other than -1, 0, 1"
    if len(graph.zone_points) != n_zones:
        return f"{len(graph.zone_points)} sample rows for {n_zones} zones"
    if graph.solids is not None and len(graph.solids) != n_zones:
        return f"zones.brep holds {len(graph.solids)} solids for {n_zones} zones (truncated?)"
    return None


def _read(folder: Path, solids: bool) -> ZoneGraph:
    zones = pq.read_table(folder / "zones.parquet")
    meta = json.loads(zones.schema.metadata[META_KEY])
    faces = pq.read_table(folder / "faces.parquet")
    links = pq.read_table(folder / "links.parquet")
    surfaces = pq.read_table(folder / "surfaces.parquet")
    samples = pq.read_table(folder / "samples.parquet")
    n_zones, n_samples = zones.num_rows, meta["samples"]
    return ZoneGraph(
        normalization=Normalization(tuple(meta["center"]), meta["scale"]),
        box=np.array(meta["box"]),
        target_volume=meta["target_volume"],
        zone_volume=zones["volume"].to_numpy(),
        zone_centroid=_unfixed(zones["centroid"], (3,)),
        zone_bbox=_unfixed(zones["bbox"], (6,)),
        zone_interior=_unfixed(zones["interior"], (3,)),
        zone_inside=zones["inside"].to_numpy(zero_copy_only=False),
        zone_points=_unfixed(samples["points"], (n_samples, 3), np.float32),
        zone_normals=_unfixed(samples["normals"], (n_samples, 3), np.float32),
        face_zones=np.stack([faces["zone_a"].to_numpy(), faces["zone_b"].to_numpy()], axis=1).astype(
            np.int32
        ),
        face_area=faces["area"].to_numpy(),
        face_centroid=_unfixed(faces["centroid"], (3,)),
        face_normal=_unfixed(faces["normal"], (3,)),
        face_surface=faces["surface"].to_numpy().astype(np.int32),
        face_links=np.stack([links["face_a"].to_numpy(), links["face_b"].to_numpy()], axis=1).astype(
            np.int32
        ),
        surface_kind=np.array(surfaces["kind"].to_pylist(), dtype=object),
        surface_normal=_unfixed(surfaces["normal"], (3,)),
        surface_offset=surfaces["offset"].to_numpy(),
        surface_axis=_unfixed(surfaces["axis"], (6,)),
        surface_radius=surfaces["radius"].to_numpy(),
        surface_on_box=surfaces["on_box"].to_numpy(zero_copy_only=False),
        surface_strip=surfaces["strip"].to_numpy(zero_copy_only=False),
        plane_side=_unfixed(surfaces["plane_side"], (n_zones,), np.int8),
        solids=_read_solids(folder / "zones.brep") if solids else None,
        info=meta["info"],
    )


def _read_solids(path: Path) -> list[TopoDS_Shape] | None:
    if not path.is_file():
        return None
    shape = TopoDS_Shape()
    if not BRepTools.Read_s(shape, str(path), BRep_Builder()) or shape.IsNull():
        raise ValueError(f"{path.name} is not a readable BREP file")
    return [TopoDS.Solid(s) for s in sub_shapes(shape, TopAbs_SOLID)]
