"""zonegraph: recover editable sketch + extrude programs from B-rep solids with zone graphs.

Fusion 360 Gallery replay (``design``, ``profiles``, ``replay``), zone graphs (``partition``,
``zone_graph``, ``zone_io``), search (``proposals``, ``search``, ``program``) and export
(``export``, ``infer``). Geometry goes through build123d and OCP; there is no torch import here.
"""

__version__ = "0.1.0"
