"""Nonlinear (softening) bending: Feng et al.'s ``k2 kappa |kappa|`` per RF patch, with a floor on the slope.

The fabric data set of Feng, Huang, Xu & Wang (2022), ACM TOG 41(6) (:mod:`rftstatic.fabrics.lab`, keys ``ctd_*``)
gives per fabric and per direction (warp, weft) a moment per unit width

    M(kappa) = k1 kappa + k2 kappa |kappa|,     k1 = B,  k2 < 0 (softening)                        (N1)

[N m/m]: at the curvature of the bending length, kappa = 1/c with c = (B/W)^(1/3), the ratio k2 kappa / k1 is
-0.41 / -0.36 (warp / weft) at the 5th percentile of its 618 fabrics, -0.13 / -0.14 at the median, -0.05 / -0.04
at the 95th. Taken as it stands, (N1)'s slope ``B + 2 k2 |kappa|`` falls to zero at ``kappa_0 = B / (2 |k2|)``
(3.8 / c at the median, 1.2 / c at the 5th percentile) and is negative beyond: a moment that falls as the fabric
bends, a concave energy, a material that kinks. The model keeps (N1) where its slope is at least a floor fraction
phi of B and continues the moment linearly with slope phi B beyond (C1 moment, convex energy, a stable material):

    kappa_f = (1 - phi) B / (2 |k2|)                                                                  (N2)
    M(kappa) = B kappa + k2 kappa |kappa|                                  |kappa| <= kappa_f
             = B kappa + sign(kappa) k2 (2 kappa_f |kappa| - kappa_f^2)    |kappa| >  kappa_f         (N3)

(the second line has slope ``B + 2 k2 kappa_f = phi B``). phi = 0.2 (:data:`FLOOR`): (N3) is (N1) up to
kappa_f = 0.8 kappa_0 and lies above it by ``phi^2 / 2 B kappa_0``, i.e. 4 % of (N1)'s own peak moment
``B kappa_0 / 2``, at kappa_0, where (N1) stops being a material law; the bending tangent stays >= 0.2 B, so a
Newton system's bending part is at most 5 times softer than the linear one. kappa_f = 0.8 / (2 |r| c) for
``r = k2 / (B c)`` the ratio at the bending length: 3.1 / c at the median (1.88 /cm for the wool of Kang & Yu,
c = 1.635 cm), 0.98 / c at the 5th percentile (0.60 /cm).

Model (per element e, per material direction k = warp, weft): the linear moment B kappa stays in the constant
K_b of Eq. 13; this module adds the correction ``m = M - B kappa`` as a scalar potential of the material-axes
curvature ``kappa_m,k = T_k (d . n)`` of :mod:`rftstatic.element.axis_curvature` (A1, rigid-motion invariant):

    psi(kappa) = k2 |kappa|^3 / 3                                          |kappa| <= kappa_f
               = k2 (kappa_f kappa^2 - kappa_f^2 |kappa| + kappa_f^3 / 3)  |kappa| >  kappa_f          (N4)
    psi'(kappa) = m(kappa) (N3 less B kappa),   psi''(kappa) = 2 k2 min(|kappa|, kappa_f)             (N5)

[N m/m, N m/m, N m]; B kappa^2 / 2 + psi is convex (its second derivative is >= phi B), and psi is C2 (psi''
is continuous: the moment is C1, its slope has kinks at 0 and +-kappa_f).
Its element forces and tangents are (A2), (A3) of :mod:`rftstatic.element.axis_curvature` with ``M = psi'``;
the PSD tangent drops psi'' (<= 0: the constant K_b is then a secant that overestimates the stiffness by at most
(1 - phi) B). A direction with k2 = 0 has no term. There is no correction in twist (the data set's bias k2 is a
value of its repository's interpolation between directions, not of a plate theory: lab.py). The term is elastic:
no internal variable, no route dependence; with bending hysteresis (:mod:`rftstatic.element.hysteresis`) both
terms add.

Stiffening (k2 > 0) is refused (:func:`nonlinear_bending`): every fabric of the data set softens, so no stiffening
value has a source here, and a stiffening term would raise the tangent above the B from which the explicit step's
stable time step and the preconditioners are estimated; a positive value is most likely a slip of sign.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.element.axis_curvature import AxisCurvature, axis_rigidities
from rftstatic.material import NONLINEAR_FLOOR, voigt_rotation

__all__ = ["FLOOR", "BendingSoftening", "nonlinear_bending", "softening", "softening_law"]

FLOOR = NONLINEAR_FLOOR
"""Default floor phi of the bending slope, a fraction of B [-] (module docstring: the moment stays within
phi^2 = 4 % of Feng et al.'s law up to the curvature where that law's moment peaks)."""


def floor_curvature(B, k2, floor):
    """``kappa_f`` (N2) [1/m] per direction for rigidities ``B (2,)`` [N m], ``k2 (2,)`` [N m^2] (<= 0) and
    the floor ``floor`` [-]; infinite where k2 = 0."""
    B, k2 = np.asarray(B, float), np.asarray(k2, float)
    with np.errstate(divide="ignore"):
        return np.where(k2 < 0, (1.0 - floor) * B / (2.0 * np.abs(k2)), np.inf)


def softening_law(kappa, k2, kf):
    """The correction's potential psi (N4) [N m/m], moment psi' (N3 less B kappa) [N m/m] and psi'' (N5) [N m] at
    curvatures ``kappa`` [1/m] for ``k2`` [N m^2] (<= 0) and the floor curvature ``kf`` [1/m] (:func:`floor_curvature`,
    inf without k2). Written with ufuncs only, so that one source serves numpy arrays (``kappa (E, 2)``, the rest
    ``(2,)``) and the compiled kernels of :mod:`rftstatic.element._axis_numba` (scalars): with ``a = |kappa|`` and
    ``c = min(a, kf)`` (a on the k2 branch, kf on the floor), ``psi = k2 (c^3 / 3 + c a (a - c))``,
    ``psi' = sign(kappa) k2 c (2 a - c)``, ``psi'' = 2 k2 c``."""
    a = np.abs(kappa)
    c = np.minimum(a, kf)
    psi = k2 * (c * c * c / 3.0 + c * a * (a - c))
    return psi, np.sign(kappa) * k2 * (c * (2.0 * a - c)), 2.0 * k2 * c


