"""Continuous collision detection of the sheet against an obstacle's sharp edges and corners within a step.

The explicit analyses' kinematic contact (:func:`rftstatic.contact.kinematic.kinematic_contact`) stops a node
whose straight step crossed the obstacle's surface; a sheet *edge* can still sweep over a sharp edge of the
obstacle (a table's rim, :meth:`rftstatic.contact.obstacles.Obstacle.sharp_features`) between its nodes: its
two nodes land on either side of the rim, the rim cuts through the sheet. Here every pair of an obstacle
feature edge ``p q`` (held) and a sheet edge ``a b`` whose nodes move along their straight steps ``a(t) = a0 + t
da``, ``b(t) = b0 + t db``, ``0 <= t <= 1``, is tested exactly: the two segments can only meet where they are
coplanar, where

    f(t) = (q - p) . ((a(t) - p) x (b(t) - p)) = c0 + c1 t + c2 t^2 = 0,

``c0 = w . (A x B)``, ``c1 = w . (A x db + da x B)``, ``c2 = w . (da x db)`` (``w = q - p``, ``A = a0 - p``,
``B = b0 - p``): a quadratic, solved in closed form. At each root in ``[0, 1]`` (ascending) the segments meet when
their closest points coincide (within :data:`TOUCH` of the sheet edge's length) inside the rim and inside the
sheet edge away from its nodes (:data:`END`: a node on the rim is the node contact's, and a sheet edge pivoting
about it is no crossing); the first such root is the pair's crossing time ``t*``. A sheet edge that starts
touching the rim (``|c0|`` round-off) is on the side the rim's outward normal ``n_f`` points to; it crosses
only when ``f`` leaves that side (``sign f`` after the root opposite ``sign (w . (n_f x (b0 - a0)))``, the
sign ``f`` takes when the edge is moved along ``n_f``).

A pair that crosses within the step is lifted at the step's end, as the node contact projects a node: the sheet's
point nearest the feature (barycentric weights ``w_k`` of the edge's or triangle's nodes, closest parameter of
the two segments or the corner's projection) moves by ``depth n``, ``n`` the unit normal of the edge pair's plane
(``(q - p) x (b - a)``) or of the triangle, on the feature's outer side (``n . n_f > 0``), ``depth`` what puts it
:data:`SHY` of the sheet edge's length clear of the feature: node ``k`` moves ``w_k depth n / sum_j w_j^2``
(averaged over its pairs). So a sheet edge can pivot about a rim (its nodes move in opposite senses about the
contact point) instead of stopping where it met it; the pairs are tested again along the corrected steps until
none crosses (:data:`ROUNDS`). The contact point's velocity towards the feature is then removed the same way
(``v_k <- v_k - w_k min(v_c . n, 0) n / sum_j w_j^2``, ``v_c = sum_k w_k v_k``).

A corner ``p`` of the obstacle (outward normal ``n_c``) against a moving sheet triangle ``a b c`` is the same with
the cubic ``f(t) = (p - a) . ((b - a) x (c - a))`` (:func:`unit_roots`: its critical points cut [0, 1] into
monotone pieces, each root bisected), the corner inside the triangle at the root, outside ``-sign(n_c . N)``
for a triangle that starts touching it (``N`` its normal): a corner poking up through a triangle's interior
crosses none of its edges.

Broad phase (each step): a node moves at most ``s = max |x1 - x0|``, so a sheet edge stays within ``l / 2 + s``
of its starting midpoint (``l`` the longest sheet edge at ``x0``); the feature edges' samples (spaced at most
``sample_step``) within that plus ``sample_step / 2`` give every edge pair that can meet within the step, the
corners within a triangle's largest radius plus ``s`` of its centroid every corner pair.
"""

from __future__ import annotations

from itertools import chain

import numpy as np

__all__ = ["END", "ROUNDS", "SHY", "TOUCH", "FeatureSweep", "corner_crossing_times", "edge_crossing_times",
           "unit_roots"]

ROUNDS = 8
"""Rounds of crossing tests and lifts along the corrected steps."""

TOUCH = 1e-9
"""Segments whose closest points lie within this fraction of the sheet edge's length meet."""

