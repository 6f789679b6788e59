"""Self-contact kernels written once as scalar loops over pairs, for the compiled (numba) twins of
:mod:`.distance` and of the law's PSD projection and step bound (:mod:`._kernels_numba` compiles a copy
of every function here; the numpy paths are those of the calling modules).

The formulas are those of :mod:`.distance` (closest feature, envelope-theorem Hessian) in the same
order of operations, so the two paths agree to round-off; ``x (4, 3)`` is one pair's points
``(p, t_0, t_1, t_2)`` or ``(a_0, a_1, b_0, b_1)`` [m], ``W (4,)``, ``D (4, 2)`` and ``act (2,)`` the
closest feature's weights, their parameter derivatives and the active parameters, filled in place.

PSD projection (:func:`psd_project_all`): a 12 x 12 block ``B`` of the law lies in the span of
``w (x) e_i`` and ``dw/du_a (x) r`` (rank <= 5, :mod:`.distance`), so instead of a 12 x 12
eigen-decomposition the columns of ``B`` are reduced by a pivoted Gram-Schmidt (twice, for
orthogonality to round-off) to an orthonormal basis ``U (12, m)`` of its range (columns whose
residual is below ``RANK_TOL`` times the largest column are round-off), ``M = U^T B U`` is diagonalised
by cyclic Jacobi rotations and ``U V max(L, 0) V^T U^T`` returned. This is exact for any symmetric
``B`` (``m = 12`` at worst) and agrees with ``numpy.linalg.eigh`` to round-off.
"""

import numpy as np

PARALLEL_TOL = 1e-12
"""``sin^2`` of the angle between two edges below which they count as parallel (interior candidate
dropped). The interior distance then differs from the end-point one by at most ``~1e-6`` of an edge
length, and ``G`` of the interior feature stays well conditioned (``det G >= 1e-12 |e_a|^2 |e_b|^2``)."""

RANK_TOL = 1e-14
"""Residual column norm, relative to the largest column of a block, below which a column adds no
direction to the block's range in :func:`psd_project_all` (round-off of the Gram-Schmidt)."""

_EDGES = ((1, 2), (2, 3), (3, 1))


def segment_param(x, p, a, b):
    """Parameter in [0, 1] of the point of segment ``x[a] x[b]`` closest to ``x[p]``."""
    ee = 0.0
    pe = 0.0
    for i in range(3):
        e = x[b, i] - x[a, i]
        ee += e * e
        pe += (x[p, i] - x[a, i]) * e
    t = pe / ee if ee > 0 else 0.0
    return min(max(t, 0.0), 1.0)


def pt_classify(x, W, D, act):
    """Closest feature of point ``x[0]`` and triangle ``x[1:]``: fills ``W, D, act``; returns the squared
    distance [m^2] and the feature code (0 face, 1 edge, 2 vertex)."""
    a11 = a12 = a22 = b1 = b2 = 0.0
    for i in range(3):
        e1, e2, w = x[2, i] - x[1, i], x[3, i] - x[1, i], x[0, i] - x[1, i]
        a11 += e1 * e1
        a12 += e1 * e2
        a22 += e2 * e2
        b1 += w * e1
        b2 += w * e2
    det = a11 * a22 - a12 * a12
    W[:] = 0.0
    D[:, :] = 0.0
    act[:] = False
    best = np.inf
    code = 0
    if det > 1e-14 * a11 * a22:
        u = (a22 * b1 - a12 * b2) / det
        v = (a11 * b2 - a12 * b1) / det
        if u >= 0 and v >= 0 and u + v <= 1:
            best = 0.0
            for i in range(3):
                r = (x[0, i] - x[1, i]) - u * (x[2, i] - x[1, i]) - v * (x[3, i] - x[1, i])
                best += r * r
            W[0], W[1], W[2], W[3] = 1.0, -(1 - u - v), -u, -v
            D[1, 0], D[1, 1], D[2, 0], D[3, 1] = 1.0, 1.0, -1.0, -1.0
            act[0] = act[1] = True
    for i, j in _EDGES:
        s = segment_param(x, 0, i, j)
        d2 = 0.0
        for k in range(3):
            r = x[0, k] - x[i, k] - s * (x[j, k] - x[i, k])
            d2 += r * r
        if d2 < best:
            best = d2
            W[:] = 0.0
            W[0], W[i], W[j] = 1.0, -(1 - s), -s
            D[:, :] = 0.0
            interior = s > 0 and s < 1
            if interior:
                D[i, 0], D[j, 0] = 1.0, -1.0
            act[0], act[1] = interior, False
            code = 1 if interior else 2
    return best, code


