"""The numpy twins of the element loops of :mod:`rftstatic.element.kernels`: all elements at once, the element
axis last (``G_last (Q, A, 2, E)``, ``u (A, 3, E)``, ``H (Q, 2, 3, E)``), the element functions of that module
run with the lane index ``...`` (:func:`rftstatic.element.kernels.lanes`), so that each of their operations is one
numpy operation over the elements."""

import numpy as np

from rftstatic.element.kernels import (averaged_strain, element_force, positive_part, strain_energy, strain_increment,
                                       stress)


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
    """:func:`membrane_state` from the gradients ``H``: ``S (6, E)``, rows ``(e_xx, e_yy, 2 e_xy, S_xx, S_yy,
    S_xy)``."""
    exx, eyy, gxy = averaged_strain(H, ...)
    return np.stack((exx, eyy, gxy, *stress(Dm, exx, eyy, gxy)))


def strains_numpy(G_last, nodes, U, D=None):
    """``(E, 3)`` averaged Green strain (e_xx, e_yy, 2 e_xy) [-] of every element; and ``H (Q, 2, 3, E)``."""
    u, H = _vectorised(G_last, nodes, U, D)
    return np.stack(averaged_strain(H, ...), axis=-1), H


def linearised_strain_numpy(G_last, nodes, U, dU, D=None):
    """``(E, 3)`` linearised membrane strain ``eps(U) + Bbar(U) dU`` [-] of every element: the strain
    that the mixed (MIP) Newton iteration carries to the next iterate (:func:`strain_increment`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    du, h = _vectorised(G_last, nodes, dU)
    eps = averaged_strain(H, ...)
    inc = strain_increment(H, h, ...)
    return np.stack([eps[k] + inc[k] for k in range(3)], axis=-1)


def energies_numpy(G_last, nodes, area, Dm, U, D=None):
    """``(E,)`` membrane energy [J] of every element (:func:`membrane_energies`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    return strain_energy(area, *_state(Dm, H))


def forces_numpy(G_last, nodes, area, Dm, U, D=None):
    """Element forces ``fe (A, 3, E)`` [N], element axis last, and energies ``(E,)`` [J]
    (:func:`membrane_forces`)."""
    u, H = _vectorised(G_last, nodes, U, D)
    S = _state(Dm, H)
    fe = np.empty(u.shape)
    element_force(G_last, H, S, area, fe)
    return fe, strain_energy(area, *S)


def strain_operator(G_last, H):
    """``Bbar (E, 3, A, 3)`` [1/m]: the derivative of the averaged Green strain (e_xx, e_yy, 2 e_xy) of Eq. 14 with
    respect to the nodal displacements ``u_a,i``, the mean over the Q strain points of
    ``dE_q = sym(F_q^T dF_q)`` with ``F_q = I + H_q``, for gradients ``G_last (Q, A, 2, E)`` [1/m] and ``H (Q, 2, 3,
    E)`` [-] (:func:`strains_numpy`); element axis first."""
    Q, A, _, E = G_last.shape
    F = H.copy()  # F[q, J, i] = dx_i / dX_J = delta_iJ + H[q, J, i]
    F[:, 0, 0] += 1.0
    F[:, 1, 1] += 1.0
    gx, gy = G_last[:, :, 0], G_last[:, :, 1]  # (Q, A, E)
    B = np.empty((E, 3, A, 3))  # Bbar[k, a, i] (the mean over the strain points), element axis first
    B[:, 0] = np.einsum("qie,qae->eai", F[:, 0], gx) / Q
    B[:, 1] = np.einsum("qie,qae->eai", F[:, 1], gy) / Q
    B[:, 2] = (np.einsum("qie,qae->eai", F[:, 0], gy) + np.einsum("qie,qae->eai", F[:, 1], gx)) / Q
    return B


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
    St = _state(Dm, H)
    fe = np.empty((E, A, 3))
    element_force(G_last, H, St, area, np.moveaxis(fe, 0, -1))
    sxx, syy, sxy = St[3], St[4], St[5]
    if S is not None and len(S):
        sxx, syy, sxy = S[:, 0], S[:, 1], S[:, 2]
    if psd:
        sxx, syy, sxy = positive_part(sxx, syy, sxy)
    gx, gy = G_last[:, :, 0], G_last[:, :, 1]  # (Q, A, E)
    Bm = strain_operator(G_last, H).reshape(E, 3, 3 * A)
    DB = np.matmul(np.asarray(Dm, float)[None] * area[:, None, None], Bm)  # A D^m Bbar (E, 3, 3A)
    ke = np.matmul(Bm.transpose(0, 2, 1), DB).reshape(E, A, 3, A, 3)
    w = area / Q  # geometric part: (A/Q) sum_q g_qa . S g_qb, times the identity in space
    sgx, sgy = w * (sxx * gx + sxy * gy), w * (sxy * gx + syy * gy)  # (Q, A, E)
    geo = np.einsum("qae,qbe->eab", gx, sgx) + np.einsum("qae,qbe->eab", gy, sgy)
    for i in range(3):
        ke[:, :, i, :, i] += geo
    return fe, ke
