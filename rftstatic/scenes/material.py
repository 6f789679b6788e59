"""A scene's ``[material]`` table -> :class:`~rftstatic.material.Material` (SI), and its summary record.

A fabric is given by a library preset (:data:`rftstatic.fabrics.library.FABRICS`), by the model's
rigidities in the scene's units, by lab values (KES-F ``kes_*``, FAST ``fast_*``: :mod:`rftstatic.fabrics.lab`,
each in its instrument's unit), or a mixture of the last two for *different* quantities. Two keys for the
same quantity in one table (``B_warp`` and ``kes_B_warp``) are a scene error naming both.

A fabric given by lab data (no preset) needs its bending rigidities and weight (``kes_B_warp``, ``kes_B_weft``,
``kes_W``; the kes_B without its kes_W is refused by name); every other quantity it does not give is filled by
the stated rules of :mod:`rftstatic.fabrics.rules` (tensile from B and the thickness ``kes_T``, shear,
twist, Poisson), listed in the summary's ``material.filled`` with unit, rule and source.

A preset never lends values to lab data: lab keys next to ``preset`` are refused (the message says how to give
the lab fabric alone: ``--set "material={kes_B_warp=0.05, kes_B_weft=0.04, kes_W=15.0, kes_T=0.5}"``
replaces the whole table). A *model* key next to a preset (``--set material.C_warp=900``, what ``fit``
varies) changes that one value of the preset: the fabric is labelled "(modified)" and the summary lists
the changed keys (``material.changed``).

Nonlinear (softening) bending (:mod:`rftstatic.element.nonlinear_bending`: Feng et al.'s M = B kappa + k2 kappa
|kappa|, slope floored at ``bending_floor`` x B) is an option: ``bending_k2_warp``, ``bending_k2_weft`` [force
length^2 in the scene's units: moment per width per curvature^2; gf cm^2 in cm-gf-s], or the data set's
``ctd_k2_warp``, ``ctd_k2_weft`` [1e-12 N m^2], both directions or neither (0: that direction stays linear), <= 0
(a stiffening k2 is refused); ``bending_floor`` [-] in (0, 1), default 0.2; a ``ctd-*`` preset carries the k2 of
its data row with ``nonlinear_bending = true`` (opt-in: a preset's results do not change otherwise).

Bending hysteresis (``kes_2HB_warp``, ``kes_2HB_weft``, both or neither; ``hysteresis_ratio``) and shear hysteresis
(``kes_2HG`` [gf/cm], :mod:`rftstatic.element.shear_friction`; ``shear_hysteresis_ratio`` [-] in [1, 1e4], default 10:
the stick stiffness over the fabric's G; ``kes_2HG5`` [gf/cm], with ``kes_2HG`` and >= it: the friction grows to
2HG5 / 2 at 5 deg, :mod:`rftstatic.element.shear_threshold`) are options of a lab fabric.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from rftstatic import material as mat
from rftstatic.errors import ParameterError
from rftstatic.fabrics.lab import LAB_KEYS, QUANTITY_KEYS, lab_to_si, sources_of
from rftstatic.fabrics.library import FABRICS, bending_lengths, nonlinear_values
from rftstatic.fabrics.rules import NEEDS_KEYS, fill, unit_label
from rftstatic.scenes.ranges import SHEET_RANGE_M
from rftstatic.units import UnitSystem, unit_system

__all__ = ["build_material", "material_summary", "FABRIC_KEYS"]

NONLINEAR_KEYS = ("bending_k2_warp", "bending_k2_weft", "bending_floor", "nonlinear_bending")
"""Keys of nonlinear bending besides the lab keys ``ctd_k2_*`` (module docstring)."""

FABRIC_KEYS = (set(mat._FABRIC_KINDS) | {"thickness", "hysteresis_ratio", "shear_hysteresis_ratio"} | set(NONLINEAR_KEYS)
               | set(LAB_KEYS))
"""Keys of a fabric ``[material]`` table besides ``preset``, ``kind`` and ``warp_angle``."""

_REQUIRED = ("C_warp", "C_weft", "C_shear", "B_warp", "B_weft", "weight")
_POSITIVE = ("C_warp", "C_weft", "C_shear", "B_warp", "B_weft", "B_twist")
"""Rigidities a fabric needs positive (the couplings C12, B12 may have either sign, within a positive
semi-definite matrix)."""

MAX_E_PA = 1e13
"""Largest Young's modulus of an isotropic shell [Pa]: ten times diamond's (1.2e12 Pa), the stiffest solid."""

MAX_THICKNESS_M = SHEET_RANGE_M[1]
"""Largest thickness [m] before the mesh is known (the largest sheet): E t^3 stays finite. The scene's model
then bounds it by the sheet itself (:func:`rftstatic.scenes.ranges.check_thickness`)."""


def _to_si(values: dict, units: UnitSystem) -> tuple[dict, dict]:
    """SI quantities and the lab record of one set of fabric ``values`` (model keys in ``units``)."""
    for q, keys in sources_of(values).items():
        if len(keys) > 1:
            shown = " and ".join(f"{k} = {values[k]!r}" for k in keys)
            raise ParameterError(keys[1], f"{shown} both give {q}; give one of them")
    si, record = lab_to_si(values)
    for key, kind in mat._FABRIC_KINDS.items():
        if key in values:
            si[key] = units.to_si(float(values[key]), kind)
    if "thickness" in values:
        si["thickness"] = units.to_si(float(values["thickness"]), "length")
    for key in ("bending_k2_warp", "bending_k2_weft"):
        if key in values:
            v = values[key]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v > 0:
                raise ParameterError(key, f"{v!r} must be a finite number <= 0 (Feng et al.'s k2: moment per width "
                                     "per curvature^2 in the scene's units, force length^2; softening only: a "
                                     "stiffening k2 > 0 is refused, rftstatic.element.nonlinear_bending; 0 keeps "
                                     "the direction linear)")
            si[key] = units.to_si(float(v), "moment_length")
    return si, record


_LAB_PAIRS = {"kes": ("kes_B_warp", "kes_B_weft", "kes_W"), "fast": ("fast_B_warp", "fast_B_weft", "fast_W"),
              "ctd": ("ctd_B_warp", "ctd_B_weft", "ctd_density")}
"""Per instrument: the bending rigidities and the mass per area a lab fabric gives together."""


def _check_lab_fabric(m: dict, si: dict) -> None:
    """ParameterError naming the missing key of a lab fabric: a lab bending rigidity without the other
    direction's, or without a weight (the drape follows the bending length c = (B/W)^(1/3))."""
    for warp, weft, weight in _LAB_PAIRS.values():
        given = [k for k in (warp, weft) if k in m]
        if not given:
            continue
        shown = f"{given[0]} = {m[given[0]]!r}"
        for key, q in ((weft, "B_weft"), (warp, "B_warp")):
            if q not in si:
                raise ParameterError(key, f"missing: {shown} is given without {key} ({LAB_KEYS[key][0]}); a fabric "
                                     "needs its bending rigidity along both warp and weft")
        if "weight" not in si:
            raise ParameterError(weight, f"missing: {shown} is given without {weight} ({LAB_KEYS[weight][0]}, "
                                 f"{LAB_KEYS[weight][1]}); the drape follows the bending length (B/W)^(1/3), so the "
                                 "bending rigidity needs the mass per area of the same fabric")


