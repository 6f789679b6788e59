"""Self-contact: the sheet never passes through itself (issue "Self-contact"; ``validate self_contact``).

Each scene runs twice, one run after the other in fresh interpreters (:func:`rftstatic.bench.harness.run_child`,
the CLI's :func:`rftstatic.api.run` without figures), with ``contact.self = false`` and ``= true``. The
judge is the independent crossing check of every run's summary.json (``self_intersections``:
:mod:`rftstatic.post.measures.intersections`, which shares no code with the contact law): the number of
crossing triangle pairs and the smallest distance between triangles that share no node.

Scenes (:data:`SCENES`): those where layers meet -- the 80 cm sheet on the 40 cm pedestal (§4.3, Fig. 8:
its corner folds cross without self-contact), the 50 cm sheet over the sphere on a floor, the coarse
RFT3 meshes the paper discusses (17 x 17 sphere, 372-node round pedestal, §4.5 "self-penetrations"),
the sheet dropped onto a post on the floor (explicit dynamics) and the 100 cm hanging sheet (§4.6) --
and paper scenes whose layers never touch (pedestal-square-20 33 x 33, sphere-30 61 x 61, hang-20),
whose drape must not change.

Tolerance (issue "Self-contact", "Done when"), with ``self = true``: 0 crossing pairs and a smallest
distance >= 0.5 d (d the contact thickness) on every scene; a static scene converged to a stable
minimum; on scenes whose layers never touch the same drape (drape coefficient within
:data:`DC_TOL`, the same fold count) and a wall time at most :data:`RATIO_APART` x that without
self-contact; on pedestal-square-80 at most :data:`RATIO_SQ80` x. The cost of the broad phase and of
the contact force is reported against one evaluation of the element (bending + membrane) force.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from rftstatic.validate.report import BenchmarkResult

# label -> (scene, overrides, layers touch, quick overrides)
SCENES = {
    "pedestal-square-80 81x81 RFT6": ("pedestal-square-80", [], True, ["mesh.nodes=[31,31]"]),
    "sphere-floor 51x51 RFT6": ("sphere-floor", [], True, ["mesh.nodes=[21,21]"]),
    "sphere-30 17x17 RFT3": ("sphere-30", ["element=RFT3", "mesh.nodes=[17,17]"], True, []),
    "pedestal-round-50-unstructured RFT3": ("pedestal-round-50-unstructured", ["element=RFT3"], True, []),
    "drop-floor 41x41 RFT6": ("drop-floor", [], True, ["mesh.nodes=[21,21]"]),
    "hang-100 RFT6": ("hang-100", [], True, ["mesh.nodes=[21,21]"]),
    "pedestal-square-20 33x33 RFT6": ("pedestal-square-20", [], False, ["mesh.nodes=[17,17]"]),
    "sphere-30 61x61 RFT6": ("sphere-30", [], False, ["mesh.nodes=[21,21]"]),
    "hang-20 41x41 RFT6": ("hang-20", [], False, ["mesh.nodes=[15,15]"]),
}
DC_TOL = 0.003          # |DC(self) - DC(no self)| on scenes whose layers never touch [-]
RATIO_APART = 1.5       # wall time with / without self-contact, layers apart
RATIO_SQ80 = 3.0        # the same on pedestal-square-80
DEFAULT_THICKNESS = 0.05  # [cm], the scenes' contact thickness when none is given (scenes.build)
TIMEOUT_S = 3600.0


def run_case(name: str, overrides: list[str]) -> dict:
    """Child: ``python -m rftstatic case NAME --set ... --no-figures`` (:func:`rftstatic.api.run`); its
    summary (scene units) and the element and broad-phase costs at the final state [s]."""
    from rftstatic.api import run
    from rftstatic.errors import ConvergenceError, InstabilityError

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        try:
            res = run(name, f"{tmp}/out", overrides=overrides, figures=False)
            summary, model, U = res.summary, res.model, res.U
        except (ConvergenceError, InstabilityError) as exc:  # the summary of the failed run was written
            summary = json.loads((Path(tmp) / "out" / "summary.json").read_text()) if (
                Path(tmp) / "out" / "summary.json").exists() else {"converged": False, "message": str(exc)}
            return {"summary": summary, "run_s": time.perf_counter() - t0}
        run_s = time.perf_counter() - t0
    costs = {"element_force_s": _median_time(lambda: model.internal_force(U))}
    if getattr(model, "self_contact", None) is not None:
        from rftstatic.contact.self_contact.broad_phase import find_pairs

        x = model.positions(U)
        sc = model.self_contact
        costs["broad_phase_build_s"] = _median_time(lambda: find_pairs(sc.prims, x, sc.thickness + sc.margin))
    return {"summary": summary, "run_s": run_s, "costs": costs}


def _median_time(f, repeat: int = 5) -> float:
    """Median wall time of ``f()`` over ``repeat`` calls [s]."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def _child(scene, overrides, label):
    from rftstatic.bench.harness import ChildError, run_child

    try:
        return run_child("rftstatic.validate.self_contact:run_case", {"name": scene, "overrides": overrides},
                         name=f"self_contact {label}", timeout=TIMEOUT_S)
    except ChildError as exc:
        return exc


