"""Per-point loops of the rounded pedestals' signed distance, normal and Hessian, plain Python compiled by numba
(:mod:`._pedestal_numba`; the numpy twins are the methods of :class:`.square_pedestal.SquarePedestal` and
:class:`.round_pedestal.RoundPedestal` over :func:`.base._rounded_box`).

The formulas are those of :mod:`.base` (the rounded-box distance ``phi = |max(q, 0)| + min(max_i q_i, 0) - r``
in the shifted coordinates ``q``) and of the two classes' notes, evaluated point by point with the same
one-sided choices (the first largest ``q_i`` inside the inner box, ``+x`` on the round pedestal's axis), so the
two twins agree to round-off. Why: the numpy twins build about 20 ``(N, 3)`` or ``(N, 3, 3)`` temporaries per
call; the penalty contact of a relaxation step calls ``signed_distance`` on the 1,700 candidate nodes of the
81 x 81 sheet on the 40 cm square pedestal once a step (0.25-0.45 ms a call, 4.5 s of pedestal-square-80's
run, validation/bench_profile.md), which the loop does in a few microseconds.

Arrays: ``x (N, 3)`` points [m]; out ``phi (N,)`` [m], ``normal (N, 3)`` [-], ``H (N, 3, 3)`` [1/m] (or
``(1, 3, 3)``, untouched, when ``hessian`` is false).

The same per-point functions serve :func:`distances_at`, the distance and normal of several analytic obstacles
(the pedestals, the sphere, the floor: :func:`distance_one`, selected by a kind code an obstacle gives with its
``point_kernel()``) at a set of points in one compiled pass, for the penalty contact's explicit force
(:mod:`rftstatic.contact.penalty_compiled`); they live in this one file because numba's cache is keyed on the
file of the compiled loop, which inlines them.
"""

from __future__ import annotations

import math

import numpy as np

from rftstatic.compiled import numba_available

__all__ = ["COMPILED_MIN_POINTS", "FLOOR", "ROUND", "SPHERE", "SQUARE", "compiled_for", "distance_one", "distances_at",
           "round_all", "round_one", "rounded_box_one", "run", "square_all", "square_one", "vertical_one"]

COMPILED_MIN_POINTS = 256
"""Fewest points of a call that the compiled loops take (numba installed): below, the numpy twins, so a small
scene that never loads numba (about 0.6 s with the first cached kernel) does not load it for its obstacle; a
function of the call alone, never of what ran before in the process."""


def compiled_for(n: int) -> bool:
    """Whether a call on ``n`` points runs the compiled loops (:data:`COMPILED_MIN_POINTS`)."""
    return n >= COMPILED_MIN_POINTS and numba_available()


def vertical_one(z, top, height, r):
    """Shifted vertical coordinate ``q_z`` [m] of one point at height ``z`` and ``dq_z/dz`` (+-1), as
    :func:`.base._vertical_q` (``height`` inf: infinitely tall)."""
    if math.isinf(height):
        return z - (top - r), 1.0
    dz = z - (top - 0.5 * height)
    return abs(dz) - (0.5 * height - r), (1.0 if dz >= 0.0 else -1.0)


def rounded_box_one(q0, q1, q2, d, r):
    """:func:`.base._rounded_box` of one point in ``d`` = 2 (``q2`` ignored) or 3 coordinates:
    ``(phi [m], g0, g1, g2, inv [1/m])`` with ``g = dphi/dq`` and ``G = (diag(q > 0) - g g^T) inv`` (``inv`` = 0
    inside the inner box, where ``G`` = 0)."""
    p0, p1 = max(q0, 0.0), max(q1, 0.0)
    p2 = max(q2, 0.0) if d == 3 else 0.0
    length = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2) if d == 3 else math.sqrt(p0 * p0 + p1 * p1)
    if length > 0.0:
        inv = 1.0 / length
        return length - r, p0 * inv, p1 * inv, p2 * inv, inv
    k, qmax = 0, q0
    if q1 > qmax:
        k, qmax = 1, q1
    if d == 3 and q2 > qmax:
        k, qmax = 2, q2
    return min(qmax, 0.0) - r, (1.0 if k == 0 else 0.0), (1.0 if k == 1 else 0.0), (1.0 if k == 2 else 0.0), 0.0


