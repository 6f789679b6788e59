"""Bending hysteresis: a friction moment per RF patch (Grosberg's model of KES pure bending).

A woven fabric bent to and fro in the KES-FB2 tester traces a loop: two nearly parallel lines of slope B
(the bending rigidity) a moment ``2HB`` apart [gf cm/cm]. Grosberg (1966) explains it by inter-fibre friction:
a frictional moment ``M_0`` that resists any change of curvature, in parallel with the elastic moment
``B kappa``. After a reversal the friction element first sticks (elastic, stiffness ``K``) and then slips
at ``|M_f| = M_0``, so on the slipping branches

    M = B kappa +/- M_0,     loop width 2 M_0 = 2HB,   M_0 = 2HB / 2                              (H1)

Model (per element e, per material direction k = warp, weft; x along the warp, as D^b of Eq. 4):

- curvature in material axes ``kappa_m = T kappa`` with kappa = (k_xx, k_yy, 2 k_xy) of Eq. 7,
  ``kappa_j = d_j . n``, ``d_j = sum_a L[j, a] u_a`` (Eq. 3 with the image rules folded, the curvature
  operator of :mod:`rftstatic.element.patch`), n the unit normal of the deformed element, T the Voigt
  strain rotation of :func:`rftstatic.material.voigt_rotation`. kappa_m is invariant under rigid motion;
- the friction element's curvature splits into a stick (elastic) part and a slip part ``s_k`` (the
  internal variable, ``(E, 2)`` [1/m], kept in the State): ``e_k = kappa_m,k - s_k``;
- friction moment ``M_f,k = K_k e_k`` while ``|K_k e_k| <= M_0,k`` (stick), else slip. With the slip of the
  last converged step ``s_n`` held, the incremental (return-mapped) friction moment is

      M_f,k = clip(K_k (kappa_m,k - s_n,k), -M_0,k, M_0,k)                                   (H2)

  and it is the derivative of the incremental potential, a Huber function of the trial stick curvature
  ``e = kappa_m - s_n`` (y = M_0 / K):

      psi(e) = K e^2 / 2           |e| <= y
             = M_0 |e| - M_0 y / 2 |e| >  y                                                  (H3)

  so a static solve minimises ``Pi + sum_e A_e sum_k psi_k`` within a step: line searches, PSD checks and
  Newton work as for the elastic model. The consistent tangent ``psi'' = K`` (stick) or 0 (slip) is exact;
- at a converged step the slip is committed (return mapping, backward Euler of the flow rule):

      s_n+1 = s_n + (e - clip(e, -y, y)),   dissipated  D = sum_e A_e sum_k M_0,k |s_n+1 - s_n|    (H4)

The elastic moment B kappa stays in the constant K_b of Eq. 13; this module adds only the friction term.
With K = ratio * B_k (material axes) the loop's turning branch spans a curvature change ``2 M_0 / K``.
There is no friction in twist (2HB measures bending only).

Derivatives (element force ``(E, 6, 3)`` [N] and tangent ``(E, 6, 3, 6, 3)`` [N/m]):
with ``w = T^T M_f`` (E, 3), ``l_a = sum_j w_j L[j, a]``, ``D = sum_j w_j d_j``, the unnormalised normal
``c = (x_1 - x_0) x (x_2 - x_0)``, r = |c|, P = I - n n^T and the vertex edges ``E_v = x_(v+1) - x_(v+2)``
(so ``dc = sum_v dx_v x E_v``):

    f_a = A (l_a n + [a = 3 + v] E_v x (P D) / r)                                            (H5)
    K_ab = A (sum_k psi''_k g_k g_k^T + l_a dn/dx_b + (l_b dn/dx_a)^T + d2(D . n)/dx_a dx_b)    (H6)

``g_k = d kappa_m,k / du`` (E, 18), ``dn/dx_v = -(P / r) [E_v]_x``, and, for the fixed vector D,
``d2(D . n)/dx_v dx_w = -[E_v]_x H_c [E_w]_x - gamma_vw [h]_x`` with ``h = P D / r``,
``H_c = -(s P + t n^T + n t^T) / r^2`` (s = D . n, t = P D) and ``gamma_01 = gamma_12 = gamma_20 = 1``,
``gamma_vw = -gamma_wv``. The element tests check (H5) and (H6) by finite differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BendingFriction", "huber"]


def huber(e, K, M0):
    """Incremental friction potential psi (H3) [N m/m], its derivative the moment M_f (H2) [N m/m] and its
    second derivative [N m] for trial stick curvatures ``e (E, 2)`` [1/m], stiffness ``K (2,)`` [N m] and
    yield moment ``M0 (2,)`` [N m/m] (a zero M0 gives a zero term)."""
    y = M0 / np.where(K > 0, K, 1.0)
    stick = np.abs(e) <= y
    m = np.clip(K * e, -M0, M0)
    psi = np.where(stick, 0.5 * K * e * e, M0 * np.abs(e) - 0.5 * M0 * y)
    return psi, m, np.where(stick, K, 0.0) * np.ones_like(e)


def _skew(v):
    """``[v]_x (..., 3, 3)`` with ``[v]_x a = v x a`` for ``v (..., 3)``."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


