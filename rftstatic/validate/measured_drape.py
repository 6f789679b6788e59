"""Predicted against measured Cusick drape, the trends where no measurement could be read, and bending hysteresis.

Issue 35 items 4 and 5. Three parts, every number from runs of the current Cusick route (``cases/cusick-*.toml``:
dynamic relaxation at full load, then Newton; the seeded starts of ``solver.seeds`` are a lab's specimens):

1. **Measured rows.** Every fabric with mechanical data (KES-F, FAST or cantilever) and a measured Cusick DC
   that the literature search could read (:mod:`rftstatic.references.drape_literature`): none. The report lists
   what was searched and what of it was readable.
2. **Trends instead** (the qualitative findings of the readable abstracts, :data:`~rftstatic.references.
   drape_literature.TRENDS`): DC and node count of the wool with its bending rigidities scaled (bending length
   c against the disc radius), of the three specimen sizes, and of the wool with its shear rigidity scaled.
   Pass: DC rises with c, the node count does not rise with c, DC and node count are anti-correlated over the
   specimens, the node count does not fall with the specimen size, DC rises with the shear rigidity.
3. **Bending hysteresis** (:mod:`rftstatic.element.hysteresis`): a lab fabric given by ``kes_B_warp, kes_B_weft,
   kes_W, kes_T`` alone (the rest filled by the stated rules, listed), without and with ``kes_2HB_warp,
   kes_2HB_weft``, on cusick-24/30/36; its DC and node count against 2HB on cusick-30, and against the stick
   stiffness ratio (a modelling choice). Reported: no measured drape of a fabric with a known 2HB was readable.

Runs are cached under ``out/validate-measured-drape/`` keyed by the scene, its overrides and the fingerprint of
the package's sources outside ``rftstatic/validate`` (an edit of a report changes how runs are shown, not what
they solve); ``RFTSTATIC_DRAPE_REFRESH=1`` solves again. Quick: the trends on two bending factors, one seed.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from pathlib import Path

import numpy as np

from rftstatic.references.drape_literature import MEASURED_ROWS, SEARCHED, TRENDS
from rftstatic.validate.report import BenchmarkResult

SEEDS = 3
WOOL_B = {"B_warp": 0.083, "B_weft": 0.063, "B_twist": 0.027}
B_FACTORS = [0.25, 0.5, 1.0, 2.0, 4.0]
SHEAR_FACTORS = [0.25, 1.0, 4.0]
WOOL_SHEAR = 41.8  # gf/cm, Kang & Yu's wool (rftstatic.material.WOOL_KANG_YU_CM_GF)
LAB = {"kes_B_warp": 0.05, "kes_B_weft": 0.04, "kes_W": 15.0, "kes_T": 0.5}
"""The lab fabric of docs/howto/fabric-data.md's "fabric given by B, W, T alone": illustrative input values, not a
measured fabric."""
HB2 = [0.0, 0.005, 0.02, 0.05]
"""2HB along the warp [gf cm/cm] of the hysteresis sweep; the weft's is scaled by B_weft / B_warp. Illustrative:
no readable source gave a fabric's 2HB with its drape; 0.05 is the KES B of the warp times 1 /cm."""
RATIOS = [10.0, 100.0]
DISC_RADIUS = 9.0  # cm


def cache_root() -> Path:
    """``out/validate-measured-drape`` of the repository."""
    import rftstatic

    return Path(rftstatic.__file__).resolve().parent.parent / "out" / "validate-measured-drape"