def ee_classify(x, W, D, act):
    """Closest feature of edges ``x[0] x[1]`` and ``x[2] x[3]``: fills ``W, D, act``; returns the squared
    distance [m^2] and the feature code (0 interior, 1 end point-edge, 2 end point-end point)."""
    aa = ab = bb = ad = bd = 0.0
    for i in range(3):
        ea, eb, w0 = x[1, i] - x[0, i], x[3, i] - x[2, i], x[0, i] - x[2, i]
        aa += ea * ea
        ab += ea * eb
        bb += eb * eb
        ad += ea * w0
        bd += eb * w0
    det = aa * bb - ab * ab
    best = np.inf
    S = T = 0.0
    act[:] = False
    code = 0
    if det > PARALLEL_TOL * aa * bb:
        s = (ab * bd - bb * ad) / det
        t = (aa * bd - ab * ad) / det
        if s > 0 and s < 1 and t > 0 and t < 1:
            best = 0.0
            for i in range(3):
                r = (x[0, i] - x[2, i]) + s * (x[1, i] - x[0, i]) - t * (x[3, i] - x[2, i])
                best += r * r
            S, T = s, t
            act[0] = act[1] = True
    for c in range(4):
        # end point of one edge (a_0, a_1, b_0, b_1) against the other segment
        value = 1.0 if c % 2 else 0.0
        if c < 2:
            pe = pp = 0.0
            for i in range(3):
                pt = x[0, i] + value * (x[1, i] - x[0, i])
                e = x[3, i] - x[2, i]
                pe += (pt - x[2, i]) * e
                pp += e * e
            q = pe / pp if pp > 0 else 0.0
            q = min(max(q, 0.0), 1.0)
            s_c, t_c = value, q
        else:
            pe = pp = 0.0
            for i in range(3):
                pt = x[2, i] + value * (x[3, i] - x[2, i])
                e = x[1, i] - x[0, i]
                pe += (pt - x[0, i]) * e
                pp += e * e
            q = pe / pp if pp > 0 else 0.0
            q = min(max(q, 0.0), 1.0)
            s_c, t_c = q, value
        d2 = 0.0
        for i in range(3):
            r = (x[0, i] - x[2, i]) + s_c * (x[1, i] - x[0, i]) - t_c * (x[3, i] - x[2, i])
            d2 += r * r
        if d2 < best:
            best = d2
            S, T = s_c, t_c
            interior = q > 0 and q < 1
            act[0] = act[1] = False
            act[1 if c < 2 else 0] = interior
            code = 1 if interior else 2
    W[0], W[1], W[2], W[3] = 1 - S, S, -(1 - T), -T
    D[:, :] = 0.0
    if act[0]:
        D[0, 0], D[1, 0] = -1.0, 1.0
    if act[1]:
        D[2, 1], D[3, 1] = 1.0, -1.0
    return best, code


