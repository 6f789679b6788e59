"""Scene checks of obstacles given as triangle surfaces (:meth:`rftstatic.contact.obstacles.Obstacle.surface`).

* :func:`check_surface_obstacles`: a surface obstacle that already cuts through the flat sheet at the start is
  refused, naming where (the independent crossing test of
  :func:`rftstatic.post.measures.obstacle_crossings.obstacle_crossings`); touching is allowed within
  :data:`START_TOUCH` mean sheet edge lengths (sphere-mesh starts with the sheet on the icosphere's top vertex,
  a table top starts flush with the sheet). The explicit analyses (``dynamic``, ``relax``) run them too: their
  kinematic contact stops a node whose step crossed the surface (continuous collision detection,
  :mod:`rftstatic.contact.obstacles.surface_ccd`), so nothing is stepped through a thin shell.
"""

from __future__ import annotations

import numpy as np

__all__ = ["START_TOUCH", "check_surface_obstacles"]

START_TOUCH = 1e-6
"""Crossing tolerance of the start check, in mean sheet edge lengths: a sheet touching a surface obstacle
(within this) is not cutting it."""


def check_surface_obstacles(scene, mesh, obstacles, law: str) -> None:
    """Scene error for a surface obstacle cutting the flat sheet (module docstring); ``law`` (``"penalty"`` or
    ``"kinematic"``) is the contact law of the run."""
    from rftstatic.post.measures.obstacle_crossings import obstacle_crossings

    edge = float(np.mean(mesh.element_size))
    u = scene.units.length
    for i, ob in enumerate(obstacles):
        surface = ob.surface()
        if surface is None:
            continue
        V, T = surface
        r = obstacle_crossings(mesh.X3, mesh.tri, V, T, tol=START_TOUCH * edge, within=edge)
        phi = ob.signed_distance(mesh.X3)[0]
        inside = phi < -START_TOUCH * edge
        if r["pairs"] or inside.any():
            if r["pairs"]:
                at = np.round(np.asarray(r["first_at"]) / u, 6).tolist()
                what = (f"{r['pairs']} sheet/obstacle triangle pairs cross, the first at {at} (sheet triangle "
                        f"{r['first'][0]}, obstacle triangle {r['first'][1]})")
            else:
                n = int(np.argmin(phi))
                what = (f"{int(inside.sum())} sheet nodes lie inside it, the deepest (node {n}) at "
                        f"{np.round(mesh.X3[n] / u, 6).tolist()}, {-phi[n] / u:.6g} deep")
            raise scene.error(f"obstacles.{i}", f"the obstacle cuts through the flat sheet at the start: {what}; move "
                              "it (translate) or the sheet (mesh.z, mesh.origin) so that it lies on one side of the "
                              f"sheet (touching within {START_TOUCH:g} edge lengths is allowed)")
