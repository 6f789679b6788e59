"""Path following from the flat sheet: the paper's load-scaled route alone on every §4 static drape (issue 17).

Each §4 drape scene of ``cases/`` is solved on its default mesh (and the coarse sphere and the fine
round pedestal) by the load-scaled route only: ``solver.start = "load-steps"``, ``solver.continuation
= "arc-length"``, ``solver.relax_fallback = false`` and, where given, ``solver.levels = L`` (the path
on the coarsest of L meshes, Newton at full load on each finer one, ``solver.level_membrane = "same"``): no
explicit or damped stage.
Each run is the drape bench's run in a fresh child interpreter (:func:`rftstatic.bench.drape.run_cached`:
its child solves as ``python -m rftstatic case`` does, mesh sequencing of ``solver.levels`` included),
cached by code fingerprint beside the drape reports' runs (:func:`rftstatic.bench.drape.run_key`).
The report lists per scene the levels and their meshes, convergence, the stable-minimum check, the
path (steps, critical points, branch switches, fixed-load descents), Newton iterations per level, the
drape coefficient, the fold count, the energy, the wall time, peak memory and the machine's load
average when the run ended (the machine is shared).

On the round pedestal (§4.4) the fold count and DC of this route are set beside the scene's default
route (dynamic relaxation, then Newton: the runs of ``drape_folds``) and the paper's 12 folds.

Pass criterion: every row converged to a stable minimum (Cholesky of the exact tangent) by the
load-scaled route alone. The paper's 12 folds are compared; a different count is stated as a
difference from the paper (``discrepancy``), not as a failure.
Quick: pedestal-square-20 on 33 x 33 and sphere-30 on 17 x 17 only (about 1.5 minutes).
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

from rftstatic.validate.drape_common import cache_root, copy_views, drape_run, mesh_label, run_cached_only
from rftstatic.validate.report import BenchmarkResult

ROUTE = ["solver.start=load-steps", "solver.continuation=arc-length", "solver.relax_fallback=false",
         "solver.level_membrane=same"]
# level_membrane: the report's sequences keep the fabric on every level, as they were measured (pedestal-square-80
# sets "matched" for its fine meshes; on this report's 81 x 81 sequence "matched" lands on another stable drape,
# docs/howto/solver-routes.md, "Fine meshes: levels")
# (scene, nodes or None for an unstructured mesh, mesh override needed, levels): fast rows first
FULL = [("pedestal-square-20", (33, 33), False, 1), ("sphere-30", (17, 17), True, 1),
        ("pedestal-square-40", (81, 81), False, 3), ("sphere-30", (61, 61), False, 3),
        ("pedestal-square-80", (81, 81), False, 3), ("pedestal-round-50-unstructured", None, False, 1),
        ("pedestal-round-50", (21, 160), False, 2), ("pedestal-round-50", (31, 240), True, 3)]
QUICK = FULL[:2]
ROUND = "pedestal-round-50"
ROUND_MESHES = [(21, 160), (31, 240)]
PAPER_FOLDS = 12  # Sze & Zhou (2016) §4.4, Fig. 10: 12 folds with RFT6 on 21 x 160 and 31 x 240 nodes
LOADAVG = "loadavg.json"  # written beside a run's record when this benchmark solved it
TIMEOUT_S = 3 * 3600.0  # a row's child is killed after this long [s]


def overrides(nodes, mesh_override: bool, levels: int) -> list[str]:
    """Scene overrides of a row: the load-scaled route, its levels and, when not the default, the mesh."""
    ov = list(ROUTE) + ([f"solver.levels={levels}"] if levels > 1 else [])
    return ov + ([f"mesh.nodes=[{nodes[0]},{nodes[1]}]"] if mesh_override else [])


def case_label(scene: str, nodes) -> str:
    return f"{scene}, {nodes[0]} x {nodes[1]}" if nodes else f"{scene}, default mesh"


def solve_case(scene: str, ov: list[str]) -> dict:
    """The record of one run (cached), with ``summary`` and ``loadavg``; ``crashed`` when the child failed."""
    from rftstatic.bench.drape import cached_dir, run_cached

    root = cache_root()
    fresh = cached_dir(scene, ov, root=root) is None
    if fresh and os.environ.get("RFTSTATIC_DRAPE_CACHED_ONLY") == "1":
        return {"scene": scene, "overrides": ov, "crashed": "not run (not in the cache, "
                                                            "RFTSTATIC_DRAPE_CACHED_ONLY=1)"}
    try:
        rec = run_cached(scene, ov, root=root, refresh=os.environ.get("RFTSTATIC_DRAPE_REFRESH") == "1",
                         figures=scene == ROUND, timeout=TIMEOUT_S)
    except RuntimeError as exc:  # ChildError / ChildTimeout: the child crashed or was killed
        text = str(exc).strip().splitlines()
        return {"scene": scene, "overrides": ov, "crashed": " ".join(text[:1] + text[-3:])[:600],
                "loadavg": list(os.getloadavg())}
    d = Path(rec["dir"])
    if fresh or not (d / LOADAVG).exists():
        la = {"loadavg": list(os.getloadavg()), "when": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
              "measured": "at the end of this run" if fresh else "when the report was built (run cached)"}
        (d / LOADAVG).write_text(json.dumps(la), encoding="utf-8")
    return attach(rec)


def attach(rec: dict) -> dict:
    """Add the run's ``summary`` (summary.json) and ``loadavg`` (loadavg.json, if any) to its record."""
    d = Path(rec["dir"])
    rec["summary"] = json.loads((d / "summary.json").read_text(encoding="utf-8"))
    la = d / LOADAVG
    rec["loadavg"] = json.loads(la.read_text(encoding="utf-8")) if la.exists() else None
    return rec


