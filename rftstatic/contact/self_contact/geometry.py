"""Pair geometry of self-contact written once: point-triangle and edge-edge squared distance, closest
feature, exact gradient and Hessian.

Both pair kinds are one problem. The four points of a pair are ``X = (X_0, .., X_3)``
(point-triangle: ``p, t_0, t_1, t_2``; edge-edge: ``a_0, a_1, b_0, b_1``) and the difference between
the two closest points is affine in ``X`` and in at most two feature parameters ``u``,

    r(X, u) = sum_k w_k(u) X_k,        s(X) = min_u |r(X, u)|^2,

with the weights ``w`` of the closest feature (:func:`pt_closest`, :func:`ee_closest`; the weights and
their derivatives: :func:`pt_classify`, :func:`ee_classify`):

* point-triangle, face: ``r = p - (t_0 + u (t_1 - t_0) + v (t_2 - t_0))``, two parameters;
  edge ``t_i t_j``: one parameter; vertex ``t_i``: none;
* edge-edge, interior: ``r = a_0 + s e_a - b_0 - t e_b``, two parameters; an end point against the
  interior of the other edge: one parameter; end point against end point: none.

Within a feature the minimiser ``u*`` is interior, ``ds/du = 0``, and (envelope theorem)

    grad s  = 2 w_k r                                          (12,)
    hess s  = 2 (w w^T) (x) I_3  -  F G^-1 F^T                 (12, 12)
    F_(k i), a = 2 (dw_k/du_a r_i + w_k t_a,i),  G_ab = 2 t_a . t_b,  t_a = sum_k dw_k/du_a X_k,

the second term being the change of the closest points with ``X`` (``du*/dX = -G^-1 F^T``). Only
the active parameters enter ``F`` and ``G`` (an inactive one has ``dw/du_a = 0``, so ``t_a = 0`` and
its column of ``F`` is zero; its row and column of ``G`` are the identity's).

The classification takes the smallest of the candidate features' distances (face or interior, then
every edge or end-point candidate with its parameter clamped to [0, 1]; a candidate replaces the best
one only when strictly closer); the distance is continuous across the switches and its gradient too
(the closest points move continuously), the Hessian jumps. Parallel edges: when
``|e_a x e_b|^2 <= PARALLEL_TOL |e_a|^2 |e_b|^2`` the interior candidate is left out and the end-point
candidates give the distance, which for parallel segments is exact (their distance is attained at an
end point of one of them); so ``G`` is never nearly singular. Near parallel overlapping edges the
segment distance has a kink in the tilt of the edges (a known feature of edge-edge distances, which
ipc-toolkit mollifies); on a sheet such pairs are also seen by the point-triangle pairs of their end
points, which are smooth there.

Each function runs two ways from this one source, as the membrane's (:mod:`rftstatic.element.kernels`):

- *compiled*, one pair at a time: :mod:`._kernels_numba` (imported lazily) hands every function here
  to ``numba.njit``, with :func:`select` replaced by :func:`select_one`; then ``x (4, 3)`` is one
  pair's points [m], ``W (4,)``, ``D (4, 2)``, ``act (2,)`` the closest feature's weights, their
  parameter derivatives and its active parameters, ``grad (4, 3)`` [m], ``H (12, 12)`` [-] (dof
  ``3 k + i``), ``tv (2, 3)`` and ``F (12, 4)`` scratch, and every entry a float;
- *vectorised* with numpy, all pairs at once: the same arrays with the pair axis **last**,
  ``x (4, 3, P)``, ``W (4, P)``, ... ``H (12, 12, P)``; every entry ``x[k, i]`` is then a ``(P,)``
  array and the same arithmetic one numpy operation over the pairs (:func:`derivatives_numpy`,
  :func:`distances_numpy`).

Written for both: accumulators are rebound (``a = a + b``), values are combined by arithmetic, ufuncs
and :func:`select` only (no ``if`` on a value), and branches are on loop indices and flags. The
loops :func:`distances_all` and :func:`derivatives_all` are compiled only; their numpy twins are the
``*_numpy`` functions. So are the other loops that call the geometry, the additive continuous
collision detection :func:`ccd_all` and the near-pair cut :func:`distances_by_index` (their numpy
twins: :func:`.law_kernels.additive_ccd`, :func:`.near_pairs._distances`). They live here, with the
geometry they inline, because numba's cache is keyed on a function's own file: a loop in another file
would keep an old geometry compiled in after this one changed.
"""

