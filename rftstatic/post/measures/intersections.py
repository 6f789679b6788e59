"""Self-intersection check of a zero-thickness sheet: crossing triangle pairs and the smallest gap.

An independent verifier of any self-contact law: it only reads positions and triangles (nothing
of :mod:`rftstatic.contact`), so a law's result is judged by a test it does not share.

Definitions
-----------
Two triangles are *adjacent* when they share a node; adjacent triangles always touch, so every
pair here shares no node.

*Intersecting* (:func:`intersecting_pairs`): an edge ``pq`` of one triangle crosses the other
triangle ``abc``. With the unit normal n of abc and the signed plane distances d_p = n·(p − a),
d_q = n·(q − a), the edge crosses the plane when d_p and d_q have strictly opposite signs, at
s = p + d_p / (d_p − d_q) (q − p). The orientation determinants ω_ab = (q − p)·((a − p) × (b − p))
(and ω_bc, ω_ca) satisfy ω_ab = |b − a| h_ab (d_q − d_p), h_ab the signed in-plane distance of s
from the line ab (positive on c's side), so "s strictly inside abc" is "ω_ab, ω_bc, ω_ca of equal
sign", and h measures by how much. Two triangles that meet transversally always have such an
edge (each end of their intersection segment is one), so the six edge-triangle tests decide.

Touching is not intersecting. The sheet has zero thickness, so a crossing counts only when it is
robust by ``tol`` [length]: both ends of the edge farther than ``tol`` from the plane
(|d_p|, |d_q| > tol, opposite signs) and the crossing point farther than ``tol`` inside each of
the three edge lines (h_ab, h_bc, h_ca > tol). Hence a vertex or an edge lying on another
triangle, an edge through a vertex, coplanar triangles (two layers lying on each other, even
overlapping) and penetrations shallower than ``tol`` are all reported as not intersecting; their
distance (:func:`smallest_distance`) is at most about ``tol``. The default ``tol`` is 1e-9 mean
edge lengths: far above round-off, far below any physical penetration.

*Distance* (:func:`smallest_distance`): between two triangles that do not intersect, the closest
points are a vertex and the interior of the other face, or a point on an edge of each, so
dist = min(6 vertex-face distances where the vertex projects inside the face, 9 edge-edge
distances); 0 for an intersecting pair. Only pairs closer than ``within`` (default one mean edge
length) are searched; candidates are taken in the order of a lower bound (their box gap), and
those that cannot beat the best distance found are skipped.

Broad phase
-----------
Each triangle is bounded by the ball about its centroid c through its farthest vertex (radius r).
Two triangles closer than ``reach`` have |c_i − c_j| ≤ r_i + r_j + reach: a ``cKDTree`` of the
centroids finds those pairs (``query_pairs``, or ``sparse_distance_matrix`` between size classes
of a graded mesh, radii within a factor 2 per class, so a few coarse triangles do not widen the
search of the fine ones); then the exact ball test, the axis-aligned box gap (≤ reach) and the
node-sharing test drop candidates. The narrow phase is vectorised over all candidate pairs; the
only Python loops run over size classes and the 3 edges of a triangle.

Cost (measured on this machine, 2 shared cores, median of 5 calls): a smoothly draped sheet of
81 x 81 nodes (12 800 triangles, 170 k candidate pairs within one edge length) takes 0.25 s for
:func:`self_intersections` (both checks sharing one broad phase) and 0.06 s for
:func:`intersecting_pairs` alone; 161 x 161 (51 200 triangles, 690 k pairs) 0.9-1.0 s and 0.25 s. On the
converged pedestal-square-80 drape (81 x 81, 356 crossing pairs) the check takes 0.1-0.16 s, 0.04 %
of the 271 s run. Most of the time goes to the in-layer neighbours, the pairs within one edge
length; a search radius of two edge lengths costs about three times as much.

Lengths are in the units of ``x`` (SI inside the package).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from rftstatic.post.measures.triangles import check_mesh

__all__ = ["intersecting_pairs", "self_intersections", "smallest_distance", "triangle_distances"]

TOL = 1e-9
"""Default crossing tolerance, in mean edge lengths (module docstring: touching is not intersecting)."""

WITHIN = 1.0
"""Default search radius of :func:`smallest_distance`, in mean edge lengths (its Notes: the in-layer
floor is about 0.7; 2 would cost 3 x as much)."""


def _mean_edge(p: np.ndarray) -> float:
    return float(np.linalg.norm(p - np.roll(p, -1, axis=1), axis=2).mean())


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", u, v)


def _candidates(p: np.ndarray, tri: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of triangles sharing no node whose boxes are within ``reach`` [length], and their box gaps.

    ``p`` (E, 3, 3) vertex positions. Returns the pairs (M, 2), i < j, a superset of the pairs
    closer than ``reach``, and (M,) the distance between their axis-aligned boxes, a lower bound
    of the triangle distance.
    """
    c = p.mean(axis=1)
    r = np.linalg.norm(p - c[:, None], axis=2).max(axis=1)
    # size classes: radii within a factor 2 of each other share one search radius
    lo = max(float(r.min()), 1e-300)
    cls = np.floor(np.log2(np.maximum(r, lo) / lo)).astype(int)
    groups = [np.flatnonzero(cls == k) for k in np.unique(cls)]
    trees = [cKDTree(c[g]) for g in groups]
    rmax = [float(r[g].max()) for g in groups]
    found = []
    for k, (gk, tk) in enumerate(zip(groups, trees)):
        ij = tk.query_pairs(2 * rmax[k] + reach, output_type="ndarray")
        found.append(gk[ij.reshape(-1, 2)])                  # gk ascending: i < j kept
        for m in range(k + 1, len(groups)):
            sd = tk.sparse_distance_matrix(trees[m], rmax[k] + rmax[m] + reach, output_type="ndarray")
            a, b = gk[sd["i"]], groups[m][sd["j"]]
            found.append(np.c_[np.minimum(a, b), np.maximum(a, b)])
    pairs = np.concatenate(found).astype(np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    dc = c[i] - c[j]
    rr = r[i] + r[j] + reach
    keep = np.flatnonzero(_dot(dc, dc) <= rr * rr)
    ti, tj = tri[i[keep]], tri[j[keep]]
    shared = np.zeros(len(keep), bool)
    for a in range(3):
        shared |= (ti[:, a, None] == tj).any(axis=1)
    keep = keep[~shared]
    i, j = i[keep], j[keep]
    bmin, bmax = p.min(axis=1), p.max(axis=1)
    gap = np.maximum(0.0, np.maximum(bmin[i] - bmax[j], bmin[j] - bmax[i]))
    g2 = _dot(gap, gap)
    near = g2 <= reach * reach
    return pairs[keep[near]], np.sqrt(g2[near])


def _edges_cross(A: np.ndarray, B: np.ndarray, tol: float) -> np.ndarray:
    """(M,) True where an edge of triangle A (M, 3, 3) crosses triangle B (M, 3, 3) by more than ``tol``."""
    n = np.cross(B[:, 1] - B[:, 0], B[:, 2] - B[:, 0])
    nn = np.linalg.norm(n, axis=1)
    unit = n / np.where(nn > 0.0, nn, 1.0)[:, None]
    d = np.einsum("mai,mi->ma", A - B[:, :1], unit)          # (M, 3) signed plane distances
    side = np.where(d > tol, 1, np.where(d < -tol, -1, 0)) * (nn > 0.0)[:, None]
    hit = np.zeros(len(A), bool)
    for a in range(3):                                        # the 3 edges pq of A
        b = (a + 1) % 3
        m = np.flatnonzero(side[:, a] * side[:, b] < 0)
        if m.size == 0:
            continue
        pp, w = A[m, a], A[m, b] - A[m, a]
        dq_dp = d[m, b] - d[m, a]
        inside = np.ones(m.size, bool)
        for e in range(3):                                    # the 3 edge lines of B
            u, v = B[m, e], B[m, (e + 1) % 3]
            omega = _dot(w, np.cross(u - pp, v - pp))
            h = omega / (np.linalg.norm(v - u, axis=1) * dq_dp)   # in-plane distance of s from line uv
            inside &= h > tol
        hit[m] |= inside
    return hit


def _crossing(P: np.ndarray, Q: np.ndarray, tol: float) -> np.ndarray:
    """(M,) True where triangles P and Q (M, 3, 3) intersect (module docstring)."""
    return _edges_cross(P, Q, tol) | _edges_cross(Q, P, tol)


def _vertex_face(V: np.ndarray, T: np.ndarray) -> np.ndarray:
    """(M, 3) distances of the vertices V (M, 3, 3) to the faces T (M, 3, 3); inf where a vertex
    does not project into the face (the edge-edge distances cover those)."""
    a = T[:, 0][:, None]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])[:, None]           # (M, 1, 3)
    inside = np.ones(V.shape[:2], bool)
    for e in range(3):
        u, v = T[:, e][:, None], T[:, (e + 1) % 3][:, None]
        inside &= _dot(np.cross(v - u, V - u), n) >= 0.0
    nn = np.linalg.norm(n, axis=2)
    dist = np.abs(_dot(V - a, n)) / np.where(nn > 0.0, nn, 1.0)
    return np.where(inside & (nn > 0.0), dist, np.inf)


