"""Contact of an obstacle's sharp features with the sheet between its nodes: edge-edge and corner-triangle pairs.

The node penalty (:mod:`rftstatic.contact.penalty`) keeps the sheet's *nodes* out of an obstacle; a sharp
edge of the obstacle (a table's rim, a box's edge: :meth:`rftstatic.contact.obstacles.Obstacle.sharp_features`)
can still cut through the sheet *between* nodes, and a corner through a triangle. Every pair of an obstacle
feature edge and a sheet edge, and of an obstacle corner and a sheet triangle, at distance ``delta`` below
the gap ``d`` [m] contributes

    E_f = k / (3 d) (d - delta)^3                                                [J]

(``k`` [N/m]: :data:`rftstatic.contact.penalty.FEATURE_STIFFNESS` times a node's penalty spring
``k_penalty A``): slope and curvature vanish at ``delta = d`` (C2 onset). ``delta`` is the distance of the
self-contact kernels (:mod:`rftstatic.contact.self_contact.distance`: exact squared distances and gradients
of the point-triangle and edge-edge pairs, the obstacle's points held), *signed* by the
side: negative when the sheet's closest point lies inside the obstacle (its signed distance, by more than
:data:`SIDE_DEPTH` of the pair's distance). So a sheet that starts touching a rim (``delta = 0``, a cloth laid on a table) or is pushed past
it within a step is pushed back out, never further through (an unsigned distance would push it on once it
crossed), and the energy keeps growing behind the feature. Energy and force are exact (``grad delta =
+-grad s / (2 |delta|)``); the tangent is the Gauss-Newton part ``e'' grad delta grad delta^T`` (positive
semi-definite): the remaining ``e' hess delta`` grows as ``1 / delta`` for a sheet edge touching an obstacle
edge (parallel edges at zero distance make it singular), and with ``e' < 0`` its PSD projection keeps
little of it. Limitation: the side is read at one point; a sheet edge passing under a 90 deg rim exactly
along one of its faces' planes has that point on the surface (``phi = 0``) and reads as outside (the
independent crossing check, :mod:`rftstatic.post.measures.obstacle_crossings`, would count it).

Broad phase: the obstacle's feature edges are sampled at the sheet's mean edge length; a ``cKDTree`` of the
sheet's edge midpoints (triangle centroids) lists the pairs within ``d + margin``; the list is kept in the
solve's :class:`~rftstatic.contact.candidates.CandidateList` (``pairs``) and rebuilt once a node moved more
than ``margin / 2``: a pair left out is farther than ``d``, so the result is the same as with every pair.
"""

from __future__ import annotations

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.contact.self_contact.distance import edge_edge, point_triangle

__all__ = ["FeatureContact", "FeatureState", "SIDE_DEPTH"]

SIDE_DEPTH = 0.1
"""A pair is behind its feature when the sheet's closest point lies inside the obstacle deeper than this
fraction of the pair's distance (:meth:`FeatureContact._side`): a sheet resting on a face beside a rim is not,
one passing under a rim bent by up to about 170 deg is."""


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

    def _side(self, xs, g, delta):
        """-1 for the pairs (sheet points ``xs (P, m, 3)``, their ``ds/dx`` ``g (P, m, 3)``, distances ``delta (P,)``)
        whose sheet closest point lies inside an obstacle deeper than ``SIDE_DEPTH |delta|``, else +1. The
        closest point is the sheet nodes weighted by ``|ds/dx_k|`` (``2 w_k (c_sheet - c_feature)``, ``w_k`` its
        barycentric weights). A sheet lying on a face next to a rim has its closest point on the face
        (``phi ~ 0``): outside; one passing under a rim has it inside, about ``|delta| cos(half the rim angle)``
        deep."""
        if len(self.obstacles) == 0 or not len(xs):
            return np.ones(len(xs))
        w = np.linalg.norm(g, axis=2)
        tot = w.sum(axis=1, keepdims=True)
        w = np.where(tot > 0, w / np.where(tot > 0, tot, 1.0), 1.0 / xs.shape[1])
        c = np.einsum("pk,pki->pi", w, xs)
        phi = np.min([ob.signed_distance(c)[0] for ob in self.obstacles], axis=0)
        return np.where(phi < -SIDE_DEPTH * delta, -1.0, 1.0)

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
        for x4, nodes, slot, kernel in parts:  # the two pair kinds
            if not len(x4):
                continue
            s, g, _, _ = kernel(x4, hessian=False, compiled=self.compiled)
            g = g[:, slot]
            delta = np.sqrt(np.maximum(s, 0.0))
            side = self._side(x4[:, slot], g, delta)
            delta = side * delta
            dmin = min(dmin, float(delta.min()))
            act = delta < d
            if not act.any():
                continue
            delta, g, nodes, side = delta[act], g[act], nodes[act], side[act]
            gap = d - delta
            e1, e2 = -k / d * gap**2, 2.0 * k / d * gap  # dE/ddelta, d2E/ddelta2
            energy += float(np.sum(k / (3.0 * d) * gap**3))
            gd = g * (side / (2.0 * np.maximum(np.abs(delta), 1e-300)))[:, None, None]  # grad delta = +-grad s / (2 |delta|)
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
