"""``python -m rftstatic fabrics --explain [SCENE]``: how a ``[material]`` table's lab data become the model's
rigidities, and, for a scene, what its fabric takes from where.

Without a scene: every lab key with its unit, plausible range and the range's source
(:mod:`rftstatic.fabrics.lab`), then every rule that fills a quantity a lab fabric does not give, with its
source (:mod:`rftstatic.fabrics.rules`). With a scene (and ``--set``): its material as the run will build it,
each quantity in the scene's units, marked given (the scene key or lab conversion), preset or filled (rule
and source), the same record the run's ``summary.json`` keeps under ``material``.
"""

from __future__ import annotations

import numpy as np

from rftstatic import material as mat
from rftstatic.fabrics.lab import K2_RANGE, LAB_KEYS, RANGES, range_source
from rftstatic.fabrics.library import bending_lengths
from rftstatic.fabrics.rules import FILL_RULES, unit_label
from rftstatic.scenes.material import build_material, material_summary

__all__ = ["explain_fabrics"]


def _rules_text() -> list[str]:
    lines = ["Lab keys of [material] (each in its instrument's unit; a value outside its range is refused):"]
    for key, (unit, meaning) in LAB_KEYS.items():
        lo, hi = RANGES.get(key, K2_RANGE if key.startswith("ctd_k2") else (None, None))
        bounds = f"[{lo:g}, {hi:g}]" if lo is not None else "-"
        lines.append(f"  {key:16s} {unit:12s} {bounds:16s} {meaning}")
    sources = dict.fromkeys(range_source(k) for k in RANGES)
    lines += ["  range sources: " + "; ".join(sources), "",
              "A fabric given by lab data and no preset needs B (warp, weft) and its weight (kes_B_warp, kes_B_weft, "
              "kes_W); what it does not give is filled by these rules (a given value is always used instead):"]
    for q, rule in FILL_RULES.items():
        lines += [f"  {q:8s} {rule.rule}", f"  {'':8s} source: {rule.source}"]
    lines += ["A preset never lends values to lab data: lab keys next to preset are refused. What each rule does to the "
              "Cusick drape coefficient: validation/fabric_rules.md.", "",
              "Nonlinear (softening) bending, M = B kappa + k2 kappa |kappa| with the slope floored at bending_floor x "
              "B (rftstatic.element.nonlinear_bending): ctd_k2_warp and ctd_k2_weft (above), or bending_k2_warp and "
              "bending_k2_weft [force length^2, scene units], both directions or neither, <= 0 (stiffening refused; "
              "0: linear); bending_floor in (0, 1), default 0.2; nonlinear_bending = true next to a ctd-* preset takes "
              "its data row's k2 (opt-in)."]
    return lines


def _scene_text(scene) -> list[str]:
    material = build_material(scene)
    s = material_summary(scene, material)
    u = scene.units
    lines = [f"Scene {scene.name}: fabric {s['name']} (units {u.name})"]
    lab, filled = s.get("lab", {}), s.get("filled", {})
    Ti = np.linalg.inv(mat.voigt_rotation(np.radians(s["warp_angle_deg"])))
    Dm, Db = Ti.T @ material.Dm @ Ti, Ti.T @ material.Db @ Ti
    values = {"C_warp": Dm[0, 0], "C_weft": Dm[1, 1], "C_shear": Dm[2, 2], "C12": Dm[0, 1],
              "B_warp": Db[0, 0], "B_weft": Db[1, 1], "B_twist": Db[2, 2], "B12": Db[0, 1], "weight": material.weight}
    for q, v in values.items():
        kind = mat._FABRIC_KINDS[q]
        shown = f"  {q:8s} {u.from_si(v, kind):12.5g} {unit_label(u, kind):10s}"
        if q in filled:
            lines += [f"{shown} filled: {filled[q]['rule']}", f"  {'':32s}source: {filled[q]['source']}"]
        elif q in lab:
            lines.append(f"{shown} given: {lab[q]['from']} = {lab[q]['value']:g} {lab[q]['unit']} ({lab[q]['rule']})")
        elif "preset" in s and q not in s.get("changed", ()):
            lines.append(f"{shown} preset {s['preset']}")
        else:
            lines.append(f"{shown} given: material.{q}")
    if "thickness" in lab:
        lines.append(f"  thickness {u.from_si(material.info['thickness'], 'length'):.5g} {unit_label(u, 'length')} "
                     f"given: {lab['thickness']['from']} = {lab['thickness']['value']:g} {lab['thickness']['unit']}")
    c = bending_lengths(material)
    lines.append("  bending length c = (B/W)^(1/3): " + ", ".join(
        f"{d} {u.from_si(c[d]['c'], 'length'):.4g} {unit_label(u, 'length')}" for d in ("warp", "weft")
        if c[d]["c"] is not None))
    nb = s.get("nonlinear_bending")
    if nb is not None:
        lines.append(f"  nonlinear bending: k2 warp {nb['k2_warp']:.5g}, weft {nb['k2_weft']:.5g} "
                     f"[force length^2, {u.name}], floor {nb['floor']:g} x B; k2 kappa / B at "
                     "kappa = 1/c: " + ", ".join(f"{d} {nb[f'ratio_at_bending_length_{d}']:.3g}"
                                                for d in ("warp", "weft")
                                                if nb[f"ratio_at_bending_length_{d}"] is not None))
    return lines


def explain_fabrics(scene=None) -> str:
    """The ``fabrics --explain`` text: the lab keys and fill rules, and for a ``scene`` its fabric's values and
    where each comes from."""
    lines = _rules_text()
    if scene is not None:
        lines += [""] + _scene_text(scene)
    return "\n".join(lines)
