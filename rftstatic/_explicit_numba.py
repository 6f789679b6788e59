"""Compiled internal force for the explicit loop (numba back end of :mod:`rftstatic.explicit_force`).

Same sums as the numpy back end: bending ``K_b @ U`` over the CSR rows of the scalar K_b (Eq. 13),
then per element the strain-point displacement gradients ``H_q = sum_a U_a (x) G_qa``, the averaged
Green strain, ``S = D^m eps`` (Eq. 15) and the nodal forces ``f_a = A/Q sum_q F_q S G_qa``.
Imported only when the numba back end is chosen.
"""

import numba as nb
import numpy as np

from ._membrane_numba import strain_and_stress


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
        exx, eyy, gxy, Sxx, Syy, Sxy = strain_and_stress(e, nodes, G, Dm, U, H)
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
