"""Coulomb friction between layers of the sheet in self-contact, lagged for the static route as on obstacles
(:mod:`rftstatic.contact.friction`, IPC §5).

For every self-contact pair active at the last converged state (a point and a triangle, or two edges, closer
than the thickness ``d``: :mod:`.law`) the lag freezes the closest points' coefficients ``w (4,)`` (point-triangle
``(1, -b_0, -b_1, -b_2)``, ``b`` the barycentric coordinates of the closest point on the triangle; edge-edge
``(1 - s, s, -(1 - t), -t)``), the unit normal ``n`` (from the second primitive's closest point to the first's),
the pair's normal force ``lambda = -e'(delta)`` [N] (:meth:`.law.SelfContact.normal_force`, the solve's stiffness) and
the anchor ``r0`` of the relative position ``r = sum_a w_a x_a`` of the closest points. Over the next solve

    D = sum_p mu lambda_p f0(|T_p (r_p - r0_p)|),     T_p = I - n_p n_p^T,                          (S1)

``f0`` the mollified norm (F2) over the slip length ``eps``: the two layers stick (a tangential spring of
stiffness ``2 mu lambda / eps`` between the closest points) until the tangential force reaches ``mu lambda``, then
slide against it. With ``u = T (r - r0)``, ``y = |u|``, ``g = f1 / y`` and ``h = f0'' - g`` as in (F3)-(F4):

    grad_a D = w_a mu lambda g u,        hess_ab D = w_a w_b mu lambda (g T + h t t^T),          (S2)

a Kronecker product of the rank-one ``w w^T`` and the 3 x 3 block of (F4), both positive semi-definite, so every
12 x 12 pair block is too: the Newton tangent and the stability check stay valid. The coefficients come from the
gradient of the squared distance ``s = delta^2`` (:mod:`.distance`): ``grad_a s = 2 w_a delta n``, and the first
primitive's weights sum to 1, so ``delta n`` is half the sum of its gradients.

The commit (:func:`commit_pairs`) works as on obstacles: a pair still active keeps its anchor while it sticks and
has it brought to ``r - TRAIL eps t`` once it slid (kinetic coefficient from then on); a new pair is anchored where
it is; a pair that separated drops out. Pairs are told apart by their kind and four nodes. The lag is State
(``State.contact_history["self_friction"]``, checkpointed); the law reads it from the solve's pair cache
(``PairCache.friction``), set by :func:`rftstatic.solvers.friction_lag.link`.
"""

from __future__ import annotations

import numpy as np

from rftstatic.contact.friction import TRAIL, FrictionLaw, _mollifier
from rftstatic.contact.self_contact.distance import edge_edge, point_triangle
from rftstatic.contact.self_contact.near_pairs import NearPairCache

__all__ = ["empty_pairs_lag", "pair_friction_terms", "commit_pairs", "with_friction", "pair_impulses", "pair_holds",
           "anchored_pairs_lag"]


def empty_pairs_lag(law: FrictionLaw) -> dict:
    """The lag without pairs (before the first converged state)."""
    return _pairs_lag(law, np.zeros((0, 4), np.int64), np.zeros(0, np.int8), np.zeros((0, 4)), np.zeros((0, 3)),
                      np.zeros(0), np.zeros((0, 3)), np.zeros(0, bool), 1.0)


def _pairs_lag(law, nodes, kind, w, normal, force, anchor, slid, lam) -> dict:
    """The lag's arrays (P pairs): ``nodes (P, 4)``, ``kind (P,)`` (0 point-triangle, 1 edge-edge), ``w (P, 4)``,
    ``normal (P, 3)``, ``normal_force (P,)`` [N] (``committed_force`` scaled to the load factor solved for),
    ``anchor (P, 3)`` [m], ``slid (P,)``, ``mu (P,)``, committed at load factor ``lam``."""
    mu = np.where(slid, law.mu_kinetic[0], law.mu_static[0]) if len(nodes) else np.zeros(0)
    return {"nodes": np.asarray(nodes, np.int64).reshape(-1, 4), "kind": np.asarray(kind, np.int8), "w": w,
            "normal": normal, "normal_force": np.array(force, dtype=float), "committed_force": force,
            "lam": float(lam), "anchor": anchor, "slid": slid, "mu": mu, "eps": float(law.eps)}


