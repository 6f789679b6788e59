"""Self-contact loops written once as scalar loops, for the compiled (numba) twins of the law's PSD
projection and of the near-pair lists' node motion (:mod:`._kernels_numba` compiles a copy of every
function here; the numpy paths are those of the calling modules, :mod:`.law_kernels` and
:mod:`.near_pairs`). None of them needs the pair geometry: the loops that do are in
:mod:`.geometry`, with it.

PSD projection (:func:`psd_project_all`): a 12 x 12 block ``B`` of the law lies in the span of
``w (x) e_i`` and ``dw/du_a (x) r`` (rank <= 5, :mod:`.geometry`), so instead of a 12 x 12
eigen-decomposition the columns of ``B`` are reduced by a pivoted Gram-Schmidt (twice, for
orthogonality to round-off) to an orthonormal basis ``U (12, m)`` of its range (columns whose
residual is below ``RANK_TOL`` times the largest column are round-off), ``M = U^T B U`` is diagonalised
by cyclic Jacobi rotations and ``U V max(L, 0) V^T U^T`` returned. This is exact for any symmetric
``B`` (``m = 12`` at worst) and agrees with ``numpy.linalg.eigh`` to round-off.
"""

import numpy as np

RANK_TOL = 1e-14
"""Residual column norm, relative to the largest column of a block, below which a column adds no
direction to the block's range in :func:`psd_project_all` (round-off of the Gram-Schmidt)."""


def jacobi_eigen(M, V, m):
    """Eigen-decomposition of the symmetric leading ``m x m`` part of ``M`` in place by cyclic Jacobi
    rotations: ``M`` ends diagonal (the eigenvalues), ``V`` holds the eigenvectors as columns."""
    for i in range(m):
        for j in range(m):
            V[i, j] = 1.0 if i == j else 0.0
    for _ in range(50):
        off = 0.0
        diag = 0.0
        for i in range(m):
            diag += M[i, i] * M[i, i]
            for j in range(i + 1, m):
                off += M[i, j] * M[i, j]
        if off <= 1e-34 * diag or off == 0.0:
            return
        for p in range(m - 1):
            for q in range(p + 1, m):
                apq = M[p, q]
                if apq == 0.0:
                    continue
                theta = (M[q, q] - M[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
                if theta < 0:
                    t = -t
                c = 1.0 / np.sqrt(t * t + 1.0)
                sn = t * c
                for k in range(m):
                    mkp, mkq = M[k, p], M[k, q]
                    M[k, p], M[k, q] = c * mkp - sn * mkq, sn * mkp + c * mkq
                for k in range(m):
                    mpk, mqk = M[p, k], M[q, k]
                    M[p, k], M[q, k] = c * mpk - sn * mqk, sn * mpk + c * mqk
                for k in range(m):
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p], V[k, q] = c * vkp - sn * vkq, sn * vkp + c * vkq


def psd_project_one(H, out, B, R, U, M, V):
    """``out (n, n)``: the symmetric part of ``H (n, n)`` with its negative eigenvalues set to 0 (module
    docstring); ``B, R, U, M, V (n, n)`` are scratch. Vectors are rows (``B`` is symmetric: its rows
    span its range), so the inner loops run over contiguous memory."""
    n = H.shape[0]
    cmax = 0.0
    for i in range(n):
        c = 0.0
        for j in range(n):
            v = 0.5 * (H[i, j] + H[j, i])
            B[i, j] = v
            R[i, j] = v  # residual rows
            c += v * v
        cmax = max(cmax, c)
    out[:, :] = 0.0
    if cmax == 0.0:
        return
    tol2 = RANK_TOL * RANK_TOL * cmax
    m = 0
    while m < n:
        jbest, nbest = -1, tol2
        for j in range(n):
            c = 0.0
            for i in range(n):
                c += R[j, i] * R[j, i]
            if c > nbest:
                jbest, nbest = j, c
        if jbest < 0:
            break
        for i in range(n):
            U[m, i] = R[jbest, i]
        for _ in range(2):  # Gram-Schmidt twice: orthogonal to round-off
            for b in range(m):
                dot = 0.0
                for i in range(n):
                    dot += U[b, i] * U[m, i]
                for i in range(n):
                    U[m, i] -= dot * U[b, i]
        nrm = 0.0
        for i in range(n):
            nrm += U[m, i] * U[m, i]
        nrm = 1.0 / np.sqrt(nrm)
        for i in range(n):
            U[m, i] *= nrm
        for j in range(n):
            dot = 0.0
            for i in range(n):
                dot += U[m, i] * R[j, i]
            for i in range(n):
                R[j, i] -= dot * U[m, i]
        m += 1
    for a in range(m):  # M = U B U^T (basis as rows), B U^T kept in the rows of R
        for j in range(n):
            v = 0.0
            for i in range(n):
                v += B[j, i] * U[a, i]
            R[a, j] = v
    for a in range(m):
        for b in range(a, m):
            v = 0.0
            for i in range(n):
                v += U[a, i] * R[b, i]
            M[a, b] = v
            M[b, a] = v
    jacobi_eigen(M, V, m)
    k = 0
    for c in range(m):  # kept eigenvectors in the full space, scaled by sqrt of their eigenvalues
        lam = M[c, c]
        if lam > 0:
            sq = np.sqrt(lam)
            for i in range(n):
                R[k, i] = 0.0
            for a in range(m):
                f = V[a, c] * sq
                for i in range(n):
                    R[k, i] += f * U[a, i]
            k += 1
    for i in range(n):
        for j in range(i, n):
            v = 0.0
            for c in range(k):
                v += R[c, i] * R[c, j]
            out[i, j] = v
            out[j, i] = v


def psd_project_all(H, out):
    """``out (A, n, n)``: every block of ``H (A, n, n)`` projected onto the PSD matrices."""
    n = H.shape[1]
    B = np.zeros((n, n))
    U = np.zeros((n, n))
    M = np.zeros((n, n))
    V = np.zeros((n, n))
    R = np.zeros((n, n))
    for a in range(H.shape[0]):
        psd_project_one(H[a], out[a], B, R, U, M, V)


def midrange_motion(a, b, s, c, out):
    """Translation-free motion (Eq. 1 of :mod:`.near_pairs`) of ``w = a + s b - c`` (``a, b, c (N, 3)``
    [m], ``s`` a scalar): ``out[k] = |w_k - m|`` ``(N,)`` [m] with ``m`` the midrange of ``w`` over the
    nodes; returns ``max_k out[k]`` (0 for no node). Two passes over the nodes, no temporary array, the
    bounds in scalars: the motion since a build (``a = x``, ``s = 0``, ``c = x_build``), at the end of a step
    (``b = dx``, ``s = 1``) or a step's own spread (``a = dx``, ``c = 0``)."""
    n = a.shape[0]
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for k in range(n):
        w0 = a[k, 0] + s * b[k, 0] - c[k, 0]
        w1 = a[k, 1] + s * b[k, 1] - c[k, 1]
        w2 = a[k, 2] + s * b[k, 2] - c[k, 2]
        lo0, hi0 = min(lo0, w0), max(hi0, w0)
        lo1, hi1 = min(lo1, w1), max(hi1, w1)
        lo2, hi2 = min(lo2, w2), max(hi2, w2)
    m0, m1, m2 = 0.5 * (lo0 + hi0), 0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2)
    big = 0.0
    for k in range(n):
        w0 = a[k, 0] + s * b[k, 0] - c[k, 0] - m0
        w1 = a[k, 1] + s * b[k, 1] - c[k, 1] - m1
        w2 = a[k, 2] + s * b[k, 2] - c[k, 2] - m2
        r = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        out[k] = r
        big = max(big, r)
    return big