def _mesh(text) -> str:
    """``"[9, 64]"`` (a level's mesh) as ``9 x 64``."""
    s = str(text).strip()
    if s.startswith("["):
        return " x ".join(v.strip() for v in s.strip("[]").split(","))
    return s


def critical_summary(points: list) -> str:
    """Critical points by kind with their load factors, briefly: ``1 bifurcation (0.0092); 7 limit (0.033-0.84)``."""
    if not points:
        return "0"
    kinds = {}
    for p in points:
        kinds.setdefault(p["kind"], []).append(p["lam"])
    parts = []
    for kind, lams in kinds.items():
        lam = ", ".join(f"{v:.2g}" for v in lams) if len(lams) <= 3 else f"{min(lams):.2g}-{max(lams):.2g}"
        parts.append(f"{len(lams)} {kind} ({lam})")
    return "; ".join(parts)


def row_values(rec: dict, energy_unit: float) -> dict:
    """The report's numbers of one run: record (see :func:`rftstatic.bench.drape.child`) with ``summary``.

    ``energy_unit``: the scene's energy unit [J] (level energies are recorded in J, the summary's in
    scene units).
    """
    s = rec["summary"]
    path = s.get("path") or {}
    levels = s.get("levels") or []
    drape = s.get("drape") or {}
    if levels:
        meshes = " -> ".join(_mesh(lv["mesh"]) for lv in levels)
        its = " / ".join(f"{lv['iterations']}" + (" (path)" if lv.get("route") == "arc-length" else "")
                         for lv in levels)
        walls = " + ".join(f"{lv['wall_time_s']:.0f}" for lv in levels)
        energies = [lv["energy_J"] / energy_unit if lv.get("energy_J") is not None else float("nan")
                    for lv in levels]
    else:
        xy = (s.get("mesh") or {}).get("nodes_xy")
        meshes = f"{xy[0]} x {xy[1]}" if xy else f"{rec['nodes']} nodes"
        its, walls, energies = f"{s.get('newton_iterations', rec['newton_iterations'])} (path)", "", []
    la = rec.get("loadavg")
    return {"levels": max(1, len(levels)), "meshes": meshes, "nodes": rec["nodes"],
            "converged": bool(s.get("converged", rec["converged"])), "message": s.get("message") or rec.get("error"),
            "load_factor": s.get("load_factor", rec["load_factor"]), "stable": s.get("stable_minimum"),
            "route": s.get("route", ""), "steps": len(path.get("steps", [])),
            "critical": critical_summary(path.get("critical_points", [])),
            "switches": len(path.get("switches", [])), "descents": path.get("descents", 0),
            "final_negative": path.get("final_negative"), "iterations": its, "level_walls": walls,
            "level_energies": energies, "dc": drape.get("drape_coefficient"), "folds": drape.get("fold_count"),
            "fold_angles": drape.get("fold_angles_deg", []), "energy": (s.get("energies") or {}).get("total"),
            "wall": rec["build_s"] + rec["solve_s"], "process_s": rec.get("process_s"),
            "peak_mb": rec["peak_rss_mb"], "loadavg": la["loadavg"][0] if la else None,
            "loadavg_note": la.get("measured", "") if la else "not recorded",
            "code": (s.get("software") or {}).get("code", ""),
            "commit": _commit((s.get("software") or {}).get("git_commit"))}


