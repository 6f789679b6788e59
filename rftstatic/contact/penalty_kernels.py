"""Per-step loops of the penalty contact's explicit force (:mod:`rftstatic.contact.penalty_compiled`), plain
Python compiled by numba (:mod:`._penalty_numba`): the candidate list's validity test and the filter of the
candidates within reach (:func:`near_nodes`), and the slope of the smoothed penalty density and the scatter
``k A_n e' n`` into the force (:func:`penalty_scatter`). Each repeats the numpy path of
:meth:`rftstatic.contact.penalty.PenaltyContact.force` operation by operation, in its order (bit-identical).

Arrays: ``x (N, 3)`` positions [m]; candidate indices ``(C,)``; ``phi (M, C)`` [m] and ``normal (M, C, 3)`` of
the ``M`` obstacles at the kept nodes; ``area (N,)`` [m^2]; ``force (N, 3)`` [N].
"""

from __future__ import annotations

import math

__all__ = ["near_nodes", "penalty_scatter", "slope_one"]


def near_nodes(x, x_ref, cand, gap0, half_margin, eps, fresh, keep):
    """Number of candidates kept in ``keep (C,)`` (their indices), or -1 when the list is stale.

    ``x, x_ref (N, 3)``: positions now and at the refresh [m]; ``cand (C,)``: the list's indices; ``gap0 (N,)``
    the distances at the refresh [m]. ``moved = max_n |x_n - x_ref_n|`` with the squares summed as numpy's
    ``einsum("...i,...i->...")`` does here, ``(d0^2 + d2^2) + d1^2`` (NaN propagates, as ``np.max``), or 0 when
    the list was ``fresh``ly made at ``x``; stale when ``moved > half_margin``. Kept: ``gap0 - 2 (gap0 - (gap0 -
    moved)) < eps``, the numpy path's expression. (The force does not depend on the last bit of ``moved``: a node
    it drops or keeps at the boundary lies beyond ``eps`` and adds +0.)"""
    big = 0.0
    for n in range(0 if fresh else x.shape[0]):
        d0, d1, d2 = x[n, 0] - x_ref[n, 0], x[n, 1] - x_ref[n, 1], x[n, 2] - x_ref[n, 2]
        v = (d0 * d0 + d2 * d2) + d1 * d1
        if v > big or v != v:
            big = v
    moved = math.sqrt(big)
    if moved > half_margin:
        return -1
    count = 0
    for j in range(cand.shape[0]):
        c = cand[j]
        g = gap0[c]
        if g - 2.0 * (g - (g - moved)) < eps:
            keep[count] = c
            count += 1
    return count


def slope_one(phi, eps):
    """``e'(phi)`` [m] of the penalty density per unit ``k A`` (:meth:`PenaltyContact._slope
    <rftstatic.contact.penalty.PenaltyContact._slope>`, the same expressions; NaN as there)."""
    if eps == 0.0:
        return phi if phi < 0.0 or phi != phi else 0.0
    if phi < 0.0:
        return phi - 0.5 * eps
    if phi < eps:
        a = eps - phi
        return -(a * a) / (2.0 * eps)
    return 0.0


def penalty_scatter(keep, phi, normal, eps, k, area, force):
    """Fill ``force[keep]`` (``force (N, 3)`` [N]) with ``sum_m (k A_n e'(phi_m)) n_m``, accumulated from 0 over the
    obstacles ``m`` as numpy's ``einsum``; ``phi (M, C)`` [m] and ``normal (M, C, 3)`` at the nodes ``keep (C,)``,
    ``k`` [N/m^3], ``area (N,)`` [m^2]."""
    for j in range(keep.shape[0]):
        c = keep[j]
        ka = k * area[c]
        f0, f1, f2 = 0.0, 0.0, 0.0
        for m in range(phi.shape[0]):
            t = ka * slope_one(phi[m, j], eps)
            f0 = t * normal[m, j, 0] + f0
            f1 = t * normal[m, j, 1] + f1
            f2 = t * normal[m, j, 2] + f2
        force[c, 0], force[c, 1], force[c, 2] = f0, f1, f2
