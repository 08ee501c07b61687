"""Bridges between the scripts' build123d/OCP and ours: the scripts target build123d 0.10.

``EllipticalCenterArc``'s old positional form is mapped onto the 0.13 signature, ``make_face`` on
the curves of a slit profile builds the region Fusion meant (`.faces`), and the OCP 8 array
classes are aliased under their old names.
"""

from __future__ import annotations

import inspect
import types
from typing import Any

from zonegraph.data.b123d.faces import NotAProfile, slit_profile_faces


def install_ocp_shims() -> None:
    """Make the scripts' pre-OCP-8 array imports resolve to their ``OCP.collections`` successors."""
    import OCP.TColgp
    import OCP.TColStd
    from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int

    for module, name, cls in (
        (OCP.TColStd, "TColStd_Array1OfReal", Array1_double),
        (OCP.TColStd, "TColStd_Array1OfInteger", Array1_int),
        (OCP.TColgp, "TColgp_Array1OfPnt", Array1_gp_Pnt),
    ):
        if not hasattr(module, name):
            setattr(module, name, cls)


def install_api_shims(module: types.ModuleType) -> None:
    """Bridge build123d API changes the scripts predate (they were written for build123d 0.9/0.10).

    ``EllipticalCenterArc(center, rx, ry, start_angle, end_angle, rotation, angular_direction)``
    became ``EllipticalCenterArc(center, rx, ry, start_angle, *, arc_size, rotation)`` (0.13), so
    the old positional form raises. The shim maps the old arguments onto the new signature; the
    result is checked like everything else (replay vs script, script vs Fusion's volume and area).
    """
    _install_make_face_shim(module)
    original = getattr(module, "EllipticalCenterArc", None)
    if original is None or "end_angle" in inspect.signature(original).parameters:
        return

    def elliptical_center_arc(
        center: Any,
        x_radius: float,
        y_radius: float,
        start_angle: float = 0.0,
        end_angle: float | None = None,
        rotation: float = 0.0,
        angular_direction: Any = None,
        **kwargs: Any,
    ) -> Any:
        if end_angle is None:  # new-style call
            return original(center, x_radius, y_radius, start_angle, rotation=rotation, **kwargs)
        clockwise = getattr(angular_direction, "name", "") == "CLOCKWISE"
        sweep = (start_angle - end_angle) % 360 if clockwise else (end_angle - start_angle) % 360
        sweep = sweep or 360.0
        return original(
            center,
            x_radius,
            y_radius,
            start_angle,
            arc_size=-sweep if clockwise else sweep,
            rotation=rotation,
            **kwargs,
        )

    module.EllipticalCenterArc = elliptical_center_arc  # type: ignore[attr-defined]


CLOSED_WIRES = "Face can only be created with closed wires"


def _install_make_face_shim(module: types.ModuleType) -> None:
    """``make_face`` that, where 0.13 refuses the open wire of a slit profile, builds its region.

    Only that refusal is caught, so every face 0.13 builds itself stays as it was; the region is
    checked like everything else (replay vs script, script vs Fusion's volume and area).
    """
    original = getattr(module, "make_face", None)
    if original is None or getattr(original, "_zonegraph_shim", False):
        return

    def make_face(edges: Any = None, mode: Any = None) -> Any:
        from build123d import Mode

        mode = Mode.ADD if mode is None else mode
        try:
            return original(edges, mode=mode)
        except ValueError as exc:
            if str(exc) != CLOSED_WIRES:
                raise
            return _slit_make_face(edges, mode, exc)

    make_face._zonegraph_shim = True  # type: ignore[attr-defined]
    module.make_face = make_face  # type: ignore[attr-defined]


def _slit_make_face(edges: Any, mode: Any, refusal: ValueError) -> Any:
    """build123d's ``make_face`` steps with `slit_profile_faces` as the face (the refusal
    re-raised where the edges are not a slit profile either)."""
    from build123d import BuildSketch, Compound, Curve, ShapeList, Sketch, Wire
    from build123d.build_common import flatten_sequence

    context = BuildSketch._get_context("make_face", log=False)
    if edges is not None:
        items = flatten_sequence(edges)
        outer = [e for it in items for e in (it.edges() if isinstance(it, (Wire, Curve)) else [it])]
    else:
        outer = list(context.pending_edges) if context is not None else []
    try:
        faces = slit_profile_faces(outer)
    except NotAProfile:
        raise refusal from None
    faces = [-f if f.normal_at().Z < 0 else f for f in faces]  # flip up-side-down faces, as make_face does
    if context is not None:
        context._add_to_context(*faces, mode=mode)
        context.pending_edges = ShapeList()
    return Sketch(Compound(faces).wrapped)
