"""Compiled (numba) kernels of the material-axes curvature terms: bending friction and softening on one pass.

The loops below evaluate, element by element and without a Python loop over the elements, what
:meth:`rftstatic.element.axis_curvature.AxisCurvature.assemble` evaluates with numpy (the reference, which the
tests compare them with): the curvature (A1), the element forces (A2) and the tangents (A3) of that module's
docstring, for the sum of the two scalar laws of one patch, the friction of :mod:`rftstatic.element.hysteresis`
(:func:`~rftstatic.element.hysteresis.friction_law`, H2-H3) and the softening of
:mod:`rftstatic.element.nonlinear_bending` (:func:`~rftstatic.element.nonlinear_bending.softening_law`, N3-N5).
The laws are not written here: their one source is compiled as it stands (ufuncs on scalars). Both terms share the
patches and the rotation T, so their moments add before the geometry (A2) is applied once: ``w = T^T (M_f + M_s)``.

Arrays: ``nodes (E, 6)`` int64 (slots 3-5 the element's vertices), ``L (E, 3, 6)`` [1/m^2], ``area (E,)``
[m^2], ``T (3, 3)``, ``Ub (N, 3)`` [m] what L acts on, ``x (N, 3)`` [m] positions; the friction's ``slip (E, 2)``
[1/m] (or ``(0, 2)`` without friction), ``K, M0, y (2,)``; the softening's ``k2, kf (2,)`` (kf = inf: no term).
The sums run in a fixed order, so a result does not depend on anything but its inputs; they differ from numpy's
einsum order by round-off (the tests' tolerance: 1e-12 of the largest entry).

Scratch arrays are on the stack (:func:`rftstatic.element._kernels_numba._stack`: LLVM then knows they alias no
argument; cusick-30's force of the softening 0.45 -> 0.37 ms a call). The functions are written plain and compiled
at import (:func:`rftstatic.element._kernels_numba.compile_in_place`, ``cache=True``): numba keys a cached
function on its own file only, and these loops link the laws' code from two other files, so each compiled copy is
named after a hash of the laws' code (:data:`LAW_KEY`): a changed law compiles new loops instead of loading old ones.

Imported only when numba is installed and a compiled back end is chosen (:mod:`rftstatic.element.axis_terms`).
"""

import hashlib
import marshal

import numba as nb
import numpy as np

from rftstatic.element._kernels_numba import _stack, compile_in_place
from rftstatic.element.hysteresis import friction_law as _friction_py
from rftstatic.element.nonlinear_bending import softening_law as _softening_py

_JIT = dict(cache=True, nogil=True, error_model="numpy")
_friction = nb.njit(**_JIT)(_friction_py)  # each cached on its own file
_softening = nb.njit(**_JIT)(_softening_py)

LAW_KEY = hashlib.sha1(b"".join(marshal.dumps(f.__code__) for f in (_friction_py, _softening_py))).hexdigest()[:12]
"""Hash of the compiled laws' code, in the names of the loops' cache entries (module docstring)."""


def _geometry(e, nodes, L, Ub, x, d, n, Ev):
    """``d[j] = sum_a L[e, j, a] Ub[nodes[e, a]]`` (3, 3), the unit normal ``n`` (3,) and the vertex edges
    ``Ev[v] = x_(v+1) - x_(v+2)`` (3, 3) of element ``e`` into the scratch arrays; returns ``r = |c|`` [m^2]."""
    for j in range(3):
        for i in range(3):
            s = 0.0
            for a in range(6):
                s += L[e, j, a] * Ub[nodes[e, a], i]
            d[j, i] = s
    for v in range(3):
        p, q = nodes[e, 3 + (v + 1) % 3], nodes[e, 3 + (v + 2) % 3]
        for i in range(3):
            Ev[v, i] = x[p, i] - x[q, i]
    # c = (x1 - x0) x (x2 - x0) = E_2 x (-E_1)
    c0 = -(Ev[2, 1] * Ev[1, 2] - Ev[2, 2] * Ev[1, 1])
    c1 = -(Ev[2, 2] * Ev[1, 0] - Ev[2, 0] * Ev[1, 2])
    c2 = -(Ev[2, 0] * Ev[1, 1] - Ev[2, 1] * Ev[1, 0])
    r = max(np.sqrt(c0 * c0 + c1 * c1 + c2 * c2), 1e-300)
    n[0], n[1], n[2] = c0 / r, c1 / r, c2 / r
    return r


def _axis_curvature(T, d, n, k):
    """``kappa_m,k = sum_j T[k, j] (d_j . n)`` [1/m] (A1)."""
    s = 0.0
    for j in range(3):
        s += T[k, j] * (d[j, 0] * n[0] + d[j, 1] * n[1] + d[j, 2] * n[2])
    return s


