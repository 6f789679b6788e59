"""The explicit step's obstacle force of the penalty contact, compiled (what
:meth:`rftstatic.contact.penalty.PenaltyContact.force` calls first: :func:`compiled_force`).

The force is ``f_n = k A_n sum_m e'(phi_m(x_n)) n_m(x_n)`` (the gradient of ``E = sum k A_n e(phi)``, Sze & Zhou
2016 §4.5, with the C^2 onset of width ``eps``: ``e' = phi - eps/2`` inside, ``-(eps - phi)^2 / (2 eps)`` for
``0 <= phi < eps``, 0 beyond; ``e' = min(phi, 0)`` when ``eps = 0``). Once a step the numpy path makes about twenty
array calls on the few thousand candidate nodes (the list's validity test, the filter of the candidates within
reach, the obstacles' distances, the slope, an ``einsum``, the scatter): 0.22 ms a step on pedestal-round-50,
mostly call overhead (validation/bench_profile.md). Here they are three compiled passes:

1. :func:`~rftstatic.contact.penalty_kernels.near_nodes`: the largest motion since the list's refresh
   (:meth:`CandidateList.lookup <rftstatic.contact.candidates.CandidateList.lookup>`'s test) and the candidates whose
   distance bound ``gap0 - 2 moved`` is below ``eps`` (the numpy path's filter);
2. :func:`~rftstatic.contact.obstacles.pedestal_kernels.distances_at`: every obstacle's distance and normal at those
   nodes (a loop in the obstacles' own file: numba's cache is keyed on the file of a loop and what it inlines);
3. :func:`~rftstatic.contact.penalty_kernels.penalty_scatter`: the slope and ``k A_n e' n`` summed over the
   obstacles into the force.

Bit-identical to the numpy path (the explicit relaxation is chaotic: one ulp changes the Newton walk after it):
the same operations in the same order, ``np.einsum("n,mn,mni->ni", ka, d1, normal)`` being ``((ka d1) n_m) + out``
accumulated from +0 over the obstacles ``m``, so a zero normal component of the other sign (the round pedestal's
numpy and compiled twins differ so) leaves the same force.

Covered (else :func:`compiled_force` returns None and the numpy path runs): numba installed and at least
:data:`~rftstatic.contact.obstacles.pedestal_kernels.COMPILED_MIN_POINTS` nodes (a small scene does not load numba
for it); every obstacle has a ``point_kernel()`` of its own class (:func:`point_form`: the round and square
pedestals, the sphere, the floor, i.e. the paper's scenes and a release route's support; not a triangle surface or
a deforming one); the obstacles at rest (no :attr:`~rftstatic.contact.candidates.CandidateList.poses`). The sharp
features' and the lagged friction's forces are added by the caller as before. The list's refresh (one distance
query of every node) is the numpy path's own, so the list and its refreshes are the same.
"""

from __future__ import annotations

import numpy as np

from rftstatic.contact.obstacles.pedestal_kernels import compiled_for

__all__ = ["compiled_force", "point_form"]


def point_form(obstacles) -> tuple[np.ndarray, np.ndarray] | None:
    """``(kinds (M,) int, params (M, P) [m])`` of the obstacles' compiled distances (their ``point_kernel()``, read
    from each obstacle's own class), or None when some obstacle has none, or there are none."""
    forms = []
    for ob in obstacles:
        own = vars(type(ob)).get("point_kernel")
        form = None if own is None else own(ob)
        if form is None:
            return None
        forms.append(form)
    if not forms:
        return None
    params = np.zeros((len(forms), max(len(p) for _, p in forms)))
    for m, (_, p) in enumerate(forms):
        params[m, :len(p)] = p
    return np.array([kind for kind, _ in forms], dtype=np.int64), params


def compiled_force(contact, x: np.ndarray, candidates) -> np.ndarray | None:
    """The obstacles' part of ``contact.force(x, candidates=candidates)``, ``(N, 3)`` [N] at ``x (N, 3)`` [m], by
    the compiled passes (``contact`` a :class:`~rftstatic.contact.penalty.PenaltyContact`, its ``point_form`` of
    :func:`point_form`; ``candidates`` its list or None), refreshing the list as the numpy path does; None where not
    covered (module docstring)."""
    form = contact.point_form
    if form is None or not compiled_for(x.shape[0]):
        return None
    if candidates is not None and (candidates.poses is not None or candidates.shape_times is not None):
        return None
    from rftstatic.contact._penalty_numba import near_nodes, penalty_scatter
    from rftstatic.contact.obstacles._pedestal_numba import distances_at

    x = np.ascontiguousarray(x, dtype=float)
    eps = contact.smoothing
    if candidates is None:
        keep = np.arange(x.shape[0])
    else:
        count, ref = -1, candidates.reference
        if ref is not None and ref[0].shape == x.shape:
            keep = np.empty(ref[1].shape[0], dtype=np.intp)
            count = near_nodes(x, *ref, 0.5 * candidates.margin, eps, False, keep)
        if count < 0:  # stale: the numpy path's refresh (one distance query of every node), then moved = 0
            candidates.refresh(x, contact._distances_of(x)[0].min(axis=0))
            ref = candidates.reference
            keep = np.empty(ref[1].shape[0], dtype=np.intp)
            count = near_nodes(x, *ref, 0.5 * candidates.margin, eps, True, keep)
        keep = keep[:count]
    kinds, params = form
    phi, normal = np.empty((kinds.shape[0], keep.shape[0])), np.empty((kinds.shape[0], keep.shape[0], 3))
    distances_at(x, keep, kinds, params, phi, normal)
    force = np.zeros((x.shape[0], 3))
    penalty_scatter(keep, phi, normal, eps, contact.stiffness, contact.node_area, force)
    return force