def _preset(name: str, lab_given: list) -> tuple[dict, dict, dict]:
    """A library preset's SI values, lab record and filled record (its ``derived`` values by its rule)."""
    if name not in FABRICS:
        raise ParameterError("preset", f'"{name}" is not a fabric of the library; known: {", ".join(FABRICS)} '
                             "(python -m rftstatic fabrics lists them)")
    if lab_given:
        shown = ", ".join(lab_given)
        raise ParameterError(lab_given[0], f'lab data ({shown}) next to preset = "{name}": the preset would lend '
                             "the values the lab data do not give to a fabric it does not describe. Give the lab "
                             "fabric without the preset (the missing values are then filled by stated rules: python "
                             "-m rftstatic fabrics --explain), e.g. --set \"material={kes_B_warp=0.05, kes_B_weft=0.04, "
                             "kes_W=15.0, kes_T=0.5}\" replaces the table; or change the preset's own rigidities "
                             "(B_warp, C_warp, weight, ... in the scene's units)")
    fab = FABRICS[name]
    si, record = _to_si(fab.values, unit_system(fab.units))
    derived, _ = _to_si(fab.derived, unit_system(fab.units))
    filled = {}
    for q in sorted(set(derived) - set(si)):  # what the source does not give, by the preset's stated rule
        si[q] = derived[q]
        filled[q] = {"si": si[q], "kind": mat._FABRIC_KINDS[q], "rule": fab.derived_rule,
                     "source": f"preset {name}: {fab.short_source or fab.source}"}
    return si, record, filled