def _slip(lag, x):
    """``u = T (r - r0) (P, 3)`` [m] of (S1) at positions ``x (N, 3)`` [m]."""
    r = np.einsum("pa,pai->pi", lag["w"], x[lag["nodes"]])
    u = r - lag["anchor"]
    n = lag["normal"]
    return u - np.einsum("pi,pi->p", u, n)[:, None] * n


def pair_friction_terms(lag: dict, x: np.ndarray, *, tangent: bool = True):
    """Energy [J], force ``(N, 3)`` [N] (the gradient) and pair blocks ``(P, 12, 12)`` [N/m] (dof ``3 a + i`` of
    the lag's ``nodes (P, 4)``; None without ``tangent``) of (S1)-(S2) at positions ``x (N, 3)`` [m]."""
    n_nodes = x.shape[0]
    force = np.zeros((n_nodes, 3))
    P = len(lag["nodes"])
    if P == 0:
        return 0.0, force, np.zeros((0, 12, 12)) if tangent else None
    ut = _slip(lag, x)
    y = np.linalg.norm(ut, axis=1)
    f0, g, h = _mollifier(y, lag["eps"])
    wgt = lag["mu"] * lag["normal_force"]  # (P,) [N]
    energy = float(np.sum(wgt * f0))
    fp = (wgt * g)[:, None] * ut  # (P, 3) the force on r
    idx = (3 * lag["nodes"][:, :, None] + np.arange(3)).ravel()
    force = np.bincount(idx, np.einsum("pa,pi->pai", lag["w"], fp).ravel(), minlength=3 * n_nodes).reshape(-1, 3)
    blocks = None
    if tangent:
        t = ut / np.maximum(y, 1e-300)[:, None]
        nrm = lag["normal"]
        T = np.eye(3)[None] - np.einsum("pi,pj->pij", nrm, nrm)
        K = wgt[:, None, None] * (g[:, None, None] * T + h[:, None, None] * np.einsum("pi,pj->pij", t, t))
        ww = np.einsum("pa,pb->pab", lag["w"], lag["w"])
        blocks = np.einsum("pab,pij->paibj", ww, K).reshape(P, 12, 12)
    return energy, force, blocks


def _active_pairs(sc, x, cache):
    """The pairs of the self-contact law ``sc`` closer than its thickness at ``x (N, 3)`` [m] (its pair cache
    ``cache``): ``nodes (P, 4)``, ``kind (P,)``, ``w (P, 4)``, ``normal (P, 3)`` and normal force ``(P,)`` [N]."""
    listed = sc.pairs(x, cache)
    if isinstance(cache, NearPairCache):
        npt, nee = cache.npt, cache.nee
    else:
        npt, nee = sc._x4(x, listed)
    d, scale = sc.thickness, 1.0 if cache is None else cache.stiffness_scale
    out = []
    for kind, rows, fun, first in ((0, npt, point_triangle, 1), (1, nee, edge_edge, 2)):
        if not len(rows):
            continue
        s, grad, _, _ = fun(x[rows], hessian=False, compiled=sc.compiled)
        act = s < d * d
        if not np.any(act):
            continue
        delta = np.sqrt(s[act])
        gr = grad[act]  # (A, 4, 3): 2 w_a delta n
        dn = 0.5 * gr[:, :first].sum(axis=1)  # delta n
        n = dn / np.maximum(delta, 1e-300)[:, None]
        w = np.einsum("pai,pi->pa", gr, n) / (2.0 * np.maximum(delta, 1e-300))[:, None]
        lam = sc.normal_force(delta, scale)
        out.append((rows[act], np.full(len(delta), kind, np.int8), w, n, lam))
    if not out:
        return np.zeros((0, 4), np.int64), np.zeros(0, np.int8), np.zeros((0, 4)), np.zeros((0, 3)), np.zeros(0)
    return tuple(np.concatenate(parts) for parts in zip(*out))


