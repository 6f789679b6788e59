"""Compiled internal force for the explicit loop (numba back end of :mod:`rftstatic.explicit_force`).

Same sums as the numpy back end: bending ``K_b @ U`` over the CSR rows of the scalar K_b (Eq. 13),
then per element the strain-point displacement gradients ``H_q = sum_a U_a (x) G_qa``, the averaged
Green strain, ``S = D^m eps`` (Eq. 15) and the nodal forces ``f_a = A/Q sum_q F_q S G_qa``.
Imported only when the numba back end is chosen.
"""

import numba as nb
import numpy as np

from rftstatic.element._membrane_numba import strain_and_stress


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


@nb.njit(cache=True, nogil=True, parallel=True)
def internal_force_parallel(indptr, indices, data, nodes, G, area, Dm, U, f, fe, slot_ptr, slots, with_membrane,
                            energy, chunks):
    """As :func:`internal_force`, on numba's threads: ``chunks`` blocks of elements write their nodal
    forces into ``fe (E * A, 3)`` [N] (no two threads touch one entry), then each node sums its
    bending row and its element slots ``slots[slot_ptr[n]:slot_ptr[n + 1]]`` in a fixed order, so
    the result does not depend on the number of threads."""
    N = U.shape[0]
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    W = 0.0
    if with_membrane:
        for c in nb.prange(chunks):
            H = np.empty((Q, 2, 3))
            for e in range(c * E // chunks, (c + 1) * E // chunks):
                exx, eyy, gxy, Sxx, Syy, Sxy = strain_and_stress(e, nodes, G, Dm, U, H)
                if energy:
                    W += 0.5 * area[e] * (exx * Sxx + eyy * Syy + gxy * Sxy)
                w = area[e] / Q
                for a in range(A):
                    k = e * A + a
                    fe[k, 0] = 0.0
                    fe[k, 1] = 0.0
                    fe[k, 2] = 0.0
                for q in range(Q):
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
                            fe[e * A + a, i] += px * G[e, q, a, 0] + py * G[e, q, a, 1]
    for n in nb.prange(N):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for p in range(indptr[n], indptr[n + 1]):
            j = indices[p]
            d = data[p]
            s0 += d * U[j, 0]
            s1 += d * U[j, 1]
            s2 += d * U[j, 2]
        if energy:
            W += 0.5 * (U[n, 0] * s0 + U[n, 1] * s1 + U[n, 2] * s2)
        if with_membrane:
            for p in range(slot_ptr[n], slot_ptr[n + 1]):
                k = slots[p]
                s0 += fe[k, 0]
                s1 += fe[k, 1]
                s2 += fe[k, 2]
        f[n, 0] = s0
        f[n, 1] = s1
        f[n, 2] = s2
    return W
