"""The membrane of RFT3 and RFT6 written once: strain-point gradients, averaged Green strain (Eq. 14),
stress and energy (Eq. 15), element force and tangent, and the explicit internal force loop.

Every path calls these functions: the static force and tangent (:mod:`rftstatic.element.membrane`),
Newton's tangent and the explicit force (:mod:`rftstatic.element.explicit_force`). Each one runs two
ways from the same code:

- *compiled*, a block of elements at a time: :mod:`rftstatic.element._kernels_numba` (imported lazily)
  hands every function here to ``numba.njit``; then the arrays have a short element axis last, the
  *lanes*: ``g (Q, A, 2, n)``, ``u (A, 3, n)``, ``H (Q, 2, 3, n)``, ``S (6, n)``, ``fe (A, 3, n)``,
  ``area (n,)`` with n = :data:`LANES` in the explicit force (:func:`membrane_force_lanes`) and n = 1 in
  the element-by-element loops; :func:`lanes` is ``range(n)``, and an element function that loops over
  the lanes innermost (:func:`strain_point_gradients`, :func:`element_force`) is vectorised by LLVM
  *across* the elements (the same arithmetic per element in the same order: the same bits as one
  element at a time);
- *vectorised* with numpy, all elements at once: the same arrays with all E elements last,
  ``g (Q, A, 2, E)``, ``u (A, 3, E)``, ... ``area (E,)``; :func:`lanes` is the one index ``...``, so that
  every entry ``g[q, a, J, L]`` is an ``(E,)`` array and the same arithmetic is one numpy operation over
  the elements (the Python loops are over strain points, local nodes and components only, never over
  elements).

Written for both: an entry is never updated in place (``x = x + y``, since in numpy it is a view),
values are combined by arithmetic and ufuncs only (``np.sqrt``, ``np.maximum``; no ``if`` on a value),
and branches are on shapes and flags. The loops at the end of the module (``membrane_*``,
``internal_force``) are compiled only; their numpy twins are the ``*_numpy`` functions of
:mod:`rftstatic.element.kernels_numpy`.

Letters: q strain point (Q = 1 for RFT3, 3 mid-side points for RFT6), a/b local node (A = 3 or 6),
J reference axis (X, Y), i/j space component, k strain component, L lane (an element of a block).
``G[e, q, a, J]`` is the reference gradient of shape function a at strain point q [1/m] (Eq. 24-26, see
:func:`rftstatic.element.membrane.membrane_operator`), ``H[q, J, i] = dU_i / dX_J`` the displacement
gradient there [-], ``F = I + H`` the deformation gradient.
"""

import numpy as np

prange = range
"""Loop over element blocks; ``numba.prange`` in the parallel compiled twins."""

_TINY = 1e-300

LANES = 16
"""Elements per block of the compiled explicit force (:func:`membrane_force_lanes`): LLVM vectorises each lane
loop over them (AVX-512 on the development machine). cusick-30's membrane loop alone (a first version of
:func:`membrane_force_lanes`), one thread: 4 lanes 0.40 ms a call, 8 0.37, 16 0.16, 24 0.19, 32 0.17, 64 0.19 ms
(one element at a time 0.53 ms); the whole kernel with the bending product and the nodes' gather 0.21 ms (0.59)."""

_Q, _A = 3, 6
"""Strain points and nodes of the element of the compiled loops: their scratch arrays (:func:`_scratch`) are
sized by them at compile time, so that every loop but the lane loops unrolls. The compiled twins make one copy
per element type (RFT6 here, RFT3 ``(1, 3)``); the numpy twins do not use them."""


def lanes(x):
    """The lane indices of the element axis (last) of ``x``: ``(...,)`` in numpy, one index taking all the
    elements at once; ``range(x.shape[-1])`` in the compiled twins."""
    return (Ellipsis,)


def _scratch(shape):
    """An uninitialised float array of ``shape``; in the compiled twins on the stack, ``shape`` known when
    compiling, so that LLVM knows it aliases nothing and may keep it in registers."""
    return np.empty(shape)