def square_one(x0, x1, x2, cx, cy, hx, hy, top, height, r):
    """The square pedestal's rounded-box distance at one point ``(x0, x1, x2)`` [m] (parameters as
    :func:`square_all`): ``(phi [m], g0, g1, g2, inv [1/m], s0, s1, s2, q0, q1, q2 [m])`` with ``g`` and ``inv`` of
    :func:`rounded_box_one` in the shifted coordinates ``q`` and ``s = dq/dx`` (+-1 per axis); the normal is
    ``g_i s_i``."""
    a0, a1 = x0 - cx, x1 - cy
    s0 = 1.0 if a0 >= 0.0 else -1.0
    s1 = 1.0 if a1 >= 0.0 else -1.0
    q2, s2 = vertical_one(x2, top, height, r)
    q0, q1 = abs(a0) - (hx - r), abs(a1) - (hy - r)
    phi, g0, g1, g2, inv = rounded_box_one(q0, q1, q2, 3, r)
    return phi, g0, g1, g2, inv, s0, s1, s2, q0, q1, q2


def square_all(x, cx, cy, hx, hy, top, height, r, hessian, phi, normal, H):
    """The square pedestal (:class:`.square_pedestal.SquarePedestal`: centre ``(cx, cy)``, half sides ``hx, hy``,
    top face ``top``, ``height`` (inf: infinitely tall), edge radius ``r`` [m]) at every point of ``x``: fills
    ``phi``, ``normal`` and, with ``hessian``, ``H`` (module docstring)."""
    for n in range(x.shape[0]):
        phi[n], g0, g1, g2, inv, s0, s1, s2, q0, q1, q2 = square_one(x[n, 0], x[n, 1], x[n, 2], cx, cy, hx, hy,
                                                                     top, height, r)
        normal[n, 0], normal[n, 1], normal[n, 2] = g0 * s0, g1 * s1, g2 * s2
        if hessian:
            g = (g0, g1, g2)
            pos = (1.0 if q0 > 0.0 else 0.0, 1.0 if q1 > 0.0 else 0.0, 1.0 if q2 > 0.0 else 0.0)
            s = (s0, s1, s2)
            for i in range(3):
                for j in range(3):
                    diag = pos[i] if i == j else 0.0
                    H[n, i, j] = (diag - g[i] * g[j]) * inv * s[i] * s[j]


def round_one(x0, x1, x2, cx, cy, radius, top, height, r):
    """The round pedestal's distance at one point ``(x0, x1, x2)`` [m] (parameters as :func:`round_all`):
    ``(phi [m], g0, g1, inv [1/m], e0, e1, rho [m], sz, q0, q1 [m])`` with ``g`` and ``inv`` of
    :func:`rounded_box_one` in ``q = (rho - (radius - r), q_z)``, ``e`` the horizontal unit vector from the axis
    (``+x`` on it) and ``sz = dq_z/dz``; the normal is ``(g0 e0, g0 e1, g1 sz)``."""
    a0, a1 = x0 - cx, x1 - cy
    rho = math.sqrt(a0 * a0 + a1 * a1)
    if rho == 0.0:
        e0, e1 = 1.0, 0.0
    else:
        e0, e1 = a0 / rho, a1 / rho
    q1, sz = vertical_one(x2, top, height, r)
    q0 = rho - (radius - r)
    phi, g0, g1, _, inv = rounded_box_one(q0, q1, 0.0, 2, r)
    return phi, g0, g1, inv, e0, e1, rho, sz, q0, q1