SHY = 1e-6
"""A lifted sheet edge or triangle ends this fraction of its (edge) length clear of the feature, on its outer side:
its next step starts outside. Small: each lift of a sheet resting on a rim moves its nodes against the neighbouring
ones, and a clearance of 1e-3 lengths a lift pumped strain energy into a table cloth relaxing over a table's rim
(the explicit energy check stopped it at 1.16 s; 1e-6: stable, validation/mesh_obstacles.md)."""

END = 1e-6
"""A meeting point within this fraction of the sheet edge's length of one of its nodes is the node's contact."""


def _cross(u, v):
    return np.cross(u, v)


def _dot(u, v):
    return np.einsum("pi,pi->p", u, v)


def _closest_params(a, b, p, q):
    """Parameters ``(s, u)`` of the closest points of the segments ``a b`` and ``p q`` ``(P, 3)`` (clamped)."""
    d1, d2, r = b - a, q - p, a - p
    aa, ee, bb = _dot(d1, d1), _dot(d2, d2), _dot(d1, d2)
    c, f = _dot(d1, r), _dot(d2, r)
    aa, ee = np.maximum(aa, 1e-300), np.maximum(ee, 1e-300)
    den = aa * ee - bb * bb
    par = den <= 1e-14 * aa * ee
    s = np.where(par, 0.0, np.clip((bb * f - c * ee) / np.where(par, 1.0, den), 0.0, 1.0))
    u = (bb * s + f) / ee
    s = np.where(u < 0.0, np.clip(-c / aa, 0.0, 1.0), np.where(u > 1.0, np.clip((bb - c) / aa, 0.0, 1.0), s))
    return s, np.clip(u, 0.0, 1.0)


def _poly(c, t):
    """``c[:, 0] + c[:, 1] t + c[:, 2] t^2 + c[:, 3] t^3`` for ``c (P, 4)``, ``t (P,)``."""
    return c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))