def softening(kappa, B, k2, floor=FLOOR):
    """The correction's potential psi (N4) [N m/m], moment psi' (N3 less B kappa) [N m/m] and psi'' (N5) [N m]
    at curvatures ``kappa (E, 2)`` [1/m] for ``B (2,)`` [N m], ``k2 (2,)`` [N m^2] (<= 0) and ``floor`` [-]:
    :func:`softening_law`."""
    return softening_law(kappa, np.asarray(k2, float), floor_curvature(B, k2, floor))


@dataclass(frozen=True, eq=False)
class BendingSoftening(AxisCurvature):
    """The softening correction of every patch (module docstring), built once per mesh.

    Attributes
    ----------
    nodes, L, area, T : the patches' geometry (:class:`rftstatic.element.axis_curvature.AxisCurvature`)
    B : (2,) bending rigidities in material axes, warp and weft [N m]
    k2 : (2,) Feng et al.'s k2, warp and weft [N m^2] (<= 0)
    floor : the floor phi of the slope, a fraction of B [-]
    """

    B: np.ndarray
    k2: np.ndarray
    floor: float

    @property
    def kappa_floor(self) -> np.ndarray:
        """``kappa_f (2,)`` [1/m] (N2), warp and weft (inf without k2)."""
        return floor_curvature(self.B, self.k2, self.floor)

    def evaluate(self, U, x, *, tangent=False, psd=False):
        """Energy [J] (the sum of A psi, N4), element forces ``(E, 6, 3)`` [N] and, with ``tangent``, element
        tangents ``(E, 6, 3, 6, 3)`` [N/m] at ``U, x (N, 3)`` [m] ((A2), (A3) of
        :mod:`rftstatic.element.axis_curvature`; ``psd``: without the correction's tangent, psi'' <= 0)."""
        return self.assemble(U, x, lambda km: softening(km, self.B, self.k2, self.floor), tangent=tangent,
                             psd=psd)

    def moment(self, U, x) -> np.ndarray:
        """The correction's moment ``M - B kappa (E, 2)`` per unit width [N m/m] (N3), warp and weft."""
        return softening(self.curvature(U, x)[:, :2], self.B, self.k2, self.floor)[1]

    def on_floor(self, U, x) -> np.ndarray:
        """``(E, 2)`` bool: the element-directions past kappa_f (on the floor branch of N3)."""
        return np.abs(self.curvature(U, x)[:, :2]) > self.kappa_floor


def nonlinear_bending(patches, area, Db, *, warp_angle, k2, floor=FLOOR) -> BendingSoftening:
    """The :class:`BendingSoftening` of a mesh's ``patches`` (:class:`rftstatic.element.patch.Patches`) and
    element ``area (E,)`` [m^2], for a fabric of bending matrix ``Db (3, 3)`` in global axes [N m] whose warp lies
    at ``warp_angle`` [rad] from X: ``k2 (2,)`` [N m^2] warp and weft (finite, <= 0), ``floor`` in (0, 1)."""
    T = voigt_rotation(warp_angle)
    k2 = np.asarray(k2, float).reshape(2)
    if not (np.all(np.isfinite(k2)) and np.all(k2 <= 0)) or not 0.0 < floor < 1.0:
        raise ValueError(f"nonlinear bending needs finite k2 <= 0 and a floor in (0, 1), got k2 = {k2}, "
                         f"floor = {floor!r}")
    return BendingSoftening(np.asarray(patches.nodes), np.asarray(patches.L), np.asarray(area, float), T,
                            axis_rigidities(Db, T), k2, float(floor))
