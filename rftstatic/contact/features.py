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

    delta = sigma(psi) |r|,   psi = z / |r|,

``z`` the depth of the sheet's closest point behind the obstacle's surface at the feature (an edge: the wedge of
its two faces, ``max(r . n1, r . n2)``; a corner: the obstacle's signed distance at the corner + ``r``), so
``psi`` in [-1, 1] says how far into the obstacle ``r`` points, and ``sigma`` (:func:`side_factor`) is +1 outside
or on a face (``psi >= -SIDE_BAND[0]``), -1 behind the feature (``psi <= -SIDE_BAND[1]``: a sheet passing under
a rim, ``psi = -cos(bend / 2)``), a C1 cubic between. So a sheet that starts touching a rim (``delta = 0``, a
cloth laid on a table) or is pushed past it within a step is pushed back out, never further through (an unsigned
distance would push it on once it crossed), and the energy keeps growing behind the feature. ``delta`` is
continuous: a side read by a threshold (the first version: behind once ``z < -0.1 |r|``) made the energy jump by
``~2 k d |r|`` where a sheet resting on a face beside a rim was pressed into it (by the node penalty's
penetration), and an undamped explicit run of a collar on a form with its rims as features gained energy each
time a node crossed that surface (0.130 -> 1.12 J in 0.3 s). Energy and force are exact: ``grad delta = sigma
grad |r| + sigma' (dz/dr - psi r / |r|) . dr/dx``, the last term (only in the band, where ``sigma' != 0``) from
the kernels' Hessians (``dr/dx_b = 1/2 sum_k d2s/dx_k dx_b``). The tangent is the Gauss-Newton part ``e'' grad
delta grad delta^T`` (positive semi-definite): the remaining ``e' hess delta`` grows as ``1 / |r|`` for a sheet
edge touching an obstacle edge (parallel edges at zero distance make it singular), and with ``e' < 0`` its PSD
projection keeps little of it. Limitations: a corner's side uses the obstacle's signed distance (its faces near
the corner); a two-sided rim has no wedge (never behind).

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