def _commit(text) -> str:
    """A git commit as 12 hex digits, keeping ``+dirty`` (uncommitted changes in the package)."""
    head, _, dirty = str(text or "-").partition("+")
    return head[:12] + (f"+{dirty}" if dirty else "")


def _yes(v) -> str:
    return {True: "yes", False: "**NO**"}.get(v, "?")


def _f(v, fmt: str, dash: str = "-") -> str:
    return dash if v is None else format(v, fmt)


TABLE_HEAD = ("| scene, mesh | levels: meshes | converged | stable minimum | path steps | critical points "
              "(kind: load factors) | switches | descents | Newton iterations per level | DC | folds | "
              "energy [gf cm] | build + solve [s] (per level) | peak memory [MB] | load average at end |",
              "|" + "---|" * 15)


def table_line(label: str, v: dict) -> str:
    """One row of the route table from :func:`row_values`."""
    conv = "yes" if v["converged"] else f"**NO** (load factor {v['load_factor']:.4g})"
    walls = f"{v['wall']:.0f}" + (f" ({v['level_walls']})" if v["level_walls"] else "")
    return (f"| {label} | {v['levels']}: {v['meshes']} | {conv} | {_yes(v['stable']) if v['converged'] else '-'} | "
            f"{v['steps']} | {v['critical']} | {v['switches']} | {v['descents']} | {v['iterations']} | "
            f"{_f(v['dc'], '.4f')} | {_f(v['folds'], 'd')} | {_f(v['energy'], '.2f')} | {walls} | "
            f"{v['peak_mb']:.0f} | {_f(v['loadavg'], '.2f')} |")


def crashed_line(label: str, rec: dict) -> str:
    return f"| {label} | - | **NO** (run failed: {rec['crashed']}) |" + " - |" * 12


def row_passed(rec: dict) -> bool:
    """Converged and a stable minimum by the load-scaled route alone."""
    if "crashed" in rec:
        return False
    s = rec["summary"]
    return bool(s.get("converged")) and s.get("stable_minimum") is True and str(s.get("route", "")).startswith(
        "arc-length")


def solves_row(label: str, rec: dict, v: dict) -> dict:
    """A row of the report's "All solves" table (value: DC, folds, energy [gf cm])."""
    return {"case": f"{label} (load-scaled route)", "element": rec["element"], "mesh": v["meshes"],
            "nodes": rec["nodes"], "value": [v["dc"], v["folds"], v["energy"]], "reference": None,
            "error": float("nan"), "wall_time_s": v["wall"], "iterations": rec["newton_iterations"],
            "converged": v["converged"], "stable_minimum": v["stable"], "solver_error": v["message"],
            "peak_rss_mb": v["peak_mb"], "loadavg_1min": v["loadavg"], "code": v["code"], "commit": v["commit"],
            "run_dir": rec["dir"]}


def route_section(rows: list) -> str:
    """The route table (rows: (label, record, values or None)) with how each run was made."""
    lines = list(TABLE_HEAD)
    for label, rec, v in rows:
        lines.append(crashed_line(label, rec) if v is None else table_line(label, v))
    codes = sorted({f"{v['commit']} (code {v['code']})" for _, _, v in rows if v})
    notes = sorted({v["loadavg_note"] for _, _, v in rows if v})
    return ("Each run: the scene solved as `python -m rftstatic case SCENE --set solver.start=load-steps --set "
            "solver.continuation=arc-length --set solver.relax_fallback=false [--set solver.levels=L] [--set "
            "mesh.nodes=[..]]` does, in a fresh interpreter (the drape bench's run, `rftstatic.bench.drape.child`). "
            "*levels*: the path (arc-length, inertia, branch switches, descents) on the coarsest mesh, Newton at "
            "full load on each finer one; the Newton iterations of the path level are its corrector iterations. "
            "*critical points*: where the tangent's negative-pivot count changed (limit: the load factor turned "
            "back). *descents*: "
            "fixed-load descents beyond the largest load reached (snaps). Energy: bending + membrane + contact - "
            "work of the weight, in the scene's units (gf cm). Wall and memory on a 2-core machine shared with "
            "other jobs: the load average (1 min, `os.getloadavg()`) when the run ended is beside each.\n\n"
            + "\n".join(lines) + f"\n\nCode: {', '.join(codes) or '-'}. Load average: {'; '.join(notes) or '-'}.")


