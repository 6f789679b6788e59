"""Kinematic contact of the explicit solver (§6.3) and the reaction it implies at rest.

After an explicit time step a penetrated node is moved to its closest surface point and the inward
normal component of its velocity is removed (:func:`kinematic_contact`); a node whose step passed through a
thin part of an obstacle (a shell, a table top: :meth:`~rftstatic.contact.obstacles.Obstacle.segment_crossings`)
is stopped where it crossed, on the side it came from. At rest, the obstacles carry
the part of the load that presses the touching nodes onto them: :func:`contact_reaction_residual` is
the out-of-balance force with that frictionless reaction taken off, the residual a rest test needs.

Nothing here depends on the obstacles' types: only ``signed_distance`` is used.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from rftstatic.contact.common import as_list as _as_list
from rftstatic.contact.common import as_points as _as_points
from rftstatic.contact.obstacles import Obstacle


def kinematic_contact(
    obstacles: Obstacle | Sequence[Obstacle], x: np.ndarray, v: np.ndarray, friction=None, dt: float = 0.0,
    x_old: np.ndarray | None = None, sweep=None
) -> tuple[np.ndarray, np.ndarray, int]:
    """Kinematic contact correction after an explicit step (§6.3), with Coulomb friction impulses.

    Each penetrated node (``phi < 0``) is moved to its closest surface point ``x - phi n`` and the inward
    part of its normal velocity is removed (``v <- v - min(v.n, 0) n``, no rebound): a normal impulse per unit
    mass ``j = -min(v.n, 0)``. With friction the tangential velocity ``v_t`` then sticks (``v_t <- 0``) where
    ``|v_t| <= mu_s j``, the impulse needed being within the static cone, and slides with the kinetic impulse
    ``v_t <- v_t (1 - mu_k j / |v_t|)`` elsewhere; on a node resting under its weight ``j = g cos(theta) dt`` per
    step, so a sheet on a plane steeper than its friction angle slides with ``g (sin theta - mu_k cos theta)``.
    The step's tangential move is corrected by the friction's change of velocity times ``dt`` (the position
    advances with the velocity friction leaves: a sticking node does not creep by ``g sin(theta) dt^2`` a step).
    Without friction tangential and outward velocities are kept. Given the step's start ``x_old``, a node whose
    straight step ``x_old -> x`` crossed a thin part of an obstacle (continuous collision detection,
    :meth:`~rftstatic.contact.obstacles.Obstacle.segment_crossings`) is first stopped where it crossed, on its
    side, and loses its velocity into the obstacle there; with ``sweep`` the sheet's edges and triangles are
    first lifted off the obstacles' sharp features they swept over (:mod:`rftstatic.contact.feature_sweep`).
    Obstacles are treated one after the other.

    Parameters
    ----------
    obstacles : an obstacle or a sequence of them
    x : (N, 3) nodal positions at the end of the step [m]
    v : (N, 3) nodal velocities [m/s]
    friction : :class:`rftstatic.contact.friction.FrictionLaw` (coefficients per obstacle), or None
    dt : the step [s] whose tangential move friction corrects
    x_old : (N, 3) positions at the start of the step [m], or None (no continuous collision detection)
    sweep : :class:`rftstatic.contact.feature_sweep.FeatureSweep` of the obstacles' sharp features, or None

    Returns
    -------
    x_new : (N, 3) corrected positions [m]
    v_new : (N, 3) corrected velocities [m/s]
    n_active : number of nodes that were corrected
    """
    items = _as_list(obstacles)
    x_new = _as_points(x).copy()
    v_new = _as_points(v, x_new.shape[0], name="v").copy()
    touched = np.zeros(x_new.shape[0], dtype=bool)
    if sweep is not None and x_old is not None:
        x_new, v_new, touched = sweep.stop(x_old, x_new, v_new)
    for m, ob in enumerate(items):
        ccd = getattr(ob, "segment_crossings", None)  # any object with signed_distance may act here
        crossed = None if x_old is None or ccd is None else ccd(x_old, x_new)
        if crossed is not None and crossed[0].any():
            hit, stop, n = crossed
            x_new[hit] = stop[hit]
            vn = np.einsum("ni,ni->n", v_new[hit], n[hit])
            v_new[hit] -= np.minimum(vn, 0.0)[:, None] * n[hit]
            touched |= hit
        phi, normal = ob.signed_distance(x_new)
        act = phi < 0.0
        if not np.any(act):
            continue
        n = normal[act]
        x_new[act] -= phi[act, None] * n
        vn = np.einsum("ni,ni->n", v_new[act], n)
        j = -np.minimum(vn, 0.0)  # normal impulse per unit mass [m/s]
        v_new[act] += j[:, None] * n
        if friction is not None and (friction.mu_static[m] > 0 or friction.mu_kinetic[m] > 0):
            va = v_new[act]
            vt = va - np.einsum("ni,ni->n", va, n)[:, None] * n
            speed = np.linalg.norm(vt, axis=1)
            stick = speed <= friction.mu_static[m] * j
            scale = np.where(stick, 0.0, 1.0 - friction.mu_kinetic[m] * j / np.maximum(speed, 1e-300))
            dv = (1.0 - np.maximum(scale, 0.0))[:, None] * vt
            v_new[act] = va - dv
            x_new[act] -= dt * dv
        touched |= act
    return x_new, v_new, int(np.count_nonzero(touched))


TOUCH_TOLERANCE = 1e-3
"""A node touches an obstacle when its signed distance is below this fraction of the smallest element size."""


def contact_reaction_residual(model, obstacles, U, lam: float = 1.0, *, slip=None) -> np.ndarray:
    """``model.residual(U, lam, slip=slip)`` ``(N, 3)`` [N] with the kinematic contact's reaction taken off (``slip``:
    the frictions' committed slips (E, k), :meth:`rftstatic.model.model.Model.initial_slip`; None: the virgin fabric).

    ``model.residual(U)`` = F(U) - P knows nothing of the kinematic obstacles: the weight carried by a
    pedestal stays in it and the sheet never counts as at rest. At a node touching an obstacle (phi below
    :data:`TOUCH_TOLERANCE` of the smallest element size) a frictionless reaction lam n (n the outward
    normal, lam >= 0) acts; lam is the one that best balances the node's free dofs,
    lam = max(0, r_f . n_f / |n_f|^2) with r_f, n_f the residual and the normal on the free components
    (on a fully free node lam = max(r . n, 0); on a node whose x and y are held, e.g. the in-plane hold
    on top of a sphere, the support takes the in-plane part of lam n), and r -> r - lam n there.
    """
    r = model.residual(U, lam, slip=slip)
    obstacles = _as_list(obstacles) if obstacles else []
    if not obstacles:
        return r
    tol = TOUCH_TOLERANCE * float(model.mesh.element_size.min())
    x = model.X3 + U
    for ob in obstacles:
        phi, n = ob.signed_distance(x)
        touch = phi <= tol
        nf = n[touch] * model.free[touch]
        nn = np.einsum("ni,ni->n", nf, nf)
        rn = np.einsum("ni,ni->n", r[touch] * model.free[touch], nf)
        reaction = np.where(nn > 0, np.maximum(rn, 0.0) / np.where(nn > 0, nn, 1.0), 0.0)
        r[touch] -= reaction[:, None] * n[touch]
    return r
