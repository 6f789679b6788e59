"""The projected outer boundary of a draped sheet and the folds counted on it.

- :func:`boundary_loop`: ordered nodes of the outer boundary (edges used by one triangle, ordered by
  pointer jumping);
- :func:`fold_count`: the number of folds, the prominent local maxima of the boundary's radius r(θ)
  about the support's axis (:class:`FoldProfile` holds r(θ) and the crests).

Lengths in the units of ``x`` (SI inside the package), angles in radians.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from rftstatic.post.measures.triangles import edge_keys

__all__ = ["FoldProfile", "boundary_loop", "fold_count"]


def boundary_loop(tri: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
    """Ordered node indices of the outer boundary.

    Boundary edges are the edges used by one triangle (counted with one ``np.unique``);
    following them in the triangles' own direction gives the loops, which are labelled and
    ordered by pointer jumping (O(n log n) numpy, no walk).

    Parameters
    ----------
    tri : (E, 3) int ndarray
        Triangles, consistently oriented.
    x : (N, 2) or (N, 3) ndarray, optional
        Node positions [m]. With it, the outer loop is the one whose xy projection encloses
        the largest area; without it, the loop with the most nodes.

    Returns
    -------
    (B,) int ndarray
        Boundary node indices in order along the loop (not repeated at the end), in the
        triangles' orientation (counter-clockwise for counter-clockwise triangles).

    Raises
    ------
    ValueError
        If the mesh has no boundary, or a node has more than one outgoing boundary edge
        (two loops touch at a node, or the triangles are not consistently oriented).
    """
    tri = np.asarray(tri)
    n = int(tri.max()) + 1
    a, b, key = edge_keys(tri, n)
    _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
    is_b = counts[inv] == 1
    ba, bb = a[is_b], b[is_b]
    if ba.size == 0:
        raise ValueError("boundary_loop: the mesh is closed (every edge has two triangles)")
    nodes, ia = np.unique(ba, return_index=True)
    if nodes.size != ba.size or not np.array_equal(np.unique(bb), nodes):
        raise ValueError("boundary_loop: a node has two outgoing boundary edges (loops touching "
                         "at a node, or inconsistent triangle orientation); fix the mesh")
    m = nodes.size
    nxt = np.searchsorted(nodes, bb[ia])                    # compact successor
    # loop label = smallest compact index on the cycle (pointer jumping)
    lab, ptr = np.arange(m), nxt.copy()
    for _ in range(int(np.ceil(np.log2(max(m, 2)))) + 1):
        lab = np.minimum(lab, lab[ptr])
        ptr = ptr[ptr]
    # rank along the loop from its label node: jump over predecessors, cut at the start
    prev = np.empty(m, dtype=np.int64)
    prev[nxt] = np.arange(m)
    start = lab == np.arange(m)
    dist = np.where(start, 0, 1)
    ptr = np.where(start, np.arange(m), prev)
    for _ in range(int(np.ceil(np.log2(max(m, 2)))) + 1):
        dist, ptr = dist + dist[ptr], ptr[ptr]             # the start points to itself, dist 0
    labels, sizes = np.unique(lab, return_counts=True)
    if x is None:
        pick = labels[np.argmax(sizes)]
    else:
        xy = np.asarray(x, dtype=float)[:, :2]
        areas = []
        for lb in labels:                                   # a handful of loops
            sel = np.flatnonzero(lab == lb)
            loop = nodes[sel[np.argsort(dist[sel])]]
            q = xy[loop]
            areas.append(abs(0.5 * np.sum(q[:, 0] * np.roll(q[:, 1], -1)
                                          - np.roll(q[:, 0], -1) * q[:, 1])))
        pick = labels[int(np.argmax(areas))]
    sel = np.flatnonzero(lab == pick)
    return nodes[sel[np.argsort(dist[sel])]]


def _prominent_peaks(r: np.ndarray, threshold: float) -> np.ndarray:
    """Indices of local maxima of a periodic signal whose prominence is at least ``threshold``.

    Prominence as in topography (and ``scipy.signal.peak_prominences``): a crest's height
    above the higher of the two lowest points met on each side before reaching higher ground.
    Vectorised as a (crests × samples) mask; the signal has only a few hundred samples.
    """
    k0 = int(np.argmin(r))
    s = np.concatenate([np.roll(r, -k0), [r[k0]]])       # start and end at the global minimum
    j = np.arange(s.size)
    c = np.flatnonzero((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:])) + 1
    if c.size == 0:
        return c
    hc = s[c][:, None]
    higher = s[None, :] > hc
    left = np.where(higher & (j[None, :] < c[:, None]), j[None, :], 0).max(axis=1)
    right = np.where(higher & (j[None, :] > c[:, None]), j[None, :], s.size - 1).min(axis=1)
    lmin = np.where((j[None, :] >= left[:, None]) & (j[None, :] <= c[:, None]), s[None, :], np.inf)
    rmin = np.where((j[None, :] >= c[:, None]) & (j[None, :] <= right[:, None]), s[None, :], np.inf)
    prom = s[c] - np.maximum(lmin.min(axis=1), rmin.min(axis=1))
    return (c[prom >= threshold] + k0) % r.size


class FoldProfile(NamedTuple):
    """Result of :func:`fold_count`.

    Attributes
    ----------
    count : int
        Number of folds (prominent local maxima of r(θ)).
    theta : (n,) ndarray
        Uniform angle grid in [0, 2π) [rad].
    r : (n,) ndarray
        Outermost projected boundary radius at each angle [m].
    peak_theta : (count,) ndarray
        Angles of the folds' crests [rad].
    """

    count: int
    theta: np.ndarray
    r: np.ndarray
    peak_theta: np.ndarray


def _ray_radius(xy: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Largest distance along rays from the origin at which they cross the closed polyline."""
    a = xy
    b = np.roll(xy, -1, axis=0)
    u = np.stack([np.cos(theta), np.sin(theta)], axis=1)              # (n, 2)
    ca = u[:, :1] * a[None, :, 1] - u[:, 1:] * a[None, :, 0]           # cross(u, a) (n, K)
    cb = u[:, :1] * b[None, :, 1] - u[:, 1:] * b[None, :, 0]
    den = ca - cb
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(den != 0.0, ca / den, np.nan)
    hit = (t >= 0.0) & (t <= 1.0)
    px = a[None, :, 0] + t * (b[None, :, 0] - a[None, :, 0])
    py = a[None, :, 1] + t * (b[None, :, 1] - a[None, :, 1])
    r = px * u[:, :1] + py * u[:, 1:]
    return np.where(hit & (r > 0.0), r, -np.inf).max(axis=1)