def _fabric(scene, m: dict, angle: float) -> mat.Material:
    name = m.pop("preset", None)
    foreign = sorted(set(m) - FABRIC_KEYS - {"kind"})
    if foreign:
        where = f'next to preset = "{name}" (a fabric' if name else "to a fabric ("
        raise scene.error(f"material.{foreign[0]}", f"does not apply {where}; it takes {', '.join(sorted(FABRIC_KEYS))} "
                          'and warp_angle); remove it, or give kind = "isotropic" with E, nu and thickness')
    if name is not None and "kind" in m:
        raise scene.error("material.kind", f'does not apply next to preset = "{name}" (a preset is a fabric '
                          "with its rigidities); remove kind, or the preset and give the rigidities")
    m.pop("kind", None)
    lab_given = sorted(k for k in m if k in LAB_KEYS)
    si, record, filled = _preset(name, lab_given) if name is not None else ({}, {}, {})
    if _opted_in(m):
        k2_si, k2_record = _preset_k2(name)
        si.update(k2_si)
        record.update(k2_record)
    own_si, own_record = _to_si(m, scene.units)
    for q in own_si:  # a scene key replaces the preset's value of its quantity
        record.pop(q, None)
        filled.pop(q, None)
    si.update(own_si)
    record.update(own_record)
    if lab_given:
        _check_lab_fabric(m, si)
        try:
            filled.update(fill(si))
        except KeyError as exc:
            key, given = NEEDS_KEYS.get(exc.args[0], (exc.args[0], exc.args[0]))
            raise ParameterError(key, f"missing: the rule that fills {', '.join(q for q in ('C_warp', 'C_weft') if q not in si)} "
                                 f"(python -m rftstatic fabrics --explain) needs the fabric's {exc.args[0]}: give {given}, "
                                 "or the tensile data (kes_EMT_warp and kes_EMT_weft, or C_warp and C_weft)") from None
    missing = [q for q in _REQUIRED if q not in si]
    if missing:
        options = ", ".join(f"{q} (or {' / '.join(QUANTITY_KEYS[q])})" for q in missing)
        raise scene.error("material", f"a fabric needs {options}; or a preset (python -m rftstatic fabrics), or lab "
                          "data (kes_B_warp, kes_B_weft, kes_W, kes_T: the rest filled by stated rules)")
    filled.update(fill(si, only=("B_twist", "C12", "B12")))
    for key in _POSITIVE:
        if key in m and not m[key] > 0:
            kind = "tensile or shear" if key[0] == "C" else "bending or twisting"
            raise ParameterError(key, f"{m[key]!r} must be > 0 (a fabric's {kind} rigidity, scene units)")
    if name is None and lab_given:
        label = "lab fabric (" + ", ".join(f"{k} {m[k]:g}" for k in lab_given[:4]) + (", ..." if len(lab_given) > 4
                                                                                     else "") + ")"
    else:
        label = (name or "fabric") + (" (modified)" if name and m else "")
    try:
        material = mat.fabric(**{k: si[k] for k in mat._FABRIC_KINDS if k in si}, warp_angle=np.radians(angle),
                              name=label)
    except ValueError as exc:  # a matrix not positive semi-definite: its coupling term is too large
        coupling = "C12" if "Dm" in str(exc) else "B12"
        if coupling in m:
            raise ParameterError(coupling, f"{m[coupling]!r} is too large for the other rigidities: {exc}") from None
        raise
    if "thickness" in si:
        material.info["thickness"] = si["thickness"]
    material = _with_shear_hysteresis(_with_nonlinear(_with_hysteresis(material, m, si), m, si), m, si)
    for q, rec in record.items():
        rec["si"] = si[q]
    if record:
        material.info["lab"] = record
    material.info["filled"] = filled
    if name is not None:
        material.info["preset"] = name
        material.info["changed"] = sorted(m)
    return material


