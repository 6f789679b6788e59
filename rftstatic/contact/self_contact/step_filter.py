"""Self-contact of the explicit solver (Eq. 20-22 with the law of :mod:`.law`): the force on the near
pairs only, and a step filter that makes tunnelling impossible within one step.

Force (:meth:`~.law.SelfContact.near_force`, added by the explicit force kernel): the gradient of the
static law's energy (one source, :meth:`~.law.SelfContact.evaluate_pairs`) over the pairs of the solve's
:class:`~.near_pairs.NearPairCache` whose lower bound (Eq. 1 of :mod:`.near_pairs`) is below the thickness
``d``: at most steps of a sheet whose layers do not touch, a test on ``N`` node motions and no distance.

Step filter (:class:`StepFilter`), applied to the half-step velocity ``v = v_(n+1/2)`` before the position
update ``x_(n+1) = x_n + dt v`` (Eq. 22), so the step is the straight path ``x_n + t dt v``, ``0 <= t <= 1``:

1. Pairs not listed. The list is rebuilt (at ``x_n``) when the translation-free motion since its build
   would exceed ``margin / 2`` at ``x_(n+1)``; the motion along the path is at most its larger end value
   (the norm is convex), so every unlisted pair stays farther than ``d`` on the whole step. A step whose
   own motion exceeds ``margin / 2`` adds the pairs of a swept broad phase over ``x_n -> x_(n+1)`` to
   the checked pairs.
2. Quick test, O(N): a listed pair can lose at most ``l_p <= 2 max_(k in p) |dt v_k - c|`` of its distance
   in the step (``c`` the midrange of ``dt v``). When ``2 max_k |dt v_k - c| <= beta (min_p lb_p - g)`` (lb the
   lower bound of Eq. 1, ``beta = 1 - approach``, ``g = floor d`` the gap floor) no pair can lose more than the
   allowed fraction ``approach`` of its gap above the floor and the step is left alone; otherwise the per-pair
   test picks the pairs that might (every pair whose bound is below the floor).
3. Velocity filter (Bridson, Fedkiw & Anderson 2002, inelastic repulsion impulses). For a picked pair
   at distance ``delta`` with closest-point weights ``w (4,)`` (``r = sum_k w_k x_k``, the weights of one
   side summing to 1, of the other to -1) and normal ``n = r / delta``, the approach rate is
   ``v_n = sum_k w_k v_k . n``. Where ``v_n < b = -approach max(delta - g, 0) / dt`` an impulse ``J n`` along
   the pair's weights, ``dv_k = w_k J M_k^-1 n`` with ``J = (b - v_n) / sum_k w_k^2 n.M_k^-1 n``,
   brings ``v_n`` to that bound (``M_k^-1`` the nodal inverse mass per dof, zero on supported dofs). Since
   ``sum_k w_k = 0`` the impulses conserve momentum; they only remove approaching normal velocity
   (inelastic, ``J >= 0``). Pairs sharing nodes are solved together: the violated ones as one sparse
   system ``C M^-1 C^T J = bound - v_n`` with an active set (``J >= 0``), then Jacobi sweeps for what a
   redundant set of pairs leaves (each impulse divided by the largest number of violated pairs at any of
   its nodes: no overshoot), at most ``sweeps``.
4. Fail-safe: the additive CCD of :meth:`~.law.SelfContact.max_step_fraction` on the pairs the per-pair
   test still picks after the filter gives the largest ``t`` such that no pair comes closer than
   ``min_fraction`` of its distance on ``x_n + t dt v``, nor below ``CCD_FLOOR d`` if it started above;
   if ``t < 1`` the whole step's velocity is scaled by ``t`` (counted in ``ccd_limited``: the filter
   usually leaves nothing to do).

The floor ``g`` (:data:`FLOOR` of the thickness) is what keeps layers apart under impacts: a pair may close
only a fraction ``approach`` of its gap above ``g`` per step, so the linear prediction of its distance never
crosses ``g``, however many steps it keeps approaching (without it, a gap allowed to halve every step went to
~1e-10 cm on the drop-floor scene, where the falling skirt hits the layers on the floor at ~1 m/s); below
``g`` a pair may not approach at all. Resting contact sits above it (the law's pairs rest at ``0.84 d`` under
the sheet's weight, at ``d / 2`` under ten times it, :mod:`.law`), so the floor acts only on impacts.

Hence no pair's distance ever falls below ``min_fraction`` of its value at the start of a step:
distances stay positive and no pair passes through another (straight-line steps; a kinematic obstacle's
projection after the step is not part of the path). The kinetic energy the filter removes is returned
(the explicit loop books the filter's change of the scheme's energy in ``contact_loss`` itself,
:mod:`rftstatic.solvers.contact_energy`, C1).

Shapes: ``x, v (N, 3)`` [m], [m/s]; ``minv (N, 3)`` [1/kg]; pairs ``(P, 4)`` node rows.
"""

