"""The membrane of RFT3 and RFT6 written once: strain-point gradients, averaged Green strain (Eq. 14),
stress and energy (Eq. 15), element force and tangent, and the explicit internal force loop.

Every path calls these functions: the static force and tangent (:mod:`rftstatic.element.membrane`),
Newton's tangent and the explicit force (:mod:`rftstatic.element.explicit_force`). Each one runs two
ways from the same code:

- *compiled*, one element at a time: :mod:`rftstatic.element._kernels_numba` (imported lazily) hands
  every function here to ``numba.njit``; then ``g = G[e] (Q, A, 2)``, ``u (A, 3)``, ``H (Q, 2, 3)``,
  ``fe (A, 3)``, ``ke (A, 3, A, 3)`` and ``area`` is a float;
- *vectorised* with numpy, all elements at once: the same arrays with the element axis **last**,
  ``g (Q, A, 2, E)``, ``u (A, 3, E)``, ... ``area (E,)``; every entry ``g[q, a, J]`` is then an
  ``(E,)`` array and the same arithmetic is one numpy operation over the elements (the Python loops
  are over strain points, local nodes and components only, never over elements).

Written for both: an entry is never updated in place (``x = x + y``, since in numpy it is a view),
values are combined by arithmetic and ufuncs only (``np.sqrt``, ``np.maximum``; no ``if`` on a value),
and branches are on shapes and flags. The loops at the end of the module (``membrane_*``,
``internal_force``) are compiled only; their numpy twins are the ``*_numpy`` functions.

Letters: q strain point (Q = 1 for RFT3, 3 mid-side points for RFT6), a/b local node (A = 3 or 6),
J reference axis (X, Y), i/j space component, k strain component. ``G[e, q, a, J]`` is the
reference gradient of shape function a at strain point q [1/m] (Eq. 24-26, see
:func:`rftstatic.element.membrane.membrane_operator`), ``H[q, J, i] = dU_i / dX_J`` the displacement
gradient there [-], ``F = I + H`` the deformation gradient.
"""

import numpy as np

prange = range
"""Loop over element blocks; ``numba.prange`` in the parallel compiled twins."""

_TINY = 1e-300


# --- one element (compiled) or all elements (numpy, element axis last) -----------------------------
def strain_point_gradients(g, u, H):
    """Fill ``H (Q, 2, 3)`` [-] with ``H[q, J, i] = sum_a g[q, a, J] u[a, i]``, the displacement
    gradients at the strain points (Eq. 24-25), from ``g (Q, A, 2)`` [1/m] and ``u (A, 3)`` [m]."""
    Q, A = g.shape[0], g.shape[1]
    for q in range(Q):
        for J in range(2):
            for i in range(3):
                h = g[q, 0, J] * u[0, i]
                for a in range(1, A):
                    h = h + g[q, a, J] * u[a, i]
                H[q, J, i] = h


def green_strain(H, q):
    """Green strain ``(e_xx, e_yy, 2 e_xy)`` [-] at strain point ``q`` (Eq. 14), written with the
    displacement gradient, ``E = (H + H^T + H^T H) / 2``, so that small strains carry no round-off
    from cancelling reference coordinates."""
    hx0, hx1, hx2 = H[q, 0, 0], H[q, 0, 1], H[q, 0, 2]  # dU/dX
    hy0, hy1, hy2 = H[q, 1, 0], H[q, 1, 1], H[q, 1, 2]  # dU/dY
    exx = hx0 + 0.5 * (hx0 * hx0 + hx1 * hx1 + hx2 * hx2)
    eyy = hy1 + 0.5 * (hy0 * hy0 + hy1 * hy1 + hy2 * hy2)
    gxy = hx1 + hy0 + (hx0 * hy0 + hx1 * hy1 + hx2 * hy2)
    return exx, eyy, gxy