# --- one element (compiled) or all elements (numpy, element axis last) -----------------------------
def strain_point_gradients(g, u, H):
    """Fill ``H (Q, 2, 3, n)`` [-] with ``H[q, J, i] = sum_a g[q, a, J] u[a, i]``, the displacement
    gradients at the strain points (Eq. 24-25), from ``g (Q, A, 2, n)`` [1/m] and ``u (A, 3, n)`` [m]."""
    Q, A = H.shape[0], u.shape[0]
    for q in range(Q):
        for J in range(2):
            for i in range(3):
                for L in lanes(H):
                    h = g[q, 0, J, L] * u[0, i, L]
                    for a in range(1, A):
                        h = h + g[q, a, J, L] * u[a, i, L]
                    H[q, J, i, L] = h


def green_strain(H, q, L):
    """Green strain ``(e_xx, e_yy, 2 e_xy)`` [-] at strain point ``q`` of lane ``L`` (Eq. 14), written with the
    displacement gradient, ``E = (H + H^T + H^T H) / 2``, so that small strains carry no round-off
    from cancelling reference coordinates."""
    hx0, hx1, hx2 = H[q, 0, 0, L], H[q, 0, 1, L], H[q, 0, 2, L]  # dU/dX
    hy0, hy1, hy2 = H[q, 1, 0, L], H[q, 1, 1, L], H[q, 1, 2, L]  # dU/dY
    exx = hx0 + 0.5 * (hx0 * hx0 + hx1 * hx1 + hx2 * hx2)
    eyy = hy1 + 0.5 * (hy0 * hy0 + hy1 * hy1 + hy2 * hy2)
    gxy = hx1 + hy0 + (hx0 * hy0 + hx1 * hy1 + hx2 * hy2)
    return exx, eyy, gxy


def averaged_strain(H, L):
    """Membrane strain of the element of lane ``L`` ``(e_xx, e_yy, 2 e_xy)`` [-]: the mean of the Green strains
    (Eq. 14) at its Q strain points (RFT6: the mid-side points I, II, III, §3)."""
    Q = H.shape[0]
    exx, eyy, gxy = green_strain(H, 0, L)
    for q in range(1, Q):
        dxx, dyy, dxy = green_strain(H, q, L)
        exx = exx + dxx
        eyy = eyy + dyy
        gxy = gxy + dxy
    return exx / Q, eyy / Q, gxy / Q


def strain_increment(H, h, L):
    """The linearised change of the membrane strain, ``Bbar(U) dU = 1/Q sum_q sym(F_q^T h_q)`` in
    the order (e_xx, e_yy, 2 e_xy) [-]: the derivative of Eq. 14 along ``dU``, from the displacement
    gradients ``H`` of U and ``h`` of dU ``(Q, 2, 3, n)`` [-] (:func:`strain_point_gradients`), lane ``L``."""
    Q = H.shape[0]
    dxx = 0.0 * h[0, 0, 0, L]
    dyy = 0.0 * h[0, 0, 0, L]
    dxy = 0.0 * h[0, 0, 0, L]
    for q in range(Q):
        for i in range(3):
            fx, fy = _deformation(H, q, i, L)
            dxx = dxx + fx * h[q, 0, i, L]
            dyy = dyy + fy * h[q, 1, i, L]
            dxy = dxy + (fx * h[q, 1, i, L] + fy * h[q, 0, i, L])
    return dxx / Q, dyy / Q, dxy / Q


def stress(Dm, exx, eyy, gxy):
    """Second Piola-Kirchhoff stress resultant ``S = D^m eps = (S_xx, S_yy, S_xy)`` [N/m] (Eq. 15),
    ``Dm (3, 3)`` [N/m]."""
    return (Dm[0, 0] * exx + Dm[0, 1] * eyy + Dm[0, 2] * gxy,
            Dm[1, 0] * exx + Dm[1, 1] * eyy + Dm[1, 2] * gxy,
            Dm[2, 0] * exx + Dm[2, 1] * eyy + Dm[2, 2] * gxy)