def solver_fingerprint() -> str:
    """SHA-1 [12 hex] of the package's Python sources outside ``rftstatic/validate`` (paths and contents)."""
    import rftstatic

    pkg = Path(rftstatic.__file__).resolve().parent
    h = hashlib.sha1()
    for path in sorted(pkg.rglob("*.py")):
        rel = path.relative_to(pkg)
        if "__pycache__" in rel.parts or rel.parts[0] == "validate":
            continue
        h.update(str(rel).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()[:12]


def _material_set(table: dict) -> str:
    return "material={" + ", ".join(f"{k}={v!r}" for k, v in table.items()) + "}"


def run_row(scene: str, sets: list[str]) -> dict:
    """The summary of ``scene`` with ``sets`` and ``solver.seeds``, from the cache or solved now (module docstring);
    ``wall_time_s`` is the whole call's (all seeds)."""
    from rftstatic import api

    sets = list(sets)
    key = hashlib.sha1(json.dumps([scene, sets, solver_fingerprint()]).encode()).hexdigest()[:16]
    folder = cache_root() / f"{scene}-{key}"
    path = folder / "summary.json"
    if path.exists() and os.environ.get("RFTSTATIC_DRAPE_REFRESH") != "1":
        return json.loads(path.read_text(encoding="utf-8"))
    t0 = time.perf_counter()
    try:
        summary = dict(api.run(api.load_scene(scene, sets), folder, figures=False).summary)
    except api.ConvergenceError as exc:
        summary = {"converged": False, "message": str(exc)}
    summary["call_wall_time_s"] = time.perf_counter() - t0
    summary["overrides_run"] = sets
    folder.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(summary, default=float), encoding="utf-8")
    return summary


def plan(quick: bool) -> dict:
    """Every run of the report: label -> (scene, overrides)."""
    seeds = 1 if quick else SEEDS
    common = [f"solver.seeds={seeds}"]
    rows = {}
    for f in ([0.5, 2.0] if quick else B_FACTORS):
        rows[f"wool B x {f:g}"] = ("cusick-30", common + [f"material.{k}={v * f!r}" for k, v in WOOL_B.items()])
    if quick:
        return rows
    for size in (24, 36):
        rows[f"wool, {size} cm"] = (f"cusick-{size}", list(common))
    for f in SHEAR_FACTORS:
        if f != 1.0:
            rows[f"wool C_shear x {f:g}"] = ("cusick-30", common + [f"material.C_shear={WOOL_SHEAR * f!r}"])
    ratio = LAB["kes_B_weft"] / LAB["kes_B_warp"]
    for size in (24, 30, 36):
        for hb in ((0.0, HB2[-1]) if size != 30 else HB2):
            rows[_lab_label(size, hb, RATIOS[0])] = (f"cusick-{size}", common + [_material_set(_lab(hb, ratio))])
    rows[_lab_label(30, HB2[-1], RATIOS[1])] = ("cusick-30", common + [_material_set(
        {**_lab(HB2[-1], ratio), "hysteresis_ratio": RATIOS[1]})])
    return rows


def _lab(hb: float, ratio: float) -> dict:
    return dict(LAB) if hb == 0 else {**LAB, "kes_2HB_warp": hb, "kes_2HB_weft": round(hb * ratio, 6)}


def _lab_label(size, hb, ratio) -> str:
    return f"lab, {size} cm, 2HB {hb:g}" + (f", ratio {ratio:g}" if ratio != RATIOS[0] else "")


def _stats(s: dict) -> dict:
    """DC [%] and node count over the seeded specimens: mean, min, max, all counts; the specimens' pairs."""
    seeds = s.get("seeds")
    if seeds:
        good = [r for r in seeds["specimens"] if r.get("converged") and r.get("drape_coefficient_percent") is not None]
        dc = [r["drape_coefficient_percent"] for r in good]
        folds = [r["fold_count"] for r in good]
    else:
        dc, folds = [s["drape"]["drape_coefficient_percent"]], [s["drape"]["fold_count"]]
    return {"dc": float(np.mean(dc)), "dc_min": float(min(dc)), "dc_max": float(max(dc)),
            "folds": float(np.mean(folds)), "folds_min": min(folds), "folds_max": max(folds),
            "pairs": list(zip(dc, folds)), "n": len(dc)}


def _c(s: dict) -> float:
    m = s["material"]
    return math.sqrt(m["bending_length_warp"] * m["bending_length_weft"])