import numpy as np

PARALLEL_TOL = 1e-12
"""``sin^2`` of the angle between two edges below which they count as parallel (interior candidate
dropped). The interior distance then differs from the end-point one by at most ``~1e-6`` of an edge
length, and ``G`` of the interior feature stays well conditioned (``det G >= 1e-12 |e_a|^2 |e_b|^2``)."""

FLAT_TOL = 1e-14
"""``sin^2`` of a triangle's angle at ``t_0`` (``det / (|e_1|^2 |e_2|^2)``, ``e_i = t_i - t_0``) below which
it counts as flat: its face candidate is dropped and its edges give the distance."""

_EDGES = ((1, 2), (2, 3), (3, 1))


def select(c, a, b):
    """``a`` where ``c`` holds, else ``b``, over the pairs (``numpy.where``); the compiled twins use
    :func:`select_one` in its place."""
    return np.where(c, a, b)


def select_one(c, a, b):
    """:func:`select` of one pair: ``a if c else b``."""
    return a if c else b


def segment_param(x, p, a, b):
    """Parameter in [0, 1] of the point of segment ``x[a] x[b]`` closest to ``x[p]`` (0 for a segment of
    zero length)."""
    ee = 0.0
    pe = 0.0
    for i in range(3):
        e = x[b, i] - x[a, i]
        ee = ee + e * e
        pe = pe + (x[p, i] - x[a, i]) * e
    return _unit_clamp(pe, ee)


def _unit_clamp(num, den):
    """``num / den`` clamped to [0, 1]; 0 where ``den`` is 0 (a segment of zero length)."""
    long = den > 0
    return np.minimum(np.maximum(select(long, num / select(long, den, 1.0), 0.0), 0.0), 1.0)


def pt_closest(x):
    """Closest feature of point ``x[0]`` and triangle ``x[1:]``: the squared distance [m^2], the feature
    code (0 face, 1 edge, 2 vertex), the edge ``e`` (0 for the face, else ``i`` of the edge ``(i, j)`` of
    ``_EDGES``), the face parameters ``u, v`` and the parameter ``sb`` along edge ``e``."""
    a11 = a12 = a22 = b1 = b2 = 0.0
    for i in range(3):
        e1, e2, w = x[2, i] - x[1, i], x[3, i] - x[1, i], x[0, i] - x[1, i]
        a11 = a11 + e1 * e1
        a12 = a12 + e1 * e2
        a22 = a22 + e2 * e2
        b1 = b1 + w * e1
        b2 = b2 + w * e2
    det = a11 * a22 - a12 * a12
    ok = det > FLAT_TOL * a11 * a22
    sdet = select(ok, det, 1.0)
    u = (a22 * b1 - a12 * b2) / sdet
    v = (a11 * b2 - a12 * b1) / sdet
    inside = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    d2 = 0.0
    for i in range(3):
        r = (x[0, i] - x[1, i]) - u * (x[2, i] - x[1, i]) - v * (x[3, i] - x[1, i])
        d2 = d2 + r * r
    best = select(inside, d2, np.inf)
    e = 0  # the closest feature: 0 the face, i the edge (i, j) of _EDGES, parameter sb along it
    sb = 0.0
    for i, j in _EDGES:
        s = segment_param(x, 0, i, j)
        d2 = 0.0
        for k in range(3):
            r = x[0, k] - x[i, k] - s * (x[j, k] - x[i, k])
            d2 = d2 + r * r
        take = d2 < best
        best = select(take, d2, best)
        e = select(take, i, e)
        sb = select(take, s, sb)
    face = e == 0
    code = select(face, 0, select((sb > 0) & (sb < 1), 1, 2))
    return best, code, e, u, v, sb