def comparison_section(path_recs: dict, relax_recs: dict) -> tuple[str, list]:
    """Round pedestal: folds, DC and energy of the load-scaled route beside the relaxation route and the paper.

    ``path_recs`` / ``relax_recs``: nodes -> record with ``summary``. Returns the Markdown and the
    meshes where a route found another fold count than the paper.
    """
    lines = ["| mesh | route | converged | stable minimum | folds | fold angles [deg] | DC | energy [gf cm] | "
             "energy - relaxation's [gf cm] | build + solve [s] |", "|" + "---|" * 10]
    differ = []
    for nodes in ROUND_MESHES:
        lab = f"{nodes[0]} x {nodes[1]}"
        relax_e = None
        if nodes in relax_recs and relax_recs[nodes]["summary"].get("converged"):
            relax_e = relax_recs[nodes]["summary"]["energies"]["total"]
        for route, recs in (("load-scaled (arc-length, levels)", path_recs),
                            ("relaxation, then Newton (scene default)", relax_recs)):
            rec = recs.get(nodes)
            if rec is None:
                lines.append(f"| {lab} | {route} | not run |" + " - |" * 7)
                continue
            s, d = rec["summary"], rec["summary"].get("drape", {})
            e = s["energies"]["total"]
            de = f"{e - relax_e:+.2f}" if relax_e is not None and recs is path_recs else "-"
            lines.append(f"| {lab} | {route} | {_yes(bool(s.get('converged')))} | {_yes(s.get('stable_minimum'))} | "
                         f"{d.get('fold_count')} | {', '.join(f'{a:.0f}' for a in d.get('fold_angles_deg', []))} | "
                         f"{d.get('drape_coefficient', float('nan')):.4f} | {e:.2f} | {de} | "
                         f"{rec['build_s'] + rec['solve_s']:.0f} |")
            if s.get("converged") and d.get("fold_count") != PAPER_FOLDS:
                differ.append((lab, route, d.get("fold_count")))
        lines.append(f"| {lab} | Sze & Zhou (2016) §4.4, Fig. 10 (RFT6) | - | - | {PAPER_FOLDS} | - | - | - | - | - |")
    text = ("The issue's item 3: the fold count of the load-scaled route on the paper's meshes next to the "
            "relaxation route's (the scene's default start, the runs of `drape_folds`) and the paper's. The paper "
            "reports the fold count only (no DC, no energy). Energies compare between routes of one model "
            "(same mesh, element and obstacle).\n\n" + "\n".join(lines))
    return text, differ


def exact_paths_section() -> str:
    """Static text: the exact-path checks live in the test suite, not in this benchmark's runs."""
    return (
        "Not run by this benchmark: these are tests (`tests/solvers/test_continuation.py`, < 5 s, run by "
        "`pytest`), and the table below is the explanatory text of the hand-written report they replaced "
        "(numbers measured by those tests when it was written; the tests assert them within their tolerances).\n\n"
        "| problem | quantity | arc-length | exact |\n|---|---|---|---|\n"
        "| sparse symmetric matrices (2-D Laplacian 12 x 11 shifted, random) | negative pivots | = | number of "
        "negative eigenvalues (dense) |\n"
        "| same | 3 eigenvalues nearest 0 (shift-invert Lanczos with the L D L^T) | to 1e-8 | dense |\n"
        "| wool strip 5 x 1 cm, 21 x 5 nodes, pinned ends, end load 1.5 x Euler's | critical point | bifurcation, "
        "0 -> 1 negative pivots, lam x 1.5 = 0.99998 | 1 (pi^2 B / L^2) |\n"
        "| same | switch | both halves stable, energies equal to 1e-6 | symmetric branch |\n"
        "| same | midspan deflection at full load | 1.9768 cm | 1.9714 cm (pinned elastica, P / P_cr = 1.5) |\n"
        "| von Mises truss (one free dof), load 1.5 x its limit load | critical point | limit, located to 2e-3 "
        "in lam | max of lam(u) = -f(u) / P |\n"
        "| same | end state | inverted branch, u to 1e-8, stable | root of -f(u) = P, u < -2h |")


