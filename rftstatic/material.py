"""Fabric and shell rigidities: the membrane matrix D^m (Eq. 15) and bending matrix D^b (Eq. 4).

Strain and curvature vectors are (e_xx, e_yy, 2 e_xy) and (k_xx, k_yy, 2 k_xy) with x along the
warp (Eq. 3, 14). A fabric cut on the bias has its warp at an angle to the global X axis; the
matrices are then rotated into global axes once, here, so the element code never sees the angle.
All rigidities are per unit width: tensile/shear [N/m], bending/twisting [N m].
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from rftstatic.units import STANDARD_GRAVITY, UnitSystem


def voigt_rotation(angle: float) -> np.ndarray:
    """Strain transformation T with e_material = T @ e_global for engineering Voigt vectors.

    Parameters
    ----------
    angle : float
        Angle of the material 1-axis (warp) measured from the global X axis [rad].
    """
    c, s = np.cos(angle), np.sin(angle)
    return np.array(
        [
            [c * c, s * s, c * s],
            [s * s, c * c, -c * s],
            [-2 * c * s, 2 * c * s, c * c - s * s],
        ]
    )


def _orthotropic(d11, d22, d12, d33) -> np.ndarray:
    return np.array([[d11, d12, 0.0], [d12, d22, 0.0], [0.0, 0.0, d33]])


@dataclass(frozen=True)
class BendingHysteresis:
    """Bending hysteresis of a fabric: a friction moment per unit width in parallel with its bending rigidity
    (:mod:`rftstatic.element.hysteresis`, Grosberg's model of the KES-FB2 loop).

    Attributes
    ----------
    M0_warp, M0_weft : yield (friction) moment per unit width [N m/m]: half the KES loop width, ``2HB / 2``
    ratio : stick stiffness over bending rigidity, ``K_k / B_k`` [-]; after a reversal the friction element
        sticks over a curvature change ``2 M0 / K`` before it slips
    """

    M0_warp: float
    M0_weft: float
    ratio: float = 10.0

    def __post_init__(self):
        for key in ("M0_warp", "M0_weft"):
            v = getattr(self, key)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"bending hysteresis {key} must be a finite number >= 0 [N m/m], got {v!r}")
        if not (np.isfinite(self.ratio) and self.ratio > 0):
            raise ValueError(f"bending hysteresis ratio must be a finite number > 0, got {self.ratio!r}")

    def as_dict(self) -> dict:
        return {"M0_warp_N": self.M0_warp, "M0_weft_N": self.M0_weft, "stick_ratio": self.ratio}


@dataclass(frozen=True)
class ShearHysteresis:
    """Shear hysteresis of a fabric: a friction shear force per unit width in parallel with its shear rigidity
    (:mod:`rftstatic.element.shear_friction`, the KES-FB1 shear loop).

    Attributes
    ----------
    tau0 : yield (friction) shear force per unit width [N/m]: half the KES loop width at 0.5 deg, ``2HG / 2``
    ratio : stick stiffness over the shear rigidity G_12 of D^m (material axes) [-]; after a reversal the friction
        element sticks over a shear-angle change ``2 tau0 / (ratio G_12)`` before it slips
    tau5 : yield shear force per unit width at 5 deg and beyond [N/m], half the KES loop width at 5 deg, ``2HG5 / 2``
        (>= tau0; the threshold grows between 0.5 and 5 deg: :mod:`rftstatic.element.shear_threshold`), or None: tau0
        at every angle
    """

    tau0: float
    ratio: float = 10.0
    tau5: float | None = None

    def __post_init__(self):
        if isinstance(self.tau0, bool) or not (np.isfinite(self.tau0) and self.tau0 >= 0):
            raise ValueError(f"shear hysteresis tau0 must be a finite number >= 0 [N/m], got {self.tau0!r}")
        if not (np.isfinite(self.ratio) and self.ratio > 0):
            raise ValueError(f"shear hysteresis ratio must be a finite number > 0, got {self.ratio!r}")
        if self.tau5 is not None and (isinstance(self.tau5, bool) or not (np.isfinite(self.tau5)
                                                                         and self.tau5 >= self.tau0)):
            raise ValueError(f"shear hysteresis tau5 (2HG5 / 2) must be a finite number >= tau0 = {self.tau0!r} N/m, "
                             f"got {self.tau5!r}")

    def as_dict(self) -> dict:
        return {"tau0_N_per_m": self.tau0, "stick_ratio": self.ratio,
                **({"tau5_N_per_m": self.tau5} if self.tau5 is not None else {})}


NONLINEAR_FLOOR = 0.2
"""Default floor of the bending slope under nonlinear bending, a fraction of B [-] (why 0.2:
:mod:`rftstatic.element.nonlinear_bending`)."""


@dataclass(frozen=True)
class NonlinearBending:
    """Softening bending of a fabric: Feng et al.'s moment ``M = B kappa + k2 kappa |kappa|`` per unit width with
    its slope held at ``floor * B`` or more (:mod:`rftstatic.element.nonlinear_bending`, N1-N3).

    Attributes
    ----------
    k2_warp, k2_weft : the quadratic coefficient per direction [N m^2] (moment per width per curvature^2;
        <= 0: softening; 0: no term in that direction)
    floor : the least bending slope as a fraction of B [-], in (0, 1) (default 0.2)
    """

    k2_warp: float
    k2_weft: float
    floor: float = NONLINEAR_FLOOR

    def __post_init__(self):
        for key in ("k2_warp", "k2_weft"):
            v = getattr(self, key)
            if isinstance(v, bool) or not (np.isfinite(v) and v <= 0):
                raise ValueError(f"nonlinear bending {key} must be a finite number <= 0 [N m^2] (softening; a "
                                 f"stiffening k2 > 0 is refused: rftstatic.element.nonlinear_bending), got {v!r}")
        if not (np.isfinite(self.floor) and 0.0 < self.floor < 1.0):
            raise ValueError(f"nonlinear bending floor must be a number in (0, 1), got {self.floor!r}")

    def as_dict(self) -> dict:
        return {"k2_warp_N_m2": self.k2_warp, "k2_weft_N_m2": self.k2_weft, "floor": self.floor}


@dataclass(frozen=True)
class Material:
    """Membrane and bending rigidities in global axes, and the areal weight.

    Attributes
    ----------
    Dm : (3, 3) membrane rigidity in global axes [N/m]
    Db : (3, 3) bending rigidity in global axes [N m]
    weight : areal weight under standard gravity [N/m^2]
    name : label for summaries
    hysteresis : bending hysteresis (:class:`BendingHysteresis`), or None (elastic bending)
    nonlinear_bending : softening bending (:class:`NonlinearBending`), or None (linear bending)
    shear_hysteresis : shear hysteresis (:class:`ShearHysteresis`), or None (elastic shear)
    """

    Dm: np.ndarray
    Db: np.ndarray
    weight: float
    name: str = "material"
    info: dict = field(default_factory=dict)
    hysteresis: BendingHysteresis | None = None
    nonlinear_bending: NonlinearBending | None = None
    shear_hysteresis: ShearHysteresis | None = None

    def __post_init__(self):
        for key in ("Dm", "Db"):
            D = np.asarray(getattr(self, key), dtype=float)
            if D.shape != (3, 3) or not np.allclose(D, D.T):
                raise ValueError(f"{self.name}: {key} must be a symmetric 3x3 matrix, got {D!r}")
            if np.linalg.eigvalsh(D).min() < -1e-12 * np.abs(D).max():
                raise ValueError(
                    f"{self.name}: {key} is not positive semi-definite (eigenvalues "
                    f"{np.linalg.eigvalsh(D)}); check the coupling terms C12/B12 or the Poisson ratio"
                )
            object.__setattr__(self, key, D)
        if self.weight < 0:
            raise ValueError(f"{self.name}: weight must be >= 0, got {self.weight}")

    @property
    def mass_per_area(self) -> float:
        """Areal mass density [kg/m^2] (weight under standard gravity)."""
        return self.weight / STANDARD_GRAVITY

    @property
    def membrane_scale(self) -> float:
        """Largest membrane rigidity [N/m] (for penalty and time-step estimates)."""
        return float(np.linalg.eigvalsh(self.Dm).max())

    @property
    def bending_scale(self) -> float:
        """Largest bending rigidity [N m]."""
        return float(np.linalg.eigvalsh(self.Db).max())

    def membrane_scaled(self, factor: float) -> Material:
        """This material with the membrane rigidity ``D^m`` multiplied by ``factor`` (> 0) [-]: the model of a
        coarse level matched to a finer mesh's locking number (:mod:`rftstatic.app.levels`)."""
        if not (np.isfinite(factor) and factor > 0):
            raise ValueError(f"{self.name}: a membrane scale must be a finite number > 0, got {factor!r}")
        if factor == 1.0:
            return self
        return replace(self, Dm=self.Dm * factor, name=f"{self.name} (membrane x {factor:.4g})",
                       info={**self.info, "membrane_scale": float(factor)})

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "Dm_N_per_m": self.Dm.tolist(),
            "Db_N_m": self.Db.tolist(),
            "weight_N_per_m2": self.weight,
            **({"bending_hysteresis": self.hysteresis.as_dict()} if self.hysteresis is not None else {}),
            **({"nonlinear_bending": self.nonlinear_bending.as_dict()} if self.nonlinear_bending is not None else {}),
            **({"shear_hysteresis": self.shear_hysteresis.as_dict()} if self.shear_hysteresis is not None else {}),
            **self.info,
        }


