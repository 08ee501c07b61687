"""Bridges between the scripts' build123d/OCP and ours: the scripts target build123d 0.10.

``EllipticalCenterArc``'s old positional form is mapped onto the 0.13 signature, and the OCP 8
array classes are aliased under their old names.
"""

from __future__ import annotations

import inspect
import types
from typing import Any


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