def _record(run) -> dict:
    """One run's row fields from its child (or the child's error)."""
    if not hasattr(run, "result"):
        return {"failed": str(run)}
    s = run.result["summary"]
    si = s.get("self_intersections") or {}
    drape = s.get("drape") or {}
    sc = s.get("self_contact") or {}
    return {"converged": s.get("converged"), "stable": s.get("stable_minimum"), "pairs": si.get("pairs"),
            "max_pairs_saved": si.get("max_pairs_saved"), "smallest_distance": si.get("smallest_distance"),
            "dc": drape.get("drape_coefficient"), "folds": drape.get("fold_count"),
            "energy": (s.get("energies") or {}).get("total"), "wall_s": run.wall_s, "cpu_s": run.cpu_s,
            "load": os.getloadavg()[0],
            "thickness": sc.get("thickness"), "broad_phase_s": sc.get("broad_phase_s"), "force_s": sc.get("force_s"),
            "rebuilds": sc.get("rebuilds"), "near_pairs": sc.get("max_pairs"),
            "costs": run.result.get("costs", {}), "analysis": s.get("analysis"), "nodes": s.get("nodes")}


def run(quick: bool = False, *, out=None) -> BenchmarkResult:
    result = BenchmarkResult(
        name="self_contact", title="Self-contact: crossings and smallest distance with and without it",
        citation="issue: self-contact",
        reference="the independent crossing check of summary.json (rftstatic.post.measures.intersections); "
                  "without self-contact pedestal-square-80 81 x 81 had 356 crossing pairs, the sphere on a floor 72, "
                  "sphere-30 RFT3 17 x 17 29, the 372-node round pedestal RFT3 33",
        tolerance=f"self = true: 0 crossing pairs, smallest distance >= 0.5 d, static runs converged and stable; "
                  f"layers apart: DC within {DC_TOL:g} and the same folds as without, wall time <= {RATIO_APART:g} x; "
                  f"pedestal-square-80 <= {RATIO_SQ80:g} x" + (" (quick: coarse meshes, reported only)" if quick else ""))
    rows = []
    for label, (scene, over, touching, quick_over) in SCENES.items():
        over = over + (quick_over if quick else [])
        off = _record(_child(scene, over + ["contact.self=false"], label + " off"))
        on = _record(_child(scene, over + ["contact.self=true"], label + " on"))
        rows.append(_row(label, touching, off, on, quick, result))
    result.rows = rows
    result.passed = all(r["verdict"] == "pass" for r in rows) or quick
    result.sections.append(("Runs", _table(rows)))
    result.sections.append(("Cost of the self-contact", _cost_table(rows)))
    return result


