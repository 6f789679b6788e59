"""Per-point loops of the surface obstacle's closest-triangle query, plain Python compiled by numba
(:mod:`._surface_numba`; the numpy twin is :func:`.surface_geometry.closest_on_triangles` over candidate
pairs).

:func:`nearest_in_sets` gives, for each point ``x_p`` and its ``K`` candidate triangles, the closest point
of the nearest one (Ericson, *Real-Time Collision Detection*, §5.1.5: the seven Voronoi regions, tested in
the order of :func:`.surface_geometry.closest_on_triangles`, so both pick the same feature), and the least
distance to the candidates' centroids (a lower bound of the distance to the surface after subtracting the
largest centroid-to-corner radius). One pass over ``n K`` triangles without the ``(n K, 3)`` temporaries of
the numpy twin, stopping at the first candidate that cannot be nearer (validation/mesh_obstacles.md, "Cost").
"""

from __future__ import annotations

import numpy as np

__all__ = ["closest_one", "nearest_in_sets"]


def closest_one(p0, p1, p2, a, b, c):
    """Closest point of triangle ``a, b, c`` ((3,) [m]) to the point ``(p0, p1, p2)``: ``(w_a, w_b, w_c, kind,
    local)``, the barycentric weights of the closest point, the kind (0 face, 1 edge, 2 vertex) and the local
    vertex or the edge by its opposite vertex (as :func:`.surface_geometry.closest_on_triangles`)."""
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    ap0, ap1, ap2 = p0 - a[0], p1 - a[1], p2 - a[2]
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    if d1 <= 0 and d2 <= 0:
        return 1.0, 0.0, 0.0, 2, 0
    bp0, bp1, bp2 = p0 - b[0], p1 - b[1], p2 - b[2]
    d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
    d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
    if d3 >= 0 and d4 <= d3:
        return 0.0, 1.0, 0.0, 2, 1
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        t = d1 / (d1 - d3)
        return 1.0 - t, t, 0.0, 1, 2
    cp0, cp1, cp2 = p0 - c[0], p1 - c[1], p2 - c[2]
    d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
    d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
    if d6 >= 0 and d5 <= d6:
        return 0.0, 0.0, 1.0, 2, 2
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        t = d2 / (d2 - d6)
        return 1.0 - t, 0.0, t, 1, 1
    va = d3 * d6 - d5 * d4
    if va <= 0 and d4 - d3 >= 0 and d5 - d6 >= 0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - t, t, 1, 0
    den = va + vb + vc
    v, w = vb / den, vc / den
    return 1.0 - v - w, v, w, 0, 0


def nearest_in_sets(x, V, T, centroid, ik, dk, moved, R, q, feature, dist):
    """For each point ``x[p] (n, 3)`` [m], the nearest of its candidate triangles ``ik[p] (n, K)`` of the
    surface ``V (m, 3)`` [m], ``T (t, 3)``, sorted by their centroid distances ``dk[p] (n, K)`` [m] from where
    the point was ``moved[p] (n,)`` [m] ago: fills its closest point ``q (n, 3)``, ``feature (n, 3)`` its kind
    and local index (as :func:`closest_one`) and triangle, ``dist (n, 2)`` its distance [m] and the least
    distance [m] from the point to the ``centroid (t, 3)`` of the candidates it tested. It stops at the first
    candidate whose centroid is surely farther than the nearest so far plus ``R`` [m] (the largest
    centroid-to-corner radius): neither it nor any after it can be nearer. The first of equally near triangles
    wins (as ``argmin``)."""
    n, K = ik.shape
    for p in range(n):
        p0, p1, p2 = x[p, 0], x[p, 1], x[p, 2]
        best = np.inf
        cbest = np.inf
        for k in range(K):
            gap = dk[p, k] - moved[p] - R
            if gap > 0 and gap * gap > best:
                break
            t = ik[p, k]
            ia, ib, ic = T[t, 0], T[t, 1], T[t, 2]
            wa, wb, wc, kd, lc = closest_one(p0, p1, p2, V[ia], V[ib], V[ic])
            s0 = wa * V[ia, 0] + wb * V[ib, 0] + wc * V[ic, 0]
            s1 = wa * V[ia, 1] + wb * V[ib, 1] + wc * V[ic, 1]
            s2 = wa * V[ia, 2] + wb * V[ib, 2] + wc * V[ic, 2]
            d2 = (p0 - s0) ** 2 + (p1 - s1) ** 2 + (p2 - s2) ** 2
            if d2 < best:
                best = d2
                q[p, 0], q[p, 1], q[p, 2] = s0, s1, s2
                feature[p, 0], feature[p, 1], feature[p, 2] = kd, lc, t
            c2 = (p0 - centroid[t, 0]) ** 2 + (p1 - centroid[t, 1]) ** 2 + (p2 - centroid[t, 2]) ** 2
            if c2 < cbest:
                cbest = c2
        dist[p, 0] = np.sqrt(best)
        dist[p, 1] = np.sqrt(cbest)
