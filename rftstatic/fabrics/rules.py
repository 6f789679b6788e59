"""Rules that fill what a lab does not measure, each with its source: a fabric given by lab data alone.

A KES-F laboratory routinely reports the bending rigidity B (warp, weft), the mass per area W and the
thickness T, often nothing else the model needs. A ``[material]`` table with lab keys and no ``preset``
(:mod:`rftstatic.fabrics.lab`) gets every missing quantity from the rules below, and the run's
``summary.json`` lists each filled value with its unit, rule and source (``material.filled``); so does
``python -m rftstatic fabrics --explain``. A value the scene gives (``kes_G``, ``kes_EMT_warp``, ``B_twist``,
``C12``, ...) is always used instead of its rule. B and W are never filled: they are the fabric.

=================  ===========================================  =========================================
quantity           rule (SI inside; any consistent unit)        source
=================  ===========================================  =========================================
C_warp, C_weft     C = 12 B / T^2 (same direction's B; T the    Kirchhoff plate: B = E T^3 / 12, C = E T
                   fabric's thickness, ``kes_T``/``fast_T``)    (Timoshenko & Woinowsky-Krieger 1959,
                                                                Theory of Plates and Shells, ch. 1).
                                                                Rule of thumb: a low estimate of a woven
                                                                fabric's low-load tensile rigidity
C_shear            C_shear = r_G sqrt(B_warp B_weft), r_G the   rule of thumb: shear and bending
                   library wool's ratio 41.8 / 0.0723 =         rigidity rise together with the weave's
                   578 cm^-2 (G = 0.73 gf/(cm deg) at           tightness and yarn count (Alam, Majumdar
                   B = 0.072 gf cm)                             & Ghosh, Indian J. Fibre Text. Res.,
                                                                "Role of fibre, yarn and fabric parameters
                                                                on bending and shear behaviour of plain
                                                                woven fabrics": "a strong degree of
                                                                association"), scaled on the one fabric
                                                                of the library with both measured
                                                                (Kang & Yu 1995)
B_twist            sqrt(B_warp B_weft) / 2                      orthotropic plate with zero Poisson
                                                                ratio, D_66 = D (1 - nu) / 2
                                                                (:func:`rftstatic.fabrics.lab.default_twist`)
C12, B12           0 (no Poisson coupling)                      KES-F and FAST measure no Poisson ratio;
                                                                the paper's wool (Kang & Yu 1995, Sze &
                                                                Zhou 2016 §4) has none
=================  ===========================================  =========================================

Why these and not the alternatives (measured in ``validation/fabric_rules.md``):

- Tensile. The KES-FB1 secant at its maximum load Fm = 500 gf/cm (``kes_EMT``, a typical woven EMT of
  3-8 % gives 6,000-17,000 gf/cm) is the stiffness at loads a thousand times those of drape (a 30 cm
  specimen's own weight pulls with ~0.1-0.3 gf/cm); crimp interchange makes the low-load modulus far
  lower. The paper's wool (C_warp 1118 gf/cm, B_warp 0.083 gf cm) has C/B = 1.35e4 cm^-2, the plate rule's
  value at T = 0.30 mm; wool suitings measure T ~ 0.5-0.8 mm at 0.5 gf/cm^2 (rule of thumb), so the rule
  is about 3 to 7 times softer than that wool. Drape is insensitive to C while C >> B / h^2, and the plate
  rule keeps the RFT6 locking number (C/B) h^2 = 12 (h/T)^2 independent of B (below the warning 1e4 for
  h < 29 T: :data:`rftstatic.model.model.LOCKING_WARN`).
- Shear. No KES-F regression of G on B, W and T with published coefficients could be checked here; the
  ratio rule carries the positive association between the two and is exact for the library wool.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from rftstatic.fabrics.lab import default_twist
from rftstatic.material import PRESETS
from rftstatic.units import unit_system

__all__ = ["FILL_RULES", "FillRule", "SHEAR_PER_BENDING", "fill", "unit_label"]


def _wool_shear_per_bending() -> float:
    """The library wool's C_shear / sqrt(B_warp B_weft) [1/m^2] (Kang & Yu 1995, as in Sze & Zhou 2016 §4)."""
    units_name, w = PRESETS["wool-kang-yu"]
    u = unit_system(units_name)
    return (u.to_si(w["C_shear"], "line_force") / u.to_si(math.sqrt(w["B_warp"] * w["B_weft"]), "moment"))


SHEAR_PER_BENDING = _wool_shear_per_bending()
"""r_G = C_shear / sqrt(B_warp B_weft) of the library wool [1/m^2] (5.78e6 m^-2 = 578 cm^-2)."""

