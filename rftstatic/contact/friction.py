"""Coulomb friction of the sheet's nodes on rigid obstacles, lagged for the static route.

The static route treats friction as IPC does (Li et al., *Incremental Potential Contact*, 2020, §5): the
normal force ``lambda_c`` of every contact node ``c`` and its tangent plane (normal ``n_c``) are *lagged*,
frozen at the last converged state, so that the friction has a potential over the next solve,

    D(x) = sum_c mu_c lambda_c f0(y_c),   y_c = |T_c (x_c - a_c)|,   T_c = I - n_c n_c^T,        (F1)

with ``a_c`` the node's **stick anchor** and ``f0`` the mollified norm of IPC (Eq. 12 there, written as a length):

    f0(y) = y^2 / eps - y^3 / (3 eps^2) + eps / 3   (y < eps),      f0(y) = y   (y >= eps),       (F2)

so ``f1 = f0' = 2 y / eps - y^2 / eps^2`` rises from 0 to 1 over the slip length ``eps`` and stays 1: a node
sticks (a tangential spring of stiffness ``2 mu lambda / eps`` about its anchor) until the tangential force
reaches ``mu lambda``, then slides against that force. The gradient is

    grad_c D = mu_c lambda_c (f1(y) / y) T_c u_c,        u_c = x_c - a_c,                         (F3)

and its Hessian ``mu lambda [g T + h t t^T]`` (``t`` the unit slip direction, ``g = f1 / y``, ``h = f0'' - g``)
is positive semi-definite everywhere: its eigenvalues are ``f0'' >= 0`` along ``t``, ``g > 0`` across it and 0
along ``n`` (F4). Newton's tangent and the stability check stay valid.

After every converged state the lag is **committed** (:func:`commit`): the normal forces and normals are
taken from the penalty at the new state; a node that slid (``y >= eps``) has its anchor brought along to
``x - 0.9 eps t`` (:data:`TRAIL`: it trails the node by about the slip length), a node that stuck keeps its anchor, so a sheet held by
friction stays where it is instead of creeping by ``eps`` per solve; a node that leaves the obstacle drops out,
one that arrives is anchored where it touched. The coefficient is the static one while a node sticks and the
kinetic one once it has slid. The static route repeats Newton at the same load until the committed normal forces
and the sticking set settle (:mod:`rftstatic.solvers.friction_lag`).

The lag is State (``State.contact_history["friction"]``, checkpointed); the penalty law reads it from the solve's
candidate list (:attr:`rftstatic.contact.candidates.CandidateList.friction`), so it adds nothing to the Model.

Explicit motion on the penalty contact (dynamic relaxation, the static route's start) takes friction as velocity
impulses instead (:func:`penalty_impulses`): after the velocity update ``v_(n+1/2)`` of a step, the tangential
velocity of a contact node, whose penalty normal force at ``x_n`` is ``lambda``, is removed where

    |v_t| <= mu_s lambda dt / m     (stick),     else     v_t <- v_t (1 - mu_k lambda dt / (m |v_t|))   (slide)   (F5)

(``m`` the node's scaled lumped mass): a node at rest under a tangential force ``F_t`` gets ``|v_t| = F_t dt / m``
and sticks exactly while ``F_t <= mu_s lambda``, a sliding node is slowed by ``mu_k lambda``. On a moving obstacle
(:mod:`rftstatic.contact.motion`) ``v_t`` is the velocity relative to the obstacle's surface at the node (the chord
velocity of the step), so a sticking node moves with the body. The impulses only
take kinetic energy away, so the explicit step stays as stable as without friction (a lagged stick spring of
stiffness ``2 mu lambda / eps`` would not: at a penalty's transient normal force it exceeds the stable step's
limit by far), and they need no history: a relaxation resumed from its checkpoint is the same run. Its Newton
handovers anchor the lag at the relaxed state (:func:`anchored_lag`). A relaxation from rest first seats the
sheet on the penalty (:func:`seated`): a sheet laid at ``phi = 0`` on a plane starts where the penalty pushes with
about 1000 x its weight and is thrown clear of the obstacle (4 cm on the 10 cm incline test), and in the air
nothing holds it against the downhill weight. Its rest test measures the out-of-balance force less what static
friction can hold, on the obstacles and between layers in self-contact together (:func:`held_by_contacts`, H1-H2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrictionLaw", "friction_terms", "initial_lag", "commit", "anchored_lag", "penalty_impulses", "seated",
           "held_residual", "obstacle_holds", "held_by_contacts"]

SLIP_LENGTH = 1e-4
"""Default slip length ``eps`` of (F2) relative to the sheet's size: the tangential motion of a sticking node under
the full friction force; a sheet held on an incline moves less than this share of its size."""


@dataclass(frozen=True)
class FrictionLaw:
    """Coulomb coefficients per obstacle and the slip length.

    Attributes
    ----------
    mu_static, mu_kinetic : (M,) coefficients [-] for the M obstacles, >= 0, finite
    eps : slip length of (F2) [m], > 0
    """

    mu_static: np.ndarray
    mu_kinetic: np.ndarray
    eps: float

    def __post_init__(self):
        for name in ("mu_static", "mu_kinetic"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.ndim != 1 or not np.all(np.isfinite(v)) or np.any(v < 0):
                raise ValueError(f"{name} must be finite coefficients >= 0, one per obstacle; got {v!r}")
            object.__setattr__(self, name, v)
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"eps (the slip length) must be > 0 [m], got {self.eps!r}")


TRAIL = 0.9
"""A node that slid has its anchor brought to this share of the slip length ``eps`` behind it: the friction force
stays at ``f1(0.9) = 0.99`` of ``mu lambda`` and the tangent along the slip keeps the curvature ``f0''(0.9 eps) =
0.2 / eps`` (at ``eps`` itself it is 0, a singular tangent at every equilibrium a sheet slid into)."""


def _mollifier(y, eps):
    """``f0 (F2)``, ``g = f1 / y`` and ``h = f0'' - g`` for slips ``y (C,)`` [m]."""
    stick = y < eps
    f0 = np.where(stick, y * y / eps - y**3 / (3 * eps * eps) + eps / 3, y)
    safe = np.maximum(y, 1e-300)
    g = np.where(stick, 2.0 / eps - y / (eps * eps), 1.0 / safe)
    h = np.where(stick, -y / (eps * eps), -1.0 / safe)
    return f0, g, h


def friction_terms(lag: dict, x: np.ndarray, *, tangent: bool = True):
    """Energy [J], force ``(N, 3)`` [N] and node-diagonal tangent blocks ``(N, 3, 3)`` [N/m] of (F1)-(F4) at
    positions ``x (N, 3)`` [m] for the lagged contacts ``lag`` (:func:`initial_lag`, :func:`commit`)."""
    n = x.shape[0]
    force = np.zeros((n, 3))
    blocks = np.zeros((n, 3, 3)) if tangent else None
    c = lag["nodes"]
    if c.size == 0:
        return 0.0, force, blocks
    nrm = lag["normal"]
    u = x[c] - lag["anchor"]
    ut = u - np.einsum("ci,ci->c", u, nrm)[:, None] * nrm
    y = np.linalg.norm(ut, axis=1)
    f0, g, h = _mollifier(y, lag["eps"])
    w = lag["mu"] * lag["normal_force"]  # (C,) [N]
    energy = float(np.sum(w * f0))
    np.add.at(force, c, (w * g)[:, None] * ut)
    if tangent:
        t = ut / np.maximum(y, 1e-300)[:, None]
        T = np.eye(3)[None] - np.einsum("ci,cj->cij", nrm, nrm)
        K = w[:, None, None] * (g[:, None, None] * T + h[:, None, None] * np.einsum("ci,cj->cij", t, t))
        np.add.at(blocks, c, K)
    return energy, force, blocks


def _contacts(penalty, x, candidates=None):
    """Contact nodes of the penalty law at ``x (N, 3)`` [m]: nodes ``(C,)``, their obstacle ``(C,)``, normal force
    magnitude ``k A |d1|`` [N] and unit normal ``(C, 3)`` of the obstacle they are deepest in; ``candidates``: the
    solve's candidate list (:class:`~rftstatic.contact.candidates.CandidateList`; only its nodes are measured),
    or None (every node)."""
    if candidates is None:
        near = np.arange(x.shape[0])
        phi, normal = penalty._distances(x)
    else:
        near = penalty._near(x, candidates)[0]
        phi, normal = penalty._distances_of(x[near], penalty._offsets(candidates))
    if phi.shape[0] == 0 or near.size == 0:
        return np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros((0, 3))
    deepest = phi.argmin(axis=0)
    cols = np.arange(near.size)
    d1 = penalty._slope(phi[deepest, cols])
    lam = -penalty.stiffness * penalty.node_area[near] * d1
    hit = np.flatnonzero(lam > 0.0)
    return near[hit], deepest[hit], lam[hit], normal[deepest[hit], hit]


def initial_lag(law: FrictionLaw, penalty, x: np.ndarray, load: np.ndarray) -> dict:
    """The lag before the first solve at positions ``x (N, 3)`` [m]: every node within the penalty's onset width
    of an obstacle, anchored where it is, with the normal force the full ``load (N, 3)`` [N] presses it onto the
    obstacle with (the lag from a converged state replaces it after the first increment)."""
    phi, normal = penalty._distances(x)
    if phi.shape[0] == 0:
        return _lag(law, np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)),
                    np.zeros(0, bool), 1.0)
    deepest = phi.argmin(axis=0)
    cols = np.arange(x.shape[0])
    near = phi[deepest, cols] <= max(penalty.smoothing, 0.0)
    nrm = normal[deepest, cols]
    press = np.maximum(-np.einsum("ni,ni->n", load, nrm), 0.0)
    nodes = np.flatnonzero(near & (press > 0.0))
    return _lag(law, nodes, deepest[nodes], press[nodes], nrm[nodes], x[nodes], np.zeros(nodes.size, bool), 1.0)


def _lag(law, nodes, obstacle, force, normal, anchor, slid, lam) -> dict:
    """The lag's arrays (C = contact nodes): ``normal_force (C,)`` [N] (the committed ``committed_force`` scaled
    to the load factor being solved for), committed at load factor ``lam``."""
    mu = np.where(slid, law.mu_kinetic[obstacle], law.mu_static[obstacle]) if nodes.size else np.zeros(0)
    return {"nodes": nodes.astype(np.int64), "obstacle": obstacle.astype(np.int64), "normal_force": force.copy(),
            "committed_force": force, "lam": float(lam), "normal": normal, "anchor": anchor, "slid": slid, "mu": mu,
            "eps": float(law.eps)}


def commit(law: FrictionLaw, penalty, lag: dict, x: np.ndarray, lam: float = 1.0) -> tuple[dict, dict]:
    """The lag after the converged state ``x (N, 3)`` [m] at load factor ``lam`` (module docstring), and how much
    it changed:
    ``{"normal_force": max |d lambda| / max lambda, "stick_changes": nodes that changed between sticking and sliding
    or entered or left the contact}``."""
    nodes, obstacle, force, normal = _contacts(penalty, x)
    anchor = x[nodes].copy()
    slid = np.zeros(nodes.size, bool)
    prev = lag["nodes"]  # sorted, as np.flatnonzero gives them
    pos = np.minimum(np.searchsorted(prev, nodes), max(prev.size - 1, 0))
    had = prev[pos] == nodes if prev.size else np.zeros(nodes.size, bool)
    keep = np.where(had, pos, -1)
    if np.any(had):
        j = keep[had]
        u = x[nodes[had]] - lag["anchor"][j]
        nj = lag["normal"][j]
        ut = u - np.einsum("ci,ci->c", u, nj)[:, None] * nj
        y = np.linalg.norm(ut, axis=1)
        sliding = y >= law.eps * (1 - 1e-12)
        a = lag["anchor"][j].copy()
        a[sliding] = x[nodes[had]][sliding] - TRAIL * law.eps * ut[sliding] / y[sliding, None]
        anchor[had] = a
        slid[had] = sliding | lag["slid"][j]
    new = _lag(law, nodes, obstacle, force, normal, anchor, slid, lam)
    prev = np.zeros(x.shape[0])
    prev[lag["nodes"]] = lag["normal_force"]
    now = np.zeros(x.shape[0])
    now[nodes] = force
    scale = max(float(now.max(initial=0.0)), 1e-300)
    was = np.zeros(x.shape[0], int)
    was[lag["nodes"]] = 1 + lag["slid"].astype(int)
    isn = np.zeros(x.shape[0], int)
    isn[nodes] = 1 + slid.astype(int)
    change = {"normal_force": float(np.abs(now - prev).max(initial=0.0)) / scale,
              "stick_changes": int(np.count_nonzero(was != isn))}
    return new, change


def anchored_lag(law: FrictionLaw, penalty, x: np.ndarray) -> dict:
    """The lag of a sheet at rest at positions ``x (N, 3)`` [m] (a relaxed state handed to Newton): every node the
    penalty presses onto an obstacle, anchored where it is (sticking, static coefficient), with the penalty's
    normal force at ``x``."""
    nodes, obstacle, force, normal = _contacts(penalty, x)
    return _lag(law, nodes, obstacle, force, normal, x[nodes].copy(), np.zeros(nodes.size, bool), 1.0)


def penalty_impulses(law: FrictionLaw, penalty, x: np.ndarray, v: np.ndarray, minv: np.ndarray, dt: float,
                     candidates=None, work: dict | None = None) -> float:
    """Coulomb friction impulses (F5) of one explicit step on the penalty contact, in place on the half-step
    velocities ``v (N, 3)`` [m/s], for positions ``x (N, 3)`` [m] at which the step's force was evaluated, inverse
    lumped masses ``minv (N, 3)`` [1/kg] (0 on supported dofs) and the step ``dt`` [s]; ``candidates``: the solve's
    candidate list (only its nodes are measured; None: every node). Returns the kinetic energy the impulses took
    away [J]; on moving obstacles the work their impulses did on the sheet, ``sum m dv . v_surface`` [J], is added
    to ``work["body_work"]`` (given a dict)."""
    nodes, obstacle, lam, normal = _contacts(penalty, x, candidates)
    if nodes.size == 0:
        return 0.0
    vc = v[nodes]
    surface = _surface_velocity(penalty, penalty._offsets(candidates), x[nodes], obstacle)
    rel = vc - surface
    vt = rel - np.einsum("ci,ci->c", rel, normal)[:, None] * normal
    speed = np.linalg.norm(vt, axis=1)
    inv_mass = minv[nodes].max(axis=1)  # 1 / m [1/kg]; 0 for a node held in every dof
    cap = lam * dt * inv_mass  # [m/s] the largest tangential change friction can make in the step
    stick = speed <= law.mu_static[obstacle] * cap
    scale = np.where(stick, 0.0, np.maximum(1.0 - law.mu_kinetic[obstacle] * cap / np.maximum(speed, 1e-300), 0.0))
    vnew = np.where(minv[nodes] > 0, vc - (1.0 - scale)[:, None] * vt, vc)  # supported dofs keep their velocity
    m = np.where(inv_mass > 0, 1.0 / np.maximum(inv_mass, 1e-300), 0.0)
    v[nodes] = vnew
    if work is not None and surface.any():
        work["body_work"] = work.get("body_work", 0.0) + float(np.einsum("c,ci,ci->", m, vnew - vc, surface))
    return 0.5 * float(np.sum(m * (np.einsum("ci,ci->c", vc, vc) - np.einsum("ci,ci->c", vnew, vnew))))


def _surface_velocity(penalty, poses, x, obstacle):
    """Velocity ``(C, 3)`` [m/s] of the obstacle surface each contact node at ``x (C, 3)`` [m] touches (its
    ``obstacle (C,)``), by the solve's ``poses`` (:class:`rftstatic.contact.motion.Poses`; None: all at rest): a
    rigid body's, or a deforming one's
    (:meth:`rftstatic.contact.obstacles.surface_sequence.SurfaceSequence.surface_velocity`)."""
    out = np.zeros_like(x)
    if poses is None:
        return out
    for m in np.unique(obstacle):  # the few obstacles
        on = obstacle == m
        t = poses.shape_time[m]
        if np.isnan(t):
            out[on] = poses.velocity(x[on], int(m))
        else:
            out[on] = penalty.obstacles[m].surface_velocity(x[on], float(t), poses.step)
    return out


def seated(penalty, x: np.ndarray, load: np.ndarray) -> np.ndarray:
    """Positions ``(N, 3)`` [m]: ``x (N, 3)`` with every node that the penalty pushes harder than ``load (N, 3)``
    [N] presses it onto its deepest obstacle moved out along the normal to where the two balance:
    ``k A |d1(phi*)| = p``, ``p = -load . n``, i.e. ``phi* = s - sqrt(2 s p / (k A))`` in the onset width ``s`` and
    ``phi* = s / 2 - p / (k A)`` below it (:meth:`~rftstatic.contact.penalty.PenaltyContact._density`)."""
    phi, normal = penalty._distances(x)
    out = np.array(x, dtype=float, copy=True)
    if phi.shape[0] == 0:
        return out
    cols = np.arange(x.shape[0])
    deepest = phi.argmin(axis=0)
    ph, n = phi[deepest, cols], normal[deepest, cols]
    s = max(penalty.smoothing, 0.0)
    kA = penalty.stiffness * penalty.node_area
    press = np.maximum(-np.einsum("ni,ni->n", load, n), 0.0)
    a = np.sqrt(2.0 * s * press / kA) if s > 0 else np.full_like(press, np.inf)
    target = np.where(a < s, s - a, 0.5 * s - press / kA)
    move = np.where((ph < target) & (ph < s), target - ph, 0.0)
    return out + move[:, None] * n


HOLD_SWEEPS = 50
"""Most sweeps of :func:`held_by_contacts` (each a bincount over the contacts; nodes on an obstacle are done after
the first; a layer resting on a held one at 0.9 of its friction angle gets within 1e-3 of the load in ~15)."""

HOLD_TOL = 1e-4
""":func:`held_by_contacts` stops when a sweep takes off less than this share of what the friction took off."""


def held_residual(law: FrictionLaw, penalty, x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The out-of-balance force ``r (N, 3)`` [N] (load minus internal force) at positions ``x (N, 3)`` [m] with
    the reaction the static friction can give taken off: at a node the penalty presses with ``lambda``, the
    tangential part ``r_t`` shrinks by up to ``mu_s lambda`` (to 0 where ``|r_t| <= mu_s lambda``, the node held).
    What a rest test of a frictional relaxation measures (:func:`penalty_impulses` keeps such a node still);
    :func:`held_by_contacts` with the obstacle contacts (:func:`obstacle_holds`), exact here after one sweep."""
    return held_by_contacts(r, [obstacle_holds(law, penalty, x)])