def _quadratic_roots(c: np.ndarray) -> np.ndarray:
    """The real roots ``(P, 2)`` (``inf`` padded) of ``c[:, 0] + c[:, 1] t + c[:, 2] t^2`` (the stable pair
    ``q / c2``, ``c0 / q`` with ``q = -(c1 + sign(c1) sqrt(disc)) / 2``; ``-c0 / c1`` where ``c2`` vanishes)."""
    c0, c1, c2 = c[:, 0], c[:, 1], c[:, 2]
    disc = c1 * c1 - 4.0 * c2 * c0
    q = -0.5 * (c1 + np.where(c1 >= 0, 1.0, -1.0) * np.sqrt(np.maximum(disc, 0.0)))
    quad, lin = (c2 != 0) & (disc >= 0), (c2 == 0) & (c1 != 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(quad, q / c2, np.where(lin, -c0 / c1, np.inf))
        r2 = np.where(quad & (q != 0), c0 / q, np.inf)
    return np.nan_to_num(np.column_stack([r1, r2]), nan=np.inf)


def unit_roots(c: np.ndarray, rounds: int = 44) -> np.ndarray:
    """The real roots ``(P, 3)`` in [0, 1] (ascending, ``inf`` padded) of the cubics ``c (P, 4)`` (coefficients
    of ``1, t, t^2, t^3``). A quadratic (``c3 = 0``: the edge pairs) in closed form (:func:`_quadratic_roots`,
    roots within 1e-12 below 0 taken as 0); a cubic by its critical points, which cut [0, 1] into monotone
    pieces: a piece whose ends differ in sign (or touch 0) holds one root, found by bisection to ``2^-rounds``."""
    P = len(c)
    roots = np.full((P, 3), np.inf)
    sq = np.flatnonzero(c[:, 3] == 0)
    if sq.size:
        r = _quadratic_roots(c[sq])
        r = np.where((r >= -1e-12) & (r <= 1.0), np.maximum(r, 0.0), np.inf)
        roots[sq, :2] = r
    cu = np.flatnonzero(c[:, 3] != 0)
    if cu.size:
        roots[cu] = _cubic_unit_roots(c[cu], rounds)
    return np.sort(roots, axis=1)


def _cubic_unit_roots(c: np.ndarray, rounds: int) -> np.ndarray:
    """:func:`unit_roots` of proper cubics, by bisection on the monotone pieces."""
    P = len(c)
    with np.errstate(divide="ignore", invalid="ignore"):
        A, B, C = 3.0 * c[:, 3], 2.0 * c[:, 2], c[:, 1]  # f' = A t^2 + B t + C
        disc = B * B - 4.0 * A * C
        sq = np.sqrt(np.maximum(disc, 0.0))
        quad = np.abs(A) > 1e-300
        cp1 = np.where(quad, (-B - sq) / (2.0 * A), np.where(np.abs(B) > 1e-300, -C / B, np.nan))
        cp2 = np.where(quad, (-B + sq) / (2.0 * A), np.nan)
        cps = np.where((disc >= 0) | ~quad, np.stack([cp1, cp2], axis=1).T, np.nan).T
    cps = np.where((cps > 0.0) & (cps < 1.0), cps, 1.0)
    knots = np.sort(np.column_stack([np.zeros(P), cps, np.ones(P)]), axis=1)  # (P, 4)
    roots = np.full((P, 3), np.inf)
    lo, hi = knots[:, :3].ravel(), knots[:, 1:].ravel()  # the 3 pieces of every cubic, bisected together
    flo, fhi = _poly(np.repeat(c, 3, axis=0), lo), _poly(np.repeat(c, 3, axis=0), hi)
    first = np.tile([True, False, False], P)
    i = np.flatnonzero((hi > lo) & (flo * fhi <= 0.0) | (first & (flo == 0.0)))
    if i.size:
        ci, lo, hi, flo = c[i // 3], lo[i], hi[i], flo[i]
        for _ in range(rounds):
            mid = 0.5 * (lo + hi)
            fm = _poly(ci, mid)
            left = (flo == 0.0) | (np.sign(fm) != np.sign(flo))
            hi, lo = np.where(left, mid, hi), np.where(left, lo, mid)
            flo = np.where(left, flo, fm)
        roots.ravel()[i] = np.where(flo == 0.0, lo, hi)
    return roots


def _first(c, side, meets, tol):
    """The first root ``t*`` of the cubics ``c (P, 4)`` at which ``meets(i, t)`` (the pairs ``i`` meet at times
    ``t``) and ``f`` leaves its ``side`` (the sign it has outside); ``inf`` for none. A cubic that vanishes
    throughout (all coefficients within ``tol (P,)``: moving within the feature's plane) crosses nothing."""
    out = np.full(len(c), np.inf)
    live = (side != 0) & (np.abs(c).max(axis=1) > tol)
    roots = unit_roots(c)
    for k in range(3):
        t = roots[:, k]
        i = np.flatnonzero(live & np.isinf(out) & np.isfinite(t))
        if not i.size:
            continue
        tt = t[i]
        after = _poly(c[i], np.minimum(tt + 1e-9, 1.0 + 1e-9))
        slope = c[i, 1] + tt * (2.0 * c[i, 2] + 3.0 * tt * c[i, 3])
        leaves = (np.sign(after) != side[i]) | (side[i] * slope < 0)
        hit = leaves & meets(i, tt)
        out[i[hit]] = tt[hit]
    return out


def edge_crossing_times(a0, b0, da, db, p, q, n_f) -> np.ndarray:
    """First time ``t* (P,)`` in [0, 1] at which the moving sheet edges ``a0 + t da, b0 + t db`` ``(P, 3)`` [m]
    cross the fixed feature edges ``p q`` ``(P, 3)`` [m] whose outward normals are ``n_f (P, 3)``; ``inf`` where
    they do not (module docstring)."""
    w, A, B = q - p, a0 - p, b0 - p
    c = np.column_stack([_dot(w, _cross(A, B)), _dot(w, _cross(A, db) + _cross(da, B)), _dot(w, _cross(da, db)),
                         np.zeros(len(a0))])
    L = np.linalg.norm(b0 - a0, axis=1)
    tol = 1e-12 * np.linalg.norm(w, axis=1) * L * (L + np.linalg.norm(da, axis=1) + np.linalg.norm(db, axis=1))
    side = np.where(np.abs(c[:, 0]) > tol, np.sign(c[:, 0]), np.sign(_dot(w, _cross(n_f, b0 - a0))))

    def meets(i, t):
        a, b = a0[i] + t[:, None] * da[i], b0[i] + t[:, None] * db[i]
        s, u = _closest_params(a, b, p[i], q[i])
        gap = a + s[:, None] * (b - a) - p[i] - u[:, None] * w[i]
        return (np.linalg.norm(gap, axis=1) <= TOUCH * L[i]) & (s > END) & (s < 1.0 - END)
    return _first(c, side, meets, tol)


def corner_crossing_times(a0, b0, c0, da, db, dc, p, n_c) -> np.ndarray:
    """First time ``t* (P,)`` in [0, 1] at which the fixed corners ``p (P, 3)`` [m] (outward normals ``n_c``) pass
    through the moving sheet triangles ``a0 + t da, b0 + t db, c0 + t dc`` ``(P, 3)`` [m], ``inf`` where they do
    not: the roots of the cubic ``f(t) = (p - a) . ((b - a) x (c - a))`` (module docstring) where the corner lies
    inside the triangle away from its edges (:data:`END`: those are the edge pairs')."""
    U0, W0, R0 = b0 - a0, c0 - a0, p - a0
    dU, dW = db - da, dc - da
    N0, N1, N2 = _cross(U0, W0), _cross(U0, dW) + _cross(dU, W0), _cross(dU, dW)
    c = np.column_stack([_dot(R0, N0), _dot(R0, N1) - _dot(da, N0), _dot(R0, N2) - _dot(da, N1), -_dot(da, N2)])
    L = np.sqrt(np.linalg.norm(N0, axis=1))
    move = np.max(np.linalg.norm(np.stack([da, db, dc]), axis=2), axis=0)
    tol = 1e-12 * (L + move) ** 3
    side = np.where(np.abs(c[:, 0]) > tol, np.sign(c[:, 0]), -np.sign(_dot(n_c, N0)))

    def meets(i, t):
        a, b, cc = a0[i] + t[:, None] * da[i], b0[i] + t[:, None] * db[i], c0[i] + t[:, None] * dc[i]
        n = _cross(b - a, cc - a)
        nn = _dot(n, n)
        inside = np.ones(len(i), bool)
        for u, v in ((a, b), (b, cc), (cc, a)):  # barycentric weight of the corner opposite each edge
            inside &= _dot(_cross(v - u, p[i] - u), n) > END * nn
        return inside & (nn > 0)
    return _first(c, side, meets, tol)


class FeatureSweep:
    """Sharp edges of the obstacles against the sheet's edges along a step (module docstring).

    Parameters
    ----------
    features : :class:`rftstatic.contact.features.FeatureContact` (its points, feature edges and normals, edge
        samples, and the sheet's edges)
    """

    def __init__(self, features):
        from scipy.spatial import cKDTree

        self.f = features
        self._stree = cKDTree(features.samples) if len(features.samples) else None
        self._ctree = cKDTree(features.points[features.corners]) if len(features.corners) else None
        used = features.points[np.unique(features.fedges)] if len(features.fedges) else np.zeros((1, 3))
        self._lo, self._hi = used.min(axis=0), used.max(axis=0)  # the features' box (sheet parts beyond: no query)

    @classmethod
    def for_sheet(cls, obstacles, tri, edges, X):
        """The sweep of the obstacles' sharp edges against a sheet of triangles ``tri (E, 3)``, unique edges
        ``edges (M, 2)`` at reference positions ``X (N, 3)`` [m]; None when no obstacle has sharp edges."""
        from rftstatic.contact.features import FeatureContact

        obstacles = [ob for ob in obstacles if getattr(ob, "sharp_features", lambda: None)() is not None]
        if not obstacles:
            return None
        fc = FeatureContact(obstacles, tri, edges, np.asarray(X, float), gap=0.0, stiffness=0.0, margin=0.0)
        return cls(fc) if len(fc.fedges) else None

    def pairs(self, x0, x1):
        """Pairs that may meet on the step ``x0 -> x1`` ``(N, 3)`` [m]: ``(ee (P, 2)`` feature edge, sheet edge;
        ``pt (Q, 2)`` corner, sheet triangle``)``."""
        f = self.f
        s = float(np.sqrt(np.max(np.einsum("ni,ni->n", x1 - x0, x1 - x0), initial=0.0)))
        a, b = x0[f.edges[:, 0]], x0[f.edges[:, 1]]
        half = 0.5 * float(np.max(np.linalg.norm(b - a, axis=1), initial=0.0))
        reach = half + s + 0.5 * f.sample_step + 1e-12 * (1 + half)
        mid = 0.5 * (a + b)
        near = np.flatnonzero(np.all((mid > self._lo - reach) & (mid < self._hi + reach), axis=1))
        lists = self._stree.query_ball_point(mid[near], reach)
        counts = np.fromiter(map(len, lists), np.int64, len(lists))
        ee = np.zeros((0, 2), np.int64)
        if counts.sum():
            samples = np.fromiter(chain.from_iterable(lists), np.int64, int(counts.sum()))
            key = np.unique(f.sample_owner[samples] * len(f.edges) + np.repeat(near, counts))
            ee = np.stack([key // len(f.edges), key % len(f.edges)], axis=1)
        pt = np.zeros((0, 2), np.int64)
        if self._ctree is not None:
            t = x0[f.tri]
            c = t.mean(axis=1)
            r = float(np.max(np.linalg.norm(t - c[:, None], axis=2)))
            reach = r + s + 1e-12 * (1 + r)
            near = np.flatnonzero(np.all((c > self._lo - reach) & (c < self._hi + reach), axis=1))
            lists = self._ctree.query_ball_point(c[near], reach)
            counts = np.fromiter(map(len, lists), np.int64, len(lists))
            if counts.sum():
                corners = np.fromiter(chain.from_iterable(lists), np.int64, int(counts.sum()))
                pt = np.stack([corners, np.repeat(near, counts)], axis=1)
        # a pair can only meet if its distance at x0 (bounded below by the midpoints and half lengths, the centroid
        # and radius) is within the step of its sheet nodes (the features are held)
        step = np.sqrt(np.einsum("ni,ni->n", x1 - x0, x1 - x0))
        if len(ee):
            a, b = x0[f.edges[ee[:, 1], 0]], x0[f.edges[ee[:, 1], 1]]
            p, q = f.points[f.fedges[ee[:, 0], 0]], f.points[f.fedges[ee[:, 0], 1]]
            bound = (np.linalg.norm(0.5 * (a + b - p - q), axis=1)
                     - 0.5 * (np.linalg.norm(b - a, axis=1) + np.linalg.norm(q - p, axis=1)))
            ee = ee[bound <= step[f.edges[ee[:, 1]]].max(axis=1) * (1 + 1e-9) + 1e-12 * (1 + half)]
        if len(pt):
            t = x0[f.tri[pt[:, 1]]]
            c = t.mean(axis=1)
            bound = np.linalg.norm(f.points[f.corners[pt[:, 0]]] - c, axis=1) - np.linalg.norm(
                t - c[:, None], axis=2).max(axis=1)
            pt = pt[bound <= step[f.tri[pt[:, 1]]].max(axis=1) * (1 + 1e-9) + 1e-12 * (1 + half)]
        return ee, pt

    def times(self, x0, x1, ee, pt):
        """Crossing times of the pairs ``ee (P,)`` and ``pt (Q,)`` on the step ``x0 -> x1`` (inf: none), with the
        pairs' sheet nodes ``(P, 2)``, ``(Q, 3)`` and the features' outward normals."""
        f = self.f
        n2, fe = f.edges[ee[:, 1]], f.fedges[ee[:, 0]]
        d = x1 - x0
        te = edge_crossing_times(x0[n2[:, 0]], x0[n2[:, 1]], d[n2[:, 0]], d[n2[:, 1]], f.points[fe[:, 0]],
                                 f.points[fe[:, 1]], f.edge_normals[ee[:, 0]])
        n3 = f.tri[pt[:, 1]]
        tc = corner_crossing_times(*(x0[n3[:, k]] for k in range(3)), *(d[n3[:, k]] for k in range(3)),
                                   f.points[f.corners[pt[:, 0]]], f.corner_normals[pt[:, 0]])
        return ((te, n2, f.edge_normals[ee[:, 0]]), (tc, n3, f.corner_normals[pt[:, 0]]))

    def _lifts(self, x, ee, pt, hit_e, hit_c):
        """The crossing pairs' lifts at the end positions ``x``: ``(nodes (P, m), weights (P, m), n (P, 3), depth
        (P,))`` per pair kind: the sheet's point nearest the feature (barycentric ``weights`` of its ``nodes``) must
        move ``depth`` [m] along ``n`` (away from the feature, on its outer side) to clear it by ``SHY`` of the
        sheet edge's length."""
        f = self.f
        out = []
        i = np.flatnonzero(hit_e)
        if i.size:
            nodes, fe = f.edges[ee[i, 1]], f.fedges[ee[i, 0]]
            a, b, p, q = x[nodes[:, 0]], x[nodes[:, 1]], f.points[fe[:, 0]], f.points[fe[:, 1]]
            s, u = _closest_params(a, b, p, q)
            nf = f.edge_normals[ee[i, 0]]
            n = _cross(q - p, b - a)
            nn = np.linalg.norm(n, axis=1, keepdims=True)
            n = np.where(nn > 1e-12 * np.linalg.norm(b - a, axis=1, keepdims=True) * np.linalg.norm(q - p, axis=1,
                                                                                             keepdims=True),
                         n / np.maximum(nn, 1e-300), nf)
            n *= np.where(_dot(n, nf) < 0, -1.0, 1.0)[:, None]
            gap = a + s[:, None] * (b - a) - p - u[:, None] * (q - p)
            depth = SHY * np.linalg.norm(b - a, axis=1) - _dot(gap, n)
            out.append((nodes, np.column_stack([1.0 - s, s]), n, depth))
        i = np.flatnonzero(hit_c)
        if i.size:
            nodes = f.tri[pt[i, 1]]
            a, b, c = (x[nodes[:, k]] for k in range(3))
            p, nc = f.points[f.corners[pt[i, 0]]], f.corner_normals[pt[i, 0]]
            n = _cross(b - a, c - a)
            area2 = np.linalg.norm(n, axis=1)
            n = n / np.maximum(area2, 1e-300)[:, None]
            n *= np.where(_dot(n, nc) < 0, -1.0, 1.0)[:, None]
            w = np.column_stack([_dot(_cross(c - b, p - b), n), _dot(_cross(a - c, p - c), n),
                                 _dot(_cross(b - a, p - a), n)]) / np.maximum(area2, 1e-300)[:, None]
            w = np.clip(w, 0.0, None)
            w /= np.maximum(w.sum(axis=1, keepdims=True), 1e-300)
            depth = SHY * np.sqrt(area2) - _dot(a - p, n)
            out.append((nodes, w, n, depth))
        return out

    def stop(self, x0: np.ndarray, x1: np.ndarray, v: np.ndarray):
        """Sheet edges and triangles kept off the sharp features: ``(x (N, 3) [m], v (N, 3) [m/s], moved (N,)
        bool)`` from the step ``x0 -> x1`` ``(N, 3)`` [m] and the velocities ``v`` (module docstring)."""
        x0, x1 = np.asarray(x0, float), np.asarray(x1, float)
        x, v = x1.copy(), np.array(v, float, copy=True)
        moved = np.zeros(len(x0), bool)
        if self._stree is None:
            return x, v, moved
        ee, pt = self.pairs(x0, x1)
        if not (len(ee) or len(pt)):
            return x, v, moved
        applied, ee_a, pt_a = [], ee, pt
        for _ in range(ROUNDS):
            (te, _, _), (tc, _, _) = self.times(x0, x, ee_a, pt_a)
            lifts = self._lifts(x, ee_a, pt_a, np.isfinite(te), np.isfinite(tc))
            if not lifts:
                break
            applied += lifts
            dx, count = np.zeros_like(x), np.zeros(len(x))
            for nodes, w, n, depth in lifts:  # the contact point moves depth n: node k by w_k depth n / sum w^2
                lift = ((np.maximum(depth, 0.0) / np.einsum("pk,pk->p", w, w))[:, None, None] * w[:, :, None]
                        * n[:, None])
                for k in range(nodes.shape[1]):
                    for i in range(3):
                        dx[:, i] += np.bincount(nodes[:, k], lift[:, k, i], minlength=len(x))
                    count += np.bincount(nodes[:, k], minlength=len(x))
            hit = count > 0
            x[hit] += dx[hit] / count[hit, None]
            moved |= hit
            # only the pairs of the nodes just lifted changed their steps: the others stay clear
            ee_a = ee[hit[self.f.edges[ee[:, 1]]].any(axis=1)]
            pt_a = pt[hit[self.f.tri[pt[:, 1]]].any(axis=1)]
        for nodes, w, n, _ in applied:  # the lifted contact points stop approaching the features
            vc = np.einsum("pk,pki->pi", w, v[nodes])
            vn = np.minimum(_dot(vc, n), 0.0)
            dv = (-vn / np.einsum("pk,pk->p", w, w))[:, None, None] * w[:, :, None] * n[:, None]
            for k in range(nodes.shape[1]):
                np.add.at(v, nodes[:, k], dv[:, k])
        return x, v, moved