def pt_classify(x, W, D, act):
    """:func:`pt_closest` that also fills the closest feature's ``W, D, act``; returns the squared
    distance [m^2] and the feature code (0 face, 1 edge, 2 vertex)."""
    best, code, e, u, v, sb = pt_closest(x)
    face = code == 0
    interior = code == 1
    act[0] = face | interior
    act[1] = face
    one = select(interior, 1.0, 0.0)  # dw/ds of an edge (i, j): +1 at t_i, -1 at t_j; 0 at a vertex
    W[0] = 1.0
    D[0, 0], D[0, 1] = 0.0, 0.0
    for k in range(1, 4):  # vertex k: t_i of edge k, t_j of the edge before
        at_i, at_j = e == k, e == (k + 1) % 3 + 1
        face_w = -(1 - u - v) if k == 1 else (-u if k == 2 else -v)
        W[k] = select(face, face_w, select(at_i, -(1 - sb), select(at_j, -sb, 0.0)))
        D[k, 0] = select(face, 1.0 if k == 1 else (-1.0 if k == 2 else 0.0),
                         select(at_i, one, select(at_j, -one, 0.0)))
        D[k, 1] = select(face, 1.0 if k == 1 else (-1.0 if k == 3 else 0.0), 0.0)
    return best, code


def ee_closest(x):
    """Closest feature of edges ``x[0] x[1]`` and ``x[2] x[3]``: the squared distance [m^2], the feature
    code (0 interior, 1 end point-edge, 2 end point-end point), the parameters ``S`` along ``a``, ``T``
    along ``b`` of the closest points and whether each is active (interior)."""
    aa = ab = bb = ad = bd = 0.0
    for i in range(3):
        ea, eb, w0 = x[1, i] - x[0, i], x[3, i] - x[2, i], x[0, i] - x[2, i]
        aa = aa + ea * ea
        ab = ab + ea * eb
        bb = bb + eb * eb
        ad = ad + ea * w0
        bd = bd + eb * w0
    det = aa * bb - ab * ab
    ok = det > PARALLEL_TOL * aa * bb
    sdet = select(ok, det, 1.0)
    s = (ab * bd - bb * ad) / sdet
    t = (aa * bd - ab * ad) / sdet
    inside = ok & (s > 0) & (s < 1) & (t > 0) & (t < 1)
    d2 = 0.0
    for i in range(3):
        r = (x[0, i] - x[2, i]) + s * (x[1, i] - x[0, i]) - t * (x[3, i] - x[2, i])
        d2 = d2 + r * r
    best = select(inside, d2, np.inf)
    S = select(inside, s, 0.0)
    T = select(inside, t, 0.0)
    act0 = inside  # active parameters s (along a) and t (along b)
    act1 = inside
    code = 0
    for c in range(4):
        # end point c of (a_0, a_1, b_0, b_1) against the other segment; its own parameter is fixed
        value = 1.0 if c % 2 else 0.0
        if c < 2:
            q = _end_point_param(x, 0, 1, 2, 3, value)
            s_c, t_c = value, q
        else:
            q = _end_point_param(x, 2, 3, 0, 1, value)
            s_c, t_c = q, value
        d2 = 0.0
        for i in range(3):
            r = (x[0, i] - x[2, i]) + s_c * (x[1, i] - x[0, i]) - t_c * (x[3, i] - x[2, i])
            d2 = d2 + r * r
        take = d2 < best
        best = select(take, d2, best)
        S = select(take, s_c, S)
        T = select(take, t_c, T)
        interior = (q > 0) & (q < 1)  # the other edge's parameter, active when q is interior
        act0 = select(take, interior if c >= 2 else False, act0)
        act1 = select(take, interior if c < 2 else False, act1)
        code = select(take, select(interior, 1, 2), code)
    return best, code, S, T, act0, act1


def ee_classify(x, W, D, act):
    """:func:`ee_closest` that also fills the closest feature's ``W, D, act``; returns the squared
    distance [m^2] and the feature code (0 interior, 1 end point-edge, 2 end point-end point)."""
    best, code, S, T, act0, act1 = ee_closest(x)
    W[0], W[1], W[2], W[3] = 1 - S, S, -(1 - T), -T
    act[0] = act0
    act[1] = act1
    one, two = select(act0, 1.0, 0.0), select(act1, 1.0, 0.0)
    D[:, :] = 0.0
    D[0, 0], D[1, 0], D[2, 1], D[3, 1] = -one, one, two, -two
    return best, code