_SUMMARY_KINDS = {**mat._FABRIC_KINDS, "thickness": "length", "M0_warp": "force", "M0_weft": "force",
                  "bending_k2_warp": "moment_length", "bending_k2_weft": "moment_length", "shear_tau0": "line_force",
                  "shear_tau5": "line_force"}
"""Unit kind of every quantity a lab record may convert (for the summary in scene units)."""


def _with_hysteresis(material: mat.Material, m: dict, si: dict) -> mat.Material:
    """``material`` with the bending hysteresis of ``kes_2HB_warp`` and ``kes_2HB_weft`` (both or neither; M0 =
    2HB / 2 in ``si``) and ``hysteresis_ratio`` (:class:`rftstatic.material.BendingHysteresis`)."""
    given = [d for d in ("warp", "weft") if f"M0_{d}" in si]
    if not given:
        if "hysteresis_ratio" in m:
            raise ParameterError("hysteresis_ratio", f"{m['hysteresis_ratio']!r} is given without the hysteresis "
                                 "itself: give kes_2HB_warp and kes_2HB_weft [gf cm/cm], or remove hysteresis_ratio")
        return material
    if len(given) == 1:
        other = "weft" if given[0] == "warp" else "warp"
        raise ParameterError(f"kes_2HB_{other}", f"missing: kes_2HB_{given[0]} = {m[f'kes_2HB_{given[0]}']!r} is given "
                             f"without kes_2HB_{other} [gf cm/cm]; bending hysteresis needs both directions (0.0005 "
                             "for a direction without measurable hysteresis)")
    ratio = m.get("hysteresis_ratio", 10.0)
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not 1.0 <= ratio <= 1e4:
        raise ParameterError("hysteresis_ratio", f"{ratio!r} must be a number in [1, 1e4] (the friction element's "
                             "stick stiffness over B; default 10)")
    return replace(material, hysteresis=mat.BendingHysteresis(si["M0_warp"], si["M0_weft"], float(ratio)))


def _with_shear_hysteresis(material: mat.Material, m: dict, si: dict) -> mat.Material:
    """``material`` with the shear hysteresis of ``kes_2HG`` (tau0 = 2HG / 2 in ``si``) and ``shear_hysteresis_ratio``
    (:class:`rftstatic.material.ShearHysteresis`) and, with ``kes_2HG5``, the threshold tau5 = 2HG5 / 2 beyond 5 deg;
    ``kes_2HG5`` or the ratio without ``kes_2HG`` are refused, and so is 2HG5 < 2HG (a threshold that falls as the
    fabric shears: KES data have 2HG5 >= 2HG)."""
    if "shear_tau0" not in si:
        for key in ("kes_2HG5", "shear_hysteresis_ratio"):
            if key in m:
                raise ParameterError("kes_2HG", f"missing: {key} = {m[key]!r} is given without kes_2HG [gf/cm], the "
                                     "shear loop's width at +-0.5 deg that sets the friction (give it, or remove "
                                     f"{key})")
        return material
    ratio = m.get("shear_hysteresis_ratio", 10.0)
    if isinstance(ratio, bool) or not isinstance(ratio, (int, float)) or not 1.0 <= ratio <= 1e4:
        raise ParameterError("shear_hysteresis_ratio", f"{ratio!r} must be a number in [1, 1e4] (the shear friction's "
                             "stick stiffness over the fabric's shear rigidity G; default 10)")
    tau5 = si.get("shear_tau5")
    if tau5 is not None and tau5 < si["shear_tau0"]:
        raise ParameterError("kes_2HG5", f"{m['kes_2HG5']!r} gf/cm is below kes_2HG = {m['kes_2HG']!r} gf/cm: the "
                             "shear loop's width at 5 deg is at least its width at 0.5 deg in KES data, and the "
                             "model's friction threshold only grows with the shear (give 2HG5 >= 2HG, or remove "
                             "kes_2HG5)")
    return replace(material, shear_hysteresis=mat.ShearHysteresis(si["shear_tau0"], float(ratio), tau5))