def pair_derivatives(x, W, D, act, grad, H, hessian):
    """Squared distance [m^2] of ``|sum_k W_k x_k|^2``; fills ``grad (4, 3)`` [m] and, with ``hessian``,
    ``H (12, 12)`` [-] minimised over the active parameters (:func:`.distance.pair_derivatives`)."""
    r0 = r1 = r2 = 0.0
    for k in range(4):
        r0 += W[k] * x[k, 0]
        r1 += W[k] * x[k, 1]
        r2 += W[k] * x[k, 2]
    s = r0 * r0 + r1 * r1 + r2 * r2
    for k in range(4):
        grad[k, 0], grad[k, 1], grad[k, 2] = 2.0 * W[k] * r0, 2.0 * W[k] * r1, 2.0 * W[k] * r2
    if not hessian:
        return s
    H[:, :] = 0.0
    for k in range(4):
        for m in range(4):
            h = 2.0 * W[k] * W[m]
            for i in range(3):
                H[3 * k + i, 3 * m + i] = h
    if not (act[0] or act[1]):
        return s
    tv = np.zeros((2, 3))
    for a in range(2):
        for i in range(3):
            t = 0.0
            for k in range(4):
                t += D[k, a] * x[k, i]
            tv[a, i] = t
    g00 = 2.0 * (tv[0, 0] * tv[0, 0] + tv[0, 1] * tv[0, 1] + tv[0, 2] * tv[0, 2]) if act[0] else 1.0
    g11 = 2.0 * (tv[1, 0] * tv[1, 0] + tv[1, 1] * tv[1, 1] + tv[1, 2] * tv[1, 2]) if act[1] else 1.0
    g01 = 2.0 * (tv[0, 0] * tv[1, 0] + tv[0, 1] * tv[1, 1] + tv[0, 2] * tv[1, 2]) if act[0] and act[1] else 0.0
    det = g00 * g11 - g01 * g01
    i00, i11, i01 = g11 / det, g00 / det, -g01 / det
    F = np.zeros((12, 2))
    r = (r0, r1, r2)
    for a in range(2):
        if act[a]:
            for k in range(4):
                for i in range(3):
                    F[3 * k + i, a] = 2.0 * (D[k, a] * r[i] + W[k] * tv[a, i])
    for m in range(12):
        f0 = F[m, 0] * i00 + F[m, 1] * i01
        f1 = F[m, 0] * i01 + F[m, 1] * i11
        for n in range(12):
            H[m, n] = H[m, n] - (f0 * F[n, 0] + f1 * F[n, 1])
    return s


def distances_all(x4, kind, s, code):
    """Squared distances ``s (P,)`` [m^2] and feature codes ``code (P,)`` of all pairs ``x4 (P, 4, 3)``
    [m]; ``kind`` 0 point-triangle, 1 edge-edge."""
    W = np.zeros(4)
    D = np.zeros((4, 2))
    act = np.zeros(2, dtype=np.bool_)
    for p in range(x4.shape[0]):
        if kind == 0:
            s[p], code[p] = pt_classify(x4[p], W, D, act)
        else:
            s[p], code[p] = ee_classify(x4[p], W, D, act)


def derivatives_all(x4, kind, hessian, s, grad, H, code):
    """Fill ``s (P,)`` [m^2], ``grad (P, 4, 3)`` [m], ``H (P, 12, 12)`` [-] (with ``hessian``) and
    ``code (P,)`` of all pairs ``x4 (P, 4, 3)`` [m]; ``kind`` 0 point-triangle, 1 edge-edge."""
    W = np.zeros(4)
    D = np.zeros((4, 2))
    act = np.zeros(2, dtype=np.bool_)
    for p in range(x4.shape[0]):
        if kind == 0:
            _, code[p] = pt_classify(x4[p], W, D, act)
        else:
            _, code[p] = ee_classify(x4[p], W, D, act)
        s[p] = pair_derivatives(x4[p], W, D, act, grad[p], H[p if hessian else 0], hessian)


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