def _segment_segment(p1, q1, p2, q2) -> np.ndarray:
    """Distances between segments p1q1 and p2q2 (..., 3) (closest parameters clamped to [0, 1])."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, b = _dot(d1, d1), _dot(d2, d2), _dot(d1, d2)
    c, f = _dot(d1, r), _dot(d2, r)
    a, e = np.maximum(a, 1e-300), np.maximum(e, 1e-300)
    den = a * e - b * b
    par = den <= 1e-14 * a * e                                # parallel: any s; take s = 0
    s = np.where(par, 0.0, np.clip((b * f - c * e) / np.where(par, 1.0, den), 0.0, 1.0))
    t = (b * s + f) / e
    s = np.where(t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    g = r + s[..., None] * d1 - t[..., None] * d2
    return np.sqrt(_dot(g, g))


def _pair_distance(P: np.ndarray, Q: np.ndarray, crossing: np.ndarray) -> np.ndarray:
    """(M,) distances between triangles P and Q (M, 3, 3); 0 where ``crossing``."""
    if len(P) == 0:
        return np.zeros(0)
    vf = np.minimum(_vertex_face(P, Q).min(axis=1), _vertex_face(Q, P).min(axis=1))
    nxt = [1, 2, 0]
    ee = _segment_segment(P[:, :, None], P[:, nxt, None], Q[:, None, :], Q[:, None, nxt]).min(axis=(1, 2))
    return np.where(crossing, 0.0, np.minimum(vf, ee))


def triangle_distances(x: np.ndarray, tri: np.ndarray, pairs: np.ndarray, *, tol: float | None = None) -> np.ndarray:
    """Distances between the triangles of given pairs.

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    pairs : (M, 2) int array_like
        Triangle index pairs.
    tol : float, optional
        Crossing tolerance [m] (default 1e-9 mean edge lengths); a crossing pair has distance 0.

    Returns
    -------
    (M,) ndarray
        Triangle-triangle distances [m].
    """
    x, tri = check_mesh(x, tri, "triangle_distances")
    p = _positions(x, tri, "triangle_distances")
    pairs = np.asarray(pairs).reshape(-1, 2)
    if pairs.size and (not np.issubdtype(pairs.dtype, np.integer) or pairs.min() < 0 or pairs.max() >= len(tri)):
        raise ValueError(f"triangle_distances: pairs must hold triangle indices in [0, {len(tri)})")
    tol = _tolerance(tol, p, "triangle_distances")
    P, Q = p[pairs[:, 0]], p[pairs[:, 1]]
    return _pair_distance(P, Q, _crossing(P, Q, tol))


def intersecting_pairs(x: np.ndarray, tri: np.ndarray, *, tol: float | None = None) -> np.ndarray:
    """All pairs of triangles that share no node and intersect (an edge of one crosses the other).

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    tol : float, optional
        Crossing tolerance [m], default 1e-9 mean edge lengths: touching, coplanar overlap and
        penetrations within ``tol`` are not intersections (module docstring).

    Returns
    -------
    (P, 2) int64 ndarray
        Triangle index pairs, smaller index first, rows sorted.
    """
    x, tri = check_mesh(x, tri, "intersecting_pairs")
    p = _positions(x, tri, "intersecting_pairs")
    tol = _tolerance(tol, p, "intersecting_pairs")
    cand, _ = _candidates(p, tri, 0.0)
    pairs = cand[_crossing(p[cand[:, 0]], p[cand[:, 1]], tol)]
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def smallest_distance(x: np.ndarray, tri: np.ndarray, *, within: float | None = None,
                      tol: float | None = None) -> tuple[float, tuple[int, int]]:
    """Smallest distance between two triangles that share no node, searched within ``within``.

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    within : float, optional
        Search radius [m], default one mean edge length: only pairs closer than this are found.
    tol : float, optional
        Crossing tolerance [m] of :func:`intersecting_pairs`; a crossing pair has distance 0.

    Returns
    -------
    distance : float
        Triangle-triangle distance [m] (0 when two triangles intersect), ``inf`` when no two
        non-adjacent triangles are closer than ``within``.
    pair : (int, int)
        The two triangles, smaller index first; ``(-1, -1)`` with ``inf``.

    Notes
    -----
    Within one smooth layer, non-adjacent triangles come as close as about 0.7 edge lengths (a
    right-angled grid: a vertex and the diagonal of the next-but-one triangle), which is why the
    default search radius of one edge length always finds a pair on a sheet; values well below
    that come from layers approaching each other.
    """
    x, tri = check_mesh(x, tri, "smallest_distance")
    p = _positions(x, tri, "smallest_distance")
    _, _, dist, pair = _check(p, tri, _within(within, p, "smallest_distance"),
                              _tolerance(tol, p, "smallest_distance"))
    return dist, pair


def self_intersections(x: np.ndarray, tri: np.ndarray, *, within: float | None = None,
                       tol: float | None = None, distance: bool = True) -> dict:
    """The self-intersection check of one state, as plain values for ``summary.json``.

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    within, tol : float, optional
        Search radius and crossing tolerance [m] (:func:`smallest_distance`).
    distance : bool, optional
        False: count the crossings only (``smallest_distance`` and its pair None, ``within`` 0);
        about a quarter of the cost (the states a dynamic run saves).

    Returns
    -------
    dict
        ``pairs`` (number of intersecting pairs, :func:`intersecting_pairs`), ``triangles``
        (distinct triangles among them), ``area_fraction`` [-] (their area over the sheet's, in
        the current state), ``smallest_distance`` [m] (:func:`smallest_distance`, ``inf`` when
        none within), ``smallest_distance_pair``, ``within`` [m], ``tol`` [m] and ``seconds``
        (wall time of the check) [s].
    """
    t0 = time.perf_counter()
    x, tri = check_mesh(x, tri, "self_intersections")
    p = _positions(x, tri, "self_intersections")
    within = _within(within, p, "self_intersections") if distance else 0.0
    tol = _tolerance(tol, p, "self_intersections")
    if distance:
        cand, crossing, dist, pair = _check(p, tri, within, tol)
    else:
        cand, _ = _candidates(p, tri, 0.0)
        crossing = _crossing(p[cand[:, 0]], p[cand[:, 1]], tol)
        dist, pair = None, None
    hit = np.unique(cand[crossing])
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return {"pairs": int(crossing.sum()), "triangles": int(hit.size),
            "area_fraction": float(area[hit].sum() / max(area.sum(), 1e-300)),
            "smallest_distance": None if dist is None else float(dist),
            "smallest_distance_pair": None if pair is None else [int(pair[0]), int(pair[1])],
            "within": within, "tol": tol, "seconds": time.perf_counter() - t0}


def _positions(x: np.ndarray, tri: np.ndarray, who: str) -> np.ndarray:
    if x.shape[1] != 3:
        raise ValueError(f"{who}: x.shape = {x.shape}, expected (N, 3) positions in space")
    if not np.isfinite(x).all():
        raise ValueError(f"{who}: x holds {int((~np.isfinite(x)).sum())} non-finite value(s)")
    return x[tri]


def _tolerance(tol, p, who: str) -> float:
    tol = TOL * _mean_edge(p) if tol is None else float(tol)
    if not tol >= 0.0:
        raise ValueError(f"{who}: tol = {tol!r}, expected a length >= 0")
    return tol


def _within(within, p, who: str) -> float:
    within = WITHIN * _mean_edge(p) if within is None else float(within)
    if not within > 0.0:
        raise ValueError(f"{who}: within = {within!r}, expected a length > 0")
    return within


def _check(p: np.ndarray, tri: np.ndarray, within: float, tol: float):
    """Candidates within ``within``, their crossing flags, the smallest distance and its pair.

    The distance is evaluated first on the E pairs with the smallest box gaps (lower bounds),
    then only on the pairs whose box gap is below the best distance found.
    """
    cand, lower = _candidates(p, tri, within)
    crossing = np.zeros(len(cand), bool)
    touch = np.flatnonzero(lower == 0.0)                     # only overlapping boxes can cross
    crossing[touch] = _crossing(p[cand[touch, 0]], p[cand[touch, 1]], tol)
    if crossing.any():
        k = int(np.flatnonzero(crossing)[0])
        return cand, crossing, 0.0, (int(cand[k, 0]), int(cand[k, 1]))
    if len(cand) == 0:
        return cand, crossing, np.inf, (-1, -1)
    first = np.argpartition(lower, len(p) - 1)[:len(p)] if len(cand) > len(p) else np.arange(len(cand))
    d = _pair_distance(p[cand[first, 0]], p[cand[first, 1]], crossing[first])
    best, dbest = int(first[np.argmin(d)]), float(d.min())
    rest = lower < dbest
    rest[first] = False
    idx = np.flatnonzero(rest)
    if idx.size:
        d = _pair_distance(p[cand[idx, 0]], p[cand[idx, 1]], crossing[idx])
        if d.min() < dbest:
            best, dbest = int(idx[np.argmin(d)]), float(d.min())
    if not dbest < within:
        return cand, crossing, np.inf, (-1, -1)
    return cand, crossing, dbest, (int(cand[best, 0]), int(cand[best, 1]))
