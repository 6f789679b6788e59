"""Shear hysteresis: a friction shear force per width in the membrane (the KES-FB1 shear loop, 2HG).

KES-FB1 shears a strip to and fro (to +-8 deg, under a tension of 10 gf/cm); the shear force per width against the
shear angle traces a loop of slope G (the shear rigidity) whose width is ``2HG`` at 0.5 deg and ``2HG5`` at 5 deg
[gf/cm]. As for bending (Grosberg's model of :mod:`rftstatic.element.hysteresis`), the loop is read as inter-yarn
friction at the crossings: a friction shear force per width ``tau_0`` resists any change of the angle between warp
and weft, in parallel with the elastic ``G gamma``. After a reversal the friction element first sticks (stiffness
``K``) and then slips at ``|tau_f| = tau_0``, so on the slipping branches

    tau = G gamma +/- tau_0,     loop width 2 tau_0 = 2HG,    tau_0 = 2HG / 2                    (S1)

Model (per element e of the membrane, RFT3 or RFT6):

- shear angle ``gamma = t . eps`` with ``eps = (e_xx, e_yy, 2 e_xy)`` the element's averaged Green strain of Eq. 14
  (RFT6: Eq. 24-26) in global axes and ``t`` the third row of the Voigt strain rotation T of
  :func:`rftstatic.material.voigt_rotation` (x along the warp), i.e. the engineering Green shear strain ``2 E_12`` in
  warp/weft axes. ``2 E_12 = sin(phi) sqrt((1 + 2 E_11)(1 + 2 E_22))`` with phi the change of the warp-weft angle,
  so gamma is the shear angle to first order (at 8 deg and no stretch 0.3 % below it); it is invariant under rigid
  motion (so is the Green strain): a sheet turned as a whole does not shear                            (S2)
- the friction element's angle splits into a stick part and a slip ``s`` (the internal variable, ``(E, 1)`` [-],
  kept in the State next to the bending friction's); with the slip of the last converged step ``s_n`` held, the
  return-mapped friction force per width is

      tau_f = clip(K (gamma - s_n), -tau_0, tau_0)                                                (S3)

  the derivative of the Huber potential ``psi(e)`` of :func:`rftstatic.element.hysteresis.huber` (H3, with ``M_0``
  -> ``tau_0``) of the trial stick angle ``e = gamma - s_n``, ``y = tau_0 / K``. The stick stiffness is
  ``K = ratio G_12`` with ``G_12`` the shear rigidity of D^m in material axes [N/m];
- element force, the membrane force of the stress ``S_f = tau_f t`` (conjugate to eps), with ``b_a = t . Bbar_a``
  (Bbar the strain operator of :func:`rftstatic.element.kernels_numpy.strain_operator`):

      f_a = A tau_f b_a                                                                             (S4)
      K_ab = A (psi'' b_a b_b^T + 1/Q sum_q (g_qa . S_f g_qb) I)                                    (S5)

  with ``psi'' = K`` (stick) or 0 (slip) (S10 with 2HG5), ``g_qa`` the strain-point gradients of the membrane and
  ``S_f`` as the 2 x 2 tensor ``[[S_xx, S_xy], [S_xy, S_yy]]``. ``psd``: ``S_f`` replaced by its positive part (as
  the membrane's own geometric stiffness, :func:`rftstatic.element.kernels.positive_part`) and psi'' by max(psi'', 0);
- at a converged step the slip is committed (backward Euler of the flow rule, as H4):

      s_n+1 = s_n + (e - clip(e, -y, y)),     dissipated  D = sum_e A_e tau_0 |s_n+1 - s_n|              (S6)

The elastic shear stays in D^m (Eq. 15); this module adds only the friction term. A static solve minimises
``Pi + sum_e A_e psi`` within a step, the same incremental potential as the bending friction, so the routes treat
both alike (the slips are committed together: :meth:`rftstatic.model.model.Model.commit_slip`).

KES 2HG5 (the loop's width at 5 deg; ``tau5 = 2HG5 / 2``): the threshold grows with the shear angle from tau_0 below
0.5 deg to tau5 beyond 5 deg (S7 of :mod:`rftstatic.element.shear_threshold`), taken at the end-of-step angle inside
the incremental potential (S8), which adds ``tau_0'(gamma) |ds|`` to the force (S9) and the terms of (S10) to psi'';
(S3)-(S6) above are its case tau5 = tau0 (no 2HG5), computed by the same law to the bit. The element tests
(tests/element/test_shear_friction.py, test_shear_threshold.py) check (S4) and (S5) by finite differences on both
branches, with and without the growth.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from rftstatic.element.kernels import averaged_strain, positive_part
from rftstatic.element.kernels_numpy import strain_operator
from rftstatic.element.shear_threshold import KES_ANGLES, growing_friction_law, max_slope, threshold

__all__ = ["ShearFriction", "shear_friction"]


@dataclass(frozen=True, eq=False)
class ShearFriction:
    """The friction shear term of every membrane element (module docstring), built once per mesh.

    Attributes
    ----------
    nodes : (E, A) the membrane's local-to-global node map (A = 3 for RFT3, 6 for RFT6)
    G_last : (Q, A, 2, E) strain-point gradients of the membrane [1/m], element axis last
    area : (E,) element areas [m^2]
    t : (3,) the warp/weft shear row of the Voigt strain rotation (gamma = t . eps, S2)
    tau0 : yield shear force per width [N/m] (= 2HG / 2, S1), below the first of ``angles``
    K : stick stiffness per width [N/m] (ratio x G_12)
    n_nodes : N, the mesh's node count
    offset : (A, 3, E) reference offsets of a sewn mesh (the membrane's ``offset_last``), or None
    compiled : :meth:`nodal_force` by the compiled loop of :mod:`rftstatic.element._shear_numba` (a run on the
        compiled kernels, :func:`rftstatic.compiled.choose_kernels`), else by numpy (the reference)
    tau5 : yield shear force per width beyond the second of ``angles`` [N/m] (= 2HG5 / 2, S7), or None: ``tau0`` at
        every angle
    angles : ``(gamma_a, gamma_b)`` [-] between which the threshold grows (S7; the KES readings' angles)
    """

    nodes: np.ndarray
    G_last: np.ndarray
    area: np.ndarray
    t: np.ndarray
    tau0: float
    K: float
    n_nodes: int
    offset: np.ndarray | None = None
    compiled: bool = False
    tau5: float | None = None
    angles: tuple[float, float] = KES_ANGLES

    @property
    def n_elements(self) -> int:
        return len(self.nodes)

    def initial_slip(self) -> np.ndarray:
        """The virgin state: no slip, ``(E, 1)`` [-]."""
        return np.zeros((self.n_elements, 1))

    @property
    def tau_b(self) -> float:
        """The threshold beyond the second angle [N/m]: ``tau5``, or ``tau0`` without it."""
        return self.tau0 if self.tau5 is None else self.tau5

    def _law(self, gamma, slip):
        """psi (S8), tau_f (S9), psi'' (S10) and tau_0(gamma) (S7), each ``(E, 1)``, at shear angles ``gamma (E, 1)``
        with the committed ``slip (E, 1)`` (:func:`rftstatic.element.shear_threshold.growing_friction_law`)."""
        return growing_friction_law(gamma - slip, gamma, self.K, self.tau0, self.tau_b, *self.angles)

    def stiffest(self) -> ShearFriction:
        """This friction with its stick stiffness raised to ``K + 2 max|tau_0'|``, which bounds psi'' (S10) on both
        branches but for the ``tau_0'' d`` term (of the order of a step's slip): for the stable-step bound
        (:func:`rftstatic.solvers.timestep.element_bound`, evaluated all sticking). Itself without 2HG5."""
        if self.tau5 is None:
            return self
        return replace(self, K=self.K + 2.0 * max_slope(self.tau0, self.tau5, *self.angles))

    @cached_property
    def _gradient(self):
        """The displacement gradients as one sparse product: ``Gs (Q 2 E, N)`` [1/m] with ``H[q, J, i, e] = (Gs
        U[:, i])[(q, J, e)] + H0[q, J, i, e]``, ``H0 (Q, 2, 3, E)`` the reference offsets' part of a sewn mesh (zero
        without), the same sum as :func:`rftstatic.element.kernels_numpy.strains_numpy` (Eq. 24-25)."""
        Q, A, _, E = self.G_last.shape
        rows = (np.arange(Q)[:, None, None, None] * 2 + np.arange(2)[None, None, :, None]) * E + np.arange(E)
        cols = np.asarray(self.nodes).T[None, :, None, :]
        shape = (Q, A, 2, E)
        ij = (np.broadcast_to(rows, shape).ravel(), np.broadcast_to(cols, shape).ravel())
        Gs = sp.csr_matrix((self.G_last.ravel(), ij), shape=(Q * 2 * E, self.n_nodes))
        H0 = 0.0 if self.offset is None else np.einsum("qaJe,aie->qJie", self.G_last, self.offset)
        return Gs, H0

    def _strain(self, U):
        """``eps (E, 3)`` [-] and ``H (Q, 2, 3, E)`` [-] at ``U (N, 3)`` [m]."""
        Gs, H0 = self._gradient
        Q, _, _, E = self.G_last.shape
        H = (Gs @ np.asarray(U, float)).reshape(Q, 2, E, 3).transpose(0, 1, 3, 2) + H0
        return np.stack(averaged_strain(H, ...), axis=-1), H

    def nodal_force(self, U, slip) -> tuple[float, np.ndarray]:
        """Friction energy [J] and nodal forces ``(N, 3)`` [N] at ``U (N, 3)`` [m] with the committed ``slip (E, 1)``:
        :meth:`evaluate`'s forces (S4) summed into the nodes, as ``f_a = A/Q sum_q g_qa . (S_f F_q)`` (no element
        array; the explicit force's path, :mod:`rftstatic.element.explicit_force`): by the compiled loop
        (``compiled``) or through the sparse gradient (:meth:`nodal_force_numpy`)."""
        if not self.compiled:
            return self.nodal_force_numpy(U, slip)
        from rftstatic.element._shear_numba import shear_force

        nodes, G, offset = self._element_first
        f = np.zeros((self.n_nodes, 3))
        W = shear_force(nodes, G, self.area, self.t, offset, np.ascontiguousarray(U, dtype=float),
                        np.ascontiguousarray(slip[:, 0], dtype=float),
                        np.array([self.K, self.tau0, self.tau_b, *self.angles]), f)
        return float(W), f

    @cached_property
    def _element_first(self):
        """The compiled loop's arrays, element axis first: nodes (E, A) int64, gradients (E, Q, A, 2) [1/m],
        offsets (E, A, 3) [m] (``(0, A, 3)`` without)."""
        A = self.nodes.shape[1]
        offset = np.zeros((0, A, 3)) if self.offset is None else np.ascontiguousarray(self.offset.transpose(2, 0, 1))
        return (np.ascontiguousarray(self.nodes, dtype=np.int64),
                np.ascontiguousarray(self.G_last.transpose(3, 0, 1, 2)), offset)

    def nodal_force_numpy(self, U, slip) -> tuple[float, np.ndarray]:
        """:meth:`nodal_force` through the sparse gradient (numpy; the reference of the compiled loop)."""
        eps, H = self._strain(U)
        psi, tau, _, _ = self._law((eps @ self.t)[:, None], slip)
        Q = H.shape[0]
        w = self.area * tau[:, 0] / Q
        sxx, syy, sxy = w * self.t[0], w * self.t[1], w * self.t[2]
        F = H.copy()  # F[q, J, i, e]
        F[:, 0, 0] += 1.0
        F[:, 1, 1] += 1.0
        P = np.stack([sxx * F[:, 0] + sxy * F[:, 1], sxy * F[:, 0] + syy * F[:, 1]], axis=1)  # (Q, 2, 3, E)
        Gs, _ = self._gradient
        f = Gs.T @ P.transpose(0, 1, 3, 2).reshape(-1, 3)
        return float(self.area @ psi[:, 0]), f

    def shear_angle(self, U) -> np.ndarray:
        """``gamma (E, 1)`` [-], the warp-weft engineering Green shear strain of every element (S2); by the compiled
        loop when ``compiled``."""
        if not self.compiled:
            return (self._strain(U)[0] @ self.t)[:, None]
        from rftstatic.element._shear_numba import shear_angles

        nodes, G, offset = self._element_first
        gamma = np.empty(self.n_elements)
        shear_angles(nodes, G, self.t, offset, np.ascontiguousarray(U, dtype=float), gamma)
        return gamma[:, None]

    def evaluate(self, U, slip, *, tangent=False, psd=False):
        """Friction energy [J] (the sum of A psi), element forces ``(E, A, 3)`` [N] (S4) and, with ``tangent``,
        element tangents ``(E, A, 3, A, 3)`` [N/m] (S5), at ``U (N, 3)`` [m] with the committed ``slip (E, 1)`` [-].
        ``psd``: the geometric part with the positive part of the friction stress, and psi'' >= 0 (S10)."""
        eps, H = self._strain(U)
        G_last = self.G_last
        psi, tau, dtau, _ = self._law((eps @ self.t)[:, None], slip)
        B = strain_operator(G_last, H)  # (E, 3, A, 3)
        b = np.einsum("k,ekai->eai", self.t, B)
        A = self.area
        fe = (A * tau[:, 0])[:, None, None] * b
        energy = float(A @ psi[:, 0])
        if not tangent:
            return energy, fe, None
        if psd:  # a falling threshold's negative slope (S10) dropped
            dtau = np.maximum(dtau, 0.0)
        ke = (A * dtau[:, 0])[:, None, None, None, None] * b[:, :, :, None, None] * b[:, None, None, :, :]
        S = tau[:, 0][:, None] * self.t[None, :]  # (E, 3): S_xx, S_yy, S_xy of S_f
        sxx, syy, sxy = S[:, 0], S[:, 1], S[:, 2]
        if psd:
            sxx, syy, sxy = positive_part(sxx, syy, sxy)
        Q = G_last.shape[0]
        gx, gy = G_last[:, :, 0], G_last[:, :, 1]  # (Q, A, E)
        w = A / Q
        geo = (np.einsum("qae,qbe->eab", gx, w * (sxx * gx + sxy * gy))
               + np.einsum("qae,qbe->eab", gy, w * (sxy * gx + syy * gy)))
        for i in range(3):
            ke[:, :, i, :, i] += geo
        return energy, fe, ke

    def commit(self, U, slip) -> tuple[np.ndarray, float]:
        """Return mapping at a converged step (S6, with the threshold tau_0(gamma) of S7 at the step's angle): the new
        slip ``(E, 1)`` [-] and the energy dissipated in the step [J]."""
        gamma = self.shear_angle(U)
        tau = self.threshold(gamma)
        e = gamma - slip
        y = tau / self.K
        ds = e - np.clip(e, -y, y)
        if self.tau5 is None:
            return slip + ds, float(self.tau0 * (self.area @ np.abs(ds[:, 0])))
        return slip + ds, float(self.area @ (tau[:, 0] * np.abs(ds[:, 0])))

    def threshold(self, gamma) -> np.ndarray:
        """The friction threshold ``tau_0(gamma)`` [N/m] (S7) at shear angles ``gamma`` [-] (any shape)."""
        return threshold(gamma, self.tau0, self.tau_b, *self.angles)[0]

    def force(self, U, slip) -> np.ndarray:
        """Friction shear force per width ``tau_f (E, 1)`` [N/m] (S3; S9 with 2HG5)."""
        return self._law(self.shear_angle(U), slip)[1]


def shear_friction(membrane, Dm, *, n_nodes, warp_angle, tau0, ratio, compiled=False, tau5=None) -> ShearFriction:
    """The :class:`ShearFriction` of a membrane operator ``membrane``
    (:class:`rftstatic.element.membrane.MembraneOperator`) of a mesh of ``n_nodes`` nodes for a fabric of membrane
    matrix ``Dm (3, 3)`` in global axes [N/m] whose warp lies at ``warp_angle`` [rad] from X: yield force per width
    ``tau0`` [N/m] (2HG / 2) and stick stiffness ``ratio * G_12`` (G_12 the material-axes shear rigidity);
    ``compiled``: its explicit force by the compiled loop (:attr:`ShearFriction.compiled`); ``tau5`` [N/m] (2HG5 / 2,
    >= tau0): the threshold beyond 5 deg (S7), or None."""
    from rftstatic.material import voigt_rotation

    T = voigt_rotation(warp_angle)
    Ti = np.linalg.inv(T)
    G12 = float((Ti.T @ np.asarray(Dm, float) @ Ti)[2, 2])
    if not (np.isfinite(tau0) and tau0 >= 0) or not ratio > 0 or not G12 > 0:
        raise ValueError(f"shear friction needs tau0 >= 0, ratio > 0 and a shear rigidity G_12 > 0, got tau0 = "
                         f"{tau0!r}, ratio = {ratio!r}, G_12 = {G12!r} N/m")
    if tau5 is not None and not (np.isfinite(tau5) and tau5 >= tau0):
        raise ValueError(f"shear friction needs tau5 >= tau0 (a threshold that grows with the shear), got tau5 = "
                         f"{tau5!r}, tau0 = {tau0!r} N/m")
    return ShearFriction(np.asarray(membrane.nodes), membrane.G_last, np.asarray(membrane.area, float),
                         T[2].copy(), float(tau0), float(ratio) * G12, int(n_nodes), membrane.offset_last,
                         bool(compiled), None if tau5 is None else float(tau5))