def _laws(e, km, k, slip, laws, psd):
    """psi [N m/m], M = psi' [N m/m] and psi'' [N m] of direction ``k`` of element ``e``: the sum of the terms on
    (``psd``: each term's psi'' clipped at 0 before the sum, as each term's reference)."""
    K, M0, y, k2, kf, friction, softening = laws
    psi = 0.0
    m = 0.0
    dm = 0.0
    if friction:
        p, mm, dd = _friction(km - slip[e, k], K[k], M0[k], y[k])
        psi += p
        m += mm
        dm += max(dd, 0.0) if psd else dd
    if softening:
        p, mm, dd = _softening(km, k2[k], kf[k])
        psi += p
        m += mm
        dm += max(dd, 0.0) if psd else dd
    return psi, m, dm


def _force(e, L, T, d, n, r, Ev, w0, w1, A, fe):
    """Element force ``fe (6, 3)`` [N] of the moments ``(w0, w1)`` (warp, weft) (A2): ``w = T^T M``,
    ``f_a = A (l_a n + [a = 3 + v] E_v x (P D) / r)``."""
    w = (T[0, 0] * w0 + T[1, 0] * w1, T[0, 1] * w0 + T[1, 1] * w1, T[0, 2] * w0 + T[1, 2] * w1)
    D0 = w[0] * d[0, 0] + w[1] * d[1, 0] + w[2] * d[2, 0]
    D1 = w[0] * d[0, 1] + w[1] * d[1, 1] + w[2] * d[2, 1]
    D2 = w[0] * d[0, 2] + w[1] * d[1, 2] + w[2] * d[2, 2]
    nD = n[0] * D0 + n[1] * D1 + n[2] * D2
    h0, h1, h2 = (D0 - nD * n[0]) / r, (D1 - nD * n[1]) / r, (D2 - nD * n[2]) / r
    for a in range(6):
        ell = w[0] * L[e, 0, a] + w[1] * L[e, 1, a] + w[2] * L[e, 2, a]
        fe[a, 0] = ell * n[0]
        fe[a, 1] = ell * n[1]
        fe[a, 2] = ell * n[2]
    for v in range(3):
        fe[3 + v, 0] += Ev[v, 1] * h2 - Ev[v, 2] * h1
        fe[3 + v, 1] += Ev[v, 2] * h0 - Ev[v, 0] * h2
        fe[3 + v, 2] += Ev[v, 0] * h1 - Ev[v, 1] * h0
    for a in range(6):
        for i in range(3):
            fe[a, i] *= A
    return nD, h0, h1, h2


def curvatures(nodes, L, T, Ub, x, km):
    """Fill ``km (E, 2)`` [1/m] with the warp and weft curvatures in material axes (A1) of every element."""
    d = _stack((3, 3))
    n = _stack((3,))
    Ev = _stack((3, 3))
    for e in range(nodes.shape[0]):
        _geometry(e, nodes, L, Ub, x, d, n, Ev)
        km[e, 0] = _axis_curvature(T, d, n, 0)
        km[e, 1] = _axis_curvature(T, d, n, 1)


def add_forces(geom, Ub, x, slip, laws, f):
    """Add the terms' nodal forces (A2) into ``f (N, 3)`` [N]; return their energy [J] (A1). ``geom = (nodes, L,
    area, T)``, ``laws = (K, M0, y, k2, kf, friction, softening)`` (module docstring)."""
    nodes, L, area, T = geom
    d = _stack((3, 3))
    n = _stack((3,))
    Ev = _stack((3, 3))
    fe = _stack((6, 3))
    W = 0.0
    for e in range(nodes.shape[0]):
        r = _geometry(e, nodes, L, Ub, x, d, n, Ev)
        p0, m0, _ = _laws(e, _axis_curvature(T, d, n, 0), 0, slip, laws, False)
        p1, m1, _ = _laws(e, _axis_curvature(T, d, n, 1), 1, slip, laws, False)
        W += area[e] * (p0 + p1)
        _force(e, L, T, d, n, r, Ev, m0, m1, area[e], fe)
        for a in range(6):
            for i in range(3):
                f[nodes[e, a], i] += fe[a, i]
    return W


def _skew(v, S):
    """``S = [v]_x`` (3, 3)."""
    S[0, 0], S[0, 1], S[0, 2] = 0.0, -v[2], v[1]
    S[1, 0], S[1, 1], S[1, 2] = v[2], 0.0, -v[0]
    S[2, 0], S[2, 1], S[2, 2] = -v[1], v[0], 0.0