def averaged_strain(H):
    """Membrane strain of the element ``(e_xx, e_yy, 2 e_xy)`` [-]: the mean of the Green strains
    (Eq. 14) at its Q strain points (RFT6: the mid-side points I, II, III, §3)."""
    Q = H.shape[0]
    exx, eyy, gxy = green_strain(H, 0)
    for q in range(1, Q):
        dxx, dyy, dxy = green_strain(H, q)
        exx = exx + dxx
        eyy = eyy + dyy
        gxy = gxy + dxy
    return exx / Q, eyy / Q, gxy / Q


def strain_increment(H, h):
    """The linearised change of the membrane strain, ``Bbar(U) dU = 1/Q sum_q sym(F_q^T h_q)`` in
    the order (e_xx, e_yy, 2 e_xy) [-]: the derivative of Eq. 14 along ``dU``, from the displacement
    gradients ``H`` of U and ``h`` of dU ``(Q, 2, 3)`` [-] (:func:`strain_point_gradients`)."""
    Q = H.shape[0]
    dxx = 0.0 * h[0, 0, 0]
    dyy = 0.0 * h[0, 0, 0]
    dxy = 0.0 * h[0, 0, 0]
    for q in range(Q):
        for i in range(3):
            fx, fy = _deformation(H, q, i)
            dxx = dxx + fx * h[q, 0, i]
            dyy = dyy + fy * h[q, 1, i]
            dxy = dxy + (fx * h[q, 1, i] + fy * h[q, 0, i])
    return dxx / Q, dyy / Q, dxy / Q


def stress(Dm, exx, eyy, gxy):
    """Second Piola-Kirchhoff stress resultant ``S = D^m eps = (S_xx, S_yy, S_xy)`` [N/m] (Eq. 15),
    ``Dm (3, 3)`` [N/m]."""
    return (Dm[0, 0] * exx + Dm[0, 1] * eyy + Dm[0, 2] * gxy,
            Dm[1, 0] * exx + Dm[1, 1] * eyy + Dm[1, 2] * gxy,
            Dm[2, 0] * exx + Dm[2, 1] * eyy + Dm[2, 2] * gxy)


def membrane_state(g, u, Dm, H):
    """Gradients into ``H``, then the averaged strain [-] and the stress [N/m] of the element:
    ``(e_xx, e_yy, 2 e_xy, S_xx, S_yy, S_xy)``."""
    strain_point_gradients(g, u, H)
    exx, eyy, gxy = averaged_strain(H)
    sxx, syy, sxy = stress(Dm, exx, eyy, gxy)
    return exx, eyy, gxy, sxx, syy, sxy


def strain_energy(area, exx, eyy, gxy, sxx, syy, sxy):
    """Membrane energy ``E_m = A/2 eps^T D^m eps`` [J] (Eq. 15), ``area`` [m^2]."""
    return 0.5 * area * (exx * sxx + eyy * syy + gxy * sxy)


def _deformation(H, q, i):
    """Row i of the deformation gradient at strain point q: ``(F[i, X], F[i, Y])``, F = I + H."""
    fx = H[q, 0, i]
    fy = H[q, 1, i]
    if i == 0:
        fx = fx + 1.0
    if i == 1:
        fy = fy + 1.0
    return fx, fy


def element_force(g, H, sxx, syy, sxy, area, fe):
    """Fill ``fe (A, 3)`` [N] with the membrane force, the gradient of Eq. 15:
    ``f_ai = A/Q sum_q sum_J P_q[i, J] g[q, a, J]`` with the first Piola-Kirchhoff stress
    ``P_q = F_q S`` (the same as ``A S . Bbar_ai``, :func:`element_tangent`)."""
    Q, A = g.shape[0], g.shape[1]
    w = area / Q
    for q in range(Q):
        for i in range(3):
            fx, fy = _deformation(H, q, i)
            px = w * (fx * sxx + fy * sxy)
            py = w * (fx * sxy + fy * syy)
            for a in range(A):
                t = px * g[q, a, 0] + py * g[q, a, 1]
                if q == 0:
                    fe[a, i] = t
                else:
                    fe[a, i] = fe[a, i] + t


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