def _row(label, touching, off, on, quick, result) -> dict:
    """Compare the two runs of one scene; the verdict and its reasons."""
    reasons = []
    if "failed" in on or "failed" in off:
        reasons.append(f"a run failed: {on.get('failed') or off.get('failed')}")
    else:
        d = on["thickness"] if on["thickness"] is not None else DEFAULT_THICKNESS
        if on["pairs"] != 0:
            reasons.append(f"{on['pairs']} crossing pairs with self-contact")
        if on["max_pairs_saved"]:
            reasons.append(f"{on['max_pairs_saved']} crossing pairs in a saved state")
        dist = on["smallest_distance"]
        if dist is not None and dist < 0.5 * d:
            reasons.append(f"smallest distance {dist:.3g} < 0.5 d = {0.5 * d:.3g}")
        if on["analysis"] == "static" and not (on["converged"] and on["stable"] is not False):
            reasons.append(f"static run converged {on['converged']}, stable {on['stable']}")
        ratio = on["wall_s"] / off["wall_s"]
        limit = RATIO_APART if not touching else (RATIO_SQ80 if label.startswith("pedestal-square-80") else None)
        if limit is not None and ratio > limit:
            reasons.append(f"wall time ratio {ratio:.2f} > {limit:g}")
        if not touching and on["dc"] is not None and off["dc"] is not None:
            if abs(on["dc"] - off["dc"]) > DC_TOL or on["folds"] != off["folds"]:
                reasons.append(f"drape changed: DC {off['dc']:.4f} -> {on['dc']:.4f}, folds {off['folds']} -> {on['folds']}")
    verdict = "pass" if not reasons else ("reported" if quick else "FAIL")
    if reasons:
        result.notes.append(f"{label}: " + "; ".join(reasons))
    element = "RFT3" if "RFT3" in label else "RFT6"
    return {"case": label, "touching": touching, "off": off, "on": on, "verdict": verdict, "reasons": reasons,
            # the index's columns: value = crossing pairs with self-contact, reference = without
            "element": element, "mesh": "-", "nodes": on.get("nodes"), "value": on.get("pairs"),
            "reference": off.get("pairs"), "error": float("nan"), "wall_time_s": on.get("wall_s", float("nan")),
            "iterations": "-"}


def _f(v, fmt):
    return "-" if v is None else format(v, fmt)


def _table(rows) -> str:
    head = ("Wall time is what the tolerance is about; the child's CPU time (user + system) and the machine's load "
            "average at its end stand beside it, since on a shared machine the wall time moves with the other jobs' "
            "load.\n\n| scene | layers meet | self | converged | stable | crossing pairs (max saved) | smallest distance [cm] "
            "| DC | folds | energy [gf cm] | wall [s] | ratio | CPU [s] (ratio) | load | verdict |\n|" + "---|" * 15 + "\n")
    lines = []
    for r in rows:
        for key in ("off", "on"):
            x = r[key]
            if "failed" in x:
                lines.append(f"| {r['case']} | {'yes' if r['touching'] else 'no'} | {key} | failed: {x['failed'][:80]} |"
                             + " |" * 11)
                continue
            ratio = (r["on"]["wall_s"] / r["off"]["wall_s"]) if key == "on" and "failed" not in r["off"] else None
            cpu = f"{x['cpu_s']:.1f}" + (f" ({x['cpu_s'] / r['off']['cpu_s']:.2f})" if ratio is not None else "")
            saved = f" ({x['max_pairs_saved']})" if x.get("max_pairs_saved") is not None else ""
            lines.append(f"| {r['case']} | {'yes' if r['touching'] else 'no'} | {key} | {x['converged']} | {x['stable']} | "
                         f"{x['pairs']}{saved} | {_f(x['smallest_distance'], '.3g')} | {_f(x['dc'], '.4f')} | "
                         f"{_f(x['folds'], 'd')} | {_f(x['energy'], '.2f')} | {x['wall_s']:.1f} | {_f(ratio, '.2f')} | {cpu} | "
                         f"{x['load']:.1f} | "
                         f"{r['verdict'] if key == 'on' else ''} |")
    return head + "\n".join(lines) + "\n"


def _cost_table(rows) -> str:
    head = ("One element (bending + membrane) force evaluation and one broad-phase build at the final state "
            "(median of 5, in the child after its run), and the run's totals from summary.json "
            "(`self_contact`: broad-phase builds and their time, the self-contact force/tangent time).\n\n"
            "| scene | nodes | element force [ms] | broad phase build [ms] | build / element force | rebuilds | "
            "broad phase total [s] | self-contact force total [s] | near pairs (max) | wall [s] |\n|" + "---|" * 10 + "\n")
    lines = []
    for r in rows:
        x = r["on"]
        if "failed" in x:
            continue
        c = x["costs"]
        el, bp = c.get("element_force_s"), c.get("broad_phase_build_s")
        lines.append(f"| {r['case']} | {x['nodes']} | {_f(el and 1e3 * el, '.2f')} | {_f(bp and 1e3 * bp, '.1f')} | "
                     f"{_f(bp / el if el and bp else None, '.2f')} | {_f(x['rebuilds'], 'd')} | "
                     f"{_f(x['broad_phase_s'], '.2f')} | {_f(x['force_s'], '.2f')} | {_f(x['near_pairs'], 'd')} | "
                     f"{x['wall_s']:.1f} |")
    return head + "\n".join(lines) + "\n"