def _opted_in(m: dict) -> bool:
    """``nonlinear_bending`` of the table (default false); ParameterError unless a boolean."""
    v = m.get("nonlinear_bending", False)
    if not isinstance(v, bool):
        raise ParameterError("nonlinear_bending", f"{v!r} must be true or false (true: a ctd-* preset's published "
                             "k2, the softening of rftstatic.element.nonlinear_bending)")
    return v


def _preset_k2(name) -> tuple[dict, dict]:
    """SI values and lab record of the k2 a preset's source gives (``nonlinear_bending = true``)."""
    if name is None:
        raise ParameterError("nonlinear_bending", "true applies next to a library preset whose source gives k2 (the "
                             "ctd-* presets: python -m rftstatic fabrics); a lab fabric gives ctd_k2_warp and "
                             "ctd_k2_weft [1e-12 N m^2], a fabric of model rigidities bending_k2_warp and "
                             "bending_k2_weft [scene units]")
    values = nonlinear_values(FABRICS[name])
    if not values:
        raise ParameterError("nonlinear_bending", f'true, but preset "{name}" has no published k2 (only the ctd-* '
                             "presets do); give bending_k2_warp and bending_k2_weft [force length^2, scene units] "
                             "to make it nonlinear, or remove nonlinear_bending")
    return lab_to_si(values)


def _with_nonlinear(material: mat.Material, m: dict, si: dict) -> mat.Material:
    """``material`` with the nonlinear bending of ``bending_k2_*`` / ``ctd_k2_*`` (both directions or neither; SI
    in ``si``) and ``bending_floor`` (:class:`rftstatic.material.NonlinearBending`)."""
    given = [d for d in ("warp", "weft") if f"bending_k2_{d}" in si]
    if not given:
        if "bending_floor" in m:
            raise ParameterError("bending_floor", f"{m['bending_floor']!r} is given without nonlinear bending: give "
                                 "bending_k2_warp and bending_k2_weft (or ctd_k2_warp and ctd_k2_weft), or remove "
                                 "bending_floor")
        return material
    if len(given) == 1:
        d, other = given[0], "weft" if given[0] == "warp" else "warp"
        key = next(k for k in (f"bending_k2_{d}", f"ctd_k2_{d}") if k in m)
        missing = f"{key.rsplit('_', 1)[0]}_{other}"
        raise ParameterError(missing, f"missing: {key} = {m[key]!r} is given without {missing}; nonlinear bending "
                             "needs both directions (0 for a direction that stays linear)")
    floor = m.get("bending_floor", mat.NONLINEAR_FLOOR)
    if isinstance(floor, bool) or not isinstance(floor, (int, float)) or not 0.0 < floor < 1.0:
        raise ParameterError("bending_floor", f"{floor!r} must be a number in (0, 1): the least bending slope as a "
                             f"fraction of B (default {mat.NONLINEAR_FLOOR}; rftstatic.element.nonlinear_bending)")
    return replace(material, nonlinear_bending=mat.NonlinearBending(si["bending_k2_warp"], si["bending_k2_weft"],
                                                                     float(floor)))