def membrane_state(g, u, Dm, H, S):
    """Gradients into ``H``, then the averaged strain [-] and the stress [N/m] of every lane into ``S (6, n)``:
    rows ``(e_xx, e_yy, 2 e_xy, S_xx, S_yy, S_xy)``."""
    strain_point_gradients(g, u, H)
    for L in lanes(H):
        exx, eyy, gxy = averaged_strain(H, L)
        sxx, syy, sxy = stress(Dm, exx, eyy, gxy)
        S[0, L] = exx
        S[1, L] = eyy
        S[2, L] = gxy
        S[3, L] = sxx
        S[4, L] = syy
        S[5, L] = sxy


def strain_energy(area, exx, eyy, gxy, sxx, syy, sxy):
    """Membrane energy ``E_m = A/2 eps^T D^m eps`` [J] (Eq. 15), ``area`` [m^2]."""
    return 0.5 * area * (exx * sxx + eyy * syy + gxy * sxy)


def _deformation(H, q, i, L):
    """Row i of the deformation gradient at strain point q of lane L: ``(F[i, X], F[i, Y])``, F = I + H."""
    fx = H[q, 0, i, L]
    fy = H[q, 1, i, L]
    if i == 0:
        fx = fx + 1.0
    if i == 1:
        fy = fy + 1.0
    return fx, fy


def element_force(g, H, S, area, fe):
    """Fill ``fe (A, 3, n)`` [N] with the membrane force, the gradient of Eq. 15:
    ``f_ai = A/Q sum_q sum_J P_q[i, J] g[q, a, J]`` with the first Piola-Kirchhoff stress
    ``P_q = F_q S`` (the same as ``A S . Bbar_ai``, :func:`element_tangent`); the stress from rows 3-5 of
    ``S (6, n)`` [N/m] (:func:`membrane_state`), ``area (n,)`` [m^2]."""
    Q, A = H.shape[0], fe.shape[0]
    for q in range(Q):
        for i in range(3):
            for L in lanes(fe):
                w = area[L] / Q
                fx, fy = _deformation(H, q, i, L)
                px = w * (fx * S[3, L] + fy * S[5, L])
                py = w * (fx * S[5, L] + fy * S[4, L])
                for a in range(A):
                    t = px * g[q, a, 0, L] + py * g[q, a, 1, L]
                    if q == 0:
                        fe[a, i, L] = t
                    else:
                        fe[a, i, L] = fe[a, i, L] + t


def positive_part(sxx, syy, sxy):
    """Positive part ``(S+_xx, S+_yy, S+_xy)`` of the symmetric 2 x 2 stress [[sxx, sxy], [sxy, syy]]
    (negative principal stresses set to zero), in closed form:
    ``S+ = max(s1, 0) v1 v1^T + max(s2, 0) v2 v2^T`` with ``v1 v1^T = [[1 + c, s], [s, 1 - c]] / 2``,
    ``(c, s) = (cos 2 theta, sin 2 theta)`` of the principal direction."""
    mean = 0.5 * (sxx + syy)
    half = 0.5 * (sxx - syy)
    rad = np.sqrt(half * half + sxy * sxy)
    p1 = np.maximum(mean + rad, 0.0)
    p2 = np.maximum(mean - rad, 0.0)
    r = np.maximum(rad, _TINY)  # isotropic stress: half = sxy = 0 and any direction will do
    c = half / r
    s = sxy / r
    return 0.5 * (p1 * (1.0 + c) + p2 * (1.0 - c)), 0.5 * (p1 * (1.0 - c) + p2 * (1.0 + c)), 0.5 * (p1 - p2) * s


