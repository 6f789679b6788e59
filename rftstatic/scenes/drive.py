"""Supports that move: ``velocity = [vx, vy, vz]`` of a ``[[supports]]`` entry (scene units of length / time).

The held components of the support's nodes (all three for ``clamped`` and ``pinned``, ``components`` for
``fixed``) move at that velocity from the start of a dynamic run (``analysis = "dynamic"``,
:mod:`rftstatic.solvers.explicit`): a sheet's edge dragged along a floor (``cases/drag-floor.toml``). The summary
then reports the mean force of the sheet on the moving supports over the run's second half
(:func:`drive_summary`). A static scene's supports stay at zero displacement, and a relaxation seeks a rest that a
moving support never reaches: a velocity there is refused.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["support_velocities", "drive_summary"]


def support_velocities(scene, mesh, select_nodes):
    """``(N, 3)`` velocity [m/s] of the supports' held components (zero elsewhere), or None when no ``[[supports]]``
    entry has a ``velocity``; raises the scene's error (exit 2) for a bad one. ``select_nodes(scene, mesh, spec,
    key)``: the nodes of an entry (:func:`rftstatic.scenes.build.select_nodes`)."""
    out = None
    for i, spec in enumerate(scene.get("supports", [])):
        if "velocity" not in spec:
            continue
        key = f"supports.{i}.velocity"
        v = np.asarray(spec["velocity"], dtype=float)
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise scene.error(key, f"expected [vx, vy, vz] (finite, scene units of length / time), got "
                              f"{spec['velocity']!r}")
        if scene.analysis != "dynamic":
            raise scene.error(key, f'a support moves only in a dynamic run; analysis = "{scene.analysis}" holds it at '
                              'zero displacement (or seeks a rest): remove velocity or set analysis = "dynamic"')
        kind = spec.get("kind", "pinned")
        held = spec.get("components", "xyz") if kind == "fixed" else "xyz"
        loose = [c for j, c in enumerate("xyz") if v[j] != 0.0 and c not in held]
        if loose:
            raise scene.error(key, f"the support holds {held} only, but its velocity moves {''.join(loose)}: set "
                              f"that component to 0 or hold it (components = \"{held + ''.join(loose)}\")")
        nodes = select_nodes(scene, mesh, spec, f"supports.{i}")
        out = np.zeros((mesh.n_nodes, 3)) if out is None else out
        for j, c in enumerate("xyz"):
            if c in held:
                out[nodes, j] = scene.units.to_si(v[j], "velocity")
    return out


def drive_summary(scene, model, run, friction=None) -> dict | None:
    """The summary's ``drive``: the mean force of the sheet on its moving supports over the run's second half
    (``reaction``, scene force units, :attr:`rftstatic.solvers.explicit.ExplicitResult.drive_reaction`), the weight
    of the nodes they pull (those not held), and, with one obstacle's kinetic friction ``mu``, the reaction along
    the supports' motion over ``mu`` times that weight (a sheet sliding on the obstacle: 1); None without a drive."""
    v = getattr(model.supports, "velocity", None)
    if v is None or run.drive_reaction is None:
        return None
    u = scene.units
    held = model.fixed.any(axis=1)
    pulled = float(-model.load[~held, 2].sum())
    speed = v[held].mean(axis=0)
    direction = speed / max(float(np.linalg.norm(speed)), 1e-300)
    along = float(np.dot(run.drive_reaction, direction))
    out = {"reaction": u.from_si(np.asarray(run.drive_reaction), "force").tolist(),
           "reaction_along_motion": u.from_si(along, "force"), "weight_pulled": u.from_si(pulled, "force")}
    mu = None if friction is None or len(friction.mu_kinetic) != 1 else float(friction.mu_kinetic[0])
    if mu and pulled > 0 and math.isfinite(along):
        out["mu"] = mu
        out["reaction_over_mu_weight"] = abs(along) / (mu * pulled)
    return out