def commit_pairs(law: FrictionLaw, sc, lag: dict, x: np.ndarray, cache=None, lam: float = 1.0) -> tuple[dict, dict]:
    """The self-friction lag after the converged state ``x (N, 3)`` [m] at load factor ``lam`` (module docstring),
    and how much it changed: ``{"normal_force": max |d lambda| / max lambda over the pairs present in both,
    "stick_changes": pairs that changed between sticking and sliding, entered or left}``."""
    nodes, kind, w, normal, force = _active_pairs(sc, x, cache)
    anchor = np.einsum("pa,pai->pi", w, x[nodes]) if len(nodes) else np.zeros((0, 3))
    slid = np.zeros(len(nodes), bool)
    key_new = np.column_stack([kind, nodes]) if len(nodes) else np.zeros((0, 5), np.int64)
    key_old = np.column_stack([lag["kind"], lag["nodes"]]) if len(lag["nodes"]) else np.zeros((0, 5), np.int64)
    both = np.concatenate([key_old, key_new]).astype(np.int64)
    _, ids = np.unique(both, axis=0, return_inverse=True)
    ids = ids.ravel()
    old_ids, new_ids = ids[:len(key_old)], ids[len(key_old):]
    order = np.argsort(old_ids)
    pos = np.searchsorted(old_ids[order], new_ids)
    pos = np.minimum(pos, max(len(order) - 1, 0))
    had = (old_ids[order][pos] == new_ids) if len(order) else np.zeros(len(nodes), bool)
    change_force = 0.0
    if np.any(had):
        j = order[pos[had]]
        ut = _slip({**lag, "nodes": lag["nodes"][j], "w": lag["w"][j], "anchor": lag["anchor"][j],
                    "normal": lag["normal"][j]}, x)
        y = np.linalg.norm(ut, axis=1)
        sliding = y >= law.eps * (1 - 1e-12)
        # a pair that sticks keeps its closest points (coefficients, normal) and anchor; one that slid takes the
        # closest points it has now, its anchor trailing them along the slip
        hold = np.flatnonzero(had)
        stick, moved = hold[~sliding], hold[sliding]
        w[stick], normal[stick], anchor[stick] = lag["w"][j[~sliding]], lag["normal"][j[~sliding]], lag["anchor"][
            j[~sliding]]
        anchor[moved] -= TRAIL * law.eps * ut[sliding] / y[sliding, None]
        slid[had] = sliding | lag["slid"][j]
        change_force = float(np.abs(force[had] - lag["normal_force"][j]).max())
    new = _pairs_lag(law, nodes, kind, w, normal, force, anchor, slid, lam)
    scale = max(float(force.max(initial=0.0)), 1e-300)
    left = len(key_old) - int(np.count_nonzero(had))
    flips = int(np.count_nonzero(slid[had] != lag["slid"][order[pos[had]]])) if np.any(had) else 0
    return new, {"normal_force": change_force / scale,
                 "stick_changes": flips + left + int(np.count_nonzero(~had))}


def with_friction(state, lag: dict, x: np.ndarray, tangent: bool):
    """A :class:`~.law.SelfContactState` with the friction (S1) of ``lag`` at ``x (N, 3)`` [m] added: energy,
    force, and its pair blocks appended to the contact's (``n_active`` and ``min_distance`` unchanged)."""
    from dataclasses import replace

    e, f, K = pair_friction_terms(lag, x, tangent=tangent)
    if not len(lag["nodes"]):
        return state
    blocks = np.concatenate([state.blocks, K]) if tangent else state.blocks
    return replace(state, energy=state.energy + e, force=state.force + f,
                   nodes=np.concatenate([state.nodes, lag["nodes"]]), blocks=blocks)