def _fmt(st: dict, s: dict) -> str:
    """DC and nodes (mean, range) and the hem's depth r_max - r_min [cm] of the first seed's drape."""
    d = s["drape"]
    return (f"{st['dc']:.2f} ({st['dc_min']:.2f}-{st['dc_max']:.2f}) | {st['folds']:.2f} "
            f"({st['folds_min']}-{st['folds_max']}) | {d['boundary_radius_max'] - d['boundary_radius_min']:.2f}")


def _trends(result, runs, quick) -> list[str]:
    """The trend tables and checks (part 2); returns the failed checks."""
    failed = []
    head = ("| fabric | specimen [cm] | c [cm] | R_disc / c | DC [%] mean (range) | nodes mean (range) | hem depth [cm] | "
            "specimens | time [s] |\n|---|---|---|---|---|---|---|---|---|")
    lines, b_rows = [head], []
    for label, s in runs.items():
        if not label.startswith("wool") or not s.get("converged", True) or "drape" not in s:
            continue
        st = _stats(s)
        size = 2 * s["resolved_scene"]["mesh"]["radius"] if "resolved_scene" in s else 30
        lines.append(f"| {label} | {size:g} | {_c(s):.3f} | {DISC_RADIUS / _c(s):.3f} | {_fmt(st, s)} | {st['n']} | "
                     f"{s['call_wall_time_s']:.0f} |")
        result.rows.append({"case": f"trend: {label}", "element": s.get("element", "RFT6"), "mesh": "default",
                            "nodes": s.get("nodes"), "value": [st["dc"], st["folds"]], "reference": None,
                            "error": float("nan"), "wall_time_s": s["call_wall_time_s"], "iterations": s.get(
                                "newton_iterations")})
        if label.startswith("wool B x"):
            b_rows.append((_c(s), st))
    b_rows.sort(key=lambda r: r[0])
    checks = []
    dc_up = all(b[1]["dc"] > a[1]["dc"] for a, b in zip(b_rows, b_rows[1:]))
    checks.append(("dc_rises_with_bending_length", dc_up, "mean DC " + " < ".join(f"{r[1]['dc']:.1f}" for r in b_rows)))
    nodes_down = all(b[1]["folds"] <= a[1]["folds"] for a, b in zip(b_rows, b_rows[1:]))
    checks.append(("fewer_nodes_at_higher_dc", nodes_down, "mean nodes by rising c: " + ", ".join(
        f"{r[1]['folds']:.2f}" for r in b_rows)))
    pairs = np.array([p for _, st in b_rows for p in st["pairs"]], float)
    if len(pairs) > 2 and np.ptp(pairs[:, 1]) > 0:
        r = float(np.corrcoef(pairs[:, 0], pairs[:, 1])[0, 1])
        checks.append(("fewer_nodes_at_higher_dc", r < 0, f"correlation of DC and nodes over {len(pairs)} "
                                                          f"specimens r = {r:+.2f}"))
    if not quick:
        sizes = [runs.get("wool, 24 cm"), runs.get("wool B x 1"), runs.get("wool, 36 cm")]
        if all(s is not None and "drape" in s for s in sizes):
            f = [_stats(s)["folds"] for s in sizes]
            checks.append(("more_nodes_on_larger_specimens", f[0] <= f[1] <= f[2],
                           f"mean nodes 24 / 30 / 36 cm: {f[0]:.2f} / {f[1]:.2f} / {f[2]:.2f}"))
        shear = [runs.get("wool C_shear x 0.25"), runs.get("wool B x 1"), runs.get("wool C_shear x 4")]
        if all(s is not None and "drape" in s for s in shear):
            d = [_stats(s)["dc"] for s in shear]
            checks.append(("dc_rises_with_shear_rigidity", d[0] < d[1] < d[2],
                           f"mean DC at C_shear x 0.25 / 1 / 4: {d[0]:.2f} / {d[1]:.2f} / {d[2]:.2f}"))
    check_lines = ["| trend (source) | holds | measured |", "|---|---|---|"]
    for key, ok, text in checks:
        check_lines.append(f"| {TRENDS[key]} | {'yes' if ok else '**no**'} | {text} |")
        if not ok:
            failed.append(key)
    result.sections.append(("Trends: DC and node count against the bending length, the specimen size and the shear",
                            "\n".join(lines) + "\n\nc = sqrt(c_warp c_weft), the bending length (B/W)^(1/3); R_disc = "
                            "9 cm. Each row is one scene solved from "
                            f"{1 if quick else SEEDS} seeded starts (the mean and range over them). Hem depth: "
                            "r_max - r_min of the projected hem (first seed). Read a node count with it: where the hem "
                            "hardly drops (a few mm), its nodes are shallow waves that the fold counter (rftstatic.post."
                            "measures.boundary.fold_count) counts once their prominence exceeds 1 % of the mean radius, "
                            "not developed folds; the checks below compare the counts as they come out.\n\n"
                            + "\n".join(check_lines)))
    return failed