from __future__ import annotations

import time

import numpy as np

from rftstatic.contact.self_contact import distance
from rftstatic.contact.self_contact.broad_phase import find_pairs
from rftstatic.contact.self_contact.distance import edge_edge, point_triangle
from rftstatic.contact.self_contact.law_kernels import additive_ccd_nodes
from rftstatic.contact.self_contact.near_pairs import NearPairCache, pair_nodes, translation_free_motion

__all__ = ["APPROACH", "StepFilter"]

FLOOR = 0.6
"""Gap floor ``g`` of the velocity filter as a fraction of the thickness ``d`` (module docstring): above the
``d / 2`` the issue asks for, with room for the second-order terms of the straight-line step that the
linear prediction leaves out."""

CCD_FLOOR = 0.5
"""Distance floor of the fail-safe CCD as a fraction of the thickness: a pair that starts a step above
``CCD_FLOOR d`` does not end it below (the velocity filter's floor is :data:`FLOOR`; this one catches what
its linear prediction misses on long steps, e.g. a mass-scaled relaxation's)."""

APPROACH = 0.5
"""Largest fraction of its gap a pair may lose in one step after the velocity filter (the fail-safe CCD
allows ``1 - min_fraction = 0.8``, so the linear prediction has room for the path's curvature)."""


def _weights(g, is_pt):
    """Closest-point difference ``r (P, 3)`` and weights ``w (P, 4)`` from ``grad s = 2 w_k r`` ``(P, 4, 3)``
    (the first side's weights sum to 1: the point alone, or the first edge's two)."""
    r = 0.5 * np.where(is_pt[:, None], g[:, 0], g[:, 0] + g[:, 1])
    rr = np.einsum("pi,pi->p", r, r)
    w = np.einsum("pki,pi->pk", g, r) / (2.0 * np.where(rr > 0, rr, 1.0))[:, None]
    return r, w


