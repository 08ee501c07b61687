"""A PNG strip of a modeling sequence: grey is the shape so far, green a union, red a subtraction;
an inferred program's strip ends on its final shape, so the result is seen without the tools."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from build123d import Compound, Shape  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from OCP.BRepMesh import BRepMesh_IncrementalMesh  # noqa: E402
from OCP.TopAbs import TopAbs_FACE  # noqa: E402
from OCP.TopoDS import TopoDS_Shape  # noqa: E402

import zonegraph.geometry.kernel  # noqa: F401 - OCCT's thread pool held before any Boolean
from zonegraph.geometry.occ import face_triangles, sub_shapes  # noqa: E402
from zonegraph.sequence.program import ProgramStep  # noqa: E402
from zonegraph.sequence.proposals import Op  # noqa: E402
from zonegraph.zones.model import ZoneGraph  # noqa: E402

LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
INSIDE, OUTSIDE = (0.25, 0.45, 0.85), (0.75, 0.75, 0.75)
COLOURS = {"shape": (0.6, 0.6, 0.6), Op.UNION: (0.2, 0.7, 0.3), Op.SUBTRACT: (0.85, 0.2, 0.2)}


def _triangles(shape: Shape | TopoDS_Shape, tolerance: float) -> np.ndarray:
    """Triangle corners (T, 3, 3); faces that fail to mesh are left out rather than failing."""
    wrapped = shape.wrapped if isinstance(shape, Shape) else shape
    BRepMesh_IncrementalMesh(wrapped, tolerance, False, 0.5, False)
    corners = [
        nodes[tris]
        for nodes, tris in (face_triangles(f) for f in sub_shapes(wrapped, TopAbs_FACE))
        if len(tris)
    ]
    return np.concatenate(corners) if corners else np.zeros((0, 3, 3))


def _draw(ax: Any, tris: np.ndarray, colour: Sequence[float], alpha: float) -> None:
    if not len(tris):
        return
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    shade = 0.45 + 0.55 * np.abs(n @ LIGHT)
    ax.add_collection3d(
        Poly3DCollection(
            tris, facecolors=np.clip(np.outer(shade, colour), 0, 1), edgecolor="none", alpha=alpha
        )
    )


@dataclass(frozen=True)
class StripStep:
    """One panel of a strip: the shape before the step (grey), the step's tool and whether it cuts
    (no tool: a panel of the shape alone, drawn opaque)."""

    before: Shape | None
    tool: Shape | None
    subtract: bool
    title: str


def _bounds(rows: Sequence[Sequence[StripStep]]) -> tuple[np.ndarray, np.ndarray]:
    shapes = [s for row in rows for step in row for s in (step.before, step.tool) if s is not None]
    boxes = [s.bounding_box() for s in shapes]
    return np.min([tuple(b.min) for b in boxes], axis=0), np.max([tuple(b.max) for b in boxes], axis=0)


def render_strips(rows: dict[str, Sequence[StripStep]], path: Path) -> Path:
    """One row of panels per named sequence, all at one scale so that rows compare side by side."""
    rows = {name: row for name, row in rows.items() if row}
    lo, hi = _bounds(list(rows.values()))
    tol = 2e-3 * float(np.linalg.norm(hi - lo))
    centre, half = (lo + hi) / 2, float((hi - lo).max()) / 2
    width = max(len(row) for row in rows.values())
    fig = plt.figure(figsize=(2.8 * width + 0.6, 3.0 * len(rows)))
    for r, (name, row) in enumerate(rows.items()):
        for i, step in enumerate(row):
            ax = fig.add_subplot(len(rows), width, r * width + i + 1, projection="3d")
            if step.before is not None:
                _draw(ax, _triangles(step.before, tol), COLOURS["shape"], 0.35 if step.tool else 0.9)
            if step.tool is not None:
                _draw(
                    ax, _triangles(step.tool, tol), COLOURS[Op.SUBTRACT if step.subtract else Op.UNION], 0.8
                )
            for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=False):
                setter(c - half, c + half)
            ax.set_axis_off()
            ax.set_title(f"{name} {step.title}" if i == 0 and len(rows) > 1 else step.title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def render_sequence(program: list[ProgramStep], states: Sequence[Shape | None], path: Path) -> Path:
    """The strip of one inferred program: panel i shows the shape after step i - 1 and step i's tool;
    a last panel the final shape."""
    steps = [
        StripStep(
            states[i - 1] if i > 0 else None,
            step.tool(),
            step.op is Op.SUBTRACT,
            f"{i + 1}: {'union' if step.op is Op.UNION else 'subtract'} {step.distance:.3g}",
        )
        for i, step in enumerate(program)
    ]
    if states and states[-1] is not None:
        steps.append(StripStep(states[-1], None, False, "final shape"))
    return render_strips({"": steps}, path)


def _diagonal(shape: Shape) -> float:
    box = shape.bounding_box()
    return float(np.linalg.norm(np.subtract(tuple(box.max), tuple(box.min))))


def _fit(ax: Any, tris: list[np.ndarray]) -> None:
    """Equal-aspect limits around the drawn triangles."""
    pts = np.concatenate([x.reshape(-1, 3) for x in tris if len(x)])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, half = (lo + hi) / 2, float((hi - lo).max()) / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=False):
        setter(c - half, c + half)


def render_zone_graph(
    graph: ZoneGraph, path: Path, target: Shape | None = None, explode: float = 1.0
) -> Path:
    """The part (``target``, when given) beside its zones, each pushed out from the box centre
    (``explode`` times its offset), inside blue and outside translucent grey, so that the
    partition the search works on can be seen. The zones are in the graph's normalised frame.

    Raises:
        ValueError: the graph was loaded without its zone solids.
    """
    if graph.solids is None:
        raise ValueError("zone graph has no zone solids to draw")
    centre = (graph.box[:3] + graph.box[3:]) / 2
    zones = [_triangles(s, 2e-3) for s in graph.solids]  # 2e-3 of the unit box diagonal
    exploded = [tris + explode * (graph.zone_centroid[z] - centre) for z, tris in enumerate(zones)]
    if target is not None and not isinstance(target, Shape):
        target = Compound(list(target))
    panels = [("the part", [(_triangles(target, 2e-3 * _diagonal(target)), INSIDE, 0.9)])] if target else []
    panels.append(
        (
            f"{graph.n_zones} zones, exploded",
            [
                (
                    exploded[z],
                    INSIDE if graph.zone_inside[z] else OUTSIDE,
                    0.9 if graph.zone_inside[z] else 0.15,
                )
                for z in range(graph.n_zones)
            ],
        )
    )
    fig = plt.figure(figsize=(3.6 * len(panels), 3.4))
    for i, (title, drawn) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1, projection="3d")
        for tris, colour, alpha in drawn:
            _draw(ax, tris, colour, alpha)
        _fit(ax, [tris for tris, _, _ in drawn])
        ax.set_axis_off()
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