def _filled(s: dict) -> str:
    f = s.get("material", {}).get("filled", {})
    return "; ".join(f"{q} = {v['value']:.4g} {v['unit']} ({v['rule']})" for q, v in f.items()
                     if q not in ("C12", "B12")) or "-"


def _hysteresis(result, runs):
    """Part 3: the lab fabric without and with 2HB on three sizes, the 2HB sweep and the stick ratio."""
    head = ("| fabric | specimen | 2HB warp / weft [gf cm/cm] | stick ratio | DC [%] mean (range) | "
            "nodes mean (range) | hem depth [cm] | dissipated [gf cm] | yielded share warp / weft | time [s] |\n"
            "|---|---|---|---|---|---|---|---|---|---|")
    lines, filled = [head], None
    base = {}
    for label, s in runs.items():
        if not label.startswith("lab"):
            continue
        if not s.get("converged", True) or "drape" not in s:
            lines.append(f"| {label} | not converged: {s.get('message', '')[:300]} ||||||||")
            continue
        st = _stats(s)
        m = s["material"]
        h = m.get("bending_hysteresis")
        hb = (f"{2 * h['M0_warp']:.3g} / {2 * h['M0_weft']:.3g}" if h else "0 / 0")
        bh = s.get("bending_hysteresis", {})
        diss = f"{bh['dissipated']:.3g}" if bh else "-"
        share = f"{bh['yielded_share_warp']:.2f} / {bh['yielded_share_weft']:.2f}" if bh else "-"
        size = label.split(", ")[1]
        lines.append(f"| {label} | {size} | {hb} | {h['stick_ratio'] if h else '-'} | {_fmt(st, s)} | {diss} | {share} | "
                     f"{s['call_wall_time_s']:.0f} |")
        filled = filled or _filled(s)
        if not h:
            base[size] = st
        result.rows.append({"case": f"hysteresis: {label}", "element": s.get("element", "RFT6"), "mesh": "default",
                            "nodes": s.get("nodes"), "value": [st["dc"], st["folds"]], "reference": None,
                            "error": float("nan"), "wall_time_s": s["call_wall_time_s"],
                            "iterations": s.get("newton_iterations")})
    text = ("\n".join(lines) + "\n\nThe lab fabric is given by " + ", ".join(f"{k} = {v:g}" for k, v in LAB.items())
            + " alone (illustrative values, the example of docs/howto/fabric-data.md; not a measured fabric); the "
            f"values filled by the stated rules (rftstatic.fabrics.rules), as the runs list them: {filled}. 2HB enters "
            "as the friction moment M0 = 2HB / 2 per unit width of rftstatic.element.hysteresis (Grosberg's model: "
            "a Coulomb friction element, stick stiffness ratio x B, in parallel with B); the weft's 2HB is the warp's "
            "times B_weft / B_warp. Dissipated: the friction's work along the route (relaxation, then Newton), "
            "from the first seed; yielded share: the element-directions at the yield moment at the end.")
    result.sections.append(("Bending hysteresis: what 2HB changes in DC and node count", text))