def obstacle_holds(law: FrictionLaw, penalty, x: np.ndarray, candidates=None):
    """The obstacle contacts at ``x (N, 3)`` [m] as :func:`held_by_contacts` takes them: ``nodes (C, 1)``,
    ``w (C, 1)`` (ones: the other side is the obstacle), normal ``(C, 3)`` and the largest static friction force
    ``mu_s lambda (C,)`` [N]."""
    nodes, obstacle, lam, normal = _contacts(penalty, x, candidates)
    return nodes[:, None], np.ones((nodes.size, 1)), normal, law.mu_static[obstacle] * lam


def held_by_contacts(r: np.ndarray, holds, mobile=None) -> np.ndarray:
    """The out-of-balance force ``r (N, 3)`` [N] with a reaction that the contacts' static friction can give taken
    off: the rest test of a relaxation with Coulomb friction (on obstacles, between layers).

    A contact ``p`` (of the list ``holds`` of ``(nodes (P, k), w (P, k), normal (P, 3), cap (P,))``) transmits a
    tangential force ``F_p`` (``n_p . F_p = 0``, ``|F_p| <= cap_p = mu_s lambda_p``) between its sides: node ``a``
    gets ``-w_pa F_p`` (``w`` the closest points' coefficients: (1) for a node on an obstacle, ``(1, -b)`` for a
    point on a triangle, ``(1 - s, s, -(1 - t), -t)`` for two edges). Returned is ``r - sum_p w_pa F_p`` for
    admissible forces ``F_p`` that make it small, by projected Jacobi sweeps on

        rho_a = r_a / D_a,   D_a = sum_p |w_pa| s_p cap_p,   s_p = sum_(b mobile) |w_pb|,                   (H1)
        F_p <- clip(F_p + cap_p T_p sum_a w_pa rho_a,  mu_s lambda_p),   r <- r_0 - sum_p w_pa F_p,          (H2)

    (``T_p = I - n_p n_p^T``; clip scales the vector to at most that length): every row of ``D^-1 W^T C W`` sums
    to at most 1, so a sweep never overshoots. A sheet whose tangential load is a share ``rho`` of the normal force
    it presses with, e.g. on an incline, is held after one sweep exactly while ``|rho| <= mu_s`` (the friction
    angle). The forces stay admissible, so ``|result|`` never falls below what static friction leaves unbalanced:
    a rest test on it passes no state that friction cannot hold. Nodes not ``mobile (N,)`` (held in every dof,
    default none) take their side's reaction (the support carries it); their rows are left as given.
    """
    out = np.array(r, dtype=float, copy=True)
    holds = [h for h in holds if len(h[0])]
    if not holds:
        return out
    k = max(h[0].shape[1] for h in holds)
    pad = [(np.pad(nd, ((0, 0), (0, k - nd.shape[1]))), np.pad(w, ((0, 0), (0, k - w.shape[1]))), n, c)
           for nd, w, n, c in holds]
    nodes, w, normal, cap = (np.concatenate(parts) for parts in zip(*pad))
    n_nodes = out.shape[0]
    mob = np.ones(n_nodes) if mobile is None else np.asarray(mobile, float)
    wm = np.abs(w) * mob[nodes]  # (P, k): the mobile nodes' weights
    s = wm.sum(axis=1)
    D = np.bincount(nodes.ravel(), (wm * (s * cap)[:, None]).ravel(), minlength=n_nodes)
    inv_D = np.where(D > 0, 1.0 / np.maximum(D, 1e-300), 0.0)
    F = np.zeros((len(cap), 3))
    r0, best = out * mob[:, None], None
    idx = (3 * nodes[:, :, None] + np.arange(3)).ravel()
    for _ in range(HOLD_SWEEPS):
        taken = np.bincount(idx, np.einsum("pa,pi->pai", w, F).ravel(), minlength=3 * n_nodes).reshape(-1, 3)
        left = r0 - taken * mob[:, None]  # a held node's reaction goes into its support
        size = float(np.linalg.norm(left))
        if best is not None and best[0] - size <= HOLD_TOL * float(np.linalg.norm(taken * mob[:, None])):
            best = min(best, (size, left), key=lambda b: b[0])
            break  # the sweep took off less than HOLD_TOL of what the friction takes off
        if best is None or size < best[0]:
            best = (size, left)
        demand = np.einsum("pa,pai->pi", w * mob[nodes], (left * inv_D[:, None])[nodes])  # rho of (H1)
        demand -= np.einsum("pi,pi->p", demand, normal)[:, None] * normal
        F = F + cap[:, None] * demand
        length = np.linalg.norm(F, axis=1)
        F *= np.minimum(1.0, cap / np.maximum(length, 1e-300))[:, None]
    return np.where(mob[:, None] > 0, best[1], out)
