"""Contact of an obstacle's sharp features with the sheet between its nodes: edge-edge and corner-triangle pairs.

The node penalty (:mod:`rftstatic.contact.penalty`) keeps the sheet's *nodes* out of an obstacle; a sharp
edge of the obstacle (a table's rim, a box's edge: :meth:`rftstatic.contact.obstacles.Obstacle.sharp_features`)
can still cut through the sheet *between* nodes, and a corner through a triangle. Every pair of an obstacle
feature edge and a sheet edge, and of an obstacle corner and a sheet triangle, at distance ``delta`` below
the gap ``d`` [m] contributes

    E_f = k / (3 d) (d - delta)^3                                                [J]

(``k`` [N/m]: :data:`rftstatic.contact.penalty.FEATURE_STIFFNESS` times a node's penalty spring
``k_penalty A``): slope and curvature vanish at ``delta = d`` (C2 onset). ``delta`` is the distance of the
self-contact kernels (:mod:`rftstatic.contact.self_contact.distance`: exact squared distances ``s = |r|^2``
and gradients of the point-triangle and edge-edge pairs, the obstacle's points held; ``r`` [m] is the sheet's
closest point minus the feature's, ``r = 1/2 sum_k ds/dx_k`` over the sheet's nodes) *signed* by the side:

    delta = sigma |r|,   sigma = 1 - (1 - sigma_0(psi)) chi(|r| / d),   psi = z / |r|  (clipped to [-1, 1]),

``z`` [m] the obstacles' signed distance at a probe point of the sheet (a corner pair: the triangle's closest
point; an edge pair: :meth:`FeatureContact._probe`, at the crossing of a sheet edge under the feature), so ``psi``
says how far behind the surface the sheet lies relative to its distance from the feature; ``sigma_0``
(:func:`side_factor`) is +1 outside or on a face (``psi >= -SIDE_BAND[0]``), -1 behind the feature (``psi <=
-SIDE_BAND[1]``: a sheet passing under a 90 deg rim has ``psi = -0.71``), a C1 cubic between; ``chi`` (1 within
``d``, 0 beyond ``2 d``, C1) keeps the side local, so that every pair's energy vanishes before it leaves the pair
list. So a sheet that starts touching a rim (``delta = 0``, a cloth laid on a table) or is pushed past it within a
step is pushed back out, never further through (an unsigned distance would push it on once it crossed). ``delta``
is continuous: a side read by a threshold (the first version: behind once ``z < -0.1 |r|`` at the closest point)
made the energy jump by ``~2 k d |r|`` where a sheet resting on a face beside a rim was pressed into it (by the
node penalty's penetration), and an undamped explicit run of a collar on a form with its rims as features gained
energy each time a node crossed that surface (0.130 -> 1.12 J in 0.3 s). The probe is not the closest point: the
closest points of a sheet edge near parallel to a rim slide along it far faster than the nodes move (the gradient
of ``z`` there was 1000 x the force's scale). Energy and force are exact: ``grad delta = (sigma - sigma_0' chi psi
- |r| chi' (1 - sigma_0) / d) grad |r| + sigma_0' chi grad z``, ``grad |r| = ds/dx / (2 |r|)``, ``grad z`` the
obstacle's normal times the probe's derivative (a corner pair's from the kernel's Hessian, ``dr/dx_b = 1/2 sum_k
d2s/dx_k dx_b``). The tangent is the Gauss-Newton part ``e'' grad delta grad delta^T`` (positive semi-definite):
the remaining ``e' hess delta`` grows as ``1 / |r|`` for a sheet edge touching an obstacle edge (parallel edges at
zero distance make it singular), and with ``e' < 0`` its PSD projection keeps little of it. Limitations: at a sheet
edge exactly parallel to a feature edge the closest points jump from one end to the other, and ``r`` with them:
inside the band ``delta`` jumps there by ``|r|`` times the change of ``sigma`` (small: both ends lie at the same
distance); a rim bent by more than about 170 deg (``psi > -0.05`` under it) reads as outside.

Broad phase: the obstacle's feature edges are sampled at the sheet's mean edge length; a ``cKDTree`` of the
sheet's edge midpoints (triangle centroids) lists the pairs within ``d + margin``; the list is kept in the
solve's :class:`~rftstatic.contact.candidates.CandidateList` (``pairs``) and rebuilt once a node moved more
than ``margin / 2``: a pair left out is farther than ``d``, so the result is the same as with every pair.
"""

