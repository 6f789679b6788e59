"""Scalar laws of the material-axes curvature of an RF patch: the geometry they share.

A term of this kind adds to the stored energy, per element e and per material direction k (warp, weft; x along the
warp, as D^b of Eq. 4), an area-weighted scalar potential of the element's curvature in material axes:

    Pi_e = A_e sum_k psi_k(kappa_m,k),     kappa_m = T kappa,   kappa_j = d_j . n,   d_j = sum_a L[j, a] u_a   (A1)

with kappa = (k_xx, k_yy, 2 k_xy) of Eq. 7 (Eq. 3 with the image rules folded: the curvature operator L of
:mod:`rftstatic.element.patch`), n the unit normal of the deformed element and T the Voigt strain rotation of
:func:`rftstatic.material.voigt_rotation`. kappa_m is invariant under rigid motion (d turns with the body, and so
does n). The law psi_k, its derivative the moment ``M_k = psi_k'`` per unit width [N m/m] and its second derivative
``psi_k''`` [N m] are all a term supplies: the bending friction of :mod:`rftstatic.element.hysteresis` (a Huber
function of the stick curvature) and the softening of :mod:`rftstatic.element.nonlinear_bending` (Feng et al.'s
k2 kappa |kappa| with a floor). The geometry below is the one source of their forces and tangents.

Derivatives (element force ``(E, 6, 3)`` [N] and tangent ``(E, 6, 3, 6, 3)`` [N/m]):
with ``w = T^T M`` (E, 3) (M = (M_warp, M_weft): no moment in twist), ``l_a = sum_j w_j L[j, a]``,
``D = sum_j w_j d_j``, the unnormalised normal ``c = (x_1 - x_0) x (x_2 - x_0)``, r = |c|, P = I - n n^T and the
vertex edges ``E_v = x_(v+1) - x_(v+2)`` (so ``dc = sum_v dx_v x E_v``):

    f_a = A (l_a n + [a = 3 + v] E_v x (P D) / r)                                            (A2)
    K_ab = A (sum_k psi''_k g_k g_k^T + l_a dn/dx_b + (l_b dn/dx_a)^T + d2(D . n)/dx_a dx_b)    (A3)

``g_k = d kappa_m,k / du`` (E, 18) ((A2) with a unit moment in direction k), ``dn/dx_v = -(P / r) [E_v]_x``, and,
for the fixed vector D, ``d2(D . n)/dx_v dx_w = -[E_v]_x H_c [E_w]_x - gamma_vw [h]_x`` with ``h = P D / r``,
``H_c = -(s P + t n^T + n t^T) / r^2`` (s = D . n, t = P D) and ``gamma_01 = gamma_12 = gamma_20 = 1``,
``gamma_vw = -gamma_wv``. The element tests (tests/element/test_hysteresis.py, test_nonlinear_bending.py) check
(A2) and (A3) by finite differences for both laws.

:meth:`AxisCurvature.assemble` is the numpy reference; :mod:`rftstatic.element.axis_terms` evaluates the terms of
a model together, with the compiled loops of :mod:`rftstatic.element._axis_numba` on a compiled run (the same
(A1)-(A3), tested against this module to round-off).

``psd``: the tangent keeps only ``A sum_k max(psi''_k, 0) g_k g_k^T`` (the terms of the turning normal dropped, and
a law's negative curvature too: a softening term's ``psi'' < 0`` lowers the constant K_b of Eq. 13 and need not
leave a positive semi-definite sum, e.g. with a Poisson coupling B12).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AxisCurvature", "axis_rigidities"]


def _skew(v):
    """``[v]_x (..., 3, 3)`` with ``[v]_x a = v x a`` for ``v (..., 3)``."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


_GAMMA = np.array([[0.0, 1.0, -1.0], [-1.0, 0.0, 1.0], [1.0, -1.0, 0.0]])
"""gamma_vw of (A3): the second derivative of ``h . c`` is ``-gamma_vw [h]_x`` between vertices v and w."""


def axis_rigidities(Db, T) -> np.ndarray:
    """Bending rigidities ``(B_warp, B_weft)`` [N m] in material axes of the global bending matrix ``Db (3, 3)``
    [N m], ``T`` the Voigt strain rotation global -> material axes."""
    Ti = np.linalg.inv(T)
    return np.diag(Ti.T @ np.asarray(Db, float) @ Ti)[:2].copy()