def fabric(
    *,
    C_warp: float,
    C_weft: float,
    C_shear: float,
    B_warp: float,
    B_weft: float,
    B_twist: float,
    weight: float,
    C12: float = 0.0,
    B12: float = 0.0,
    warp_angle: float = 0.0,
    name: str = "fabric",
) -> Material:
    """Orthotropic woven fabric (Kang & Yu's rigidities), in SI.

    Parameters
    ----------
    C_warp, C_weft, C_shear, C12 : tensile, shear and coupling rigidity [N/m]
    B_warp, B_weft, B_twist, B12 : bending, twisting and coupling rigidity [N m]
    weight : areal weight [N/m^2]
    warp_angle : angle of the warp from the global X axis [rad]
    """
    T = voigt_rotation(warp_angle)
    Dm = T.T @ _orthotropic(C_warp, C_weft, C12, C_shear) @ T
    Db = T.T @ _orthotropic(B_warp, B_weft, B12, B_twist) @ T
    info = {"warp_angle_deg": float(np.degrees(warp_angle))}
    return Material(Dm=Dm, Db=Db, weight=weight, name=name, info=info)


def isotropic_shell(*, E: float, nu: float, thickness: float, weight: float = 0.0, name="shell") -> Material:
    """Isotropic thin shell: C = E h / (1 - nu^2), D = E h^3 / (12 (1 - nu^2)).

    Parameters
    ----------
    E : Young's modulus [Pa]; nu : Poisson ratio [-]; thickness : [m]; weight : [N/m^2]
    """
    if not (-1.0 < nu < 0.5):
        raise ValueError(f"{name}: Poisson ratio nu must lie in (-1, 0.5), got {nu}")
    if E <= 0 or thickness <= 0:
        raise ValueError(f"{name}: E and thickness must be positive, got E={E}, thickness={thickness}")
    C = E * thickness / (1 - nu**2)
    D = E * thickness**3 / (12 * (1 - nu**2))
    shape = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, (1 - nu) / 2]])
    info = {"E": E, "nu": nu, "thickness": thickness}
    return Material(Dm=C * shape, Db=D * shape, weight=weight, name=name, info=info)