def tangents(geom, Ub, x, slip, laws, psd, fe, ke, emap, data):
    """Fill ``fe (E, 6, 3)`` [N] with the element forces (A2) and ``ke (E, 6, 3, 6, 3)`` [N/m] with the element
    tangents (A3) (``psd``: only ``A sum_k max(psi''_k, 0) g_k g_k^T``); return the energy [J] (A1); ``geom``,
    ``laws`` as :func:`add_forces`. With rows in ``emap (E, 6, 3, 6, 3)`` (int64; ``(0, 6, 3, 6, 3)`` else) the
    tangents are added into the sparse matrix values ``data`` at those positions instead (``ke`` unused): the
    scatter of :func:`rftstatic.model.assembly.scatter_matrices` without the element array."""
    nodes, L, area, T = geom
    scatter = emap.shape[0] > 0
    kl = _stack((6, 3, 6, 3))
    d = _stack((3, 3))
    n = _stack((3,))
    Ev = _stack((3, 3))
    g = _stack((2, 6, 3))
    scratch = (_stack((3, 3)), _stack((3, 3, 3)), _stack((3, 3)), _stack((3, 3)), _stack((3, 3)))
    hv = _stack((3,))
    W = 0.0
    for e in range(nodes.shape[0]):
        ke_e = kl if scatter else ke[e]
        A = area[e]
        r = _geometry(e, nodes, L, Ub, x, d, n, Ev)
        km0 = _axis_curvature(T, d, n, 0)
        km1 = _axis_curvature(T, d, n, 1)
        p0, m0, dm0 = _laws(e, km0, 0, slip, laws, psd)
        p1, m1, dm1 = _laws(e, km1, 1, slip, laws, psd)
        W += A * (p0 + p1)
        nD, hv[0], hv[1], hv[2] = _force(e, L, T, d, n, r, Ev, m0, m1, A, fe[e])
        # g_k: (A2) with a unit moment in direction k, A = 1
        _force(e, L, T, d, n, r, Ev, 1.0, 0.0, 1.0, g[0])
        _force(e, L, T, d, n, r, Ev, 0.0, 1.0, 1.0, g[1])
        for a in range(6):
            for i in range(3):
                ga0, ga1 = A * dm0 * g[0, a, i], A * dm1 * g[1, a, i]
                for b in range(6):
                    for j in range(3):
                        ke_e[a, i, b, j] = ga0 * g[0, b, j] + ga1 * g[1, b, j]
        if not psd:
            _turning(e, L, T, (n, r, Ev, hv, nD), m0, m1, A, scratch, ke_e)
        if scatter:
            for a in range(6):
                for i in range(3):
                    for b in range(6):
                        for j in range(3):
                            data[emap[e, a, i, b, j]] += kl[a, i, b, j]
    return W


def _turning(e, L, T, geo, m0, m1, A, scratch, ke_e):
    """Add to ``ke_e (6, 3, 6, 3)`` the terms of (A3) from the turning normal at the moments ``(m0, m1)``:
    ``A (l_a dn/dx_b + (l_b dn/dx_a)^T + d2(D . n)/dx_a dx_b)``; ``geo = (n, r, Ev, hv, nD)`` with ``hv = P D / r``
    and ``nD = n . D``; ``scratch = (P, S, Hc, SH, hx)``."""
    n, r, Ev, hv, nD = geo
    P, S, Hc, SH, hx = scratch
    gam = ((0.0, 1.0, -1.0), (-1.0, 0.0, 1.0), (1.0, -1.0, 0.0))  # gamma_vw of (A3)
    w0 = T[0, 0] * m0 + T[1, 0] * m1
    w1 = T[0, 1] * m0 + T[1, 1] * m1
    w2 = T[0, 2] * m0 + T[1, 2] * m1
    for i in range(3):
        for j in range(3):
            P[i, j] = (1.0 if i == j else 0.0) - n[i] * n[j]
    for v in range(3):
        _skew(Ev[v], S[v])
    # l_a dn/dx_v and its transpose: dn/dx_v = -(P / r) [E_v]_x
    for v in range(3):
        for i in range(3):
            for j in range(3):
                dn = -(P[i, 0] * S[v, 0, j] + P[i, 1] * S[v, 1, j] + P[i, 2] * S[v, 2, j]) / r
                for a in range(6):
                    c = A * (w0 * L[e, 0, a] + w1 * L[e, 1, a] + w2 * L[e, 2, a]) * dn
                    ke_e[a, i, 3 + v, j] += c
                    ke_e[3 + v, j, a, i] += c
    # d2(D . n)/dx_v dx_w = -[E_v]_x H_c [E_w]_x - gamma_vw [h]_x, H_c = -(s P + t n^T + n t^T) / r^2, t = P D
    t = (hv[0] * r, hv[1] * r, hv[2] * r)
    for i in range(3):
        for j in range(3):
            Hc[i, j] = -(nD * P[i, j] + t[i] * n[j] + n[i] * t[j]) / (r * r)
    _skew(hv, hx)
    for v in range(3):
        for i in range(3):
            for k in range(3):
                SH[i, k] = S[v, i, 0] * Hc[0, k] + S[v, i, 1] * Hc[1, k] + S[v, i, 2] * Hc[2, k]
        for w in range(3):
            for i in range(3):
                for m in range(3):
                    s = SH[i, 0] * S[w, 0, m] + SH[i, 1] * S[w, 1, m] + SH[i, 2] * S[w, 2, m]
                    ke_e[3 + v, i, 3 + w, m] += A * (-s - gam[v][w] * hx[i, m])


_INLINE = ("_geometry", "_axis_curvature", "_laws", "_force", "_skew", "_turning")
_LOOPS = ("curvatures", "add_forces", "tangents")

compile_in_place(globals(), _INLINE, _LOOPS, LAW_KEY, **_JIT)