def _literature() -> str:
    lines = ["| source | public copy found | readable there | what that part says | fabric table in reach |",
             "|---|---|---|---|---|"]
    for s in SEARCHED:
        lines.append(f"| {s['citation']} | {s['found_at']} | {s['readable']} | {s['says']} | "
                     f"{'yes' if s['table_within_reach'] else 'no'} |")
    return ("**No fabric with both mechanical data and a measured Cusick DC could be read: there is no row of "
            "predicted against measured DC and node count.** The studies that pair them (below) were found by "
            "title and abstract only; the stored copies reachable here stop before their tables "
            "(rftstatic.references.drape_literature, searched 2026-12-04). The one public data set in the library "
            "(Feng et al. 2022) has cantilever-derived bending data but no drape-tester reading per fabric. Nothing "
            "is entered from memory. In place of the comparison the next section checks the trends that the "
            "readable abstracts state.\n\n" + "\n".join(lines)
            + f"\n\nMeasured rows in rftstatic.references.drape_literature.MEASURED_ROWS: {len(MEASURED_ROWS)}.")


SCOPE = ("Measured with the current Cusick route (cases/cusick-*.toml: dynamic relaxation at full load, then Newton; "
         "specimen = seeded start); the route is being reworked in another branch, so these numbers belong to this "
         "commit's route. Nonlinear bending (Feng et al.'s k2, rftstatic.element.nonlinear_bending) is measured in "
         "section g of the hand-written section, shear hysteresis (KES 2HG and 2HG5, rftstatic.element.shear_friction "
         "and rftstatic.element.shear_threshold) in section h.")


NODES_HEADING = "Why the node count does not follow the fabric"
"""A section written by hand from ``tools/node_count_study.py`` (issue 35, item 3): its runs take about an hour, so the
report does not solve them; a regeneration carries the section over from the report it replaces."""


def carried_section(report: Path, heading: str = NODES_HEADING) -> str | None:
    """The text of the ``## heading`` section of the Markdown ``report`` (up to the next ``## ``), or None when the
    file or the section is missing."""
    if not report.exists():
        return None
    lines = report.read_text(encoding="utf-8").splitlines()
    if f"## {heading}" not in lines:
        return None
    start = lines.index(f"## {heading}") + 1
    end = next((i for i in range(start, len(lines)) if lines[i].startswith("## ")), len(lines))
    return "\n".join(lines[start:end]).strip("\n") or None


def run(quick: bool = False, *, out=None) -> BenchmarkResult:
    result = BenchmarkResult(
        name="measured_drape", title="Cusick drape: measured fabrics (none readable), trends, bending hysteresis",
        citation="Cusick drape tester; KES-F 2HB (Kawabata); Grosberg (1966)",
        reference="Published fabrics with mechanical data and a measured Cusick DC: none readable (see report); "
                  "trends of the readable abstracts (Hu & Chan 1998; Behera & Pattanayak 2008; Cerda et al. 2004)",
        tolerance="trends hold on the means over seeded specimens (DC up with the bending length and the shear "
                  "rigidity, nodes not up with the bending length and anti-correlated with DC, nodes not down with the "
                  "specimen size); hysteresis reported")
    runs = {label: run_row(scene, sets) for label, (scene, sets) in plan(quick).items()}
    result.sections.append(("Published fabrics: predicted against measured", _literature()))
    failed = _trends(result, runs, quick)
    if not quick:
        _hysteresis(result, runs)
    from rftstatic.validate import default_out

    nodes = carried_section(Path(out or default_out()) / "measured_drape.md")
    if nodes is not None:
        result.sections.append((NODES_HEADING, nodes))
    result.sections.append(("Route and scope", SCOPE))
    result.passed = not failed
    result.notes.append("trend checks failed: " + ", ".join(failed) if failed else "every trend check holds")
    return result