_GAMMA = np.array([[0.0, 1.0, -1.0], [-1.0, 0.0, 1.0], [1.0, -1.0, 0.0]])
"""gamma_vw of (H6): the second derivative of ``h . c`` is ``-gamma_vw [h]_x`` between vertices v and w."""


@dataclass(frozen=True, eq=False)
class BendingFriction:
    """The friction-moment term of every patch (module docstring), built once per mesh.

    Attributes
    ----------
    nodes : (E, 6) patch nodes (slots 3-5: the element's vertices)
    L : (E, 3, 6) curvature operator with the image rules folded [1/m^2]
    area : (E,) element areas [m^2]
    T : (3, 3) Voigt strain rotation, global -> material axes (kappa_m = T kappa)
    M0 : (2,) yield moment per unit width, warp and weft [N m/m] (= 2HB / 2, H1)
    K : (2,) stick stiffness per unit width, warp and weft [N m]
    """

    nodes: np.ndarray
    L: np.ndarray
    area: np.ndarray
    T: np.ndarray
    M0: np.ndarray
    K: np.ndarray

    @property
    def n_elements(self) -> int:
        return len(self.nodes)

    def initial_slip(self) -> np.ndarray:
        """The virgin state: no slip, ``(E, 2)`` [1/m]."""
        return np.zeros((self.n_elements, 2))

    def curvature(self, U, x) -> np.ndarray:
        """Material-axes curvature ``kappa_m (E, 3)`` [1/m] (warp, weft, 2 x twist) at displacements ``U (N, 3)``
        [m] and positions ``x (N, 3)`` [m]."""
        d = np.einsum("eka,eai->eki", self.L, U[self.nodes])
        n, _, _ = self._normal(x)
        return np.einsum("eki,ei->ek", d, n) @ self.T.T

    def _normal(self, x):
        """Unit normal ``n (E, 3)``, ``r = |c| (E,)`` [m^2] and vertex edges ``E_v (E, 3, 3)`` [m] of (H5)."""
        P = x[self.nodes[:, 3:]]  # (E, 3 vertices, 3)
        c = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
        r = np.maximum(np.linalg.norm(c, axis=1), 1e-300)
        edges = P[:, [1, 2, 0]] - P[:, [2, 0, 1]]  # E_v = x_(v+1) - x_(v+2)
        return c / r[:, None], r, edges

    def evaluate(self, U, x, slip, *, tangent=False, psd=False):
        """Friction energy [J] (the sum of A psi, H3), element forces ``(E, 6, 3)`` [N] (H5) and, with
        ``tangent``, element tangents ``(E, 6, 3, 6, 3)`` [N/m] (H6), at ``U, x (N, 3)`` [m] with the
        committed slip ``slip (E, 2)`` [1/m]. ``psd``: the tangent keeps only its positive semi-definite
        part ``A sum_k psi''_k g_k g_k^T`` (the terms of the turning normal are dropped)."""
        d = np.einsum("eka,eai->eki", self.L, U[self.nodes])  # (E, 3, 3)
        n, r, Ev = self._normal(x)
        km = np.einsum("eki,ei->ek", d, n) @ self.T.T
        psi, m, dm = huber(km[:, :2] - slip, self.K, self.M0)
        A = self.area
        w = m @ self.T[:2]  # (E, 3): T^T M_f
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
        # g_k = d kappa_m,k / du (H5 with w = T row k, unit moments)
        g = np.zeros((E, 2, 6, 3))
        for k in range(2):
            lk = np.einsum("j,eja->ea", self.T[k], self.L)
            Dk = np.einsum("j,eji->ei", self.T[k], d)
            tk = Dk - np.einsum("ei,ei->e", n, Dk)[:, None] * n
            g[:, k] = lk[:, :, None] * n[:, None, :]
            g[:, k, 3:] += np.cross(Ev, (tk / r[:, None])[:, None, :])
        ke = np.einsum("ek,ekai,ekbj->eaibj", dm, g, g)
        if psd:
            return energy, fe, ke * A[:, None, None, None, None]
        # l_a dn/dx_v and its transpose (H6)
        Pm = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
        dn = -np.einsum("eij,evjk->evik", Pm / r[:, None, None], _skew(Ev))  # (E, 3 vertices, 3, 3)
        cross = np.einsum("ea,evij->eaivj", ell, dn)  # (E, 6, 3, 3, 3): u_a component i, vertex v component j
        ke[:, :, :, 3:, :] += cross
        ke[:, 3:, :, :, :] += cross.transpose(0, 3, 4, 1, 2)
        # d2(D . n) / dx_v dx_w at fixed D
        Hc = -(nD[:, None, None] * Pm + t[:, :, None] * n[:, None, :] + n[:, :, None] * t[:, None, :]) \
            / (r * r)[:, None, None]
        S = _skew(Ev)
        nn = -np.einsum("evij,ejk,ewkl->eviwl", S, Hc, S)
        nn -= np.einsum("vw,eil->eviwl", _GAMMA, _skew(h))
        ke[:, 3:, :, 3:, :] += nn
        ke *= A[:, None, None, None, None]
        return energy, fe, ke

    def commit(self, U, x, slip) -> tuple[np.ndarray, float]:
        """Return mapping at a converged step (H4): the new slip ``(E, 2)`` [1/m] and the energy dissipated
        in the step [J]."""
        km = self.curvature(U, x)[:, :2]
        e = km - slip
        y = self.M0 / np.where(self.K > 0, self.K, 1.0)
        ds = e - np.clip(e, -y, y)
        return slip + ds, float(np.einsum("e,ek,k->", self.area, np.abs(ds), self.M0))

    def moment(self, U, x, slip) -> np.ndarray:
        """Friction moment ``M_f (E, 2)`` per unit width [N m/m] (H2), warp and weft."""
        km = self.curvature(U, x)[:, :2]
        return huber(km - slip, self.K, self.M0)[1]


def bending_friction(patches, area, Db, *, warp_angle, M0, ratio) -> BendingFriction:
    """The :class:`BendingFriction` of a mesh's ``patches`` (:class:`rftstatic.element.patch.Patches`) and
    element ``area (E,)`` [m^2], for a fabric of bending matrix ``Db (3, 3)`` in global axes [N m] whose warp
    lies at ``warp_angle`` [rad] from X: yield moments ``M0 (2,)`` [N m/m] and stick stiffness ``ratio * B_k``
    (B_k the material-axes bending rigidities)."""
    from rftstatic.material import voigt_rotation

    T = voigt_rotation(warp_angle)
    Ti = np.linalg.inv(T)
    Bm = np.diag(Ti.T @ np.asarray(Db, float) @ Ti)[:2]
    M0 = np.asarray(M0, float).reshape(2)
    if np.any(M0 < 0) or not ratio > 0:
        raise ValueError(f"bending friction needs M0 >= 0 and ratio > 0, got M0 = {M0}, ratio = {ratio!r}")
    return BendingFriction(np.asarray(patches.nodes), np.asarray(patches.L), np.asarray(area, float), T, M0,
                           ratio * Bm)
