"""Fabric data as textile laboratories report it (KES-F, FAST) converted to the model's rigidities.

A ``[material]`` table may give, instead of (or mixed with, for *other* quantities) the model's
rigidities ``C_warp, C_weft, C_shear, B_warp, B_weft, B_twist, weight``, the values a lab measures, in
the units the instruments print, whatever the scene's ``units``:

KES-F (Kawabata 1980; Kawabata & Niwa 1989), key ``kes_*``:

=================  ==================  ===================================================================
key                unit                conversion to the model (cm-gf-s; SI factors in :mod:`rftstatic.units`)
=================  ==================  ===================================================================
kes_B_warp/weft    gf cm^2/cm          B_warp/weft [gf cm] = B  (a bending rigidity per unit width: gf cm^2/cm
                                       *is* gf cm, the paper's unit; 1 gf cm = 9.80665e-5 N m)
kes_G              gf/(cm deg)         C_shear [gf/cm] = G * 180/pi  (per degree of shear angle -> per radian;
                                       the shear angle is the engineering shear strain gamma = 2 e_xy)
kes_EMT_warp/weft  %                   C [gf/cm] = Fm / (EMT/100): the secant at the test's maximum load Fm
                                       (``kes_Fm``, default 500 gf/cm, the standard woven setting)
kes_LT, kes_WT     -, gf cm/cm^2       without EMT: EMT/100 = 2 WT / (LT Fm)  (WT = LT Fm eps_m / 2), then as EMT
kes_W              mg/cm^2             weight [gf/cm^2] = W / 1000  (mass per area under standard gravity)
kes_T              mm                  thickness (self-contact default): T / 10 cm
kes_2HB_warp/weft  gf cm/cm            bending hysteresis: the friction moment per width M0 = 2HB / 2 [gf cm/cm = gf]
                                       of :mod:`rftstatic.element.hysteresis` (the KES-FB2 loop's width is 2HB);
                                       the stick stiffness is ``hysteresis_ratio`` (default 10) times B
kes_2HG            gf/cm               shear hysteresis: the friction shear force per width tau0 = 2HG / 2
                                       [gf/cm] of :mod:`rftstatic.element.shear_friction` (the KES-FB1 loop's
                                       width at +-0.5 deg); stick stiffness ``shear_hysteresis_ratio``
                                       (default 10) times the shear rigidity G (given, or filled by its rule)
kes_2HG5           gf/cm               the loop's width at +-5 deg: the friction's threshold tau5 = 2HG5 / 2
                                       [gf/cm] beyond 5 deg; it grows smoothly from tau0 at 0.5 deg
                                       (:mod:`rftstatic.element.shear_threshold`); needs kes_2HG, >= kes_2HG
=================  ==================  ===================================================================

FAST (SiroFAST: De Boos & Tester 1994, CSIRO report WT92.02), key ``fast_*``:

=================  ==================  ===================================================================
fast_B_warp/weft   uN m                B [N m] = B * 1e-6  (FAST's B = W c^3 per unit width, uN m = uN m^2/m)
fast_E100_warp/weft  %                 C [N/m] = 98.0665 N/m / (E100/100): the secant at 100 gf/cm
fast_G             N/m                 C_shear [N/m] = G  (FAST's G = 123 / EB5, already per radian)
fast_W             g/m^2               weight [N/m^2] = W * 1e-3 * 9.80665
fast_T             mm                  thickness (T2, at 2 gf/cm^2)
=================  ==================  ===================================================================

Feng et al.'s public data set (below; ``ctd_*``, the ClothDrapeTester repository's ``dataset/dataset.csv``):

=================  ==================  ===================================================================
ctd_density        kg/m^2              weight [N/m^2] = density * g (standard gravity 9.80665 m/s^2; the
                                       repository's own ``bending_validation/Main.m`` takes 9.8)
ctd_B_warp/weft    1e-9 N m            B [N m] = value * 1e-9 (column "linear warp/weft[SI*1e9]")
ctd_k2_warp/weft   1e-12 N m^2         nonlinear (softening) bending: k2 [N m^2] = value * 1e-12 (column "nonlinear
                                       warp/weft[SI*1e12]"), the moment B kappa + k2 kappa |kappa| of
                                       :mod:`rftstatic.element.nonlinear_bending` (slope floored at
                                       ``bending_floor`` x B, default 0.2); both or neither; <= 0
=================  ==================  ===================================================================

What the data set's columns are, as far as its repository (commit 24a980c) establishes them (its readme
calls the file "the 618-fabric parameter dataset" and says no more): they are the parameters of the
repository's bending law, ``arcsim/AdaptiveCloth/physics.cpp`` (``principal_curvature_based_bending_*``):
per unit edge length the bending moment is ``M = k1 kappa + k2 kappa^2`` (energy ``(k1 kappa theta/2 + k2
kappa^2 theta/3) l``), with ``k1, k2`` interpolated between warp, bias and weft values by the direction of
principal curvature (``nonlinear_bending_stiff``: cos^2/sin^2 of twice the angle). So "linear warp" is k1
along the warp, a moment per width per curvature [N m], stored x 1e9; "nonlinear" is k2 [N m^2], stored
x 1e12 (negative: the data set's fabrics soften as they bend); "diag" is the bias (45 deg) value. That k1
is the flexural rigidity B of the continuum rests on ``bending_validation/Main.m``, which runs the law
against the cantilever master curve of Romero et al. (2021) with the abscissa ``density * gravity * L^3 /
modulus`` (density [kg/m^2], gravity [m/s^2], L [m]): the dimensionless group rho g L^3 / B of a strip
(Peirce's bending length c = (B / rho g)^(1/3)). How the values were obtained (which tester; the paper's
drape tester and its network, or another instrument) the repository does not say, and the paper was not
read here: they are the published parameters, not necessarily a direct measurement. This module reads
k1 (warp, weft) and the density; the linear model's B is the data set's small-curvature rigidity. k2 enters
only when asked for (``ctd_k2_*``, or ``nonlinear_bending = true`` next to a ``ctd-*`` preset): at the curvature
1/c of the bending length, k2 kappa / k1 over the 618 rows is, warp and weft, -0.41 / -0.36 at the 5th
percentile, -0.13 / -0.14 at the median, -0.05 / -0.04 at the 95th (the data set's own moment at that curvature
is that fraction below k1 kappa; ``tools/select_ctd_fabrics.py`` prints these). Six rows (three distinct fabrics)
have a positive k2 along warp or weft (+2693148.6, +50701.9 warp; +1755.9 weft; k2 kappa / k1 = +1.3 at 1/c for
the first): a stiffening law the model refuses (:mod:`rftstatic.element.nonlinear_bending`: give 0 for such a
direction). The largest softening |k2| is 1122487.5 (k2 kappa / k1 = -0.72 at 1/c); ``ctd_k2_*`` is bounded at
-1e7 (a factor 9 beyond). What it drops: the bias k1 and k2 (values of the repository's interpolation, not of a plate
theory: turning them into a twisting rigidity would need the plate's compliance rotation, which the
repository's law does not follow).

What the model drops (bending hysteresis 2HB, nonlinear bending k2 and shear hysteresis 2HG, 2HG5 are options,
``kes_2HB_*``, ``ctd_k2_*``, ``kes_2HG`` and ``kes_2HG5`` above): the nonlinear shear curve beyond the small angles
where G is measured
(0.5-5 deg), the tensile curve's nonlinearity (the secant at Fm replaces it: crimp interchange makes the initial
modulus far lower, so a drape that stretches little is too stiff in tension; drape is insensitive to it while C >> B /
h^2), the compression and surface data (LC, WC, RC, MIU, MMD, SMD), and anything not measured: Poisson coupling (C12 =
B12 = 0) and the twisting rigidity, which defaults to ``B_twist = sqrt(B_warp B_weft) / 2`` (the orthotropic plate
with zero Poisson ratio, M_xy = D (1 - nu)/2 * 2 k_xy; Kang & Yu's wool has 0.37 instead of 0.5 of the mean) unless
the scene gives ``B_twist``. A fabric given by lab data and no preset gets every quantity it lacks (tensile, shear,
twist, Poisson) by the stated rules of :mod:`rftstatic.fabrics.rules`, each listed in the run's summary
(``material.filled``).

Range checks (:data:`RANGES`): a value outside them is almost surely a slip of unit or decimal point.
What the bounds rest on (searched for through public material on 2026-12-02; nothing entered from memory):

- bending rigidity and weight: the public data set of Feng, Huang, Xu & Wang (2022), "Learning-Based Bending
  Stiffness Parameter Estimation by a Drape Tester", ACM Trans. Graph. 41(6) (SIGGRAPH Asia),
  doi:10.1145/3550454.3555464, file ``dataset/dataset.csv`` of github.com/DrapeTester/ClothDrapeTester
  (commit 24a980c): 618 fabrics (251 distinct rows), columns "density[kg.m-2]" and "linear
  warp/weft[SI*1e9]" (the ``ctd_*`` keys above: how the data set's values were obtained its repository does
  not say). Read as N m per width x 1e9 (dimensionally the modulus rho g L^3 / gamma of the repository's
  ``GenerateModulusForSampling.m``; the paper itself was not read), they span
  B 0.223-265.7 uN m (0.00227-2.71 gf cm^2/cm) and 15.3-870.3 g/m^2 (1.53-87.0 mg/cm^2). The bounds lie
  a factor 4.5-7.5 beyond that span (tests/fabrics/test_lab.py checks the extremes are inside);
- the paper's wool (B 0.083/0.063 gf cm, G 0.73 gf/(cm deg), W 19 mg/cm^2) is inside every bound;
- UNVERIFIED (no table found through the tools; Kawabata's charts, the SiroFAST manual and its control
  chart could not be read): the bounds of G, 2HG, 2HG5 (searched again on 2026-12-05: the public KES parameter
  lists give their definitions, 2HG at 0.5 deg and 2HG5 at 5 deg in gf/cm, but no readable table of values), EMT, LT, WT, Fm, thickness, FAST E100 and G. They are kept
  loose (two to three decades) and only catch gross slips; a fabric outside them is refused by name, so
  widen a bound here (with its source) rather than bend a measured value.

The FAST relations above (B in uN m, E100 at 100 gf/cm, G = 123/EB5 in N/m) are quoted after De Boos &
Tester (1994), which could not be read here: unverified against the manual. A public note that
summarises Kuijpers, Luible-Baer & Gong (2020), "The measurement of fabric properties for virtual
simulation - a critical review", IEEE SA Industry Connections report STDVA24083 (its Table 2), gives the
same definitions and KES-FB1's maximum load Fm = 500 gf/cm (50 for knits), the default of ``kes_Fm``; only
that report's title page could be read here. The KES citations (Kawabata 1980; Kawabata & Niwa 1989) are
likewise not checked against their text.
"""