def element_tangent(g, H, L, sxx, syy, sxy, area, Dm, psd, B, DB, SG, ke):
    """Fill ``ke (A, 3, A, 3)`` [N/m] with the membrane tangent of lane ``L``, the Hessian of Eq. 15:
    ``A (Bbar^T D^m Bbar + 1/Q sum_q (g_qa . S g_qb) I)``, where ``Bbar[k, a, i] = d eps_k / d U_ai``
    (the mean over the strain points, into the scratch ``B (3, A, 3)`` [1/m]; ``DB = A D^m Bbar``
    [N/m^2]; ``SG (Q, A, 2) = (A/Q) S g_qa`` [N/m^2], scratch).
    With ``psd`` the geometric part uses the :func:`positive_part` of S, so the tangent is positive
    semi-definite under compression (docs/theory/membrane.md); the material part always is. The element area and
    the weight 1/Q are folded into DB and SG, so that the numpy twin (element axis last) does a third
    fewer whole-array operations."""
    Q, A = SG.shape[0], SG.shape[1]
    for a in range(A):
        for i in range(3):
            b0 = 0.0
            b1 = 0.0
            b2 = 0.0
            for q in range(Q):
                fx, fy = _deformation(H, q, i, L)
                gx = g[q, a, 0, L]
                gy = g[q, a, 1, L]
                b0 = b0 + fx * gx
                b1 = b1 + fy * gy
                b2 = b2 + (fx * gy + fy * gx)
            B[0, a, i] = b0 / Q
            B[1, a, i] = b1 / Q
            B[2, a, i] = b2 / Q
    for k in range(3):
        d0, d1, d2 = area * Dm[k, 0], area * Dm[k, 1], area * Dm[k, 2]
        for a in range(A):
            for i in range(3):
                DB[k, a, i] = d0 * B[0, a, i] + d1 * B[1, a, i] + d2 * B[2, a, i]
    if psd:
        pxx, pyy, pxy = positive_part(sxx, syy, sxy)
    else:
        pxx, pyy, pxy = sxx, syy, sxy
    w = area / Q
    wxx, wyy, wxy = w * pxx, w * pyy, w * pxy
    for q in range(Q):
        for b in range(A):
            gb0, gb1 = g[q, b, 0, L], g[q, b, 1, L]
            SG[q, b, 0] = wxx * gb0 + wxy * gb1
            SG[q, b, 1] = wxy * gb0 + wyy * gb1
    for a in range(A):
        for b in range(a, A):
            geo = g[0, a, 0, L] * SG[0, b, 0] + g[0, a, 1, L] * SG[0, b, 1]  # (A/Q) sum_q g_qa . S g_qb
            for q in range(1, Q):
                geo = geo + (g[q, a, 0, L] * SG[q, b, 0] + g[q, a, 1, L] * SG[q, b, 1])
            for i in range(3):
                b0, b1, b2 = B[0, a, i], B[1, a, i], B[2, a, i]
                for j in range(i if b == a else 0, 3):
                    m = b0 * DB[0, b, j] + b1 * DB[1, b, j] + b2 * DB[2, b, j]
                    if i == j:
                        m = m + geo
                    ke[a, i, b, j] = m
                    ke[b, j, a, i] = m


# --- element loops: compiled only (numba), ``prange`` runs element blocks on threads ----------------
def _gather(U, n, u, L):
    """``u[a, i, L] = U[n[a], i]``: the nodal displacements [m] of the element of lane ``L``."""
    for a in range(n.shape[0]):
        for i in range(3):
            u[a, i, L] = U[n[a], i]
    return u


def _gather_offset(U, n, D, e, u, L):
    """:func:`_gather` plus the element's reference offset ``D[e] (A, 3)`` [m] when ``D`` has rows (a mesh sewn
    from panels, :attr:`rftstatic.element.membrane.MembraneOperator.offset`; ``D (0, A, 3)`` otherwise): the
    displacements of the element's nodes from its own flat reference."""
    _gather(U, n, u, L)
    if D.shape[0] > 0:
        for a in range(n.shape[0]):
            for i in range(3):
                u[a, i, L] = u[a, i, L] + D[e, a, i]
    return u


def _one(x):
    """One element's ``x (...)`` as one lane, ``(..., 1)`` (a view)."""
    return x[..., np.newaxis]