class StepFilter:
    """The explicit step filter of self-contact (module docstring).

    Parameters
    ----------
    sc : :class:`~.law.SelfContact`
    minv : (N, 3) inverse nodal mass per dof [1/kg], zero on supported dofs
    approach : allowed fraction of its gap above the floor a pair may lose in a step (:data:`APPROACH`)
    floor : the gap floor as a fraction of the thickness (:data:`FLOOR`), in [0, 1)
    sweeps : Jacobi sweeps of the velocity filter
    """

    def __init__(self, sc, minv: np.ndarray, *, approach: float = APPROACH, floor: float = FLOOR, sweeps: int = 50):
        if not 0.0 < approach < 1.0 - sc.min_fraction:
            raise ValueError(f"approach must be in (0, {1.0 - sc.min_fraction:g}), got {approach!r}")
        if not 0.0 <= floor < 1.0:
            raise ValueError(f"floor must be in [0, 1), got {floor!r}")
        self.gap_floor = float(floor) * sc.thickness
        self.ccd_floor = min(CCD_FLOOR, float(floor)) * sc.thickness
        self.sc, self.minv, self.approach, self.sweeps = sc, np.asarray(minv, float), float(approach), int(sweeps)
        self.eta = sc.min_fraction
        with np.errstate(divide="ignore"):  # nodal mass per dof [kg], zero on supported dofs (for _kinetic)
            self._mass = np.where(self.minv > 0, 1.0 / np.where(self.minv > 0, self.minv, 1.0), 0.0)
        self._zeros = None
        self._bound = None  # (cache, its build count, motion at the last full test [m], sum of steps since [m])

    def __call__(self, cache: NearPairCache, x: np.ndarray, v: np.ndarray, dt: float) -> float:
        """Filter ``v (N, 3)`` [m/s] in place for the step ``x -> x + dt v`` from ``x (N, 3)`` [m]; return the
        kinetic energy removed [J]."""
        t0 = time.perf_counter()
        sc, stats = self.sc, cache.stats
        stats.filter_steps += 1
        try:
            return self._filter(sc, cache, x, v, dt, stats)
        finally:
            stats.filter_s += time.perf_counter() - t0

    def _filter(self, sc, cache, x, v, dt, stats) -> float:
        if self._quick_pass(cache, v, dt):
            return 0.0
        removed, m_max = self._full(sc, cache, x, v, dt, stats)
        step = _largest(v, self.sc.compiled) * dt
        self._bound = (cache, cache.builds, m_max, step)  # for the quick passes that follow
        return removed

    def _quick_pass(self, cache, v, dt) -> bool:
        """0. Whether the step passes on a running bound alone (one O(N) pass): since the last full test
        (translation-free motion ``m`` of the build then), every node has moved at most ``2 S``, ``S`` the
        sum of the steps' largest nodal moves (a step's own move plus at most as much again from the
        kinematic obstacle projection after it), so the translation-free motion is at most ``m + 6 S``
        (the midrange moves by at most sqrt(3) times the largest move) and a node's step relative to the
        midrange at most 3 times the largest move; the step passes when that keeps the list valid
        (``m + 6 S <= margin / 2``), needs no swept search and leaves every listed pair (lower bound
        ``min_dist - 2 (m + 6 S)``) beyond the approach limit: the tests 1-2 of the full path with
        bounds in place of the values. hang-20 with self-contact: the filter's time 0.29 ms a step."""
        b = self._bound
        if b is None or b[0] is not cache or b[1] != cache.builds:
            return False
        step = _largest(v, self.sc.compiled) * dt
        total = b[3] + step
        bound = b[2] + 6.0 * total
        if bound > 0.5 * cache.margin or 3.0 * step > 0.5 * cache.margin:
            return False
        if 6.0 * step > (1.0 - self.approach) * (cache.min_dist - 2.0 * bound - self.gap_floor):
            return False
        self._bound = (cache, cache.builds, b[2], total)
        return True

    def _full(self, sc, cache, x, v, dt, stats) -> tuple[float, float]:
        """Tests 1-4 (module docstring); the kinetic energy removed [J] and the largest motion since the build [m]."""
        d, half = sc.thickness, 0.5 * cache.margin
        dx = dt * v
        m_max, end_max, spread_max = cache.step_motions(sc.prims, x, dx, d)  # m_max <= margin / 2 now
        if end_max > half:
            cache.rebuild(sc.prims, x, d)  # 1. the list must cover the whole step
            m_max = 0.0
        extra = None
        if spread_max > half:
            stats.swept += 1
            extra = find_pairs(sc.prims, x, d, x + dx, compiled=sc.compiled)
        lb_min = cache.min_dist - 2.0 * m_max
        beta, g = 1.0 - self.approach, self.gap_floor
        if extra is None and 2.0 * spread_max <= beta * (lb_min - g):  # 2. quick test
            return 0.0, m_max
        m = cache.motion(x)[0]  # per node, since the build (zero after one at x)
        spread = translation_free_motion(dx, self._zero(dx), compiled=sc.compiled)[0]
        lb = cache.lower_bounds(m)
        pick = 2.0 * spread[cache.nodes].max(axis=1) > beta * (lb - g)
        nodes, is_pt = cache.nodes[pick], np.flatnonzero(pick) < len(cache.npt)
        if extra is not None:
            spt, see = pair_nodes(sc.prims, extra)
            nodes = np.concatenate([nodes, spt, see])
            is_pt = np.concatenate([is_pt, np.ones(len(spt), bool), np.zeros(len(see), bool)])
        if not len(nodes):
            return 0.0, m_max
        stats.filter_work_steps += 1
        k_before = self._kinetic(v)
        self._impulses(x, v, dt, nodes, is_pt, stats)
        self._fail_safe(cache, x, v, dt, m, nodes, is_pt, extra is not None, stats)
        return k_before - self._kinetic(v), m_max

    def _zero(self, like):
        """A zero array shaped as ``like (N, 3)`` (kept: the spread of a step is its motion from 0)."""
        if self._zeros is None or self._zeros.shape != like.shape:
            self._zeros = np.zeros_like(like)
        return self._zeros

    def _kinetic(self, v):
        return 0.5 * float(np.einsum("ni,ni,ni->", self._mass, v, v))

    def _impulses(self, x, v, dt, nodes, is_pt, stats):
        """3. Inelastic impulses ``J >= 0`` on the pairs ``nodes (P, 4)`` (module docstring), by active sets:
        the violated pairs ``S`` solve ``A_SS J_S = bound_S - v_n,S`` (``A = C M^-1 C^T``, ``C`` the rows
        ``w_k n`` of the pairs; conjugate gradients on the slightly regularised SPD system); pairs whose
        ``J < 0`` leave ``S``, pairs violated by the result join it; a few rounds, then Jacobi sweeps."""
        from scipy.sparse.linalg import cg

        x4 = x[nodes]
        g = np.empty((len(nodes), 4, 3))
        if np.any(is_pt):
            g[is_pt] = point_triangle(x4[is_pt], hessian=False, compiled=self.sc.compiled)[1]
        if not np.all(is_pt):
            g[~is_pt] = edge_edge(x4[~is_pt], hessian=False, compiled=self.sc.compiled)[1]
        r, w = _weights(g, is_pt)
        delta = np.sqrt(np.einsum("pi,pi->p", r, r))
        n = r / np.where(delta > 0, delta, 1.0)[:, None]
        bound = -self.approach * np.maximum(delta - self.gap_floor, 0.0) / dt
        if not np.any(np.einsum("pk,pki,pi->p", w, v[nodes], n) < bound):  # nothing approaches too fast
            return
        rows = w[:, :, None] * n[:, None, :]  # (P, 4, 3): d v_n / d v
        P = len(nodes)
        dof_g = (3 * nodes[:, :, None] + np.arange(3)).reshape(-1, 12)
        used, dof = np.unique(dof_g, return_inverse=True)  # the solve lives on the pairs' own dofs
        dof = dof.reshape(P, 12)
        minv = self.minv.ravel()[used]
        meff = np.einsum("pm,pm->p", rows.reshape(-1, 12) ** 2, minv[dof])
        movable = (delta > 0) & (meff > 0)
        C = _pair_rows(rows.reshape(P, 12), dof, len(used))
        v0 = v.reshape(-1)[used]  # a copy (fancy indexing)
        vn0 = C @ v0
        tol = 1e-9 * np.abs(bound).max(initial=0.0) + 1e-300

        def violated(vflat):
            return movable & (C @ vflat < bound - tol)

        S = violated(v0)
        J = np.zeros(P)
        vflat = v0
        for _ in range(8):
            if not S.any():
                break
            Cs = C[S]
            A = _gram(Cs, minv)
            Js, _ = cg(A, bound[S] - vn0[S], x0=J[S], rtol=1e-10, maxiter=400)
            J[:] = 0.0
            J[S] = np.maximum(Js, 0.0)
            vflat = v0 + minv * (C.T @ J)
            again = violated(vflat)
            if not again.any():
                break
            S = (J > 0) | again
        # the projection of v0 (kinetic metric) on the allowed velocities (0 among them) cannot add kinetic
        # energy: a solve that did (a redundant, inconsistent set of pairs) is dropped for the sweeps alone
        mass = np.where(minv > 0, 1.0 / np.where(minv > 0, minv, 1.0), 0.0)
        ke = lambda u: float(np.einsum("i,i,i->", mass, u, u))  # noqa: E731
        if np.all(np.isfinite(vflat)) and ke(vflat) <= ke(v0) * (1 + 1e-12):
            stats.impulses += int((J > 0).sum())
        else:
            stats.rejected_solves += 1
            vflat = v0
        for _ in range(self.sweeps):  # leftovers (a redundant set of pairs): Jacobi sweeps, no overshoot
            vn = C @ vflat
            bad = movable & (vn < bound - tol)
            if not np.any(bad):
                break
            cnt = np.bincount(nodes[bad].ravel(), minlength=len(v))
            share = cnt[nodes[bad]].max(axis=1)
            Jb = (bound[bad] - vn[bad]) / (meff[bad] * share)
            dv = (rows[bad] * Jb[:, None, None]).reshape(-1) * minv[dof[bad]].ravel()
            vflat = vflat + np.bincount(dof[bad].ravel(), dv, minlength=len(used))
            stats.impulses += int(bad.sum())
        np.put(v, used, vflat)  # flat indices into v (N, 3), C order

    def _fail_safe(self, cache, x, v, dt, m, nodes_checked, is_pt_checked, swept, stats):
        """4. Additive CCD on the pairs that the per-pair test picks for the filtered step."""
        dx = dt * v
        spread = translation_free_motion(dx, self._zero(dx), compiled=self.sc.compiled)[0]
        lb = cache.lower_bounds(m)
        floor = self.ccd_floor  # a pair's target is max(eta delta_0, floor) when it starts above the floor
        pick = 2.0 * spread[cache.nodes].max(axis=1) > lb - np.maximum(self.eta * lb, floor)
        q = len(cache.npt)
        pt_rows = cache.nodes[:q][pick[:q]]
        ee_rows = cache.nodes[q:][pick[q:]]
        if swept:  # the swept pairs are not in the list: check them all
            pt_rows = np.concatenate([pt_rows, nodes_checked[is_pt_checked]])
            ee_rows = np.concatenate([ee_rows, nodes_checked[~is_pt_checked]])
        t_pt = additive_ccd_nodes(x, dx, pt_rows, 0, self.eta, 200, floor, compiled=self.sc.compiled)
        t_ee = additive_ccd_nodes(x, dx, ee_rows, 1, self.eta, 200, floor, compiled=self.sc.compiled)
        t = min(1.0, t_pt, t_ee)
        if t < 1.0:
            v *= t
            stats.ccd_limited += 1
            stats.ccd_min_fraction = min(stats.ccd_min_fraction, t)