from __future__ import annotations

import math

from rftstatic.errors import ParameterError
from rftstatic.units import STANDARD_GRAVITY, unit_system

__all__ = ["K2_RANGE", "LAB_KEYS", "RANGES", "RANGE_EVIDENCE", "QUANTITY_KEYS", "check_ranges", "default_twist",
           "lab_to_si", "range_source", "sources_of"]

GF = STANDARD_GRAVITY * 1e-3
"""One gram-force [N]."""

LAB_KEYS = {
    "kes_B_warp": ("gf cm^2/cm", "KES-FB2 bending rigidity, warp (bending about the weft)"),
    "kes_B_weft": ("gf cm^2/cm", "KES-FB2 bending rigidity, weft"),
    "kes_G": ("gf/(cm deg)", "KES-FB1 shear rigidity"),
    "kes_EMT_warp": ("%", "KES-FB1 extension at the maximum load Fm, warp"),
    "kes_EMT_weft": ("%", "KES-FB1 extension at Fm, weft"),
    "kes_LT_warp": ("-", "KES-FB1 tensile linearity, warp"),
    "kes_LT_weft": ("-", "KES-FB1 tensile linearity, weft"),
    "kes_WT_warp": ("gf cm/cm^2", "KES-FB1 tensile energy, warp"),
    "kes_WT_weft": ("gf cm/cm^2", "KES-FB1 tensile energy, weft"),
    "kes_Fm": ("gf/cm", "KES-FB1 maximum tensile load (default 500)"),
    "kes_W": ("mg/cm^2", "KES mass per area"),
    "kes_T": ("mm", "KES-FB3 thickness at 0.5 gf/cm^2"),
    "kes_2HB_warp": ("gf cm/cm", "KES-FB2 bending hysteresis (loop width at +-1 /cm), warp"),
    "kes_2HB_weft": ("gf cm/cm", "KES-FB2 bending hysteresis, weft"),
    "kes_2HG": ("gf/cm", "KES-FB1 shear hysteresis (loop width at +-0.5 deg)"),
    "kes_2HG5": ("gf/cm", "KES-FB1 shear hysteresis (loop width at +-5 deg): the friction threshold grows from "
                 "2HG / 2 at 0.5 deg to 2HG5 / 2 at 5 deg"),
    "fast_B_warp": ("uN m", "FAST-2 bending rigidity, warp"),
    "fast_B_weft": ("uN m", "FAST-2 bending rigidity, weft"),
    "fast_E100_warp": ("%", "FAST-3 extensibility at 100 gf/cm, warp"),
    "fast_E100_weft": ("%", "FAST-3 extensibility at 100 gf/cm, weft"),
    "fast_G": ("N/m", "FAST shear rigidity 123/EB5"),
    "fast_W": ("g/m^2", "FAST mass per area"),
    "fast_T": ("mm", "FAST-1 thickness T2"),
    "ctd_B_warp": ("1e-9 N m", 'Feng et al. (2022) data set, column "linear warp[SI*1e9]" (k1 along the warp)'),
    "ctd_B_weft": ("1e-9 N m", 'Feng et al. (2022) data set, column "linear weft[SI*1e9]"'),
    "ctd_density": ("kg/m^2", 'Feng et al. (2022) data set, column "density[kg.m-2]" (mass per area)'),
    "ctd_k2_warp": ("1e-12 N m^2", 'Feng et al. (2022) data set, column "nonlinear warp[SI*1e12]" (k2 along the '
                    "warp: softening bending, <= 0)"),
    "ctd_k2_weft": ("1e-12 N m^2", 'Feng et al. (2022) data set, column "nonlinear weft[SI*1e12]"'),
}
"""Lab keys of ``[material]``: (unit as printed by the instrument, meaning)."""