def ccd_all(x, dx, nodes, kind, eta, max_rounds, floor):
    """Smallest safe time in [0, 1] over all pairs ``nodes (P, 4)`` of positions ``x`` and step ``dx``
    ``(N, 3)`` [m] of the additive continuous collision detection (:mod:`.law`); ``kind`` 0
    point-triangle (sides ``{0}``, ``{1, 2, 3}``), 1 edge-edge (``{0, 1}``, ``{2, 3}``). A pair's
    target distance is ``g = eta d0``, raised to ``floor`` [m] when it starts above it. A pair stops
    once its time passes the smallest one found (its time only grows), which leaves the minimum
    unchanged."""
    W = np.zeros(4)
    D = np.zeros((4, 2))
    act = np.zeros(2, dtype=np.bool_)
    x4 = np.zeros((4, 3))
    dx4 = np.zeros((4, 3))
    y = np.zeros((4, 3))
    na = 1 if kind == 0 else 2
    tmin = 1.0
    for p in range(nodes.shape[0]):
        for k in range(4):
            for i in range(3):
                x4[k, i] = x[nodes[p, k], i]
                dx4[k, i] = dx[nodes[p, k], i]
        ell2 = 0.0
        for a in range(na):
            for b in range(na, 4):
                r = 0.0
                for i in range(3):
                    v = dx4[a, i] - dx4[b, i]
                    r += v * v
                ell2 = max(ell2, r)
        ell = np.sqrt(ell2)
        if not ell > 0:
            continue
        if kind == 0:
            s0, _ = pt_classify(x4, W, D, act)
        else:
            s0, _ = ee_classify(x4, W, D, act)
        d0 = np.sqrt(s0)
        g = eta * d0
        if d0 > floor:
            g = max(g, floor)
        if not ell > d0 - g:
            continue
        t = 0.0
        dcur = d0
        for _ in range(max_rounds):
            tn = t + (dcur - g) / ell
            if tn >= 1.0:
                t = 1.0
                break
            t = tn
            if t >= tmin:
                break
            for k in range(4):
                for i in range(3):
                    y[k, i] = x4[k, i] + t * dx4[k, i]
            if kind == 0:
                s, _ = pt_classify(y, W, D, act)
            else:
                s, _ = ee_classify(y, W, D, act)
            dcur = np.sqrt(s)
            if dcur - g <= 1e-3 * (d0 - g):
                break
        tmin = min(tmin, t)
    return tmin


def midrange_motion(a, b, s, c, out):
    """Translation-free motion (Eq. 1 of :mod:`.near_pairs`) of ``w = a + s b - c`` (``a, b, c (N, 3)``
    [m], ``s`` a scalar): ``out[k] = |w_k - m|`` ``(N,)`` [m] with ``m`` the midrange of ``w`` over the
    nodes; returns ``max_k out[k]`` (0 for no node). Two passes over the nodes, no temporary array:
    the motion since a build (``a = x``, ``s = 0``, ``c = x_build``), at the end of a step
    (``b = dx``, ``s = 1``) or a step's own spread (``a = dx``, ``c = 0``)."""
    n = a.shape[0]
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for k in range(n):
        for i in range(3):
            w = a[k, i] + s * b[k, i] - c[k, i]
            lo[i] = min(lo[i], w)
            hi[i] = max(hi[i], w)
    mid = 0.5 * (lo + hi)
    big = 0.0
    for k in range(n):
        r = 0.0
        for i in range(3):
            w = a[k, i] + s * b[k, i] - c[k, i] - mid[i]
            r += w * w
        r = np.sqrt(r)
        out[k] = r
        big = max(big, r)
    return big


def distances_by_index(x, pairs, tri, edges, kind, s):
    """Squared distances ``s (P,)`` [m^2] of the broad phase's pairs ``pairs (P, 2)`` read from positions
    ``x (N, 3)`` [m] without gathering them first: kind 0 (node, triangle of ``tri (T, 3)``), kind 1
    (edge, edge of ``edges (M, 2)``). The near-pair cut of every list build (:mod:`.near_pairs`)."""
    W = np.zeros(4)
    D = np.zeros((4, 2))
    act = np.zeros(2, dtype=np.bool_)
    x4 = np.zeros((4, 3))
    for p in range(pairs.shape[0]):
        a, b = pairs[p, 0], pairs[p, 1]
        for i in range(3):
            if kind == 0:
                x4[0, i] = x[a, i]
                x4[1, i] = x[tri[b, 0], i]
                x4[2, i] = x[tri[b, 1], i]
                x4[3, i] = x[tri[b, 2], i]
            else:
                x4[0, i] = x[edges[a, 0], i]
                x4[1, i] = x[edges[a, 1], i]
                x4[2, i] = x[edges[b, 0], i]
                x4[3, i] = x[edges[b, 1], i]
        if kind == 0:
            s[p], _ = pt_classify(x4, W, D, act)
        else:
            s[p], _ = ee_classify(x4, W, D, act)