def build_material(scene) -> mat.Material:
    """The scene's material in SI (module docstring); scene errors name the key and value."""
    m = dict(scene.get("material", {"preset": "wool-kang-yu"}))
    units = scene.units
    angle = m.pop("warp_angle", 0.0)
    if not -360.0 <= angle <= 360.0:
        raise scene.error("material.warp_angle", f"{angle!r} must lie in [-360, 360] deg (the warp's angle from the x "
                          "axis; 90: the weft along x)")
    try:
        if m.get("kind", "fabric") == "isotropic" and "preset" not in m:
            m.pop("kind")
            for key in ("E", "nu", "thickness"):
                if key not in m:
                    raise scene.error(f"material.{key}", "an isotropic shell needs E, nu and thickness")
            extra = set(m) - {"E", "nu", "thickness", "weight"}
            if extra:
                raise scene.error("material", f"keys {sorted(extra)} do not apply to an isotropic shell")
            E, thickness = units.to_si(m["E"], "pressure"), units.to_si(m["thickness"], "length")
            _check_isotropic(m, E, thickness, units)
            return mat.isotropic_shell(E=E, nu=m["nu"], thickness=thickness,
                                       weight=units.to_si(m.get("weight", 0.0), "pressure"))
        if m.get("kind", "fabric") not in ("fabric", "isotropic"):
            raise scene.error("material.kind", f'"{m["kind"]}" is not a material kind; use fabric or isotropic')
        return _fabric(scene, m, angle)
    except ParameterError as exc:
        raise scene.error(f"material.{exc.key}", exc.detail) from None
    except ValueError as exc:
        if isinstance(exc, type(scene.error("", ""))):
            raise
        raise scene.error("material", str(exc)) from None


def _check_isotropic(m: dict, E: float, thickness: float, units: UnitSystem) -> None:
    """ParameterError unless an isotropic shell's Poisson ratio lies in (-1, 0.5), its Young's modulus ``E``
    [Pa] in (0, :data:`MAX_E_PA`] and its ``thickness`` [m] in (0, :data:`MAX_THICKNESS_M`]."""
    if not -1.0 < m["nu"] < 0.5:
        raise ParameterError("nu", f"{m['nu']!r} must lie in (-1, 0.5) (the Poisson ratio of an isotropic solid: 0.5 "
                             "is incompressible, -1 has no shear stiffness)")
    if not 0 < E <= MAX_E_PA:
        raise ParameterError("E", f"{m['E']!r} must lie in (0, {MAX_E_PA / units.pressure:.3g}] (Young's modulus, "
                             f"scene units; up to {MAX_E_PA:g} Pa, ten times diamond's)")
    if not 0 < thickness <= MAX_THICKNESS_M:
        raise ParameterError("thickness", f"{m['thickness']!r} must lie in (0, {MAX_THICKNESS_M / units.length:g}] "
                             f"scene length units ({MAX_THICKNESS_M:g} m, the largest sheet; the model then bounds "
                             "it by the sheet's smaller side)")