RANGES = {
    "kes_B_warp": (0.0005, 20.0), "kes_B_weft": (0.0005, 20.0), "kes_G": (0.02, 20.0),
    "kes_EMT_warp": (0.2, 60.0), "kes_EMT_weft": (0.2, 60.0), "kes_LT_warp": (0.2, 1.5), "kes_LT_weft": (0.2, 1.5),
    "kes_WT_warp": (0.5, 100.0), "kes_WT_weft": (0.5, 100.0), "kes_Fm": (5.0, 1000.0),
    "kes_W": (0.3, 500.0), "kes_T": (0.05, 10.0), "kes_2HB_warp": (0.0005, 20.0), "kes_2HB_weft": (0.0005, 20.0),
    "kes_2HG": (0.01, 50.0), "kes_2HG5": (0.01, 100.0),
    "fast_B_warp": (0.05, 2000.0), "fast_B_weft": (0.05, 2000.0), "fast_E100_warp": (0.1, 60.0),
    "fast_E100_weft": (0.1, 60.0), "fast_G": (2.0, 2000.0), "fast_W": (3.0, 5000.0), "fast_T": (0.05, 10.0),
}
RANGES.update({"ctd_B_warp": tuple(b * 1e3 for b in RANGES["fast_B_warp"]),   # uN m -> 1e-9 N m
               "ctd_B_weft": tuple(b * 1e3 for b in RANGES["fast_B_weft"]),
               "ctd_density": tuple(w * 1e-3 for w in RANGES["fast_W"])})      # g/m^2 -> kg/m^2
