"""What shear hysteresis (KES 2HG, rftstatic.element.shear_friction) changes in the Cusick DC and node count (issue 35).

The four fabrics of Matsudaira et al. (2015) as a third party transcribed them
(:func:`rftstatic.references.drape_literature.secondary_table`; KES B, 2HB, W, T, the measured DC and node count; one
B per fabric, so B_warp = B_weft; no G and no 2HG) are given to ``cusick-30`` by their KES values alone (every other
quantity, the shear rigidity G among them, filled by the stated rules: ``python -m rftstatic fabrics --explain``),
seed 1, on the scene's own route (relaxation, then Newton), without and with an assumed 2HG (:data:`HG2`: the
transcription has none), and on the load steps (``solver.start = "load-steps"``) without and with the smaller 2HG.
Then one fabric (:data:`COMBINED`) with its transcribed 2HB alone and with 2HB and 2HG
together, and with the stick ratio of the shear friction raised (a modelling choice). ``--hg5``: that fabric at 2HG
1 without and with an assumed 2HG5 (:data:`HG5`, the threshold growing from 2HG / 2 at 0.5 deg to 2HG5 / 2 at 5 deg:
rftstatic.element.shear_threshold) on both routes. Each run is one process
(:func:`tools.matsudaira_study.run_case`, kept in ``--out``: a finished run is read, not solved again). Prints a
Markdown table.

    PYTHONPATH=$PWD python tools/shear_hysteresis_study.py [--out /tmp/shear-runs] [--hg5]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from matsudaira_study import run_case  # noqa: E402

HG2 = (1.0, 3.0)
"""Assumed 2HG [gf/cm] (the transcription has none): within the 0.5-5 gf/cm the study's brief gives for woven apparel
fabrics (not checked against a readable table: lab.py's range notes)."""

COMBINED = "B"
"""The fabric of the 2HB + 2HG rows (Wool Tropical: 2HB 0.033 gf cm/cm)."""

RULE_G = 578.1
"""The filled shear rigidity's ratio r_G [cm^-2] (rftstatic.fabrics.rules: C_shear = r_G sqrt(B_warp B_weft) [gf/cm per
rad]), to print G [gf/(cm deg)] next to each fabric; the run's summary gives the value used."""


HG5 = (2.5, 3.0)
"""Assumed 2HG5 [gf/cm] next to 2HG 1 (2.5 and 3 x 2HG, within the 1.5-3 x of the brief; no measured value): the
first on both routes, the second on the scene's route."""

LOAD_STEPS = ["solver.start=load-steps"]
"""Route keys of the load-steps rows."""


def _keys(f, hg=None, hb=False, ratio=None, hg5=None):
    keys = [f"kes_B_warp={f['B']}", f"kes_B_weft={f['B']}", f"kes_W={f['W']}", f"kes_T={f['T']}"]
    if hb:
        keys += [f"kes_2HB_warp={f['2HB']}", f"kes_2HB_weft={f['2HB']}"]
    if hg is not None:
        keys.append(f"kes_2HG={hg}")
    if ratio is not None:
        keys.append(f"shear_hysteresis_ratio={ratio}")
    if hg5 is not None:
        keys.append(f"kes_2HG5={hg5}")
    return keys


def _row(f, label, s) -> str:
    d = s["drape"]
    sh = s.get("shear_hysteresis", {})
    bh = s.get("bending_hysteresis", {})
    diss = sh.get("dissipated_both_frictions", bh.get("dissipated"))
    g = s["material"]["filled"].get("C_shear", {}).get("value")
    g_deg = f"{g * math.pi / 180:.3g}" if g is not None else "-"
    slipping = f"{sh['yielded_share']:.3f}" if sh else "-"
    shear = f"{sh['max_shear_angle_deg']:.2f}" if sh else "-"
    dissipated = "-" if diss is None else f"{diss:.3g}"
    return (f"| {f['id']} {f['name']} | {f['DC']:g}, {f['nodes']} | {g_deg} | {label} | "
            f"{d['drape_coefficient_percent']:.1f} | {d['fold_count']} | {s['energies']['total']:.4f} | {dissipated} | "
            f"{slipping} | {shear} | {s['stable_minimum']} | {s['self_intersections'].get('pairs')} | "
            f"{s['wall_s']:.0f} |")


def main(argv=None):
    from rftstatic.references.drape_literature import secondary_table

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/shear-runs")
    ap.add_argument("--hg5", action="store_true", help="the 2HG5 rows (fabric B at 2HG 1, both routes)")
    a = ap.parse_args(argv)
    root = Path(a.out)
    fabrics = [{"id": r["id"], "name": r["name"], "B": float(r["B_gf*cm^2/cm"]), "2HB": float(r["2HB_gf*cm/cm"]),
                "W": float(r["W_mg/cm^2"]), "T": float(r["T_mm"]), "DC": float(r["DC_pub_%"]),
                "nodes": int(r["nodes_pub"])} for r in secondary_table()]
    if a.hg5:
        return _hg5(next(f for f in fabrics if f["id"] == COMBINED), root)
    runs = []
    for f in fabrics:
        runs.append((f, "no hysteresis", _keys(f), "none", []))
        runs += [(f, f"2HG {hg:g}", _keys(f, hg), f"hg{hg:g}", []) for hg in HG2]
    f = next(f for f in fabrics if f["id"] == COMBINED)
    runs += [(f, f"2HB {f['2HB']:g}", _keys(f, hb=True), "hb", []),
             (f, f"2HB {f['2HB']:g} + 2HG {HG2[0]:g}", _keys(f, HG2[0], hb=True), f"hb-hg{HG2[0]:g}", []),
             (f, f"2HG {HG2[0]:g}, stick ratio 100", _keys(f, HG2[0], ratio=100.0), f"hg{HG2[0]:g}-r100", [])]
    for f in fabrics:
        runs += [(f, "load steps, no hysteresis", _keys(f), "ls-none", LOAD_STEPS),
                 (f, f"load steps, 2HG {HG2[0]:g}", _keys(f, HG2[0]), f"ls-hg{HG2[0]:g}", LOAD_STEPS)]
    lines = ["| fabric | measured DC [%], nodes | G filled [gf/(cm deg)] | variant | DC [%] | nodes | energy [gf cm] | "
             "dissipated [gf cm] | shear slipping share | max shear [deg] | stable | crossing pairs | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for f, label, keys, tag, route in runs:
        s = _solve(f, label, keys, tag, route, root)
        if s is None:
            continue
        lines.append(_row(f, label, s))
        print(lines[-1], flush=True)
    print("\n".join(lines))


def _solve(f, label, keys, tag, route, root: Path):
    """The summary of fabric ``f`` given by its material ``keys`` on ``route`` (extra overrides), seed 1, in
    ``root/<id>-<tag>``; None when the run failed."""
    return run_case(["material={" + ", ".join(keys) + "}", "solver.seed=1", *route], root / f"{f['id']}-{tag}",
                    f"{f['id']} {label}")


def _hg5(f, root: Path):
    """The 2HG5 table: fabric ``f`` at 2HG 1, without and with each of :data:`HG5`."""
    hg = HG2[0]
    scene, steps = "scene's route", "load steps"
    runs = [(scene, f"2HG {hg:g}", _keys(f, hg), f"hg{hg:g}", []),
            *[(scene, f"2HG {hg:g}, 2HG5 {h5:g}", _keys(f, hg, hg5=h5), f"hg{hg:g}-hg5{h5:g}", []) for h5 in HG5],
            (steps, f"2HG {hg:g}", _keys(f, hg), f"ls-hg{hg:g}", LOAD_STEPS),
            (steps, f"2HG {hg:g}, 2HG5 {HG5[0]:g}", _keys(f, hg, hg5=HG5[0]), f"ls-hg{hg:g}-hg5{HG5[0]:g}", LOAD_STEPS)]
    lines = ["| route | variant | DC [%] | nodes | energy [gf cm] | dissipated [gf cm] | shear slipping share | "
             "max shear [deg] | Newton iterations | explicit / load steps | run [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for route_label, label, keys, tag, route in runs:
        s = _solve(f, label, keys, tag, route, root)
        if s is None:
            continue
        d, sh = s["drape"], s["shear_hysteresis"]
        n = s["relax"]["steps"] if route_label == scene else s["load_steps"]
        lines.append(f"| {route_label} | {label} | {d['drape_coefficient_percent']:.4f} | {d['fold_count']} | "
                     f"{s['energies']['total']:.4f} | {sh['dissipated_both_frictions']:.3g} | "
                     f"{sh['yielded_share']:.3f} | {sh['max_shear_angle_deg']:.2f} | {s['newton_iterations']} | {n} | "
                     f"{s['wall_time_s']:.1f} |")
        print(lines[-1], flush=True)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
