"""Independent check that the sheet does not pass through a triangle-surface obstacle.

Reads only positions and triangles (nothing of :mod:`rftstatic.contact`): the sheet's triangles against the
obstacle's (:meth:`rftstatic.contact.obstacles.Obstacle.surface`), with the crossing test and the
triangle-triangle distance of the self-intersection check (:mod:`.intersections`: an edge of one triangle
crosses the other by more than ``tol``). Touching is not crossing: a sheet resting on the obstacle within
``tol`` (default 1e-9 mean sheet edge lengths) counts 0 pairs.

Broad phase: ``cKDTree``s of both meshes' triangle centroids, pairs whose centroid distance is below the
two largest centroid-to-corner radii plus ``within``; the narrow phase is vectorised over the pairs: the crossing
test over the pairs whose bounding boxes overlap (within ``tol``), the exact distance over those whose boxes lie
within the nearest vertex pair's distance (the smallest distance is among them).
"""

from __future__ import annotations

import time

import numpy as np

from rftstatic.post.measures.intersections import TOL, _crossing, _pair_distance

__all__ = ["obstacle_crossings"]


def obstacle_crossings(x: np.ndarray, tri: np.ndarray, V: np.ndarray, T: np.ndarray, *,
                       within: float | None = None, tol: float | None = None) -> dict:
    """Sheet/obstacle triangle pairs that cross, and the smallest distance between the two surfaces.

    Parameters
    ----------
    x : (N, 3) sheet positions [m]
    tri : (E, 3) sheet triangles
    V : (n, 3) obstacle surface points [m]
    T : (t, 3) obstacle triangles
    within : search radius of the distance [m] (default one mean sheet edge length)
    tol : crossing tolerance [m] (default 1e-9 mean sheet edge lengths)

    Returns
    -------
    ``{"pairs": crossing pairs, "first": [sheet triangle, obstacle triangle] or None, "first_at": (3,) a point
    of the first crossing pair [m] or None, "smallest_distance": [m] (inf when none within), "within", "tol",
    "seconds"}``
    """
    from scipy.spatial import cKDTree

    t0 = time.perf_counter()
    x, V = np.asarray(x, float), np.asarray(V, float)
    P, Q = x[tri], V[T]
    edge = float(np.mean(np.linalg.norm(P - np.roll(P, 1, axis=1), axis=2)))
    within = edge if within is None else float(within)
    tol = TOL * edge if tol is None else float(tol)
    cp, cq = P.mean(axis=1), Q.mean(axis=1)
    rp = float(np.max(np.linalg.norm(P - cp[:, None], axis=2)))
    rq = float(np.max(np.linalg.norm(Q - cq[:, None], axis=2)))
    m = cKDTree(cp).sparse_distance_matrix(cKDTree(cq), rp + rq + within, output_type="ndarray")
    i, j = m["i"].astype(np.int64), m["j"].astype(np.int64)
    # the gap between the pairs' bounding boxes bounds their distance from below: only pairs whose boxes
    # overlap within tol can cross, and only those within the nearest vertex pair's distance can be nearest
    gap = np.maximum(0.0, np.maximum(P.min(axis=1)[i] - Q.max(axis=1)[j], Q.min(axis=1)[j] - P.max(axis=1)[i]))
    box = np.sqrt(np.einsum("mi,mi->m", gap, gap))
    cand = np.flatnonzero(box <= tol)
    crossing = np.zeros(len(i), bool)
    crossing[cand] = _crossing(P[i[cand]], Q[j[cand]], tol)
    smallest = float("inf")
    if len(i):
        vv = np.linalg.norm(P[i][:, :, None] - Q[j][:, None, :], axis=3).min(axis=(1, 2))
        cand = np.flatnonzero(box <= vv.min())
        smallest = float(_pair_distance(P[i[cand]], Q[j[cand]], crossing[cand]).min())
    first = None if not crossing.any() else int(np.flatnonzero(crossing)[0])
    return {"pairs": int(crossing.sum()),
            "first": None if first is None else [int(i[first]), int(j[first])],
            "first_at": None if first is None else P[i[first]].mean(axis=0).tolist(),
            "smallest_distance": smallest,
            "within": within, "tol": tol, "seconds": time.perf_counter() - t0}