def step_motions(x, xb, dx):
    """The largest translation-free motions (Eq. 1 of :mod:`.near_pairs`) of an explicit step's filter, in two passes:
    since the build ``xb`` at ``x`` (``w = x - xb``), at the step's end (``w = x + dx - xb``) and of the step ``dx``
    itself (``w = dx``); ``x, xb, dx (N, 3)`` [m]. Returns the three maxima [m], each the square root of the largest
    squared norm: the values of three :func:`midrange_motion` calls (the same arithmetic: ``a + s b - c`` with
    ``s = 0`` is ``a - c``; a correctly rounded square root keeps the order), without a root per node."""
    n = x.shape[0]
    lo = np.full((3, 3), np.inf)  # rows: since the build, at the step's end, the step; columns: axes
    hi = np.full((3, 3), -np.inf)
    for i in range(3):
        la, lb, lc, ha, hb, hc = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
        for k in range(n):
            w0 = x[k, i] - xb[k, i]
            w1 = x[k, i] + dx[k, i] - xb[k, i]
            w2 = dx[k, i]
            la, ha = min(la, w0), max(ha, w0)
            lb, hb = min(lb, w1), max(hb, w1)
            lc, hc = min(lc, w2), max(hc, w2)
        lo[0, i], lo[1, i], lo[2, i], hi[0, i], hi[1, i], hi[2, i] = la, lb, lc, ha, hb, hc
    mid = 0.5 * (lo + hi)
    a0, a1, a2 = mid[0, 0], mid[0, 1], mid[0, 2]
    b0, b1, b2 = mid[1, 0], mid[1, 1], mid[1, 2]
    c0, c1, c2 = mid[2, 0], mid[2, 1], mid[2, 2]
    big0 = big1 = big2 = 0.0
    for k in range(n):
        w0, w1, w2 = x[k, 0] - xb[k, 0] - a0, x[k, 1] - xb[k, 1] - a1, x[k, 2] - xb[k, 2] - a2
        big0 = max(big0, w0 * w0 + w1 * w1 + w2 * w2)
        w0 = x[k, 0] + dx[k, 0] - xb[k, 0] - b0
        w1 = x[k, 1] + dx[k, 1] - xb[k, 1] - b1
        w2 = x[k, 2] + dx[k, 2] - xb[k, 2] - b2
        big1 = max(big1, w0 * w0 + w1 * w1 + w2 * w2)
        w0, w1, w2 = dx[k, 0] - c0, dx[k, 1] - c1, dx[k, 2] - c2
        big2 = max(big2, w0 * w0 + w1 * w1 + w2 * w2)
    return np.sqrt(big0), np.sqrt(big1), np.sqrt(big2)


def largest_norm(v):
    """``max_k |v_k|`` of ``v (N, 3)`` (0 for no row)."""
    big = 0.0
    for k in range(v.shape[0]):
        big = max(big, v[k, 0] * v[k, 0] + v[k, 1] * v[k, 1] + v[k, 2] * v[k, 2])
    return np.sqrt(big)