def membrane_energies(nodes, G, area, D, Dm, U, We):
    """Fill ``We (E,)`` [J] with the membrane energy of every element at ``U (N, 3)`` [m];
    ``nodes (E, A)``, ``G (E, Q, A, 2)`` [1/m], ``area (E,)`` [m^2], ``D (E, A, 3)`` [m] the reference offsets
    of a sewn mesh or ``(0, A, 3)`` (:func:`_gather_offset`; the same in every loop below). The loops' scratch
    arrays are sized by :data:`_Q` and :data:`_A` (the compiled twins' element sizes)."""
    E = G.shape[0]
    H = _scratch((_Q, 2, 3, 1))
    u = _scratch((_A, 3, 1))
    S = _scratch((6, 1))
    for e in range(E):
        membrane_state(_one(G[e]), _gather_offset(U, nodes[e], D, e, u, 0), Dm, H, S)
        We[e] = strain_energy(area[e], S[0, 0], S[1, 0], S[2, 0], S[3, 0], S[4, 0], S[5, 0])


def membrane_forces(nodes, G, area, D, Dm, U, fe, start, stop):
    """Fill ``fe[start:stop] (E, A, 3)`` [N] with the membrane forces of elements ``start`` to
    ``stop - 1``, one at a time; return their membrane energy [J]."""
    H = _scratch((_Q, 2, 3, 1))
    u = _scratch((_A, 3, 1))
    S = _scratch((6, 1))
    W = 0.0
    for e in range(start, stop):
        membrane_state(_one(G[e]), _gather_offset(U, nodes[e], D, e, u, 0), Dm, H, S)
        element_force(_one(G[e]), H, S, area[e:e + 1], _one(fe[e]))
        W += strain_energy(area[e], S[0, 0], S[1, 0], S[2, 0], S[3, 0], S[4, 0], S[5, 0])
    return W


def _gather_lanes(U, n, D, k, u):
    """``u[a, i, L] = U[n[a, L], i]`` (plus ``D[k, a, i, L]`` when ``D`` has rows, :func:`_gather_offset`): the
    nodal displacements [m] of a block of elements from its nodes ``n (A, LANES)``, lanes innermost (vector
    gathers)."""
    for a in range(u.shape[0]):
        for i in range(3):
            for L in lanes(u):
                u[a, i, L] = U[n[a, L], i]
    if D.shape[0] > 0:
        for a in range(u.shape[0]):
            for i in range(3):
                for L in lanes(u):
                    u[a, i, L] = u[a, i, L] + D[k, a, i, L]


