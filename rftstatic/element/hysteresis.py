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

Derivatives: the friction is a scalar law psi(kappa_m) of the material-axes curvature, so its element forces
(H5) and tangents (H6) are (A2) and (A3) of :mod:`rftstatic.element.axis_curvature` (the geometry shared with
the softening of :mod:`rftstatic.element.nonlinear_bending`) with ``M = M_f`` (H2) and ``psi'' = K`` (stick) or 0
(slip): with ``w = T^T M_f``, ``f_a = A (l_a n + [a = 3 + v] E_v x (P D) / r)`` (H5) and
``K_ab = A (sum_k psi''_k g_k g_k^T + l_a dn/dx_b + (l_b dn/dx_a)^T + d2(D . n)/dx_a dx_b)`` (H6).
The element tests check (H5) and (H6) by finite differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.element.axis_curvature import AxisCurvature, axis_rigidities

__all__ = ["BendingFriction", "friction_law", "friction_yield", "huber"]


def friction_yield(K, M0):
    """The stick range ``y = M0 / K`` [1/m] of (H3) per direction, for stiffness ``K (2,)`` [N m] and yield moment
    ``M0 (2,)`` [N m/m] (``M0`` where K = 0)."""
    return M0 / np.where(K > 0, K, 1.0)


def friction_law(e, K, M0, y):
    """Incremental friction potential psi (H3) [N m/m], its derivative the moment M_f (H2) [N m/m] and its
    second derivative [N m] at trial stick curvatures ``e`` [1/m], for stiffness ``K`` [N m], yield moment ``M0``
    [N m/m] and stick range ``y`` (:func:`friction_yield`) [1/m]. Written with ufuncs only, so that one source
    serves numpy arrays (``e (E, 2)``, the rest ``(2,)``) and the compiled kernels of
    :mod:`rftstatic.element._axis_numba` (scalars): with ``e_c = clip(e, -y, y)``,
    ``psi = K e_c^2 / 2 + M0 (|e| - |e_c|)``, which is (H3) on both branches (K y = M0)."""
    m = np.minimum(np.maximum(K * e, -M0), M0)
    ec = np.minimum(np.maximum(e, -y), y)
    psi = 0.5 * K * ec * ec + M0 * (np.abs(e) - np.abs(ec))
    return psi, m, K * (np.abs(e) <= y)


def huber(e, K, M0):
    """Incremental friction potential psi (H3) [N m/m], its derivative the moment M_f (H2) [N m/m] and its
    second derivative [N m] for trial stick curvatures ``e (E, 2)`` [1/m], stiffness ``K (2,)`` [N m] and
    yield moment ``M0 (2,)`` [N m/m] (a zero M0 gives a zero term): :func:`friction_law`."""
    return friction_law(e, K, M0, friction_yield(K, M0))


@dataclass(frozen=True, eq=False)
class BendingFriction(AxisCurvature):
    """The friction-moment term of every patch (module docstring), built once per mesh.

    Attributes
    ----------
    nodes, L, area, T : the patches' geometry (:class:`rftstatic.element.axis_curvature.AxisCurvature`)
    M0 : (2,) yield moment per unit width, warp and weft [N m/m] (= 2HB / 2, H1)
    K : (2,) stick stiffness per unit width, warp and weft [N m]
    """

    M0: np.ndarray
    K: np.ndarray

    def initial_slip(self) -> np.ndarray:
        """The virgin state: no slip, ``(E, 2)`` [1/m]."""
        return np.zeros((self.n_elements, 2))

    def evaluate(self, U, x, slip, *, tangent=False, psd=False):
        """Friction energy [J] (the sum of A psi, H3), element forces ``(E, 6, 3)`` [N] (H5) and, with
        ``tangent``, element tangents ``(E, 6, 3, 6, 3)`` [N/m] (H6), at ``U, x (N, 3)`` [m] with the
        committed slip ``slip (E, 2)`` [1/m]. ``psd``: the tangent keeps only its positive semi-definite
        part ``A sum_k psi''_k g_k g_k^T`` (the terms of the turning normal are dropped)."""
        return self.assemble(U, x, lambda km: huber(km - slip, self.K, self.M0), tangent=tangent, psd=psd)

    def commit(self, U, x, slip) -> tuple[np.ndarray, float]:
        """Return mapping at a converged step (H4): the new slip ``(E, 2)`` [1/m] and the energy dissipated
        in the step [J]."""
        return self.return_map(self.curvature(U, x)[:, :2], slip)

    def return_map(self, km, slip) -> tuple[np.ndarray, float]:
        """(H4) from the material-axes curvatures ``km (E, 2)`` [1/m] (warp, weft) of a converged step and the
        committed ``slip (E, 2)`` [1/m]: the new slip and the energy dissipated in the step [J]."""
        e = km - slip
        ds = e - np.clip(e, -self.y, self.y)
        return slip + ds, float(np.einsum("e,ek,k->", self.area, np.abs(ds), self.M0))

    @property
    def y(self) -> np.ndarray:
        """The stick range ``M0 / K (2,)`` [1/m] (:func:`friction_yield`)."""
        return friction_yield(self.K, self.M0)

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
    Bm = axis_rigidities(Db, T)
    M0 = np.asarray(M0, float).reshape(2)
    if np.any(M0 < 0) or not ratio > 0:
        raise ValueError(f"bending friction needs M0 >= 0 and ratio > 0, got M0 = {M0}, ratio = {ratio!r}")
    return BendingFriction(np.asarray(patches.nodes), np.asarray(patches.L), np.asarray(area, float), T, M0,
                           ratio * Bm)