def material_summary(scene, material: mat.Material) -> dict:
    """The material as run, in the scene's units: the rigidities in the fabric's own axes, the bending
    lengths, the warp angle and, for lab input, how each value was converted (``lab``)."""
    u = scene.units
    out = {"name": material.name, "warp_angle_deg": material.info.get("warp_angle_deg", 0.0),
           "weight": u.from_si(material.weight, "pressure")}
    lengths = bending_lengths(material)
    for d in ("warp", "weft"):
        out[f"B_{d}"] = u.from_si(lengths[d]["B"], "moment")
        c = lengths[d]["c"]
        out[f"bending_length_{d}"] = None if c is None else u.from_si(c, "length")
    out["Dm_global"] = (np.asarray(material.Dm) / u.line_force).tolist()
    out["Db_global"] = (np.asarray(material.Db) / u.moment).tolist()
    if "lab" in material.info:
        out["lab"] = {q: {**{k: v for k, v in rec.items() if k != "si"},
                          "converted": u.from_si(rec["si"], _SUMMARY_KINDS[q]), "converted_units": u.name}
                      for q, rec in material.info["lab"].items()}
    if "filled" in material.info:
        out["filled"] = {q: {"value": u.from_si(rec["si"], rec["kind"]), "unit": unit_label(u, rec["kind"]),
                             "rule": rec["rule"], "source": rec["source"]}
                         for q, rec in material.info["filled"].items()}
    h = material.hysteresis
    if h is not None:
        out["bending_hysteresis"] = {"M0_warp": u.from_si(h.M0_warp, "force"), "M0_weft": u.from_si(h.M0_weft, "force"),
                                     "unit": "force per width x length / length (gf in cm-gf-s: gf cm/cm)",
                                     "stick_ratio": h.ratio, "model": "rftstatic.element.hysteresis"}
    if material.nonlinear_bending is not None:
        out["nonlinear_bending"] = _nonlinear_summary(u, material.nonlinear_bending, lengths)
    sh = material.shear_hysteresis
    if sh is not None:
        out["shear_hysteresis"] = {"tau0": u.from_si(sh.tau0, "line_force"), "unit": unit_label(u, "line_force"),
                                   "stick_ratio": sh.ratio, "model": "rftstatic.element.shear_friction"}
        if sh.tau5 is not None:
            out["shear_hysteresis"].update(
                tau5=u.from_si(sh.tau5, "line_force"),
                growth="the friction threshold grows smoothly (C1) from tau0 at 0.5 deg to tau5 at 5 deg and beyond "
                       "(KES loop widths 2HG and 2HG5; rftstatic.element.shear_threshold)")
    for key in ("preset", "changed"):
        if key in material.info:
            out[key] = material.info[key]
    return out


def _nonlinear_summary(u: UnitSystem, nb: mat.NonlinearBending, lengths: dict) -> dict:
    """Nonlinear bending in scene units: k2, the floor, the floor curvature kappa_f (N2) and k2 kappa / B at the
    bending length's curvature kappa = 1/c (the data set's -0.41 ... -0.05, median -0.13)."""
    out = {"unit": "force length^2 (moment per width per curvature^2; gf cm^2 in cm-gf-s)", "floor": nb.floor,
           "model": "rftstatic.element.nonlinear_bending"}
    for d in ("warp", "weft"):
        k2, B, c = getattr(nb, f"k2_{d}"), lengths[d]["B"], lengths[d]["c"]
        out[f"k2_{d}"] = u.from_si(k2, "moment_length")
        out[f"floor_curvature_{d}"] = None if k2 == 0 else u.length * (1 - nb.floor) * B / (2 * abs(k2))
        out[f"ratio_at_bending_length_{d}"] = None if c is None else k2 / (B * c)
    return out


def list_fabrics() -> list[dict]:
    """Every library fabric as built for a scene in cm-gf-s: name, bending rigidities B [gf cm] and bending
    lengths c = (B/W)^(1/3) [cm] along warp and weft, weight [gf/cm^2], description and source (full and
    short), ``derived``: the quantities not from the source (by ``derived_rule``, or B_twist by default; the
    Poisson couplings C12 = B12 = 0 of every fabric are not listed),
    and ``not_used``: published values the linear model does not take."""
    from rftstatic.scenes.schema import scene_from_dict

    rows = []
    for name, fab in FABRICS.items():
        scene = scene_from_dict({"units": "cm-gf-s", "material": {"preset": name}})
        m = material_summary(scene, build_material(scene))
        rows.append({"name": name, "B_warp": m["B_warp"], "B_weft": m["B_weft"], "weight": m["weight"],
                     "c_warp": m["bending_length_warp"], "c_weft": m["bending_length_weft"],
                     "published_units": fab.units, "description": fab.description, "source": fab.source,
                     "short_source": fab.short_source or fab.source, "measured_dc": dict(fab.measured_dc),
                     "derived": sorted(q for q in m.get("filled", {}) if q not in ("C12", "B12")),
                     "derived_rule": fab.derived_rule, "not_used": dict(fab.not_used)})
    return rows