"""Plausible bounds (inclusive) of each lab key, in its lab unit (module docstring: B and W from a public
618-fabric data set; the others unverified and loose)."""

K2_RANGE = (-1e7, 0.0)
"""Bounds (inclusive) of ``ctd_k2_*`` [1e-12 N m^2]: softening only (module docstring: the data set's largest
|k2| is 1.12e6; its six positive values are refused)."""

RANGE_EVIDENCE = {
    "source": "Feng, Huang, Xu & Wang (2022), ACM TOG 41(6), doi:10.1145/3550454.3555464; "
              "github.com/DrapeTester/ClothDrapeTester dataset/dataset.csv (commit 24a980c), 618 fabrics",
    "B_uNm": (0.223, 265.7254), "W_g_per_m2": (15.3, 870.3),
}
"""The measured span the B and W bounds were set against (module docstring)."""

QUANTITY_KEYS = {
    "B_warp": ("kes_B_warp", "fast_B_warp", "ctd_B_warp"),
    "B_weft": ("kes_B_weft", "fast_B_weft", "ctd_B_weft"),
    "C_shear": ("kes_G", "fast_G"),
    "C_warp": ("kes_EMT_warp", "kes_WT_warp", "fast_E100_warp"),
    "C_weft": ("kes_EMT_weft", "kes_WT_weft", "fast_E100_weft"),
    "weight": ("kes_W", "fast_W", "ctd_density"),
    "thickness": ("kes_T", "fast_T"),
    "M0_warp": ("kes_2HB_warp",),
    "M0_weft": ("kes_2HB_weft",),
    "bending_k2_warp": ("ctd_k2_warp",),
    "bending_k2_weft": ("ctd_k2_weft",),
    "shear_tau0": ("kes_2HG",),
    "shear_tau5": ("kes_2HG5",),
}
"""Model quantity -> the lab keys that give it (one source per quantity)."""

