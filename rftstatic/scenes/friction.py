"""The scene's Coulomb friction (:class:`rftstatic.contact.friction.FrictionLaw`) from ``[contact] friction``,
``friction_static``, ``friction_kinetic`` and each ``[[obstacles]] friction``."""

from __future__ import annotations

import math

import numpy as np

from rftstatic.scenes.schema import Scene


def contact_friction(scene: Scene, c, n_obstacles: int, mesh):
    """The scene's Coulomb friction law (:class:`rftstatic.contact.friction.FrictionLaw`), or None when
    frictionless: lagged on the static routes (load steps; relaxation commits the lag at every sample, its Newton
    handovers settle it), impulses in a dynamic run."""
    mu_s = np.full(n_obstacles, c.friction if c.friction_static is None else c.friction_static)
    mu_k = np.full(n_obstacles, c.friction if c.friction_kinetic is None else c.friction_kinetic)
    for i, spec in enumerate(scene.get("obstacles", [])[:n_obstacles]):
        if "friction" in spec:  # this obstacle's own coefficient, static and kinetic
            mu = spec["friction"]
            if isinstance(mu, bool) or not isinstance(mu, (int, float)) or not math.isfinite(mu) or mu < 0:
                raise scene.error(f"obstacles.{i}.friction", f"must be a finite coefficient >= 0, got {mu!r}")
            mu_s[i] = mu_k[i] = float(mu)
    if not (mu_s.any() or mu_k.any()):
        return None
    if np.any(mu_k > mu_s):
        raise scene.error("contact.friction_kinetic", f"the kinetic coefficient {mu_k.max():g} exceeds the static "
                          f"one {mu_s.min():g} (contact.friction_static); give friction_kinetic <= friction_static")
    if scene.analysis not in ("static", "dynamic"):
        given = [f"contact.{k} = {getattr(c, k)!r}" for k in ("friction", "friction_static", "friction_kinetic")
                 if getattr(c, k)]  # the keys that gave the friction, so the message names the one set
        raise scene.error("contact.friction", f"{', '.join(given) or 'an obstacle friction'}: friction acts in static "
                          'solves (analysis = "static", by load steps or by relaxation and Newton) and dynamic runs '
                          f'(analysis = "dynamic"), not in analysis = "{scene.analysis}": set contact.friction = 0 '
                          "for it")
    from rftstatic.contact.friction import SLIP_LENGTH, FrictionLaw

    size = float(np.ptp(mesh.X, axis=0).max())
    return FrictionLaw(mu_s, mu_k, eps=SLIP_LENGTH * size)