@dataclass(frozen=True, eq=False)
class AxisCurvature:
    """The material-axes curvature of every patch and the assembly of a scalar law of it (module docstring).

    Attributes
    ----------
    nodes : (E, 6) patch nodes (slots 3-5: the element's vertices)
    L : (E, 3, 6) curvature operator with the image rules folded [1/m^2]
    area : (E,) element areas [m^2]
    T : (3, 3) Voigt strain rotation, global -> material axes (kappa_m = T kappa)
    """

    nodes: np.ndarray
    L: np.ndarray
    area: np.ndarray
    T: np.ndarray

    @property
    def n_elements(self) -> int:
        return len(self.nodes)

    def curvature(self, U, x) -> np.ndarray:
        """Material-axes curvature ``kappa_m (E, 3)`` [1/m] (warp, weft, 2 x twist) at displacements ``U (N, 3)``
        [m] and positions ``x (N, 3)`` [m] (A1)."""
        d = np.einsum("eka,eai->eki", self.L, U[self.nodes])
        n, _, _ = self._normal(x)
        return np.einsum("eki,ei->ek", d, n) @ self.T.T

    def _normal(self, x):
        """Unit normal ``n (E, 3)``, ``r = |c| (E,)`` [m^2] and vertex edges ``E_v (E, 3, 3)`` [m] of (A2)."""
        P = x[self.nodes[:, 3:]]  # (E, 3 vertices, 3)
        c = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
        r = np.maximum(np.linalg.norm(c, axis=1), 1e-300)
        edges = P[:, [1, 2, 0]] - P[:, [2, 0, 1]]  # E_v = x_(v+1) - x_(v+2)
        return c / r[:, None], r, edges

    def assemble(self, U, x, law, *, tangent=False, psd=False):
        """Energy [J] ``sum_e A_e sum_k psi_k`` (A1), element forces ``(E, 6, 3)`` [N] (A2) and, with ``tangent``,
        element tangents ``(E, 6, 3, 6, 3)`` [N/m] (A3) at ``U, x (N, 3)`` [m] of the scalar ``law``: a function
        of the warp and weft curvatures ``kappa_m (E, 2)`` [1/m] returning ``psi`` [N m/m], ``psi'`` [N m/m] and
        ``psi''`` [N m], each ``(E, 2)``. ``psd``: the positive semi-definite part of (A3) only (module
        docstring)."""
        d = np.einsum("eka,eai->eki", self.L, U[self.nodes])  # (E, 3, 3)
        n, r, Ev = self._normal(x)
        km = np.einsum("eki,ei->ek", d, n) @ self.T.T
        psi, m, dm = law(km[:, :2])
        A = self.area
        w = m @ self.T[:2]  # (E, 3): T^T M
        ell = np.einsum("ej,eja->ea", w, self.L)  # (E, 6)
        D = np.einsum("ej,eji->ei", w, d)  # (E, 3)
        nD = np.einsum("ei,ei->e", n, D)
        t = D - nD[:, None] * n  # P D
        h = t / r[:, None]
        fe = ell[:, :, None] * n[:, None, :]
        fe[:, 3:] += np.cross(Ev, h[:, None, :])
        fe *= A[:, None, None]
        energy = float(np.einsum("e,ek->", A, psi))
        if not tangent:
            return energy, fe, None
        E = self.n_elements
        # g_k = d kappa_m,k / du ((A2) with w = T row k, unit moments)
        g = np.zeros((E, 2, 6, 3))
        for k in range(2):
            lk = np.einsum("j,eja->ea", self.T[k], self.L)
            Dk = np.einsum("j,eji->ei", self.T[k], d)
            tk = Dk - np.einsum("ei,ei->e", n, Dk)[:, None] * n
            g[:, k] = lk[:, :, None] * n[:, None, :]
            g[:, k, 3:] += np.cross(Ev, (tk / r[:, None])[:, None, :])
        ke = np.einsum("ek,ekai,ekbj->eaibj", np.maximum(dm, 0.0) if psd else dm, g, g)
        if psd:
            return energy, fe, ke * A[:, None, None, None, None]
        # l_a dn/dx_v and its transpose (A3)
        Pm = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
        dn = -np.einsum("eij,evjk->evik", Pm / r[:, None, None], _skew(Ev))  # (E, 3 vertices, 3, 3)
        cross = np.einsum("ea,evij->eaivj", ell, dn)  # (E, 6, 3, 3, 3): u_a component i, vertex v component j
        ke[:, :, :, 3:, :] += cross
        ke[:, 3:, :, :, :] += cross.transpose(0, 3, 4, 1, 2)
        # d2(D . n) / dx_v dx_w at fixed D
        Hc = -(nD[:, None, None] * Pm + t[:, :, None] * n[:, None, :] + n[:, :, None] * t[:, None, :]) \
            / (r * r)[:, None, None]
        S = _skew(Ev)
        nn = -np.einsum("evik,ewkl->eviwl", np.einsum("evij,ejk->evik", S, Hc), S)  # [E_v]_x H_c [E_w]_x
        nn -= np.einsum("vw,eil->eviwl", _GAMMA, _skew(h))
        ke[:, 3:, :, 3:, :] += nn
        ke *= A[:, None, None, None, None]
        return energy, fe, ke