def _end_point_param(x, a0, a1, b0, b1, value):
    """Parameter in [0, 1] of the point of segment ``x[b0] x[b1]`` closest to the point ``value`` along
    ``x[a0] x[a1]`` (0: ``x[a0]``, 1: ``x[a1]``)."""
    pe = 0.0
    pp = 0.0
    for i in range(3):
        pt = x[a0, i] + value * (x[a1, i] - x[a0, i])
        e = x[b1, i] - x[b0, i]
        pe = pe + (pt - x[b0, i]) * e
        pp = pp + e * e
    return _unit_clamp(pe, pp)


def pair_derivatives(x, W, D, act, grad, H, hessian, tv, F):
    """Squared distance [m^2] of ``|sum_k W_k x_k|^2``; fills ``grad (4, 3)`` [m] and, with ``hessian``,
    ``H (12, 12)`` [-] minimised over the active parameters (module docstring); ``tv (2, 3)`` and
    ``F (12, 4)`` are scratch (``F`` and ``-F G^-1``). ``H`` is symmetric: each entry above the diagonal
    is computed once and written twice."""
    r0 = r1 = r2 = 0.0
    for k in range(4):
        r0 = r0 + W[k] * x[k, 0]
        r1 = r1 + W[k] * x[k, 1]
        r2 = r2 + W[k] * x[k, 2]
    s = r0 * r0 + r1 * r1 + r2 * r2
    for k in range(4):
        w2 = 2.0 * W[k]
        grad[k, 0], grad[k, 1], grad[k, 2] = w2 * r0, w2 * r1, w2 * r2
    if not hessian:
        return s
    for a in range(2):
        for i in range(3):
            t = 0.0
            for k in range(4):
                t = t + D[k, a] * x[k, i]
            tv[a, i] = t
    g00 = select(act[0], 2.0 * (tv[0, 0] * tv[0, 0] + tv[0, 1] * tv[0, 1] + tv[0, 2] * tv[0, 2]), 1.0)
    g11 = select(act[1], 2.0 * (tv[1, 0] * tv[1, 0] + tv[1, 1] * tv[1, 1] + tv[1, 2] * tv[1, 2]), 1.0)
    g01 = select(act[0] & act[1], 2.0 * (tv[0, 0] * tv[1, 0] + tv[0, 1] * tv[1, 1] + tv[0, 2] * tv[1, 2]), 0.0)
    det = g00 * g11 - g01 * g01
    i00, i11, i01 = g11 / det, g00 / det, -g01 / det
    for a in range(2):
        for k in range(4):
            F[3 * k, a] = 2.0 * (D[k, a] * r0 + W[k] * tv[a, 0])
            F[3 * k + 1, a] = 2.0 * (D[k, a] * r1 + W[k] * tv[a, 1])
            F[3 * k + 2, a] = 2.0 * (D[k, a] * r2 + W[k] * tv[a, 2])
    for m in range(12):  # -F G^-1 next to F
        F[m, 2] = -(F[m, 0] * i00 + F[m, 1] * i01)
        F[m, 3] = -(F[m, 0] * i01 + F[m, 1] * i11)
    for k in range(4):
        for l in range(k, 4):
            b = 2.0 * W[k] * W[l]  # 2 (w w^T) (x) I_3
            for i in range(3):
                m = 3 * k + i
                for j in range(i if l == k else 0, 3):
                    n = 3 * l + j
                    h = F[m, 2] * F[n, 0] + F[m, 3] * F[n, 1]
                    if i == j:
                        h = b + h
                    H[m, n] = h
                    H[n, m] = h
    return s


# --- loops over the pairs: compiled only (numba) ---------------------------------------------------
def distances_all(x4, kind, s, code):
    """Squared distances ``s (P,)`` [m^2] and feature codes ``code (P,)`` of all pairs ``x4 (P, 4, 3)``
    [m]; ``kind`` 0 point-triangle, 1 edge-edge."""
    for p in range(x4.shape[0]):
        if kind == 0:
            s[p], code[p], _, _, _, _ = pt_closest(x4[p])
        else:
            s[p], code[p], _, _, _, _ = ee_closest(x4[p])