def _largest(v, compiled: bool | None = None) -> float:
    """``max_k |v_k|`` of ``v (N, 3)``; compiled (:func:`.kernels.largest_norm`: 54 -> ~5 us for the 6,561 nodes of
    pedestal-square-80, twice a step) when the self-contact twins are (``compiled``; None: by size). Its last bit
    may differ from numpy's: it only chooses between the quick pass and the full test, which then does nothing."""
    if distance.compiled_for(len(v), compiled):
        from rftstatic.contact.self_contact._kernels_numba import largest_norm

        return float(largest_norm(v))
    return float(np.sqrt(np.einsum("ni,ni->n", v, v).max(initial=0.0)))


DENSE_ENTRIES = 400_000
"""Largest ``P x m`` (pairs x their dofs) for which the velocity filter's pair rows are a dense matrix:
a few tens of pairs in contact, a step of the drop-floor pile, took 3.4 ms a step through scipy.sparse's
construction and checks, most of the filter's time."""


def _pair_rows(rows, dof, m):
    """The pairs' velocity rows ``C (P, m)`` (``rows (P, 12)`` at local dofs ``dof (P, 12)``): dense when
    small (:data:`DENSE_ENTRIES`), else CSR."""
    P = len(rows)
    if P * m <= DENSE_ENTRIES:
        C = np.zeros((P, m))
        np.add.at(C, (np.repeat(np.arange(P), 12), dof.ravel()), rows.ravel())
        return C
    import scipy.sparse as sp

    return sp.csr_matrix((rows.ravel(), (np.repeat(np.arange(P), 12), dof.ravel())), shape=(P, m))


def _gram(Cs, minv):
    """``A = C_S M^-1 C_S^T + eps I`` (``eps = 1e-8`` of its mean diagonal: the SPD system of the active set)."""
    if isinstance(Cs, np.ndarray):
        A = (Cs * minv) @ Cs.T
        A[np.diag_indices_from(A)] += 1e-8 * float(np.diagonal(A).mean())
        return A
    import scipy.sparse as sp

    A = (Cs.multiply(minv[None, :]) @ Cs.T).tocsr()
    return A + sp.identity(A.shape[0], format="csr") * (1e-8 * float(A.diagonal().mean()))
