"""Small corpus-style batch models for tests and benchmarks of ``zonegraph convert``.

A corpus batch (``../shared/data/fusion360_b123d``) is a Python file of ``model_<id>()`` functions
in build123d's builder API, one per design, each timeline feature under a ``# SketchN ->
ExtrudeN (Operation)`` comment. These write the same shape, so that a test can mix a good model
with hostile ones without the corpus present; each module's own header supplies the imports.
"""

from __future__ import annotations

__all__ = ["PLATE_AREA", "PLATE_VOLUME", "block_model", "plate_model"]

PLATE_VOLUME = 7.2146018366  # 4 x 2 x 1 less a cylinder of radius 0.5
PLATE_AREA = 29.5707963268


def _model(name: str, body: str) -> str:
    """``model_<name>()`` building ``body`` (its features, indented under ``BuildPart``)."""
    return f"\ndef model_{name}():\n    with BuildPart() as part:\n{body}    return part.part\n"


def plate_model(name: str) -> str:
    """``model_<name>()``: a 4 x 2 x 1 plate with a through hole (a new body and a cut)."""
    return _model(
        name,
        """        # Sketch1 -> Extrude1 (NewBody)
        with BuildSketch(Plane.XY):
            Rectangle(4, 2)
        extrude(amount=1)
        # Sketch2 -> Extrude2 (Cut)
        with BuildSketch(Plane(origin=(0, 0, 1), x_dir=(1, 0, 0), z_dir=(0, 0, 1))):
            Circle(0.5)
        extrude(amount=-1, mode=Mode.SUBTRACT)
""",
    )


def block_model(name: str) -> str:
    """``model_<name>()``: a 3 x 3 x 2 block (one new body)."""
    return _model(
        name,
        """        # Sketch1 -> Extrude1 (NewBody)
        with BuildSketch(Plane.XY):
            Rectangle(3, 3)
        extrude(amount=2)
""",
    )
