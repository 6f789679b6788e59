"""Continuous collision detection of points moving along straight segments against a fixed triangle surface
(the explicit steps' kinematic contact, :func:`rftstatic.contact.kinematic.kinematic_contact`).

A kinematic step moves a node from ``x0`` to ``x1`` and then projects it out of the obstacle if ``phi(x1) < 0``.
That is blind to a step through a thin part: through a two-sided shell's mid-surface (``x1`` then lies
nearer the far face, and is pushed out there) or right through a solid (``x1`` outside again). So the segment
is tested against the surface's triangles (the mid-surface of a shell): the first proper crossing (its ends
on opposite sides of the triangle's plane, the crossing point inside the triangle) stops the node there,
lifted by the shell's half-thickness towards its start, and the normal there is returned (towards the start).

Broad phase: only a point whose step is longer than its end point's distance to the surface can have
crossed it (the distance is 1-Lipschitz), and of the triangles only those whose centroid lies within
``|x1 - x0| / 2 + R`` of the segment's midpoint (``R`` the largest centroid-to-corner radius; the centroid
k-d tree of the obstacle, built once).
"""

from __future__ import annotations

from itertools import chain

import numpy as np

__all__ = ["first_crossings"]

PLANE_TOL = 1e-9
"""A segment end within this fraction of the segment's length of a triangle's plane is on it, not across it:
a node resting on a solid's face (projected onto it by the last step) slides without crossing."""


def first_crossings(ob, x0: np.ndarray, x1: np.ndarray, candidates: np.ndarray, half: float):
    """First crossing of the segments ``x0[c] -> x1[c]`` (``c`` in ``candidates``) through the triangles of the
    surface obstacle ``ob`` (:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`: ``V, T, nf,
    centroid, radius`` and its centroid tree).

    Returns ``(hit (n,) bool, stop (n, 3) [m], normal (n, 3))`` over all ``n`` points: the crossing point
    moved ``half`` [m] along the triangle's normal towards ``x0``, and that normal (module docstring)."""
    n = len(x0)
    hit = np.zeros(n, bool)
    stop, normal = x1.copy(), np.zeros((n, 3))
    if candidates.size == 0:
        return hit, stop, normal
    a0, a1 = x0[candidates], x1[candidates]
    d = a1 - a0
    length = np.linalg.norm(d, axis=1)
    lists = ob._ctree.query_ball_point(0.5 * (a0 + a1), 0.5 * length + ob.radius * (1 + 1e-12) + 1e-300)
    counts = np.fromiter(map(len, lists), np.int64, len(lists))
    tri = np.fromiter(chain.from_iterable(lists), np.int64, int(counts.sum()))
    seg = np.repeat(np.arange(len(candidates)), counts)
    if tri.size == 0:
        return hit, stop, normal
    nf = ob.nf[tri]
    A, B, C = (ob.V[ob.T[tri, k]] for k in range(3))
    s0 = np.einsum("pi,pi->p", a0[seg] - A, nf)
    s1 = np.einsum("pi,pi->p", a1[seg] - A, nf)
    tol = PLANE_TOL * length[seg]
    across = ((s0 > tol) & (s1 < -tol)) | ((s0 < -tol) & (s1 > tol))
    if not across.any():
        return hit, stop, normal
    t = np.where(across, s0 / np.where(across, s0 - s1, 1.0), 0.0)
    p = a0[seg] + t[:, None] * d[seg]
    # inside the triangle: on the inner side of its three edges (within round-off: a crossing on an edge is one)
    eps = -1e-12 * np.einsum("pi,pi->p", B - A, B - A)
    inside = across.copy()
    for P, Q in ((A, B), (B, C), (C, A)):  # the three edges
        inside &= np.einsum("pi,pi->p", np.cross(Q - P, p - P), nf) >= eps
    t = np.where(inside, t, np.inf)
    order = np.lexsort((t, seg))
    first = order[np.r_[0, np.cumsum(counts[counts > 0])[:-1]]]
    ok = np.isfinite(t[first])
    first = first[ok]
    who = candidates[seg[first]]
    side = np.sign(s0[first])[:, None] * nf[first]
    hit[who] = True
    stop[who] = p[first] + half * side
    normal[who] = side
    return hit, stop, normal
