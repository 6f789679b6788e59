"""Compiled internal force for the explicit loop (numba back end of :mod:`rftstatic.explicit_force`).

Same sums as the numpy back end: bending ``K_b @ U`` over the CSR rows of the scalar K_b (Eq. 13),
then per element the strain-point displacement gradients ``H_q = sum_a U_a (x) G_qa``, the averaged
Green strain, ``S = D^m eps`` (Eq. 15) and the nodal forces ``f_a = A/Q sum_q F_q S G_qa``.
Imported only when the numba back end is chosen.
"""

import numba as nb
import numpy as np


@nb.njit(cache=True, nogil=True)
def internal_force(indptr, indices, data, nodes, G, area, Dm, U, f, with_membrane, energy):
    """Fill ``f (N, 3)`` [N] with the internal force at ``U (N, 3)`` [m]; return the stored energy [J]."""
    N = U.shape[0]
    W = 0.0
    for n in range(N):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for p in range(indptr[n], indptr[n + 1]):
            j = indices[p]
            d = data[p]
            s0 += d * U[j, 0]
            s1 += d * U[j, 1]
            s2 += d * U[j, 2]
        f[n, 0] = s0
        f[n, 1] = s1
        f[n, 2] = s2
        if energy:
            W += 0.5 * (U[n, 0] * s0 + U[n, 1] * s1 + U[n, 2] * s2)
    if not with_membrane:
        return W
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    for e in range(E):
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
        if energy:
            W += 0.5 * area[e] * (exx * Sxx + eyy * Syy + gxy * Sxy)
        w = area[e] / Q
        for q in range(Q):
            # first Piola-Kirchhoff P = F S, F = I + H (stored here as P[q, J, i])
            for i in range(3):
                fx = H[q, 0, i]
                fy = H[q, 1, i]
                if i == 0:
                    fx += 1.0
                if i == 1:
                    fy += 1.0
                px = w * (fx * Sxx + fy * Sxy)
                py = w * (fx * Sxy + fy * Syy)
                for a in range(A):
                    f[nodes[e, a], i] += px * G[e, q, a, 0] + py * G[e, q, a, 1]
    return W
