"""The compiled path of the surface obstacle's signed distance
(:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`): its held candidate sets through
:func:`.surface_kernels.signed_in_sets`, the sets that no longer prove the nearest triangle sought again (and made
wider where fresh ones rarely prove it: :data:`WIDEST`), the points still unproven searched over
every triangle within their distance plus ``R`` in the same compiled loop (validation/mesh_obstacles.md, "Cost").
"""

from __future__ import annotations

from itertools import chain

import numpy as np

__all__ = ["FAR", "HELD_SETS", "NEAREST", "WIDER", "WIDEST", "ball_sets", "evaluate_compiled", "kernel_call"]

NEAREST = 12
"""Triangle centroids each point's nearest triangle is sought among by the numpy twin (then proven, or searched
wider)."""

WIDER = 64
"""Triangle centroids each point's nearest triangle is sought among by the compiled twin, nearest first: it
stops at the first that cannot be nearer (a point on the surface tests a few), and a point several triangles
off the surface (the sheet hanging beside a finely tessellated body) is still proven among them, without the
search of every triangle within its distance plus ``R``."""

WIDEST = 512
"""The most centroids a compiled candidate set grows to: where fresh sets of :data:`WIDER` fail to prove the
nearest triangle for more than a quarter of the points sought again (slivers along a rounded edge: the nearest
centroids all lie within a few millimetres), the next calls use sets twice as large."""

FAR = "dk_0 - moved - R >= band"
"""A point whose held candidate set bounds its distance beyond the band (its set's nearest centroid, less how far it
moved since, less ``R``) needs only that bound: it is evaluated with its nearest centroid now as its set (a k-d
tree query of one centroid) rather than its held set tested, failing its proof and sought again with ``K``
centroids; its value then no longer depends on which set it held. On sphere-mesh with the level-4 icosphere the
all-node evaluations of the candidate list's refreshes re-sought ~700 far nodes each: 2.5 of the query's 4.8 s."""

HELD_SETS = 8
"""Candidate sets kept between calls, one per number of points asked about (the sheet's nodes, its edge
midpoints, the feature contact's points ...): a static obstacle's triangles never move, so a point that moved
less than its margin keeps its set (:meth:`.surface_mesh.SurfaceObstacle._candidates`) and Newton's iterations skip the
k-d tree."""


def kernel_call(ob, x, ik, dk, moved, hessian, every=False):
    """:func:`.surface_kernels.signed_in_sets` at ``x (n, 3)`` [m] over the candidate sets ``ik, dk, moved``:
    ``(phi, normal, H, out)`` (``H`` a dummy unless ``hessian``)."""
    from rftstatic.contact.obstacles._surface_numba import signed_in_sets

    n = len(x)
    phi, normal, out = np.empty(n), np.empty((n, 3)), np.empty((n, 6))
    H = np.empty((n, 3, 3) if hessian else (1, 3, 3))
    consts = ob._consts
    if every:
        consts = consts.copy()
        consts[10] = 1.0
    signed_in_sets(np.ascontiguousarray(x), ob._surface, np.ascontiguousarray(ik), np.ascontiguousarray(dk),
                   moved, consts, hessian, phi, normal, H, out)
    return phi, normal, H, out


def ball_sets(ob, xo, reach):
    """Each point's triangles whose centroid lies within ``reach (m,) + R`` [m] (every one that can be nearest
    to a point ``reach`` from the surface), as rows of an ``(m, k)`` array padded with repeats."""
    lists = ob._ctree.query_ball_point(xo, reach + ob.radius * (1 + 1e-12) + 1e-300)
    counts = np.fromiter(map(len, lists), np.int64, len(lists))
    flat = np.fromiter(chain.from_iterable(lists), np.int64, int(counts.sum()))
    start = np.cumsum(counts) - counts
    k = int(counts.max(initial=1))
    col = np.minimum(np.arange(k)[None, :], np.maximum(counts, 1)[:, None] - 1)
    return flat[start[:, None] + col]


def evaluate_compiled(ob, x, hessian):
    """:meth:`~.surface_mesh.SurfaceObstacle._evaluate` of the obstacle ``ob`` at ``x (n, 3)`` [m] by the compiled
    :func:`.surface_kernels.signed_in_sets` over the held candidate sets; the points it leaves (status 1: a held
    set that no longer proves the nearest triangle is sought again where the point is, then every triangle within
    ``r + R`` in the same loop; status 2: beyond the band inside the box) go through the numpy path; a held set's
    point beyond the band by its bound alone (status 3) is evaluated again with its nearest centroid now
    (:meth:`~.surface_mesh.SurfaceObstacle._signed`)."""
    K = min(ob._wider, len(ob.T))
    ik, dk, moved = ob._candidates(x, K)
    phi, normal, H, out = kernel_call(ob, x, ik, dk, moved, hessian)
    far = np.flatnonzero(out[:, 5] == 3.0)
    if far.size:  # beyond the band whatever its held set: its nearest centroid now as its set (FAR)
        dkf, ikf = ob._ctree.query(x[far], k=1)
        phi[far], normal[far], Hf, out[far] = kernel_call(ob, x[far], ikf.reshape(-1, 1), dkf.reshape(-1, 1),
                                                          np.zeros(len(far)), hessian)
        if hessian:
            H[far] = Hf
    again = np.flatnonzero((out[:, 5] == 1.0) & (moved > 0))
    if again.size:  # sets kept from the last call that no longer prove the nearest: the K nearest now
        dka, ika = ob._ctree.query(x[again], k=K)
        dka, ika = dka.reshape(len(again), K), ika.reshape(len(again), K)
        x_ref, ik_held, dk_held = ob._sets[len(x)]
        x_ref[again], ik_held[again], dk_held[again] = x[again], ika, dka
        phi[again], normal[again], Ha, out[again] = kernel_call(ob, x[again], ika, dka, np.zeros(len(again)),
                                                                      hessian)
        if hessian:
            H[again] = Ha
        if np.count_nonzero(out[again, 5] == 1.0) > 0.25 * again.size and ob._wider < ob.widest:
            ob._wider *= 2  # sets that rarely prove (fine, anisotropic facets): wider ones from the next call
    ball = np.flatnonzero(out[:, 5] == 1.0)
    if ball.size:  # still unproven within the band: every triangle within r + R, in the compiled loop
        ikb = ball_sets(ob, x[ball], out[ball, 3])
        phi[ball], normal[ball], Hb, out[ball] = kernel_call(ob, x[ball], ikb, np.zeros(ikb.shape),
                                                                   np.zeros(len(ball)), hessian, every=True)
        if hessian:
            H[ball] = Hb
    rest = np.flatnonzero(out[:, 5] != 0.0)
    if rest.size:  # beyond the band inside the box: the winding number's (and a deep point's ball search)
        xr, o = x[rest], out[rest]
        kind, gid = np.zeros(len(rest), np.int8), np.zeros(len(rest), np.int64)
        phi[rest], normal[rest], Hr = ob._signed(xr, o[:, :3].copy(), kind, gid, np.zeros(len(rest), bool),
                                                   o[:, 4], hessian)
        if hessian:
            H[rest] = Hr
    return phi, normal, (H if hessian else None)