def pair_impulses(law: FrictionLaw, sc, x: np.ndarray, v: np.ndarray, minv: np.ndarray, dt: float,
                  cache=None) -> float:
    """Coulomb friction impulses between layers for one explicit step (the pairs' analogue of
    :func:`rftstatic.contact.friction.penalty_impulses`), in place on the half-step velocities ``v (N, 3)`` [m/s],
    at positions ``x (N, 3)`` [m] where the step's force was evaluated, inverse lumped masses ``minv (N, 3)``
    [1/kg] (0 on held dofs), step ``dt`` [s], the solve's pair cache ``cache``. Every pair closer than the thickness
    (``nodes (P, 4)``, closest points' coefficients ``w``, normal ``n``, normal force ``lambda``: :func:`_active_pairs`)
    has the relative tangential velocity of its closest points ``v_t = T sum_a w_a v_a``; an impulse ``J`` against it
    changes it by ``J / m_p``, ``1 / m_p = sum_a w_a^2 / m_a``. The pair slides with ``J = mu_k lambda dt`` where
    stopping it would take more than ``mu_s lambda dt``; else it sticks, with ``J`` the stopping impulse over the
    number of pairs at its busiest node (the pairs act together, Jacobi: a node in several sticking pairs would
    otherwise be stopped several times over). Node ``a`` gains ``-w_a J t / m_a`` on its free dofs. Returns the
    kinetic energy taken [J]."""
    nodes, _, w, normal, lam = _active_pairs(sc, x, cache)
    if not len(nodes):
        return 0.0
    vr = np.einsum("pa,pai->pi", w, v[nodes])
    vt = vr - np.einsum("pi,pi->p", vr, normal)[:, None] * normal
    speed = np.linalg.norm(vt, axis=1)
    inv_m = minv[nodes].max(axis=2)  # (P, 4) [1/kg]; 0 for a node held in every dof
    inv_mp = np.einsum("pa,pa->p", w * w, inv_m)
    busy = np.bincount(nodes.ravel(), minlength=len(v))[nodes].max(axis=1)
    stop = speed / np.maximum(inv_mp, 1e-300)  # [N s]
    slide = stop > law.mu_static[0] * lam * dt
    J = np.where(slide, np.minimum(law.mu_kinetic[0] * lam * dt, stop), stop / busy)
    J = np.where(inv_mp > 0, J, 0.0)
    t = vt / np.maximum(speed, 1e-300)[:, None]
    dv = -(J[:, None, None] * w[:, :, None] * t[:, None, :]) * minv[nodes]  # (P, 4, 3), free dofs only
    before = v.copy()
    np.add.at(v, nodes.ravel(), dv.reshape(-1, 3))
    m = np.where(minv > 0, 1.0 / np.maximum(minv, 1e-300), 0.0)
    return 0.5 * float(np.sum(m * (before * before - v * v)))


def pair_holds(law: FrictionLaw, sc, x: np.ndarray, cache=None):
    """The self-contact pairs closer than the thickness at ``x (N, 3)`` [m] (pair cache ``cache``) as
    :func:`rftstatic.contact.friction.held_by_contacts` takes them: ``nodes (P, 4)``, the closest points'
    coefficients ``w (P, 4)``, normal ``(P, 3)`` and the largest static friction force ``mu_s lambda (P,)`` [N]
    each can transmit between its two layers (what :func:`pair_impulses` holds still): the rest test of a
    relaxation with friction between layers."""
    nodes, _, w, normal, lam = _active_pairs(sc, x, cache)
    return nodes, w, normal, law.mu_static[0] * lam


def anchored_pairs_lag(law: FrictionLaw, sc, x: np.ndarray, cache=None) -> dict:
    """The lag between layers of a sheet at rest at ``x (N, 3)`` [m] (a relaxed state handed to Newton, which
    :func:`pair_impulses` held there): every pair closer than the thickness anchored where it is (sticking, static
    coefficient), with its normal force at ``x`` (:func:`commit_pairs` from no lag)."""
    return commit_pairs(law, sc, empty_pairs_lag(law), x, cache)[0]
