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

__all__ = ["closest_one", "nearest_in_sets", "nearest_one", "signed_in_sets"]


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


def nearest_one(p0, p1, p2, V, T, centroid, ik_p, dk_p, moved_p, R):
    """The nearest of one point's candidate triangles ``ik_p (K,)`` (sorted by their centroid distances ``dk_p
    (K,)`` [m] from where the point was ``moved_p`` [m] ago): ``(d2, s0, s1, s2, kind, local, tri, c2)``, its
    squared distance [m^2], closest point, kind and local index (as :func:`closest_one`) and triangle, and the
    least squared distance [m^2] to the centroids of the candidates tested. It stops at the first candidate whose
    centroid is surely farther than the nearest so far plus ``R`` [m] (the largest centroid-to-corner radius):
    neither it nor any after it can be nearer. The first of equally near triangles wins (as ``argmin``)."""
    best = np.inf
    cbest = np.inf
    s0 = s1 = s2 = 0.0
    kbest = lbest = tbest = 0
    for k in range(ik_p.shape[0]):
        gap = dk_p[k] - moved_p - R
        if gap > 0 and gap * gap > best:
            break
        t = ik_p[k]
        ia, ib, ic = T[t, 0], T[t, 1], T[t, 2]
        wa, wb, wc, kd, lc = closest_one(p0, p1, p2, V[ia], V[ib], V[ic])
        c0 = wa * V[ia, 0] + wb * V[ib, 0] + wc * V[ic, 0]
        c1 = wa * V[ia, 1] + wb * V[ib, 1] + wc * V[ic, 1]
        c2 = wa * V[ia, 2] + wb * V[ib, 2] + wc * V[ic, 2]
        d2 = (p0 - c0) ** 2 + (p1 - c1) ** 2 + (p2 - c2) ** 2
        if d2 < best:
            best = d2
            s0, s1, s2 = c0, c1, c2
            kbest, lbest, tbest = kd, lc, t
        e2 = (p0 - centroid[t, 0]) ** 2 + (p1 - centroid[t, 1]) ** 2 + (p2 - centroid[t, 2]) ** 2
        if e2 < cbest:
            cbest = e2
    return best, s0, s1, s2, kbest, lbest, tbest, cbest


def nearest_in_sets(x, V, T, centroid, ik, dk, moved, R, q, feature, dist):
    """For each point ``x[p] (n, 3)`` [m], the nearest of its candidate triangles ``ik[p] (n, K)`` of the
    surface ``V (m, 3)`` [m], ``T (t, 3)``, sorted by their centroid distances ``dk[p] (n, K)`` [m] from where
    the point was ``moved[p] (n,)`` [m] ago (:func:`nearest_one`): fills its closest point ``q (n, 3)``,
    ``feature (n, 3)`` its kind and local index (as :func:`closest_one`) and triangle, ``dist (n, 2)`` its
    distance [m] and the least distance [m] from the point to the ``centroid (t, 3)`` of the candidates it
    tested."""
    for p in range(ik.shape[0]):
        d2, s0, s1, s2, kd, lc, t, c2 = nearest_one(x[p, 0], x[p, 1], x[p, 2], V, T, centroid, ik[p], dk[p],
                                                     moved[p], R)
        q[p, 0], q[p, 1], q[p, 2] = s0, s1, s2
        feature[p, 0], feature[p, 1], feature[p, 2] = kd, lc, t
        dist[p, 0] = np.sqrt(d2)
        dist[p, 1] = np.sqrt(c2)