# Kang & Yu (1995) wool, used throughout §4 of the paper, in the paper's units (cm, gf).
WOOL_KANG_YU_CM_GF = dict(
    C_warp=1118.2, C_weft=759.5, C_shear=41.8, B_warp=0.083, B_weft=0.063, B_twist=0.027, weight=0.019
)

PRESETS = {"wool-kang-yu": ("cm-gf-s", WOOL_KANG_YU_CM_GF)}

_FABRIC_KINDS = {
    "C_warp": "line_force", "C_weft": "line_force", "C_shear": "line_force", "C12": "line_force",
    "B_warp": "moment", "B_weft": "moment", "B_twist": "moment", "B12": "moment",
    "weight": "pressure",
}


def fabric_from_units(values: dict, units: UnitSystem, *, warp_angle_deg=0.0, name="fabric") -> Material:
    """Build a :func:`fabric` from rigidities given in ``units`` (e.g. the paper's cm-gf-s)."""
    si = {k: units.to_si(float(v), _FABRIC_KINDS[k]) for k, v in values.items()}
    return fabric(**si, warp_angle=np.radians(warp_angle_deg), name=name)


def preset(name: str, *, warp_angle_deg: float = 0.0, **overrides) -> Material:
    """A named fabric preset (``"wool-kang-yu"``), optionally rotated and with overrides in its units."""
    from rftstatic.units import unit_system

    if name not in PRESETS:
        raise ValueError(f'unknown material preset "{name}"; known: {", ".join(PRESETS)}')
    units_name, values = PRESETS[name]
    return fabric_from_units({**values, **overrides}, unit_system(units_name), warp_angle_deg=warp_angle_deg, name=name)
