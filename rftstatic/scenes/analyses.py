"""The analysis types a scene may ask for, registered by name (the one list: the scene schema checks
``analysis`` against it, :mod:`rftstatic.app.registry` runs it).

Each entry names the module of :mod:`rftstatic.app` whose ``run(scene, out, *, progress, figures)``
returns a :class:`~rftstatic.app.result.RunResult`; it is imported only when a scene asks for it, so a
static drape does not pay for the explicit solver's or the mesher's imports.
"""

from __future__ import annotations

ANALYSES = {
    "static": "rftstatic.app.static",  # static drape: load-scaled Newton and/or relaxation + Newton
    "dynamic": "rftstatic.app.dynamic",  # explicit central differences with mass damping (§2.4, §4.6)
    "relax": "rftstatic.app.dynamic",  # dynamic relaxation to rest (§6)
    "remeshed": "rftstatic.app.remeshed",
    "garment": "rftstatic.app.garment",  # a garment pattern on a dress form (issue 37)
    "garment-motion": "rftstatic.app.garment_motion",  # the dressed form turned by keyframes (issue 37 item 4)
    "cantilever": "rftstatic.app.cantilever",  # Peirce's cantilever tester: the overhang at which the tip meets 41.5 deg  # a scene with [remesh]: global adaptive remeshing (§5-6)
}
"""Analysis name -> module that runs it."""

SCENE_ANALYSES = tuple(name for name in ANALYSES if name != "remeshed")
"""Values of a scene's ``analysis`` key (``remeshed`` is chosen by a ``[remesh]`` table)."""