def element_tangent(g, H, sxx, syy, sxy, area, Dm, psd, B, DB, SG, ke):
    """Fill ``ke (A, 3, A, 3)`` [N/m] with the membrane tangent, the Hessian of Eq. 15:
    ``A (Bbar^T D^m Bbar + 1/Q sum_q (g_qa . S g_qb) I)``, where ``Bbar[k, a, i] = d eps_k / d U_ai``
    (the mean over the strain points, into the scratch ``B (3, A, 3)`` [1/m]; ``DB = A D^m Bbar``
    [N/m^2]; ``SG (Q, A, 2) = (A/Q) S g_qa`` [N/m^2], scratch).
    With ``psd`` the geometric part uses the :func:`positive_part` of S, so the tangent is positive
    semi-definite under compression (docs/theory/membrane.md); the material part always is. The element area and
    the weight 1/Q are folded into DB and SG, so that the numpy twin (element axis last) does a third
    fewer whole-array operations."""
    Q, A = g.shape[0], g.shape[1]
    for a in range(A):
        for i in range(3):
            b0 = 0.0
            b1 = 0.0
            b2 = 0.0
            for q in range(Q):
                fx, fy = _deformation(H, q, i)
                gx = g[q, a, 0]
                gy = g[q, a, 1]
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
            gb0, gb1 = g[q, b, 0], g[q, b, 1]
            SG[q, b, 0] = wxx * gb0 + wxy * gb1
            SG[q, b, 1] = wxy * gb0 + wyy * gb1
    for a in range(A):
        for b in range(a, A):
            geo = g[0, a, 0] * SG[0, b, 0] + g[0, a, 1] * SG[0, b, 1]  # (A/Q) sum_q g_qa . S g_qb
            for q in range(1, Q):
                geo = geo + (g[q, a, 0] * SG[q, b, 0] + g[q, a, 1] * SG[q, b, 1])
            for i in range(3):
                b0, b1, b2 = B[0, a, i], B[1, a, i], B[2, a, i]
                for j in range(i if b == a else 0, 3):
                    m = b0 * DB[0, b, j] + b1 * DB[1, b, j] + b2 * DB[2, b, j]
                    if i == j:
                        m = m + geo
                    ke[a, i, b, j] = m
                    ke[b, j, a, i] = m


# --- element loops: compiled only (numba), ``prange`` runs element blocks on threads ----------------
def _gather(U, n, u):
    """``u[a, i] = U[n[a], i]``: the element's nodal displacements [m]."""
    for a in range(n.shape[0]):
        for i in range(3):
            u[a, i] = U[n[a], i]
    return u


def _gather_offset(U, n, D, e, u):
    """:func:`_gather` plus the element's reference offset ``D[e] (A, 3)`` [m] when ``D`` has rows (a mesh sewn
    from panels, :attr:`rftstatic.element.membrane.MembraneOperator.offset`; ``D (0, A, 3)`` otherwise): the
    displacements of the element's nodes from its own flat reference."""
    _gather(U, n, u)
    if D.shape[0] > 0:
        for a in range(n.shape[0]):
            for i in range(3):
                u[a, i] = u[a, i] + D[e, a, i]
    return u


def membrane_energies(nodes, G, area, D, Dm, U, We):
    """Fill ``We (E,)`` [J] with the membrane energy of every element at ``U (N, 3)`` [m];
    ``nodes (E, A)``, ``G (E, Q, A, 2)`` [1/m], ``area (E,)`` [m^2], ``D (E, A, 3)`` [m] the reference offsets
    of a sewn mesh or ``(0, A, 3)`` (:func:`_gather_offset`; the same in every loop below)."""
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    u = np.empty((A, 3))
    for e in range(E):
        exx, eyy, gxy, sxx, syy, sxy = membrane_state(G[e], _gather_offset(U, nodes[e], D, e, u), Dm, H)
        We[e] = strain_energy(area[e], exx, eyy, gxy, sxx, syy, sxy)