_PLATE = "Kirchhoff plate, B = E T^3/12 and C = E T (Timoshenko & Woinowsky-Krieger 1959, Theory of Plates and Shells)"
_SHEAR = ("rule of thumb: G rises with B (Alam, Majumdar & Ghosh, Indian J. Fibre Text. Res., 'Role of fibre, yarn and "
          "fabric parameters on bending and shear behaviour of plain woven fabrics': 'a strong degree of association'), "
          "scaled on the library wool, Kang & Yu (1995) via Sze & Zhou (2016) §4")
_TWIST = "orthotropic plate with zero Poisson ratio, D66 = D (1 - nu)/2 (rftstatic.fabrics.lab.default_twist)"
_POISSON = "KES-F and FAST measure no Poisson ratio; the paper's wool (Kang & Yu 1995, Sze & Zhou 2016 §4) has none"


@dataclass(frozen=True)
class FillRule:
    """How one model quantity is filled when a lab fabric does not give it.

    Attributes
    ----------
    kind : the quantity's kind for unit conversion (``line_force`` [N/m], ``moment`` [N m])
    needs : the quantities (SI) the rule reads
    value : (si: dict) -> the filled value [SI]
    rule : the formula, in words
    source : where the rule comes from
    """

    kind: str
    needs: tuple
    value: Callable[[dict], float]
    rule: str
    source: str


def _tensile(d: str) -> FillRule:
    return FillRule("line_force", (f"B_{d}", "thickness"), lambda q: 12.0 * q[f"B_{d}"] / q["thickness"] ** 2,
                    f"C_{d} = 12 B_{d} / T^2 (a plate of the fabric's thickness T and bending rigidity; a low estimate "
                    "of a woven fabric's low-load tensile rigidity)", _PLATE)


FILL_RULES = {
    "C_warp": _tensile("warp"),
    "C_weft": _tensile("weft"),
    "C_shear": FillRule("line_force", ("B_warp", "B_weft"),
                        lambda q: SHEAR_PER_BENDING * math.sqrt(q["B_warp"] * q["B_weft"]),
                        f"C_shear = r_G sqrt(B_warp B_weft), r_G = {SHEAR_PER_BENDING * 1e-4:.4g} cm^-2 (the library "
                        "wool's ratio: G = 0.73 gf/(cm deg) at B = 0.0723 gf cm)", _SHEAR),
    "B_twist": FillRule("moment", ("B_warp", "B_weft"), lambda q: default_twist(q["B_warp"], q["B_weft"]),
                        "B_twist = sqrt(B_warp B_weft) / 2 (not measured)", _TWIST),
    "C12": FillRule("line_force", (), lambda q: 0.0, "C12 = 0 (no Poisson coupling)", _POISSON),
    "B12": FillRule("moment", (), lambda q: 0.0, "B12 = 0 (no Poisson coupling)", _POISSON),
}
"""Model quantity -> its :class:`FillRule` (module docstring), in the order they are filled."""

NEEDS_KEYS = {"thickness": ("kes_T", "kes_T [mm] (or fast_T [mm], or thickness in the scene's units)")}
"""A quantity a rule needs -> (the scene key an error names, what the scene may give), for messages."""


def fill(si: dict, only=None) -> dict:
    """Fill the quantities of :data:`FILL_RULES` missing from ``si`` (SI, updated in place).

    Parameters
    ----------
    si : dict
        Model quantities in SI (``B_warp``, ``B_weft`` [N m], ``thickness`` [m], ...).
    only : iterable of str, optional
        Fill only these quantities (default: every rule's).

    Returns
    -------
    dict
        ``{quantity: {"si": value, "kind", "rule", "source"}}`` of the filled ones.

    Raises
    ------
    KeyError
        A rule needs a quantity ``si`` lacks (the key is the missing quantity's name).
    """
    filled = {}
    for q, rule in FILL_RULES.items():
        if q in si or (only is not None and q not in only):
            continue
        missing = [n for n in rule.needs if n not in si]
        if missing:
            raise KeyError(missing[0])
        si[q] = float(rule.value(si))
        filled[q] = {"si": si[q], "kind": rule.kind, "rule": rule.rule, "source": rule.source}
    return filled


def unit_label(units, kind: str) -> str:
    """The unit of a ``kind`` (``line_force``, ``moment``, ``pressure``, ``length``) in a scene's unit system
    (``"gf/cm"`` in cm-gf-s, ``"N/m"`` in SI; ``"-"`` in ``consistent``)."""
    if units.name == "consistent":
        return "-"
    length, force = ("m", "N") if units.name == "SI" else units.name.split("-")[:2]
    return {"line_force": f"{force}/{length}", "moment": f"{force} {length}", "pressure": f"{force}/{length}^2",
            "length": length}[kind]