def signed_in_sets(x, surface, ik, dk, moved, consts, hessian, phi, normal, H, out):
    """The signed distance of :class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle` (its
    ``_evaluate``, equations in :mod:`.surface_geometry`) at the points ``x (n, 3)`` [m] whose nearest triangle
    the candidate sets ``ik, dk, moved`` prove (:func:`nearest_one`), in one pass.

    ``surface = (V, T, centroid, nf, ne, nv, edge_of, edges, rim_edge, rim_vertex)``: the obstacle's nodes [m],
    triangles, centroids [m], face / edge / vertex pseudo-normals, triangle edges, edges' nodes, and open-boundary
    flags; ``consts = (R, band, half, mode, lo (3), hi (3), every, dmin)``: the largest centroid-to-corner radius, the
    exact band [m], the contact surface's offset [m] (a shell's half thickness or the rounding), ``mode`` 0 closed,
    1 open with a side, 2 a two-sided shell, the bounding box [m], ``dmin`` the distance [m] below which the edges'
    curvature ``1 / r`` is capped (a rounded surface's, else 0), and ``every`` 1 when each point's candidates hold every triangle that can be nearest (a ball
    search's, padded with repeats; ``dk`` 0: no early stop), else 0. Fills ``phi (n,)`` [m], ``normal (n, 3)``, ``H
    (n, 3, 3)`` [1/m] (when ``hessian``) and ``out (n, 6)``: the closest point of the nearest candidate [m], its
    distance ``r`` [m], the lower bound of the distance [m], and a status: 0 done; 1 unproven and within the band,
    or unproven with a held set (the caller seeks its set again, or searches every triangle within ``r + R``); 2
    beyond the band inside a closed surface's box (the caller's winding number); 3 a held set's point beyond the
    band by its bound alone (``dk_0 - moved - R >= band``), left untested: the caller evaluates it with its nearest
    centroid now as its set (:data:`rftstatic.contact.obstacles.surface_query.FAR`)."""
    V, T, centroid, nf, ne, nv, edge_of, edges, rim_edge, rim_vertex = surface
    R, band, half, mode = consts[0], consts[1], consts[2], int(consts[3])
    n, K = ik.shape
    whole = T.shape[0] <= K or consts[10] > 0
    for p in range(n):
        if moved[p] > 0 and dk[p, 0] - moved[p] - R >= band:
            out[p, 5] = 3.0  # beyond the band whatever its set: the caller's nearest centroid now (FAR)
            continue
        p0, p1, p2 = x[p, 0], x[p, 1], x[p, 2]
        d2, s0, s1, s2, kd, lc, t, c2 = nearest_one(p0, p1, p2, V, T, centroid, ik[p], dk[p], moved[p], R)
        r, dc = np.sqrt(d2), np.sqrt(c2)
        beyond = dk[p, K - 1] - moved[p]
        lower = max(min(min(dc, beyond) - R, r), 0.0)
        out[p, 0], out[p, 1], out[p, 2], out[p, 3], out[p, 4], out[p, 5] = s0, s1, s2, r, lower, 0.0
        if hessian:
            for i in range(3):
                for j in range(3):
                    H[p, i, j] = 0.0
        if not (whole or beyond - R >= r) and (moved[p] > 0 or lower < band):
            out[p, 5] = 1.0
            continue
        d0, d1, d2_ = p0 - s0, p1 - s1, p2 - s2
        if lower >= band or not (whole or beyond - R >= r):
            if mode == 0 and consts[4] <= p0 <= consts[7] and consts[5] <= p1 <= consts[8] and \
                    consts[6] <= p2 <= consts[9]:
                out[p, 5] = 2.0
                continue
            inv = 1.0 / max(r, 1e-300)
            phi[p] = lower - half
            normal[p, 0], normal[p, 1], normal[p, 2] = d0 * inv, d1 * inv, d2_ * inv
            continue
        if kd == 0:
            g = t
            n0, n1, n2 = nf[g, 0], nf[g, 1], nf[g, 2]
        elif kd == 1:
            g = edge_of[t, lc]
            n0, n1, n2 = ne[g, 0], ne[g, 1], ne[g, 2]
        else:
            g = T[t, lc]
            n0, n1, n2 = nv[g, 0], nv[g, 1], nv[g, 2]
        s = 1.0
        if mode != 2 and d0 * n0 + d1 * n1 + d2_ * n2 < 0.0:
            s = -1.0
        if mode == 1 and ((kd == 1 and rim_edge[g]) or (kd == 2 and rim_vertex[g])):
            s = 1.0  # closest point on the open boundary: outside
        tiny = r <= 1e-12 * band
        if tiny:
            u0, u1, u2 = n0, n1, n2
        else:
            u0, u1, u2 = d0 / r, d1 / r, d2_ / r
        phi[p] = s * r - half
        normal[p, 0], normal[p, 1], normal[p, 2] = s * u0, s * u1, s * u2
        if hessian and kd != 0 and not tiny and s > 0:
            # inside (s < 0) the closest point is on a face except at a reflex edge or on the surface: 0 there
            t0 = t1 = t2 = 0.0
            if kd == 1:
                e0, e1 = edges[g, 0], edges[g, 1]
                t0, t1, t2 = V[e1, 0] - V[e0, 0], V[e1, 1] - V[e0, 1], V[e1, 2] - V[e0, 2]
                tl = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
                t0, t1, t2 = t0 / tl, t1 / tl, t2 / tl
            w = s / max(r, consts[11])
            H[p, 0, 0] = w * (1.0 - u0 * u0 - t0 * t0)
            H[p, 1, 1] = w * (1.0 - u1 * u1 - t1 * t1)
            H[p, 2, 2] = w * (1.0 - u2 * u2 - t2 * t2)
            H[p, 0, 1] = H[p, 1, 0] = -w * (u0 * u1 + t0 * t1)
            H[p, 0, 2] = H[p, 2, 0] = -w * (u0 * u2 + t0 * t2)
            H[p, 1, 2] = H[p, 2, 1] = -w * (u1 * u2 + t1 * t2)