def run(quick: bool = False, *, out=None) -> BenchmarkResult:
    from rftstatic.scenes.schema import load_scene

    result = BenchmarkResult(
        name="path_following", title="Path following from the flat sheet: the load-scaled route alone (issue 17)",
        citation="Sze & Zhou (2016) §4 (load-scaled Newton from the flat sheet); §4.4: 12 folds",
        reference="Sze & Zhou (2016) solve every static drape of §4 by Newton with the load scaled up from the flat "
                  "sheet, without dynamic relaxation; §4.4, Fig. 10: the 50 x 50 cm sheet on the 20 cm round "
                  "pedestal has 12 folds with RFT6 on both 21 x 160 and 31 x 240 nodes.",
        tolerance="every scene converges to a stable minimum (Cholesky of the exact tangent) by the load-scaled "
                  "route alone (arc-length path, branch switches, fixed-load descents, Newton on finer levels; no "
                  f"explicit or damped stage). The paper's {PAPER_FOLDS} folds on the round pedestal are compared, "
                  "and a different count is stated as a difference from the paper.")
    rows, path_recs = [], {}
    for scene, nodes, mesh_override, levels in (QUICK if quick else FULL):
        label = case_label(scene, nodes)
        rec = solve_case(scene, overrides(nodes, mesh_override, levels))
        if "crashed" in rec:
            rows.append((label, rec, None))
            result.notes.append(f"NOT CONVERGED (run failed): {label}: {rec['crashed']}")
            continue
        v = row_values(rec, load_scene(scene, rec["overrides"]).units.energy)
        rows.append((label, rec, v))
        result.rows.append(solves_row(label, rec, v))
        if scene == ROUND:
            path_recs[nodes] = rec
        if not v["converged"]:
            result.notes.append(f"NOT CONVERGED: {label}: {v['message']}")
        elif v["stable"] is not True:
            result.notes.append(f"NOT A STABLE MINIMUM: {label} (stable_minimum = {v['stable']}).")
    result.sections.append(("The load-scaled route on the §4 drape scenes", route_section(rows)))
    relax_recs = {}
    for nodes in ROUND_MESHES:  # the scene's default route: the runs drape_folds uses
        rec = run_cached_only(ROUND, nodes, "RFT6") if quick else drape_run(ROUND, nodes, "RFT6")
        if rec is not None:
            relax_recs[nodes] = attach(rec)
    text, differ = comparison_section(path_recs, relax_recs)
    result.sections.append(("Round pedestal (§4.4): fold count by route", text))
    result.sections.append(("Exact paths (tests, not this benchmark's runs)", exact_paths_section()))
    if out is not None:
        for nodes, rec in path_recs.items():
            result.figures += copy_views(rec, Path(out), f"path_following_{mesh_label(nodes)}", views=("top",))
        if path_recs or relax_recs:
            result.figures.append(_profiles(Path(out), path_recs, relax_recs))
    result.finish()
    result.passed = bool(rows) and all(row_passed(rec) for _, rec, _ in rows)
    if differ:
        result.discrepancy = (f"the paper's {PAPER_FOLDS} folds on the round pedestal are not reproduced: "
                              + "; ".join(f"{route} on {lab}: {n} folds" for lab, route, n in differ)
                              + " (the comparison table has each branch's energy; `drape_folds` the other starts).")
    if quick:
        result.notes.append("Quick mode: pedestal-square-20 33 x 33 and sphere-30 17 x 17 only; the relaxation runs "
                            "of the round pedestal are shown only if cached.")
    return result


def _profiles(out: Path, path_recs: dict, relax_recs: dict) -> str:
    """r(theta) of the round pedestal's boundary, both routes on both meshes (drape_folds' plot)."""
    from rftstatic.validate.drape_folds import _profiles as fold_profiles

    recs = {f"{mesh_label(n)} load-scaled": r for n, r in path_recs.items()}
    recs.update({f"{mesh_label(n)} relaxation": r for n, r in relax_recs.items()})
    return fold_profiles(out, recs, name="path_following_round_profiles.png",
                         title="Round pedestal: boundary radius by route (load-scaled vs relaxation)")