def membrane_force_lanes(nodes, Gb, area, D, Dm, U, fe, start, stop):
    """:func:`membrane_forces` of elements ``start`` to ``stop - 1`` in blocks of :data:`LANES` (the element
    of :data:`_Q`, :data:`_A`): the arithmetic of each element vectorised across the block, the same bits;
    fill ``fe[start:stop] (E, A, 3)`` [N] and return their membrane energy [J], summed in element order.

    ``nodes (B, A, LANES)``, ``Gb (B, Q, A, 2, LANES)`` [1/m], ``area (B, LANES)`` [m^2] and ``D (B, A, 3,
    LANES)`` [m] (or ``(0, A, 3, LANES)``, :func:`_gather_offset`) are laid out by blocks of elements
    (:func:`lane_blocks`: element ``e`` is lane ``e % LANES`` of block ``e // LANES``, the last block padded).
    A block that ``start`` or ``stop`` cuts is computed whole, and only its lanes in the range are written
    (the forces go out element by element: the nodes' gather in :func:`internal_force` reads one element's
    slot from one cache line)."""
    u = _scratch((_A, 3, LANES))
    H = _scratch((_Q, 2, 3, LANES))
    S = _scratch((6, LANES))
    fl = _scratch((_A, 3, LANES))
    W = 0.0
    for k in range(start // LANES, (stop + LANES - 1) // LANES):
        e0 = k * LANES
        _gather_lanes(U, nodes[k], D, k, u)
        g = Gb[k]
        membrane_state(g, u, Dm, H, S)
        element_force(g, H, S, area[k], fl)
        for L in range(max(start - e0, 0), min(stop - e0, LANES)):
            W += strain_energy(area[k, L], S[0, L], S[1, L], S[2, L], S[3, L], S[4, L], S[5, L])
            for a in range(_A):
                for i in range(3):
                    fe[e0 + L, a, i] = fl[a, i, L]
    return W


def membrane_force_blocks(nodes, Gb, area, D, Dm, U, fe, chunks):
    """:func:`membrane_force_lanes` of all elements in ``chunks`` ranges (on threads in the parallel twin;
    any number of ranges gives the same ``fe (E, A, 3)``); return the membrane energy [J]."""
    E = fe.shape[0]
    W = 0.0
    for c in prange(chunks):
        W += membrane_force_lanes(nodes, Gb, area, D, Dm, U, fe, c * E // chunks, (c + 1) * E // chunks)
    return W


def _force_and_tangent(g, u, area, Dm, psd, S, e, H, St, B, DB, SG, fe, ke):
    """Element ``e``'s force into ``fe (A, 3, 1)`` and tangent into ``ke (A, 3, A, 3)`` from its
    displacements ``u (A, 3, 1)``, ``g (Q, A, 2, 1)``, ``area (1,)``, the state into ``St (6, 1)``; the
    geometric part takes ``S[e]`` when ``S`` is not empty (MIP Newton's carried stress), else the element's own
    stress (:func:`membrane_tangents`)."""
    membrane_state(g, u, Dm, H, St)
    element_force(g, H, St, area, fe)
    sxx, syy, sxy = St[3, 0], St[4, 0], St[5, 0]
    if S.shape[0] > 0:
        sxx, syy, sxy = S[e, 0], S[e, 1], S[e, 2]
    element_tangent(g, H, 0, sxx, syy, sxy, area[0], Dm, psd, B, DB, SG, ke)


def membrane_tangents(nodes, G, area, D, Dm, U, psd, S, fe, ke):
    """Fill ``fe (E, A, 3)`` [N] and ``ke (E, A, 3, A, 3)`` [N/m] for every element.

    ``S (E, 3)`` [N/m]: the stress of the geometric part (the mixed stress of
    :func:`linearised_strain`, MIP Newton); ``S (0, 3)``: the element's own stress ``D^m eps(U)``,
    the exact Hessian. The force is always the gradient of Eq. 15 at ``U``."""
    E = G.shape[0]
    H = _scratch((_Q, 2, 3, 1))
    u = _scratch((_A, 3, 1))
    St = _scratch((6, 1))
    B = _scratch((3, _A, 3))
    DB = _scratch((3, _A, 3))
    SG = _scratch((_Q, _A, 2))
    for e in range(E):
        u = _gather_offset(U, nodes[e], D, e, u, 0)
        _force_and_tangent(_one(G[e]), u, area[e:e + 1], Dm, psd, S, e, H, St, B, DB, SG, _one(fe[e]), ke[e])


def membrane_tangents_into(nodes, G, area, D, Dm, U, psd, S, emap, fe, data):
    """:func:`membrane_tangents` with every element tangent added straight into the CSR values
    ``data (nnz,)`` [N/m] at the positions ``emap (E, A, 3, A, 3)`` (no (E, A, 3, A, 3) array, no
    separate scatter), element by element in order; ``fe (E, A, 3)`` [N] is filled as there."""
    E, A = G.shape[0], G.shape[2]
    H = _scratch((_Q, 2, 3, 1))
    u = _scratch((_A, 3, 1))
    St = _scratch((6, 1))
    B = _scratch((3, _A, 3))
    DB = _scratch((3, _A, 3))
    SG = _scratch((_Q, _A, 2))
    ke = _scratch((_A, 3, _A, 3))
    for e in range(E):
        u = _gather_offset(U, nodes[e], D, e, u, 0)
        _force_and_tangent(_one(G[e]), u, area[e:e + 1], Dm, psd, S, e, H, St, B, DB, SG, _one(fe[e]), ke)
        m = emap[e]
        for a in range(A):
            for i in range(3):
                for b in range(A):
                    for j in range(3):
                        data[m[a, i, b, j]] += ke[a, i, b, j]


def membrane_linearised_strains(nodes, G, D, U, dU, out):
    """Fill ``out (E, 3)`` [-] with ``eps(U) + Bbar(U) dU`` of every element (:func:`strain_increment`),
    ``U, dU (N, 3)`` [m]."""
    E = G.shape[0]
    H = _scratch((_Q, 2, 3, 1))
    h = _scratch((_Q, 2, 3, 1))
    u = _scratch((_A, 3, 1))
    du = _scratch((_A, 3, 1))
    for e in range(E):
        g = _one(G[e])
        strain_point_gradients(g, _gather_offset(U, nodes[e], D, e, u, 0), H)
        strain_point_gradients(g, _gather(dU, nodes[e], du, 0), h)
        exx, eyy, gxy = averaged_strain(H, 0)
        dxx, dyy, dxy = strain_increment(H, h, 0)
        out[e, 0] = exx + dxx
        out[e, 1] = eyy + dyy
        out[e, 2] = gxy + dxy


def internal_force(indptr, indices, data, nodes, Gb, area, D, Dm, U, f, fe, slot_ptr, slots, with_membrane, chunks):
    """Fill ``f (N, 3)`` [N] with the internal force at ``U (N, 3)`` [m]; return the stored energy [J].

    Bending ``K_b @ U`` over the CSR rows ``indptr, indices, data`` of the scalar K_b [N/m] (Eq. 13),
    plus the membrane forces of :func:`membrane_force_blocks` (into ``fe (E, A, 3)``, with ``nodes``, ``Gb``,
    ``area`` and ``D`` laid out by :func:`lane_blocks`), which each node gathers from its element slots
    ``slots[slot_ptr[n]:slot_ptr[n + 1]]`` (flat indices ``e * A + a``, in element order, :func:`element_slots`):
    no two threads write one entry, and the sums do not depend on ``chunks``.
    """
    N = U.shape[0]
    W = 0.0
    if with_membrane:
        W = membrane_force_blocks(nodes, Gb, area, D, Dm, U, fe, chunks)
    flat = fe.reshape((fe.shape[0] * fe.shape[1], 3))
    for n in prange(N):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for p in range(indptr[n], indptr[n + 1]):
            j = indices[p]
            d = data[p]
            s0 += d * U[j, 0]
            s1 += d * U[j, 1]
            s2 += d * U[j, 2]
        W += 0.5 * (U[n, 0] * s0 + U[n, 1] * s1 + U[n, 2] * s2)
        if with_membrane:
            for p in range(slot_ptr[n], slot_ptr[n + 1]):
                k = slots[p]
                s0 += flat[k, 0]
                s1 += flat[k, 1]
                s2 += flat[k, 2]
        f[n, 0] = s0
        f[n, 1] = s1
        f[n, 2] = s2
    return W


def lane_blocks(nodes, G, area, D):
    """``nodes (E, A)``, ``G (E, Q, A, 2)``, ``area (E,)`` and the reference offsets ``D (E, A, 3)`` or
    ``(0, A, 3)`` laid out by blocks of :data:`LANES` elements for :func:`membrane_force_lanes`, the element
    axis split and its lanes moved last: ``(B, A, LANES)``, ``(B, Q, A, 2, LANES)``, ``(B, LANES)``,
    ``(B or 0, A, 3, LANES)``; B = ceil(E / LANES), the last block padded with copies of the last element
    (computed, never written)."""
    E = len(area)
    B = -(-E // LANES)
    take = np.minimum(np.arange(B * LANES), E - 1)

    def blocks(x):
        if len(x) == 0:
            return np.zeros((0,) + x.shape[1:] + (LANES,))
        return np.ascontiguousarray(np.moveaxis(x[take].reshape((B, LANES) + x.shape[1:]), 1, -1))

    return blocks(nodes), blocks(G), blocks(area), blocks(D)


def element_slots(nodes, N):
    """The node -> element-slot map of :func:`internal_force`'s force gather for ``nodes (E, A)`` on ``N`` nodes:
    ``slot_ptr (N + 1,)`` and ``slots``, the slots of node n (``nodes[e, a] == n``, in element order, a node
    repeated in a patch once each) as flat indices ``e * A + a``, both int64."""
    flat = nodes.ravel()
    slots = np.argsort(flat, kind="stable").astype(np.int64)
    slot_ptr = np.concatenate([[0], np.cumsum(np.bincount(flat, minlength=N))]).astype(np.int64)
    return slot_ptr, slots