def derivatives_all(x4, kind, hessian, s, grad, H, code):
    """Fill ``s (P,)`` [m^2], ``grad (P, 4, 3)`` [m], ``H (P, 12, 12)`` [-] (with ``hessian``) and
    ``code (P,)`` of all pairs ``x4 (P, 4, 3)`` [m]; ``kind`` 0 point-triangle, 1 edge-edge."""
    W = np.zeros(4)
    D = np.zeros((4, 2))
    act = np.zeros(2, dtype=np.bool_)
    tv = np.zeros((2, 3))
    F = np.zeros((12, 4))
    for p in range(x4.shape[0]):
        if kind == 0:
            _, code[p] = pt_classify(x4[p], W, D, act)
        else:
            _, code[p] = ee_classify(x4[p], W, D, act)
        s[p] = pair_derivatives(x4[p], W, D, act, grad[p], H[p if hessian else 0], hessian, tv, F)


def ccd_all(x, dx, nodes, kind, eta, max_rounds, floor):
    """Smallest safe time in [0, 1] over all pairs ``nodes (P, 4)`` of positions ``x`` and step ``dx``
    ``(N, 3)`` [m] of the additive continuous collision detection (:mod:`.law`); ``kind`` 0
    point-triangle (sides ``{0}``, ``{1, 2, 3}``), 1 edge-edge (``{0, 1}``, ``{2, 3}``). A pair's
    target distance is ``g = eta d0``, raised to ``floor`` [m] when it starts above it. A pair stops
    once its time passes the smallest one found (its time only grows), which leaves the minimum
    unchanged."""
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
            s0 = pt_closest(x4)[0]
        else:
            s0 = ee_closest(x4)[0]
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
                s = pt_closest(y)[0]
            else:
                s = ee_closest(y)[0]
            dcur = np.sqrt(s)
            if dcur - g <= 1e-3 * (d0 - g):
                break
        tmin = min(tmin, t)
    return tmin


def distances_by_index(x, pairs, tri, edges, kind, s):
    """Squared distances ``s (P,)`` [m^2] of the broad phase's pairs ``pairs (P, 2)`` read from positions
    ``x (N, 3)`` [m] without gathering them first: kind 0 (node, triangle of ``tri (T, 3)``), kind 1
    (edge, edge of ``edges (M, 2)``). The near-pair cut of every list build (:mod:`.near_pairs`)."""
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
            s[p] = pt_closest(x4)[0]
        else:
            s[p] = ee_closest(x4)[0]


# --- the numpy twins of the loops: all pairs at once, pair axis last -------------------------------
def distances_numpy(x4, kind):
    """Squared distances ``(P,)`` [m^2] of the pairs ``x4 (P, 4, 3)`` [m] (:func:`distances_all`)."""
    x = np.ascontiguousarray(np.moveaxis(x4, 0, -1))
    return (pt_closest if kind == 0 else ee_closest)(x)[0]


def derivatives_numpy(x4, kind, hessian):
    """Squared distances ``(P,)`` [m^2], gradients ``(P, 4, 3)`` [m], Hessians ``(P, 12, 12)`` [-] (or None
    without ``hessian``) and feature codes ``(P,)`` of the pairs ``x4 (P, 4, 3)`` [m]
    (:func:`derivatives_all`); the arrays are pair-first views of the kernels' pair-last ones."""
    x = np.ascontiguousarray(np.moveaxis(x4, 0, -1))
    P = x.shape[-1]
    W, D, act = np.empty((4, P)), np.empty((4, 2, P)), np.empty((2, P), dtype=bool)
    _, code = (pt_classify if kind == 0 else ee_classify)(x, W, D, act)
    grad = np.empty((4, 3, P))
    H = np.empty((12, 12, P)) if hessian else None
    s = pair_derivatives(x, W, D, act, grad, H, hessian, np.empty((2, 3, P)), np.empty((12, 4, P)))
    return s, np.moveaxis(grad, -1, 0), (np.moveaxis(H, -1, 0) if hessian else None), code.astype(np.int8)