from __future__ import annotations

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.contact.self_contact.distance import edge_edge, point_triangle

__all__ = ["FeatureContact", "FeatureState", "SIDE_BAND", "side_factor"]

SIDE_BAND = (0.05, 0.5)
"""The band of relative depths ``-psi`` (:func:`side_factor`) over which a pair's side turns from outside (+1) to
behind its feature (-1): a sheet resting on a face beside a rim, pressed into it by less than 5 % of its distance
from the rim, is outside; one passing under a rim bent by up to 120 deg (``cos(bend / 2) >= 0.5``) is behind, and
more than half so up to about 150 deg. Wide, so that the signed distance's curvature, ``~ sigma_0'' / |r|``, stays
within ten times that of the distance itself (a band of width 0.15 was too stiff for the explicit step)."""


class FeatureState:
    """Feature contact at one configuration: ``energy`` [J], ``force (N, 3)`` [N], and the tangent as node
    pair blocks ``rows (B,), cols (B,), blocks (B, 3, 3)`` [N/m] (all node pairs of each active pair), and
    ``min_distance`` [m] over the listed pairs (inf without)."""

    def __init__(self, energy, force, rows, cols, blocks, min_distance):
        self.energy, self.force = energy, force
        self.rows, self.cols, self.blocks = rows, cols, blocks
        self.min_distance = min_distance