_CM_GF = unit_system("cm-gf-s")


def sources_of(values: dict) -> dict:
    """``{quantity: [keys]}``: the keys of ``values`` that give each model quantity (the model key itself
    and its lab keys), for the quantities given at all."""
    out = {}
    for q, lab in QUANTITY_KEYS.items():
        keys = [k for k in (q, *lab) if k in values]
        if q.startswith("C_w"):  # LT goes with WT: one source
            keys = [k for k in keys if not k.startswith("kes_LT")]
        if keys:
            out[q] = keys
    return out


def range_source(key: str) -> str:
    """Where the bounds of :data:`RANGES` ``[key]`` come from (module docstring), for messages."""
    if key.split("_")[1] in ("B", "W", "density"):
        return ("bounds a factor 4.5-7.5 beyond the span of the 618 fabrics of Feng et al. (2022), ACM TOG 41(6), "
                "data set github.com/DrapeTester/ClothDrapeTester: B 0.0023-2.71 gf cm^2/cm, W 1.53-87.0 mg/cm^2")
    return "a loose bound (two to three decades) that only catches slips of unit or decimal point; unverified"


def check_ranges(values: dict) -> None:
    """ParameterError(key, ...) for a lab value that is not a number inside :data:`RANGES`; a zero or negative
    value is named as such. The message gives the range and where it comes from (:func:`range_source`)."""
    for key, v in values.items():
        if key in ("ctd_k2_warp", "ctd_k2_weft"):
            _check_k2(key, v)
        if key not in RANGES:
            continue
        lo, hi = RANGES[key]
        unit, meaning = LAB_KEYS[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ParameterError(key, f"{v!r} is not a finite number: give the {meaning} in {unit}")
        if v <= 0:
            raise ParameterError(key, f"{v!r} {unit} must be > 0 (a {meaning}); real fabrics lie in [{lo:g}, {hi:g}] "
                                 f"{unit} ({range_source(key)})")
        if not lo <= v <= hi:
            raise ParameterError(key, f"{v!r} {unit} is outside the plausible range [{lo:g}, {hi:g}] {unit} of "
                                 f"a {meaning} ({range_source(key)}); check the unit and the decimal point")


def _check_k2(key: str, v) -> None:
    """ParameterError unless the data set's k2 ``v`` [1e-12 N m^2] is a finite number in :data:`K2_RANGE`."""
    lo, hi = K2_RANGE
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ParameterError(key, f"{v!r} is not a finite number: give the {LAB_KEYS[key][1]} in 1e-12 N m^2")
    if v > hi:
        raise ParameterError(key, f"{v!r} 1e-12 N m^2 is > 0: a stiffening k2 is refused (six rows of the data set "
                             "have one, up to k2 kappa / k1 = +1.3 at the bending length's curvature, which the "
                             "stable time step, estimated from B, does not see); give 0 for this direction (the "
                             "linear law)")
    if v < lo:
        raise ParameterError(key, f"{v!r} 1e-12 N m^2 is outside [{lo:g}, 0] (the data set's largest |k2| is "
                             "1.12e6 among 618 fabrics); check the unit (1e-12 N m^2) and the decimal point")


def _tensile(values: dict, d: str) -> tuple[float, dict] | None:
    """Secant tensile rigidity [N/m] in direction ``d`` (warp/weft) from the lab keys, and its record."""
    if f"kes_EMT_{d}" in values or f"kes_WT_{d}" in values:
        fm = float(values.get("kes_Fm", 500.0))
        if f"kes_EMT_{d}" in values:
            strain = values[f"kes_EMT_{d}"] / 100.0
            rule = f"secant at Fm = {fm:g} gf/cm: C = Fm / (EMT/100)"
        else:
            if f"kes_LT_{d}" not in values:
                raise ParameterError(f"kes_WT_{d}", f"{values[f'kes_WT_{d}']!r}: the tensile energy needs "
                                     f"kes_LT_{d} (linearity) or kes_EMT_{d} to give a strain")
            strain = 2.0 * values[f"kes_WT_{d}"] / (values[f"kes_LT_{d}"] * fm)
            rule = f"secant at Fm = {fm:g} gf/cm with EMT/100 = 2 WT / (LT Fm)"
        return fm * GF / 1e-2 / strain, {"rule": rule, "strain_at_Fm": strain}
    if f"fast_E100_{d}" in values:
        strain = values[f"fast_E100_{d}"] / 100.0
        return 100.0 * GF / 1e-2 / strain, {"rule": "secant at 100 gf/cm: C = 98.0665 N/m / (E100/100)",
                                            "strain_at_100gf_per_cm": strain}
    return None


def default_twist(B_warp: float, B_weft: float) -> float:
    """Twisting rigidity when no lab measures it: ``sqrt(B_warp B_weft) / 2`` (any consistent unit)."""
    return 0.5 * math.sqrt(B_warp * B_weft)


def lab_to_si(values: dict) -> tuple[dict, dict]:
    """The model quantities the lab keys of ``values`` give, in SI, and a record of the conversion.

    Parameters
    ----------
    values : dict
        ``[material]`` entries; only the keys of :data:`LAB_KEYS` are read (each in its lab unit).

    Returns
    -------
    si : dict
        ``{quantity: value}`` for the quantities given: ``B_warp, B_weft`` [N m], ``C_shear, C_warp,
        C_weft`` [N/m], ``weight`` [N/m^2], ``thickness`` [m], ``M0_warp, M0_weft`` [N m/m = N],
        ``bending_k2_warp, bending_k2_weft`` [N m^2], ``shear_tau0`` (2HG / 2) and ``shear_tau5`` (2HG5 / 2)
        [N/m].
    record : dict
        ``{quantity: {"from": key, "value": lab value, "unit": lab unit, "rule": ...}}``.

    Raises
    ------
    ParameterError
        A value outside :data:`RANGES` (key = the lab key).
    """
    lab = {k: v for k, v in values.items() if k in LAB_KEYS}
    check_ranges(lab)
    si, record = {}, {}

    def put(q, key, value_si, rule, **extra):
        si[q] = value_si
        record[q] = {"from": key, "value": lab[key], "unit": LAB_KEYS[key][0], "rule": rule, **extra}

    for d in ("warp", "weft"):
        if f"kes_B_{d}" in lab:
            put(f"B_{d}", f"kes_B_{d}", _CM_GF.to_si(lab[f"kes_B_{d}"], "moment"), "gf cm^2/cm = gf cm (per width)")
        if f"fast_B_{d}" in lab:
            put(f"B_{d}", f"fast_B_{d}", lab[f"fast_B_{d}"] * 1e-6, "uN m = 1e-6 N m (per width)")
        if f"ctd_B_{d}" in lab:
            put(f"B_{d}", f"ctd_B_{d}", lab[f"ctd_B_{d}"] * 1e-9, "1e-9 N m (per width): the data set's k1")
        tensile = _tensile(lab, d)
        if tensile is not None:
            key = next(k for k in (f"kes_EMT_{d}", f"kes_WT_{d}", f"fast_E100_{d}") if k in lab)
            put(f"C_{d}", key, tensile[0], tensile[1].pop("rule"), **tensile[1])
    if "kes_G" in lab:
        put("C_shear", "kes_G", _CM_GF.to_si(lab["kes_G"] * 180.0 / math.pi, "line_force"),
            "per degree -> per radian: C_shear = G * 180/pi")
    if "fast_G" in lab:
        put("C_shear", "fast_G", float(lab["fast_G"]), "N/m, per radian (123/EB5)")
    if "kes_W" in lab:
        put("weight", "kes_W", lab["kes_W"] * 1e-2 * STANDARD_GRAVITY, "mg/cm^2 = 1e-2 kg/m^2, times g")
    if "fast_W" in lab:
        put("weight", "fast_W", lab["fast_W"] * 1e-3 * STANDARD_GRAVITY, "g/m^2 = 1e-3 kg/m^2, times g")
    if "ctd_density" in lab:
        put("weight", "ctd_density", lab["ctd_density"] * STANDARD_GRAVITY, "kg/m^2 times g")
    for key in ("kes_T", "fast_T"):
        if key in lab:
            put("thickness", key, lab[key] * 1e-3, "mm")
    for d in ("warp", "weft"):
        if f"ctd_k2_{d}" in lab:
            put(f"bending_k2_{d}", f"ctd_k2_{d}", lab[f"ctd_k2_{d}"] * 1e-12, "1e-12 N m^2: the data set's k2 "
                "(moment per width per curvature^2)")
        if f"kes_2HB_{d}" in lab:
            put(f"M0_{d}", f"kes_2HB_{d}", 0.5 * lab[f"kes_2HB_{d}"] * GF,
                "friction moment per width M0 = 2HB / 2; gf cm/cm = gf = 9.80665e-3 N")
    if "kes_2HG" in lab:
        put("shear_tau0", "kes_2HG", 0.5 * lab["kes_2HG"] * GF / 1e-2,
            "friction shear force per width tau0 = 2HG / 2; gf/cm = 0.980665 N/m")
    if "kes_2HG5" in lab:
        put("shear_tau5", "kes_2HG5", 0.5 * lab["kes_2HG5"] * GF / 1e-2,
            "friction shear force per width beyond 5 deg tau5 = 2HG5 / 2, grown to from tau0 between 0.5 and 5 deg "
            "(rftstatic.element.shear_threshold); gf/cm = 0.980665 N/m")
    return si, record
