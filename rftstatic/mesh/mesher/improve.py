"""Mesh improvement: Delaunay edge flips and constrained smoothing.

Flips (Lawson): an interior edge (u, v) with opposite nodes p and q is
flipped to (p, q) when ``cot(angle p) + cot(angle q) < 0`` (the angles sum to
more than pi).  For a convex quadrilateral that is exactly the diagonal
choice maximising the smallest of its six angles, so every flip raises the
local minimum angle.  Each pass flips an independent set (no triangle in two
flips) chosen greedily by violation, all at once with numpy.

Smoothing: Jacobi Laplacian moves of the interior nodes, x_i <- mean of its
neighbours, after which any node of a triangle that got inverted or whose
minimum angle dropped below ``min(old, 30 deg)`` is put back (repeated until
no such triangle remains).  Boundary nodes never move.  A final local
optimisation moves the nodes of the remaining worst triangles by a compass
search that maximises the smallest angle of their star.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["flip_edges", "smooth", "improve", "triangle_angles", "interior_edges", "optimise_worst"]


def triangle_angles(points, tri):
    """Interior angles [rad].

    Parameters
    ----------
    points : (N, 2) [m]
    tri : (E, 3) node indices

    Returns
    -------
    (E, 3) angle at each local node
    """
    p = points[tri]                       # (E, 3, 2)
    e_next = np.roll(p, -1, axis=1) - p   # a -> b
    e_prev = np.roll(p, 1, axis=1) - p    # a -> c
    cross = e_next[..., 0] * e_prev[..., 1] - e_next[..., 1] * e_prev[..., 0]
    dot = (e_next * e_prev).sum(axis=-1)
    return np.arctan2(cross, dot)         # negative for inverted triangles


def signed_area(points, tri):
    """(E,) signed areas [m²], > 0 for counter-clockwise triangles."""
    a, b, c = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def interior_edges(tri):
    """Interior edges with their two triangles.

    Returns
    -------
    t1, k1, t2, k2 : (I,) int64; local edge k of triangle t runs from
        ``tri[t, k]`` to ``tri[t, (k + 1) % 3]``; (t1, k1) and (t2, k2) are the
        two sides of the same edge.
    """
    n = int(tri.max()) + 1
    a = tri.ravel()
    b = np.roll(tri, -1, axis=1).ravel()
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    same = np.flatnonzero(ks[1:] == ks[:-1])
    h1, h2 = order[same], order[same + 1]
    return h1 // 3, h1 % 3, h2 // 3, h2 % 3


def flip_edges(points, tri, *, max_passes=100):
    """Delaunay-flip interior edges in place until none violates (see module doc).

    Parameters
    ----------
    points : (N, 2) [m]
    tri : (E, 3) int64 counter-clockwise, modified in place

    Returns
    -------
    number of flips done
    """
    total = 0
    for _ in range(max_passes):
        t1, k1, t2, k2 = interior_edges(tri)
        u = tri[t1, k1]
        v = tri[t1, (k1 + 1) % 3]
        p = tri[t1, (k1 + 2) % 3]
        q = tri[t2, (k2 + 2) % 3]
        P, Q, U, V = points[p], points[q], points[u], points[v]

        def cot(o, x, y):
            e1, e2 = x - o, y - o
            cr = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
            return (e1 * e2).sum(axis=1) / np.maximum(cr, 1e-300)

        viol = -(cot(P, U, V) + cot(Q, U, V))
        # the flipped pair must be valid (convex quadrilateral)
        ok = (viol > 1e-9) & (_orient(U, Q, P) > 0) & (_orient(Q, V, P) > 0)
        cand = np.flatnonzero(ok)
        if len(cand) == 0:
            break
        cand = cand[np.argsort(-viol[cand], kind="stable")]
        rank = np.arange(len(cand))
        claim = np.full(len(tri), len(cand))
        np.minimum.at(claim, t1[cand], rank)
        np.minimum.at(claim, t2[cand], rank)
        sel = cand[(claim[t1[cand]] == rank) & (claim[t2[cand]] == rank)]
        tri[t1[sel]] = np.column_stack([u[sel], q[sel], p[sel]])
        tri[t2[sel]] = np.column_stack([q[sel], v[sel], p[sel]])
        total += len(sel)
    return total


def _orient(a, b, c):
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def adjacency(tri, n):
    """(n, n) CSR node adjacency (1 per edge) of a triangulation."""
    i = np.concatenate([tri[:, 0], tri[:, 1], tri[:, 2]])
    j = np.concatenate([tri[:, 1], tri[:, 2], tri[:, 0]])
    a = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    a = ((a + a.T) > 0).astype(float)
    return a.tocsr()


def smooth(points, tri, movable, *, iterations=3, min_keep=np.radians(30.0)):
    """Constrained Jacobi-Laplacian smoothing (see module doc).

    Parameters
    ----------
    points : (N, 2) [m], modified in place
    tri : (E, 3) int64 counter-clockwise
    movable : (N,) bool, False for boundary nodes
    iterations : number of Laplacian sweeps
    min_keep : a move may not push a triangle's minimum angle below
        ``min(old, min_keep)`` [rad]
    """
    n = len(points)
    adj = adjacency(tri, n)
    deg = np.asarray(adj.sum(axis=1)).ravel()
    for _ in range(iterations):
        old = points.copy()
        old_min = triangle_angles(old, tri).min(axis=1)
        target = (adj @ old) / deg[:, None]
        moved = movable.copy()
        points[moved] = target[moved]
        for _guard in range(50):
            new_min = triangle_angles(points, tri).min(axis=1)
            bad = (new_min <= 0) | (new_min < np.minimum(old_min, min_keep) - 1e-12)
            if not bad.any():
                break
            back = np.zeros(n, dtype=bool)
            back[tri[bad].ravel()] = True
            back &= moved
            if not back.any():
                break
            points[back] = old[back]
            moved &= ~back
    return points


def optimise_worst(points, tri, movable, *, threshold=np.radians(32.0), rounds=3):
    """Compass-search the nodes of triangles below ``threshold`` [rad].

    Each movable node of such a triangle is moved to the best of 16 trial
    positions (two radii, eight directions, shrinking) if that raises the
    smallest angle of its star.  Python loops over these few nodes only.
    """
    n = len(points)
    node_tris = sp.csr_matrix((np.ones(tri.size), (tri.ravel(), np.repeat(np.arange(len(tri)), 3))),
                              shape=(n, len(tri)))
    dirs = np.exp(1j * np.pi / 4 * np.arange(8))
    dirs = np.column_stack([dirs.real, dirs.imag])
    for _ in range(rounds):
        angmin = triangle_angles(points, tri).min(axis=1)
        bad = np.flatnonzero(angmin < threshold)
        if len(bad) == 0:
            break
        nodes = np.unique(tri[bad].ravel())
        nodes = nodes[movable[nodes]]
        for v in nodes.tolist():
            ts = node_tris.indices[node_tris.indptr[v]:node_tris.indptr[v + 1]]
            star = tri[ts]
            loc = (star == v)
            # the other two nodes of each star triangle in ccw order after v
            k = np.argmax(loc, axis=1)
            o1 = star[np.arange(len(ts)), (k + 1) % 3]
            o2 = star[np.arange(len(ts)), (k + 2) % 3]
            A, B = points[o1], points[o2]
            scale = np.sqrt(np.mean(((A - points[v]) ** 2).sum(axis=1)))
            best_x = points[v].copy()
            best_q = _star_min_angle(best_x[None, :], A, B)[0]
            step = 0.15 * scale
            for _it in range(8):
                trial = best_x + step * np.concatenate([dirs, 0.5 * dirs])
                q = _star_min_angle(trial, A, B)
                j = int(np.argmax(q))
                if q[j] > best_q + 1e-12:
                    best_q, best_x = q[j], trial[j]
                else:
                    step *= 0.5
            points[v] = best_x
    return points


def _star_min_angle(x, A, B):
    """(T,) smallest angle of triangles (x_t, A_s, B_s) over s, -inf if inverted."""
    X = x[:, None, :]
    e_a, e_b = A[None] - X, B[None] - X
    f = B[None] - A[None]

    def ang(u, w):
        cr = u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]
        return np.arctan2(cr, (u * w).sum(axis=-1))

    cr = e_a[..., 0] * e_b[..., 1] - e_a[..., 1] * e_b[..., 0]
    a0 = ang(e_a, e_b)
    a1 = ang(f, -e_a)
    a2 = ang(-e_b, -f)
    m = np.minimum(np.minimum(a0, a1), a2).min(axis=1)
    return np.where((cr > 0).all(axis=1), m, -np.inf)


def improve(points, tri, movable, *, smooth_iterations=4):
    """Flip, then alternate smoothing and flips, then optimise the worst nodes.

    Parameters
    ----------
    points : (N, 2) [m], modified in place
    tri : (E, 3) int64 counter-clockwise, modified in place
    movable : (N,) bool, False for boundary nodes
    smooth_iterations : number of smooth+flip cycles (0: flips only)
    """
    flip_edges(points, tri)
    for _ in range(smooth_iterations):
        smooth(points, tri, movable, iterations=1)
        flip_edges(points, tri)
    if smooth_iterations:
        optimise_worst(points, tri, movable)
        flip_edges(points, tri)
    return points, tri