def round_all(x, cx, cy, radius, top, height, r, hessian, phi, normal, H):
    """The round pedestal (:class:`.round_pedestal.RoundPedestal`: axis at ``(cx, cy)``, ``radius``, top face
    ``top``, ``height`` (inf: infinitely tall), rim radius ``r`` [m]) at every point of ``x``: fills ``phi``,
    ``normal`` and, with ``hessian``, ``H = J^T G J + (g_0 / rho) (P_xy - e e^T)`` (the class notes)."""
    for n in range(x.shape[0]):
        phi[n], g0, g1, inv, e0, e1, rho, sz, q0, q1 = round_one(x[n, 0], x[n, 1], x[n, 2], cx, cy, radius, top,
                                                                 height, r)
        normal[n, 0], normal[n, 1], normal[n, 2] = g0 * e0, g0 * e1, g1 * sz
        if hessian:
            # G = (diag(q > 0) - g g^T) inv in (rho, z); J rows e = (e0, e1, 0) and (0, 0, sz)
            G00 = ((1.0 if q0 > 0.0 else 0.0) - g0 * g0) * inv
            G01 = -g0 * g1 * inv
            G11 = ((1.0 if q1 > 0.0 else 0.0) - g1 * g1) * inv
            coef = 0.0 if rho == 0.0 else g0 / rho
            e = (e0, e1, 0.0)
            for i in range(3):
                for j in range(3):
                    v = G00 * e[i] * e[j] + coef * ((1.0 if i == j and i < 2 else 0.0) - e[i] * e[j])
                    if i == 2:
                        v += G01 * sz * e[j]
                    if j == 2:
                        v += G01 * e[i] * sz
                    if i == 2 and j == 2:
                        v += G11 * sz * sz
                    H[n, i, j] = v


FLOOR, SPHERE, SQUARE, ROUND = 0, 1, 2, 3
"""Kind codes of the analytic obstacles in :func:`distances_at` (an obstacle's ``point_kernel()``, e.g.
:meth:`.sphere.Sphere.point_kernel`): the floor ``(height,)``, the sphere ``(cx, cy, cz, radius)``, the square
pedestal :func:`square_one`'s and the round pedestal :func:`round_one`'s parameters after the point [m]."""


def distance_one(kind, p, x0, x1, x2):
    """``(phi [m], n0, n1, n2)`` of the obstacle of ``kind`` (:data:`FLOOR`, ...) with parameters ``p`` at one point:
    the operations of the type's numpy ``signed_distance``, in its order (the same bits; a zero normal component
    may differ in sign). The sphere: ``d = x - c``, ``phi = |d| - R`` (``|d|`` summed as ``(d0^2 + d1^2) + d2^2``,
    numpy's ``norm``), ``n = d / |d|`` (``+z`` at the centre); the floor: ``phi = z - height``, ``n = +z``."""
    if kind == FLOOR:
        return x2 - p[0], 0.0, 0.0, 1.0
    if kind == SPHERE:
        d0, d1, d2 = x0 - p[0], x1 - p[1], x2 - p[2]
        dist = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if dist == 0.0:
            return dist - p[3], 0.0, 0.0, 1.0
        return dist - p[3], d0 / dist, d1 / dist, d2 / dist
    if kind == SQUARE:
        phi, g0, g1, g2, _, s0, s1, s2, _, _, _ = square_one(x0, x1, x2, p[0], p[1], p[2], p[3], p[4], p[5], p[6])
        return phi, g0 * s0, g1 * s1, g2 * s2
    phi, g0, g1, _, e0, e1, _, sz, _, _ = round_one(x0, x1, x2, p[0], p[1], p[2], p[3], p[4], p[5])
    return phi, g0 * e0, g0 * e1, g1 * sz


def distances_at(x, index, kinds, params, phi, normal):
    """Signed distance and normal of ``M`` analytic obstacles (``kinds (M,)``, ``params (M, P)``, :func:`distance_one`)
    at the points ``x[index]`` (``x (N, 3)`` [m], ``index (C,)``): fills ``phi (M, C)`` [m] and ``normal (M, C, 3)``
    in one pass (the penalty contact's explicit force, :mod:`rftstatic.contact.penalty_compiled`)."""
    for j in range(index.shape[0]):
        c = index[j]
        for m in range(kinds.shape[0]):
            phi[m, j], normal[m, j, 0], normal[m, j, 1], normal[m, j, 2] = distance_one(kinds[m], params[m], x[c, 0],
                                                                                        x[c, 1], x[c, 2])


def run(kernel, x, params, hessian):
    """``(phi (N,), normal (N, 3), H (N, 3, 3) or None)`` of the compiled ``kernel`` (:mod:`._pedestal_numba`)
    at the points ``x (N, 3)`` [m] with the obstacle's ``params`` (the kernel's arguments after ``x``)."""
    x = np.ascontiguousarray(x, dtype=float)
    n = x.shape[0]
    phi, normal = np.empty(n), np.empty((n, 3))
    H = np.empty((n, 3, 3) if hessian else (1, 3, 3))
    kernel(x, *params, hessian, phi, normal, H)
    return phi, normal, (H if hessian else None)