class FeatureContact:
    """Sharp features of the obstacles against the sheet's edges and triangles (module docstring).

    Parameters
    ----------
    obstacles : the obstacles; those whose ``sharp_features()`` is not None take part
    tri : (E, 3) the sheet's triangles
    edges : (M, 2) the sheet's unique edges
    X : (N, 3) reference positions [m] (edge lengths for the broad phase)
    gap : ``d`` [m]
    stiffness : ``k`` [N/m]
    margin : broad-phase margin [m]: pairs are listed within ``d + margin`` (by a lower bound of their
        distance) and the list is rebuilt once a node moved ``margin / 2``
    """

    def __init__(self, obstacles, tri, edges, X, gap: float, stiffness: float, margin: float):
        pts, fedges, corners, en, cn = [], [], [], [], []
        offset = 0
        for ob in obstacles:
            f = ob.sharp_features()
            if f is None:
                continue
            pts.append(np.asarray(f.points, float))
            fedges.append(np.asarray(f.edges, np.int64).reshape(-1, 2) + offset)
            corners.append(np.asarray(f.corners, np.int64).ravel() + offset)
            en.append(np.asarray(f.edge_normals, float).reshape(-1, 3))
            cn.append(np.asarray(f.corner_normals, float).reshape(-1, 3))
            offset += len(f.points)
        self.obstacles = [ob for ob in obstacles if ob.sharp_features() is not None]
        self.points = np.vstack(pts) if pts else np.zeros((0, 3))
        self.fedges = np.vstack(fedges) if fedges else np.zeros((0, 2), np.int64)
        self.corners = np.concatenate(corners) if corners else np.zeros(0, np.int64)
        self.edge_normals = np.vstack(en) if en else np.zeros((0, 3))
        self.corner_normals = np.vstack(cn) if cn else np.zeros((0, 3))
        self.tri, self.edges = np.asarray(tri, np.int64), np.asarray(edges, np.int64)
        self.gap, self.stiffness, self.margin = float(gap), float(stiffness), float(margin)
        self.compiled = numba_available()  # few pairs a call: the numpy path's ~0.5 ms a call would dominate
        length = np.linalg.norm(X[self.edges[:, 1]] - X[self.edges[:, 0]], axis=1)
        self.spacing = float(length.mean())
        # samples along every feature edge, no farther apart than the sheet's mean edge length
        a, b = self.points[self.fedges[:, 0]], self.points[self.fedges[:, 1]]
        n = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / self.spacing).astype(np.int64))
        owner = np.repeat(np.arange(len(self.fedges)), n + 1)
        t = (np.arange(int((n + 1).sum())) - np.repeat(np.cumsum(n + 1) - (n + 1), n + 1)) / np.repeat(n, n + 1)
        self.samples = a[owner] + t[:, None] * (b - a)[owner]
        self.sample_owner = owner
        self.sample_step = float(np.max(np.linalg.norm(b - a, axis=1) / n, initial=0.0))

    @property
    def empty(self) -> bool:
        return len(self.fedges) == 0 and len(self.corners) == 0

    def _pairs(self, x, cache):
        """The pairs that may be closer than ``d`` at ``x``: ``(edge pairs (P, 2): feature edge, sheet edge;
        corner pairs (Q, 2): corner, sheet triangle)``. The list holds the pairs whose distance bound
        (:meth:`_bounds`) was below ``d + margin`` at its build; since then a bound fell by at most 3 x the
        largest node motion (a midpoint or centroid moves as far as the nodes, a half length or radius
        changes by at most twice that), so comparing the stored bounds with that is enough at every step."""
        moved = np.inf
        if cache is not None and cache.pairs is not None:
            x0, listed = cache.pairs
            if x0.shape == x.shape:
                moved = float(np.sqrt(np.max(np.einsum("ni,ni->n", x - x0, x - x0), initial=0.0)))
        if moved > 0.5 * self.margin:
            listed, x0 = self._build(x), np.array(x, copy=True)
            moved = 0.0
            if cache is not None:
                cache.pairs = (x0, listed)
        ee, bee, pt, bpt = listed
        return ee[bee - 3.0 * moved < self.gap], pt[bpt - 3.0 * moved < self.gap]

    def _build(self, x):
        """Pairs within ``d + margin`` (by their bounds) and their bounds: ``(ee, bound_ee, pt, bound_pt)``."""
        from scipy.spatial import cKDTree

        reach = self.gap + self.margin
        mid = 0.5 * (x[self.edges[:, 0]] + x[self.edges[:, 1]])
        half = 0.5 * float(np.max(np.linalg.norm(x[self.edges[:, 1]] - x[self.edges[:, 0]], axis=1)))
        ee = np.zeros((0, 2), np.int64)
        if len(self.samples):
            m = cKDTree(self.samples).sparse_distance_matrix(cKDTree(mid), half + 0.5 * self.sample_step + reach,
                                                             output_type="ndarray")
            key = np.unique(self.sample_owner[m["i"]] * len(self.edges) + m["j"])  # a pair once
            ee = np.stack([key // len(self.edges), key % len(self.edges)], axis=1)
        pt = np.zeros((0, 2), np.int64)
        if len(self.corners):
            c = x[self.tri].mean(axis=1)
            r = float(np.max(np.linalg.norm(x[self.tri] - c[:, None, :], axis=2)))
            m = cKDTree(self.points[self.corners]).sparse_distance_matrix(cKDTree(c), r + reach, output_type="ndarray")
            pt = np.stack([m["i"], m["j"]], axis=1).astype(np.int64)
        bee, bpt = self._bounds(x, ee, pt)
        keep_e, keep_t = bee < reach, bpt < reach
        return ee[keep_e], bee[keep_e], pt[keep_t], bpt[keep_t]

    def _bounds(self, x, ee, pt):
        """Lower bounds of the pairs' distances [m]: from the segments' midpoints and half lengths, and the
        triangles' centroids and radii."""
        a, b = x[self.edges[ee[:, 1], 0]], x[self.edges[ee[:, 1], 1]]
        p, q = self.points[self.fedges[ee[:, 0], 0]], self.points[self.fedges[ee[:, 0], 1]]
        bee = (np.linalg.norm(0.5 * (a + b - p - q), axis=1)
               - 0.5 * (np.linalg.norm(b - a, axis=1) + np.linalg.norm(q - p, axis=1)))
        t = x[self.tri[pt[:, 1]]]
        c = t.mean(axis=1)
        bpt = (np.linalg.norm(self.points[self.corners[pt[:, 0]]] - c, axis=1)
               - np.max(np.linalg.norm(t - c[:, None], axis=2), axis=1, initial=0.0))
        return bee, bpt

    def _depth(self, c):
        """``z (P,)`` [m]: the obstacles' signed distance at the sheet's closest points ``c (P, 3)`` [m] (the least
        over the obstacles), and its gradient ``(P, 3)``, the normal there."""
        phis, normals = zip(*(ob.signed_distance(c) for ob in self.obstacles))
        k = np.argmin(np.stack(phis), axis=0)
        i = np.arange(len(c))
        return np.stack(phis)[k, i], np.stack(normals)[k, i]

    @staticmethod
    def _probe(x4):
        """The sheet points whose depth decides the side of edge pairs ``x4 (P, 4, 3)`` [m] (sheet edge ``a b``,
        feature edge ``p q``), ``(P, 3)`` [m], and their gradients ``dc/dx (P, 2, 3, 3)`` over ``a, b``: the point
        of the sheet edge nearest ``a*``, the point of the feature edge nearest the sheet edge's midpoint (both
        clamped to their edges). At a sheet edge crossing under the feature it lies at the crossing; unlike the
        closest points it moves no faster than the nodes (a sheet edge near parallel to the feature edge)."""
        a, b, p = x4[:, 0], x4[:, 1], x4[:, 2]
        w, e = x4[:, 3] - p, b - a
        ww = np.maximum(np.einsum("pi,pi->p", w, w), 1e-300)
        ee = np.maximum(np.einsum("pi,pi->p", e, e), 1e-300)
        t1 = np.einsum("pi,pi->p", 0.5 * (a + b) - p, w) / ww
        W = np.einsum("pi,pj->pij", w, w) * (((t1 > 0.0) & (t1 < 1.0)) / ww)[:, None, None]  # d a* / d midpoint
        s = p + np.clip(t1, 0.0, 1.0)[:, None] * w - a  # a* - a
        t2 = np.einsum("pi,pi->p", s, e) / ee
        inner = ((t2 > 0.0) & (t2 < 1.0)) / ee
        tc = np.clip(t2, 0.0, 1.0)
        We = 0.5 * np.einsum("pij,pj->pi", W, e)
        eye = np.eye(3)
        # dt2/da = (W e / 2 - e - s + 2 t2 e) / |e|^2, dt2/db = (W e / 2 + s - 2 t2 e) / |e|^2 (inside the edge)
        dta = (We - e - s + 2.0 * t2[:, None] * e) * inner[:, None]
        dtb = (We + s - 2.0 * t2[:, None] * e) * inner[:, None]
        dca = (1.0 - tc)[:, None, None] * eye + np.einsum("pi,pj->pij", e, dta)  # [p, i (c), j (x_a)]
        dcb = tc[:, None, None] * eye + np.einsum("pi,pj->pij", e, dtb)
        return a + tc[:, None] * e, np.stack([dca, dcb], axis=1)

    def _corner_gradient(self, x4, nz):
        """``dz/dx (P, 3, 3)`` [-] over the triangle's nodes of corner pairs ``x4 (P, 4, 3)`` [m]: ``z`` the signed
        distance at the triangle's point closest to the corner (``nz (P, 3)`` its gradient there), ``dr/dx_b = 1/2
        sum_k d2s/dx_k dx_b`` (from ``ds/dx_k = 2 w_k r``, the kernel's exact Hessian)."""
        _, _, H, _ = point_triangle(x4, hessian=True, compiled=self.compiled)
        idx = np.arange(3, 12)  # the triangle's dofs in x4
        drdx = 0.5 * H[:, idx][:, :, idx].reshape(len(x4), 3, 3, 3, 3).sum(axis=1)  # [p, i, b, l]
        return np.einsum("pi,pibl->pbl", nz, drdx)

    def evaluate(self, x: np.ndarray, *, tangent: bool = True, cache=None) -> FeatureState:
        """Energy, force and (``tangent``) the PSD node-pair blocks at ``x (N, 3)`` [m]."""
        n = len(x)
        force = np.zeros((n, 3))
        none = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3, 3)))
        if self.empty:
            return FeatureState(0.0, force, *none, np.inf)
        ee, pt = self._pairs(x, cache)
        energy, rows, cols, blocks, dmin = 0.0, [], [], [], np.inf
        parts = (  # (x4 rows, the sheet nodes, their slots in x4, the kernel)
            (np.concatenate([x[self.edges[ee[:, 1]]], self.points[self.fedges[ee[:, 0]]]], axis=1),
             self.edges[ee[:, 1]], slice(0, 2), edge_edge),
            (np.concatenate([self.points[self.corners[pt[:, 0]], None], x[self.tri[pt[:, 1]]]], axis=1),
             self.tri[pt[:, 1]], slice(1, 4), point_triangle),
        )
        d, k = self.gap, self.stiffness
        for kind, (x4, nodes, slot, kernel) in enumerate(parts):  # the two pair kinds
            if not len(x4):
                continue
            s, g, _, _ = kernel(x4, hessian=False, compiled=self.compiled)
            g = g[:, slot]
            dist = np.sqrt(np.maximum(s, 0.0))
            r = 0.5 * g.sum(axis=1)  # sheet point - feature point: ds/dx_k = 2 w_k r, sum w_k = 1
            if kind == 0:
                c, dc = self._probe(x4)
            else:
                c, dc = x4[:, 0] + r, None
            z, nz = self._depth(c)
            psi = np.clip(z / np.maximum(dist, 1e-300), -1.0, 1.0)
            side, slope = side_factor(psi)
            reach, reach_slope = _cubic_step(dist / d - 1.0)  # chi(|r| / d): 1 within d, 0 beyond 2 d
            side, slope, fade = 1.0 - (1.0 - side) * reach, slope * reach, (1.0 - side) * reach_slope
            delta = side * dist
            dmin = min(dmin, float(delta.min()))
            act = delta < d
            if not act.any():
                continue
            delta, g, nodes, side, slope, fade = delta[act], g[act], nodes[act], side[act], slope[act], fade[act]
            dist, nz, psi = dist[act], nz[act], psi[act]
            gap = d - delta
            e1, e2 = -k / d * gap**2, 2.0 * k / d * gap  # dE/ddelta, d2E/ddelta2
            energy += float(np.sum(k / (3.0 * d) * gap**3))
            # grad delta (module docstring); slope = sigma_0' chi, fade = (1 - sigma_0) chi'
            gd = g * ((side - dist * fade / d - slope * psi) / (2.0 * np.maximum(dist, 1e-300)))[:, None, None]
            band = np.flatnonzero(slope != 0.0)
            if band.size:
                if kind == 0:
                    dz = np.einsum("pi,pbij->pbj", nz[band], dc[act][band])
                else:
                    dz = self._corner_gradient(x4[act][band], nz[band])
                gd[band] += slope[band, None, None] * dz
            fn = (e1[:, None, None] * gd).reshape(-1, 3)
            for i in range(3):  # the three components
                force[:, i] += np.bincount(nodes.ravel(), fn[:, i], minlength=n)
            if tangent:  # Gauss-Newton: e'' grad delta grad delta^T, PSD (module docstring)
                m = nodes.shape[1]
                gs = gd.reshape(len(delta), -1)
                B = (e2[:, None, None] * np.einsum("pi,pj->pij", gs, gs)).reshape(len(delta), m, 3, m, 3)
                rows.append(np.repeat(nodes, m, axis=1).ravel())
                cols.append(np.tile(nodes, (1, m)).ravel())
                blocks.append(B.transpose(0, 1, 3, 2, 4).reshape(-1, 3, 3))  # (P, a, b, 3, 3) -> node pairs
        if rows:
            return FeatureState(energy, force, np.concatenate(rows), np.concatenate(cols), np.concatenate(blocks), dmin)
        return FeatureState(energy, force, *none, dmin)


def _cubic_step(u):
    """``1 - 3 u^2 + 2 u^3`` on ``u`` in [0, 1] (1 below, 0 above) and its derivative: a C1 step down."""
    u = np.clip(u, 0.0, 1.0)
    return 1.0 - u * u * (3.0 - 2.0 * u), -6.0 * u * (1.0 - u)


def side_factor(psi):
    """The side ``sigma_0 (P,)`` of pairs whose relative depth is ``psi = z / |r| (P,)`` (module docstring) and ``d
    sigma_0 / d psi``: +1 (outside) for ``psi >= -SIDE_BAND[0]``, -1 (behind the feature) for ``psi <=
    -SIDE_BAND[1]``, a C1 cubic between, so that the signed distance is continuous."""
    lo, hi = SIDE_BAND
    step, slope = _cubic_step((-psi - lo) / (hi - lo))
    return 2.0 * step - 1.0, -2.0 * slope / (hi - lo)