def _rays(x, loop, centre, n_angles):
    """``theta (n,)`` [rad] and the projected boundary's radius ``r (n,)`` [m] along the rays from ``centre``
    (``-inf`` where a ray misses it)."""
    xy = np.asarray(x, dtype=float)[np.asarray(loop), :2] - np.asarray(centre, dtype=float)[:2]
    theta = np.linspace(0.0, 2.0 * np.pi, int(n_angles), endpoint=False)
    return theta, _ray_radius(xy, theta)


def outline_surrounds(x: np.ndarray, loop: np.ndarray, centre=(0.0, 0.0), *, n_angles: int = 720) -> bool:
    """Whether every ray from ``centre`` crosses the projected boundary ``loop`` (``x`` (N, 2 or 3) [m]), as
    :func:`fold_count` needs: False when a draped sheet has slid off its support's axis."""
    return bool(np.all(np.isfinite(_rays(x, loop, centre, n_angles)[1])))


def fold_count(x: np.ndarray, loop: np.ndarray, centre=(0.0, 0.0), *, n_angles: int = 720,
               prominence: float = 0.1, min_amplitude: float = 0.01) -> FoldProfile:
    """Number of folds of a draped sheet from its projected outer boundary.

    r(θ) is the largest distance from ``centre`` at which a ray at angle θ crosses the
    projected boundary polygon (the outer envelope, so boundaries that fold back in
    projection are handled), sampled on ``n_angles`` uniform angles. A fold is a local
    maximum of the periodic r(θ) whose prominence exceeds
    ``max(prominence·(r_max − r_min), min_amplitude·mean(r))``; the relative threshold
    suppresses mesh noise, the absolute one makes a nearly circular outline count 0.

    Parameters
    ----------
    x : (N, 3) or (N, 2) ndarray
        Node positions [m].
    loop : (B,) int ndarray
        Ordered outer boundary nodes (:func:`boundary_loop`).
    centre : (2,) array_like, optional
        Axis of the support in the xy-plane [m].
    n_angles : int, optional
        Angle samples.
    prominence : float, optional
        Relative prominence threshold [-].
    min_amplitude : float, optional
        Absolute prominence floor as a fraction of the mean radius [-].

    Returns
    -------
    FoldProfile
        ``(count, theta, r, peak_theta)``.

    Raises
    ------
    ValueError
        If some ray misses the boundary (``centre`` is outside the projected outline).
    """
    theta, r = _rays(x, loop, centre, n_angles)
    if not np.all(np.isfinite(r)):
        bad = theta[~np.isfinite(r)][0]
        raise ValueError(f"fold_count: the ray at θ = {np.degrees(bad):.1f}° from centre = "
                         f"{tuple(np.asarray(centre)[:2])} misses the boundary; is the centre "
                         "inside the projected outline?")
    thr = max(prominence * (r.max() - r.min()), min_amplitude * r.mean())
    peaks = _prominent_peaks(r, thr)
    peak_theta = np.sort(theta[peaks])
    return FoldProfile(int(peaks.size), theta, r, peak_theta)