SIDE_BAND = (0.05, 0.2)
"""The band of relative depths ``-psi`` (:func:`side_factor`) over which a pair's side turns from outside (+1) to
behind its feature (-1): a sheet resting on a face beside a rim, pressed into it by less than 5 % of its distance
from the rim, is outside; one passing under a rim bent by up to about 155 deg is behind (``cos(bend / 2) >= 0.2``)."""


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

    def _depth_gradient(self, kernel, x4, slot, r, w, xs, nz):
        """``dz/dx (P, m, 3)`` [-] over the sheet's ``m`` nodes of the pairs ``x4 (P, 4, 3)`` [m]: ``z`` the signed
        distance at the sheet's closest point ``c = sum_k w_k x_k`` (``nz (P, 3)`` its gradient), ``dc/dx_b = w_b I +
        sum_k x_k dw_k/dx_b``. From ``ds/dx_k = 2 w_k r``: ``dr/dx_b = 1/2 sum_k d2s/dx_k dx_b`` and ``dw_k/dx_b = (1/2
        d2s/dx_k dx_b - w_k dr/dx_b)^T r / |r|^2`` (the kernels' exact Hessians)."""
        _, _, H, _ = kernel(x4, hessian=True, compiled=self.compiled)
        m = xs.shape[1]
        idx = np.arange(12).reshape(4, 3)[slot].ravel()  # the sheet's dofs in x4
        Hs = H[:, idx][:, :, idx].reshape(len(x4), m, 3, m, 3)  # [p, k, i, b, l]
        drdx = 0.5 * Hs.sum(axis=1)  # [p, i, b, l]
        rr = r / np.maximum(np.einsum("pi,pi->p", r, r), 1e-300)[:, None]
        dw = np.einsum("pkibl,pi->pkbl", 0.5 * Hs, rr) - w[:, :, None, None] * np.einsum("pibl,pi->pbl", drdx, rr)[:, None]
        return w[:, :, None] * nz[:, None, :] + np.einsum("pk,pkbl->pbl", np.einsum("pki,pi->pk", xs, nz), dw)

    def evaluate(self, x: np.ndarray, *, tangent: bool = True, cache=None) -> FeatureState:
        """Energy, force and (``tangent``) the PSD node-pair blocks at ``x (N, 3)`` [m]."""
        n = len(x)
        force = np.zeros((n, 3))
        none = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3, 3)))
        if self.empty:
            return FeatureState(0.0, force, *none, np.inf)
        ee, pt = self._pairs(x, cache)
        energy, rows, cols, blocks, dmin = 0.0, [], [], [], np.inf
        parts = (  # (x4 rows, the sheet nodes, their slots in x4, the kernel, the features)
            (np.concatenate([x[self.edges[ee[:, 1]]], self.points[self.fedges[ee[:, 0]]]], axis=1),
             self.edges[ee[:, 1]], slice(0, 2), edge_edge, ee[:, 0]),
            (np.concatenate([self.points[self.corners[pt[:, 0]], None], x[self.tri[pt[:, 1]]]], axis=1),
             self.tri[pt[:, 1]], slice(1, 4), point_triangle, pt[:, 0]),
        )
        d, k = self.gap, self.stiffness
        for kind, (x4, nodes, slot, kernel, feature) in enumerate(parts):  # the two pair kinds
            if not len(x4):
                continue
            s, g, _, _ = kernel(x4, hessian=False, compiled=self.compiled)
            g, xs = g[:, slot], x4[:, slot]
            dist = np.sqrt(np.maximum(s, 0.0))
            r = 0.5 * g.sum(axis=1)  # sheet point - feature point: ds/dx_k = 2 w_k r, sum w_k = 1
            w = np.linalg.norm(g, axis=2) / (2.0 * np.maximum(dist, 1e-300))[:, None]  # barycentric weights (P, m)
            z, nz = self._depth(np.einsum("pk,pki->pi", w, xs))
            psi = np.clip(z / np.maximum(dist, 1e-300), -1.0, 1.0)
            side, slope = side_factor(psi)
            delta = side * dist
            dmin = min(dmin, float(delta.min()))
            act = delta < d
            if not act.any():
                continue
            delta, g, nodes, side, slope = delta[act], g[act], nodes[act], side[act], slope[act]
            dist, r, w, xs, nz, psi = dist[act], r[act], w[act], xs[act], nz[act], psi[act]
            gap = d - delta
            e1, e2 = -k / d * gap**2, 2.0 * k / d * gap  # dE/ddelta, d2E/ddelta2
            energy += float(np.sum(k / (3.0 * d) * gap**3))
            # grad delta = sigma grad |r| + sigma' (grad z - psi grad |r|), grad |r| = ds/dx / (2 |r|)
            gn = g / (2.0 * np.maximum(dist, 1e-300))[:, None, None]
            gd = gn * side[:, None, None]
            band = np.flatnonzero(slope != 0.0)
            if band.size:
                gd[band] += slope[band, None, None] * (self._depth_gradient(kernel, x4[act][band], slot, r[band],
                                                                            w[band], xs[band], nz[band])
                                                       - psi[band, None, None] * gn[band])
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


def side_factor(psi):
    """The side ``sigma (P,)`` of pairs whose relative depth is ``psi = z / |r| (P,)`` (:meth:`FeatureContact._depth`)
    and ``d sigma / d psi``: +1 (outside) for ``psi >= -SIDE_BAND[0]``, -1 (behind the feature) for ``psi <=
    -SIDE_BAND[1]``, a C1 cubic between, so that the signed distance ``sigma |r|`` is continuous (module docstring)."""
    lo, hi = SIDE_BAND
    u = np.clip((-psi - lo) / (hi - lo), 0.0, 1.0)
    return 1.0 - 2.0 * u * u * (3.0 - 2.0 * u), 12.0 * u * (1.0 - u) / (hi - lo)