def membrane_forces(nodes, G, area, D, Dm, U, fe, start, stop):
    """Fill ``fe[start:stop] (E, A, 3)`` [N] with the membrane forces of elements ``start`` to
    ``stop - 1``; return their membrane energy [J]."""
    Q, A = G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    u = np.empty((A, 3))
    W = 0.0
    for e in range(start, stop):
        exx, eyy, gxy, sxx, syy, sxy = membrane_state(G[e], _gather_offset(U, nodes[e], D, e, u), Dm, H)
        element_force(G[e], H, sxx, syy, sxy, area[e], fe[e])
        W += strain_energy(area[e], exx, eyy, gxy, sxx, syy, sxy)
    return W


def membrane_force_blocks(nodes, G, area, D, Dm, U, fe, chunks):
    """:func:`membrane_forces` of all elements in ``chunks`` blocks (on threads in the parallel twin;
    any number of blocks gives the same ``fe``); return the membrane energy [J]."""
    E = G.shape[0]
    W = 0.0
    for c in prange(chunks):
        W += membrane_forces(nodes, G, area, D, Dm, U, fe, c * E // chunks, (c + 1) * E // chunks)
    return W


def _force_and_tangent(g, u, area, Dm, psd, S, e, H, B, DB, SG, fe, ke):
    """Element ``e``'s force into ``fe (A, 3)`` and tangent into ``ke (A, 3, A, 3)`` from its
    displacements ``u (A, 3)``; the geometric part takes ``S[e]`` when ``S`` is not empty (MIP Newton's
    carried stress), else the element's own stress (:func:`membrane_tangents`)."""
    _, _, _, sxx, syy, sxy = membrane_state(g, u, Dm, H)
    element_force(g, H, sxx, syy, sxy, area, fe)
    if S.shape[0] > 0:
        sxx, syy, sxy = S[e, 0], S[e, 1], S[e, 2]
    element_tangent(g, H, sxx, syy, sxy, area, Dm, psd, B, DB, SG, ke)


def membrane_tangents(nodes, G, area, D, Dm, U, psd, S, fe, ke):
    """Fill ``fe (E, A, 3)`` [N] and ``ke (E, A, 3, A, 3)`` [N/m] for every element.

    ``S (E, 3)`` [N/m]: the stress of the geometric part (the mixed stress of
    :func:`linearised_strain`, MIP Newton); ``S (0, 3)``: the element's own stress ``D^m eps(U)``,
    the exact Hessian. The force is always the gradient of Eq. 15 at ``U``."""
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    u = np.empty((A, 3))
    B = np.empty((3, A, 3))
    DB = np.empty((3, A, 3))
    SG = np.empty((Q, A, 2))
    for e in range(E):
        u = _gather_offset(U, nodes[e], D, e, u)
        _force_and_tangent(G[e], u, area[e], Dm, psd, S, e, H, B, DB, SG, fe[e], ke[e])


def membrane_tangents_into(nodes, G, area, D, Dm, U, psd, S, emap, fe, data):
    """:func:`membrane_tangents` with every element tangent added straight into the CSR values
    ``data (nnz,)`` [N/m] at the positions ``emap (E, A, 3, A, 3)`` (no (E, A, 3, A, 3) array, no
    separate scatter), element by element in order; ``fe (E, A, 3)`` [N] is filled as there."""
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    u = np.empty((A, 3))
    B = np.empty((3, A, 3))
    DB = np.empty((3, A, 3))
    SG = np.empty((Q, A, 2))
    ke = np.empty((A, 3, A, 3))
    for e in range(E):
        u = _gather_offset(U, nodes[e], D, e, u)
        _force_and_tangent(G[e], u, area[e], Dm, psd, S, e, H, B, DB, SG, fe[e], ke)
        m = emap[e]
        for a in range(A):
            for i in range(3):
                for b in range(A):
                    for j in range(3):
                        data[m[a, i, b, j]] += ke[a, i, b, j]


def membrane_linearised_strains(nodes, G, D, U, dU, out):
    """Fill ``out (E, 3)`` [-] with ``eps(U) + Bbar(U) dU`` of every element (:func:`strain_increment`),
    ``U, dU (N, 3)`` [m]."""
    E, Q, A = G.shape[0], G.shape[1], G.shape[2]
    H = np.empty((Q, 2, 3))
    h = np.empty((Q, 2, 3))
    u = np.empty((A, 3))
    du = np.empty((A, 3))
    for e in range(E):
        g = G[e]
        strain_point_gradients(g, _gather_offset(U, nodes[e], D, e, u), H)
        strain_point_gradients(g, _gather(dU, nodes[e], du), h)
        exx, eyy, gxy = averaged_strain(H)
        dxx, dyy, dxy = strain_increment(H, h)
        out[e, 0] = exx + dxx
        out[e, 1] = eyy + dyy
        out[e, 2] = gxy + dxy


def internal_force(indptr, indices, data, nodes, G, area, D, Dm, U, f, fe, slot_ptr, slots, with_membrane, chunks):
    """Fill ``f (N, 3)`` [N] with the internal force at ``U (N, 3)`` [m]; return the stored energy [J].

    Bending ``K_b @ U`` over the CSR rows ``indptr, indices, data`` of the scalar K_b [N/m] (Eq. 13),
    plus the membrane forces of :func:`membrane_force_blocks` (into ``fe (E, A, 3)``), which each node
    gathers from its element slots ``slots[slot_ptr[n]:slot_ptr[n + 1]]`` (flat indices ``e * A + a``
    in element order): no two threads write one entry, and the sums do not depend on ``chunks``.
    """
    N = U.shape[0]
    E, A = nodes.shape[0], nodes.shape[1]
    W = 0.0
    if with_membrane:
        W = membrane_force_blocks(nodes, G, area, D, Dm, U, fe, chunks)
    flat = fe.reshape((E * A, 3))
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


# --- the numpy twins of the loops: all elements at once, element axis last -------------------------
def element_last(G):
    """``G (E, Q, A, 2)`` -> ``(Q, A, 2, E)``, contiguous: the layout of the numpy twins."""
    return np.ascontiguousarray(np.moveaxis(G, 0, -1))


def _vectorised(G_last, nodes, U, D=None):
    """Nodal displacements ``u (A, 3, E)`` [m] and their strain-point gradients ``H (Q, 2, 3, E)`` [-]
    (Eq. 24-25, :func:`strain_point_gradients`: the same sum as one contraction over the element axis); with
    the reference offsets ``D (A, 3, E)`` [m] of a sewn mesh added (:func:`_gather_offset`)."""
    u = np.ascontiguousarray(U.T)[:, nodes.T].transpose(1, 0, 2)
    if D is not None:
        u = u + D
    return u, np.einsum("qaJe,aie->qJie", G_last, u)


def _state(Dm, H):
    """:func:`membrane_state` from the gradients ``H``: ``(e_xx, e_yy, 2 e_xy, S_xx, S_yy, S_xy)``."""
    exx, eyy, gxy = averaged_strain(H)
    return (exx, eyy, gxy, *stress(Dm, exx, eyy, gxy))


def strains_numpy(G_last, nodes, U, D=None):
    """``(E, 3)`` averaged Green strain (e_xx, e_yy, 2 e_xy) [-] of every element; and ``H (Q, 2, 3, E)``."""
    u, H = _vectorised(G_last, nodes, U, D)
    return np.stack(averaged_strain(H), axis=-1), H


def linearised_strain_numpy(G_last, nodes, U, dU, D=None):
    """``(E, 3)`` linearised membrane strain ``eps(U) + Bbar(U) dU`` [-] of every element: the strain
    that the mixed (MIP) Newton iteration carries to the next iterate (:func:`strain_increment`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    du, h = _vectorised(G_last, nodes, dU)
    eps = averaged_strain(H)
    inc = strain_increment(H, h)
    return np.stack([eps[k] + inc[k] for k in range(3)], axis=-1)


def energies_numpy(G_last, nodes, area, Dm, U, D=None):
    """``(E,)`` membrane energy [J] of every element (:func:`membrane_energies`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    return strain_energy(area, *_state(Dm, H))


def forces_numpy(G_last, nodes, area, Dm, U, D=None):
    """Element forces ``fe (A, 3, E)`` [N], element axis last, and energies ``(E,)`` [J]
    (:func:`membrane_forces`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    exx, eyy, gxy, sxx, syy, sxy = _state(Dm, H)
    fe = np.empty(u.shape)
    element_force(G_last, H, sxx, syy, sxy, area, fe)
    return fe, strain_energy(area, exx, eyy, gxy, sxx, syy, sxy)


def tangents_numpy(G_last, nodes, area, Dm, U, psd, S=None, D=None):
    """Element forces ``(E, A, 3)`` [N] and tangents ``(E, A, 3, A, 3)`` [N/m] (:func:`membrane_tangents`;
    ``S (E, 3)`` or None as there). The forces come from the kernel :func:`element_force` (through an
    element-last view); the tangent is :func:`element_tangent`'s Hessian of Eq. 15 as whole-array
    operations, ``A (Bbar^T D^m Bbar + 1/Q sum_q (g_qa . S g_qb) I)``, the material part one batched
    matrix product (the kernel's loops over node pairs cost a numpy twin ~1,700 array operations).
    The element tests run both back ends (force = gradient of energy, tangent = gradient of force)."""
    u, H = _vectorised(G_last, nodes, U, D)
    E, A = nodes.shape
    Q = G_last.shape[0]
    _, _, _, sxx, syy, sxy = _state(Dm, H)
    fe = np.empty((E, A, 3))
    element_force(G_last, H, sxx, syy, sxy, area, np.moveaxis(fe, 0, -1))
    if S is not None and len(S):
        sxx, syy, sxy = S[:, 0], S[:, 1], S[:, 2]
    if psd:
        sxx, syy, sxy = positive_part(sxx, syy, sxy)
    F = H.copy()  # F[q, J, i] = dx_i / dX_J = delta_iJ + H[q, J, i]
    F[:, 0, 0] += 1.0
    F[:, 1, 1] += 1.0
    gx, gy = G_last[:, :, 0], G_last[:, :, 1]  # (Q, A, E)
    B = np.empty((E, 3, A, 3))  # Bbar[k, a, i] (the mean over the strain points), element axis first
    B[:, 0] = np.einsum("qie,qae->eai", F[:, 0], gx) / Q
    B[:, 1] = np.einsum("qie,qae->eai", F[:, 1], gy) / Q
    B[:, 2] = (np.einsum("qie,qae->eai", F[:, 0], gy) + np.einsum("qie,qae->eai", F[:, 1], gx)) / Q
    Bm = B.reshape(E, 3, 3 * A)
    DB = np.matmul(np.asarray(Dm, float)[None] * area[:, None, None], Bm)  # A D^m Bbar (E, 3, 3A)
    ke = np.matmul(Bm.transpose(0, 2, 1), DB).reshape(E, A, 3, A, 3)
    w = area / Q  # geometric part: (A/Q) sum_q g_qa . S g_qb, times the identity in space
    sgx, sgy = w * (sxx * gx + sxy * gy), w * (sxy * gx + syy * gy)  # (Q, A, E)
    geo = np.einsum("qae,qbe->eab", gx, sgx) + np.einsum("qae,qbe->eab", gy, sgy)
    for i in range(3):
        ke[:, :, i, :, i] += geo
    return fe, ke
