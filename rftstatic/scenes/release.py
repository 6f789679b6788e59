"""The support of the release route (``solver.start = "release"``, :mod:`rftstatic.solvers.release`).

The scene does not name it: for a static scene whose route is the release, :func:`release_support` makes a
support plane (:class:`~rftstatic.contact.obstacles.floor.Floor`) at its *rest pose*, below anything the sheet can
reach (the sheet's flat height minus :data:`REST_DEPTH` x the diagonal of its reference box: a sheet held anywhere
hangs no lower than that); the route raises it to the sheet at the start and lowers it back to that pose (its
translation is State, :attr:`rftstatic.model.state.State.obstacle_offsets`). At the rest pose it touches nothing,
so a model evaluated without the solve's State (the summary's contact numbers) sees no support. It is the contact
law's last obstacle and not one of the scene's ``[[obstacles]]`` (the drape's measures ignore it).
"""

from __future__ import annotations

import numpy as np

from rftstatic.contact.obstacles.floor import Floor
from rftstatic.scenes.options import static_options

REST_DEPTH = 1.1
"""The support's rest pose below the flat sheet, in diagonals of the sheet's reference box."""


def release_support(scene, mesh, law: str) -> list:
    """``[Floor]``: the release route's support at its rest pose [m] (module docstring) when ``scene`` is a static
    scene with ``solver.start = "release"`` and its contact is the penalty ``law``; else ``[]``."""
    if scene.analysis != "static" or law != "penalty":
        return []
    if static_options(scene, progress=False).route.start != "release":
        return []
    X = np.asarray(mesh.X3, float)
    diagonal = float(np.linalg.norm(np.ptp(X, axis=0)))
    return [Floor(height=float(X[:, 2].min()) - REST_DEPTH * diagonal)]
