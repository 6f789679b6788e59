"""Compiled membrane forces and tangents for Newton (numba back end of
:meth:`rftstatic.membrane.MembraneOperator.element_tangents`).

The same sums as the numpy path, one element at a time: the strain-point displacement gradients
``H_q = sum_a U_a (x) G_qa``, the averaged Green strain (Eq. 14), ``S = D^m eps`` (Eq. 15), the
averaged strain-displacement matrix ``Bbar`` and the element tangent
``A (Bbar^T D^m Bbar + 1/Q sum_q G_q S G_q^T (x) I)``. With ``psd`` the stress in the geometric part
is replaced by its positive part (2 x 2 eigen-decomposition in closed form). Imported only when
numba is installed; :func:`rftstatic.membrane.MembraneOperator.element_tangents` falls back to numpy.
"""

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, nogil=True)
def _positive_part(sxx, syy, sxy):
    """Positive part of the symmetric 2 x 2 stress [[sxx, sxy], [sxy, syy]] -> (pxx, pyy, pxy)."""
    mean = 0.5 * (sxx + syy)
    half = 0.5 * (sxx - syy)
    rad = math.sqrt(half * half + sxy * sxy)
    w1 = mean + rad
    w2 = mean - rad
    if w2 >= 0.0:
        return sxx, syy, sxy
    if w1 <= 0.0:
        return 0.0, 0.0, 0.0
    # only w1 > 0: w1 v v^T with v the unit eigenvector of w1
    if rad == 0.0:
        return 0.0, 0.0, 0.0
    c2 = 0.5 * (1.0 + half / rad)  # cos^2 of the principal angle
    s2 = 1.0 - c2
    cs = 0.5 * sxy / rad
    return w1 * c2, w1 * s2, w1 * cs


@nb.njit(cache=True, nogil=True)
def strain_and_stress(e, nodes, G, Dm, U, H):
    """Element ``e``: fill ``H (Q, 2, 3)`` with the strain-point displacement gradients
    ``H[q, J, i] = sum_a G[e, q, a, J] U[n(e, a), i]`` and return the averaged Green strain (Eq. 14)
    ``(e_xx, e_yy, 2 e_xy)`` [-] and the stress resultant ``S = D^m eps`` (Eq. 15) [N/m]."""
    Q, A = G.shape[1], G.shape[2]
    for q in range(Q):
        for J in range(2):
            for i in range(3):
                H[q, J, i] = 0.0
        for a in range(A):
            n = nodes[e, a]
            gx = G[e, q, a, 0]
            gy = G[e, q, a, 1]
            for i in range(3):
                u = U[n, i]
                H[q, 0, i] += gx * u
                H[q, 1, i] += gy * u
    exx = 0.0
    eyy = 0.0
    gxy = 0.0
    for q in range(Q):
        exx += H[q, 0, 0] + 0.5 * (H[q, 0, 0] ** 2 + H[q, 0, 1] ** 2 + H[q, 0, 2] ** 2)
        eyy += H[q, 1, 1] + 0.5 * (H[q, 1, 0] ** 2 + H[q, 1, 1] ** 2 + H[q, 1, 2] ** 2)
        gxy += (H[q, 0, 1] + H[q, 1, 0]
                + H[q, 0, 0] * H[q, 1, 0] + H[q, 0, 1] * H[q, 1, 1] + H[q, 0, 2] * H[q, 1, 2])
    exx /= Q
    eyy /= Q
    gxy /= Q
    Sxx = Dm[0, 0] * exx + Dm[0, 1] * eyy + Dm[0, 2] * gxy
    Syy = Dm[1, 0] * exx + Dm[1, 1] * eyy + Dm[1, 2] * gxy
    Sxy = Dm[2, 0] * exx + Dm[2, 1] * eyy + Dm[2, 2] * gxy
    return exx, eyy, gxy, Sxx, Syy, Sxy


@nb.njit(cache=True, nogil=True)
def element_tangents(nodes, G, area, Dm, U, psd, f, K):
    """Fill ``f (E, A, 3)`` [N] and ``K (E, A, 3, A, 3)`` [N/m] at displacements ``U (N, 3)`` [m]."""
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    B = np.empty((3, A, 3))  # Bbar[k, a, i]
    DB = np.empty((3, A, 3))
    for e in range(E):
        exx, eyy, gxy, Sxx, Syy, Sxy = strain_and_stress(e, nodes, G, Dm, U, H)
        # Bbar: d eps_k / d x_ai averaged over the strain points, F = I + H
        for a in range(A):
            for i in range(3):
                b0 = 0.0
                b1 = 0.0
                b2 = 0.0
                for q in range(Q):
                    fx = H[q, 0, i]
                    fy = H[q, 1, i]
                    if i == 0:
                        fx += 1.0
                    elif i == 1:
                        fy += 1.0
                    gx = G[e, q, a, 0]
                    gy = G[e, q, a, 1]
                    b0 += fx * gx
                    b1 += fy * gy
                    b2 += fx * gy + fy * gx
                B[0, a, i] = b0 / Q
                B[1, a, i] = b1 / Q
                B[2, a, i] = b2 / Q
        w = area[e]
        for a in range(A):
            for i in range(3):
                f[e, a, i] = w * (Sxx * B[0, a, i] + Syy * B[1, a, i] + Sxy * B[2, a, i])
                for k in range(3):
                    DB[k, a, i] = Dm[k, 0] * B[0, a, i] + Dm[k, 1] * B[1, a, i] + Dm[k, 2] * B[2, a, i]
        if psd:
            pxx, pyy, pxy = _positive_part(Sxx, Syy, Sxy)
        else:
            pxx, pyy, pxy = Sxx, Syy, Sxy
        for a in range(A):
            for b in range(A):
                # geometric part: 1/Q sum_q G_qa . S G_qb, times the identity in space
                g = 0.0
                for q in range(Q):
                    ga0 = G[e, q, a, 0]
                    ga1 = G[e, q, a, 1]
                    gb0 = G[e, q, b, 0]
                    gb1 = G[e, q, b, 1]
                    g += ga0 * (pxx * gb0 + pxy * gb1) + ga1 * (pxy * gb0 + pyy * gb1)
                g /= Q
                for i in range(3):
                    for j in range(3):
                        m = B[0, a, i] * DB[0, b, j] + B[1, a, i] * DB[1, b, j] + B[2, a, i] * DB[2, b, j]
                        if i == j:
                            m += g
                        K[e, a, i, b, j] = w * m
