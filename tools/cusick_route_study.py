"""Route study of the Cusick drape tester (issue 35 item 3): which drape the static routes find on cusick-30,
with what energy, over seeds, imperfection amplitudes, fabrics and model changes. Writes
``validation/cusick_route.md`` and ``validation/cusick_route.json``.

Usage::

    PYTHONPATH=$PWD python tools/cusick_route_study.py [--out DIR] [--study NAME ...] [--seeds N]

Each row solves cusick-30 in this process (``rftstatic.solvers.static.solve_static`` on the scene's model with
``--set``-style overrides) and records the drape coefficient, the fold count, the total potential energy
(bending + membrane - work of the weight, at the converged equilibrium, [mJ]), the route's explicit steps and
Newton iterations, whether the equilibrium is a stable minimum (Cholesky of the exact tangent) and the solve's
wall time (model built, numba warm). Every drape compared by energy is a converged stable equilibrium of the
same model, so a lower energy is a better minimum of the same problem.

Studies:

- ``routes``: the wool (Kang & Yu) by the load steps (quasi-static gravity ramp from the flat sheet, Newton
  path following through the snap-throughs) and by dynamic relaxation at full load (the sheet dropped flat, then
  Newton), each from seeded smooth lifts of 0.01, 0.3 and 1 mean element sizes (``solver.perturbation``);
- ``fabrics``: the library's ``ctd-*`` fabrics and the wool with its rigidities scaled, both routes;
- ``branches``: the load steps from an n-fold lift of 1 element size (``solver.perturbation_folds = n``), n = 3 to
  12: which fold counts are stable equilibria of the wool and their energies (one route, so the energies
  compare the branches themselves);
- ``soft``: the relaxation run with the membrane rigidity x 0.1 (``build_model(..., membrane_scale=0.1)``: a
  sqrt(10) times longer stable step), then Newton at full load on the true model from its rest
  (``StaticOptions.from_state``): a candidate route, compared with the two above on the same fabrics;
- ``release``: the release route (``solver.start = "release"``: the sheet at full weight on a support plane lowered
  step by step, Newton at each height, :mod:`rftstatic.solvers.release`) on the wool and a limp fabric (the wool's
  rigidities x 0.25), over ``--seeds`` seeds at the scene's lift and at 0.3 element sizes, the wool at a smaller
  lowering step (``solver.release_step``), which a quasi-static route must not depend on, and on coarser meshes;
- ``causes``: one change at a time (isotropic bending, the alternate diagonal pattern, a ten times stiffer
  in-plane shear, a ten times softer membrane), both routes, to find what sets the fold count.
"""

import argparse
import json
import logging
import sys
import time
from pathlib import Path

import numpy as np

from rftstatic import api
from rftstatic.errors import ConvergenceError
from rftstatic.io.summary import drape_summary
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import static_options
from rftstatic.solvers.static import solve_static

SCENE = "cusick-30"
ROUTES = {"load steps": ["solver.start=load-steps"], "relaxation": ["solver.start=relax"]}
AMPLITUDES = [0.01, 0.3, 1.0]
WOOL = {"B_warp": 0.083, "B_weft": 0.063, "B_twist": 0.027}  # gf cm (cases/cusick-30.toml's preset)
FABRICS = [("wool, B x 0.25", [f"material.{k}={v * 0.25}" for k, v in WOOL.items()]),
           ("wool", []),
           ("wool, B x 4", [f"material.{k}={v * 4}" for k, v in WOOL.items()]),
           ("ctd-350-heavy-soft", ["material.preset=ctd-350-heavy-soft"]),
           ("ctd-213-medium", ["material.preset=ctd-213-medium"]),
           ("ctd-367-heavy-stiff", ["material.preset=ctd-367-heavy-stiff"]),
           ("ctd-12-light-stiff", ["material.preset=ctd-12-light-stiff"])]
RELEASE_ROUTE = {"release": ["solver.start=release"]}
LIMP = [f"material.{k}={v * 0.25}" for k, v in WOOL.items()]
RELEASE_CASES = [("wool", []), ("wool, B x 0.25", LIMP),
                 ("wool, lift 0.3 element sizes", ["solver.perturbation=0.3"]),
                 ("wool, B x 0.25, lift 0.3 element sizes", [*LIMP, "solver.perturbation=0.3"]),
                 ("wool, lowering step 0.5 element sizes", ["solver.release_step=0.5"]),
                 ("wool, lowering step 0.2 element sizes", ["solver.release_step=0.2"]),
                 ("wool, lowering step 0.1 element sizes", ["solver.release_step=0.1"]),
                 ("wool, B x 0.25, lowering step 0.5 element sizes", [*LIMP, "solver.release_step=0.5"]),
                 ("wool, B x 0.25, lowering step 0.2 element sizes", [*LIMP, "solver.release_step=0.2"]),
                 ("wool, mesh 7 x 80", ["mesh.nodes=[7,80]"]), ("wool, mesh 10 x 120", ["mesh.nodes=[10,120]"])]
CAUSES = [("as the scene", []),
          ("isotropic bending (B_weft = B_warp, B_twist = B_warp / 2)", ["material.B_weft=0.083", "material.B_twist=0.0415"]),
          ("alternate diagonal pattern", ["mesh.pattern=alternate"]),
          ("in-plane shear x 10", ["material.C_shear=418.0"]),
          ("membrane x 0.1", ["material.C_warp=111.82", "material.C_weft=75.95", "material.C_shear=4.18"])]


def solve(sets: list) -> dict:
    """One cusick-30 solve with the overrides ``sets``: its drape, energy [mJ] and cost."""
    scene = api.load_scene(SCENE, sets)
    model, extras = build_model(scene)
    opts = static_options(scene, progress=False)
    t0 = time.perf_counter()
    try:
        res, ok, error = solve_static(model, options=opts), True, None
    except ConvergenceError as exc:
        res, ok, error = exc.result, False, str(exc)[:200]
    wall = time.perf_counter() - t0
    row = {"sets": sets, "converged": ok and res is not None and bool(res.converged), "error": error, "time_s": wall}
    if res is None:
        return row
    drape = drape_summary(scene, model, extras, res.U)
    energy = res.energies or {}
    row.update(dc=drape.get("drape_coefficient_percent"), folds=drape.get("fold_count"),
               fold_angles=drape.get("fold_angles_deg"), energy_mJ=1e3 * energy.get("total", np.nan),
               bending_mJ=1e3 * energy.get("bending", np.nan), membrane_mJ=1e3 * energy.get("membrane", np.nan),
               route=res.route, explicit_steps=(res.relax or {}).get("steps", 0), newton=res.iterations,
               route_steps=len(res.load_steps),
               stable=res.stable)
    return row


LOG = None
"""Where each row is appended as it is solved (JSON lines), so an interrupted study keeps its rows."""


def _keep(row: dict):
    if LOG is not None:
        with open(LOG, "a") as f:
            f.write(json.dumps(row, default=str) + "\n")


SOFT_MEMBRANE = 0.1
"""Membrane factor of the ``soft`` study's relaxation."""


def soft_then_newton(sets: list) -> dict:
    """Relax the model with its membrane x :data:`SOFT_MEMBRANE`, then Newton on the true model from there."""
    scene = api.load_scene(SCENE, [*sets, "solver.start=relax"])
    model, extras = build_model(scene)
    soft, _ = build_model(scene, quiet=True, membrane_scale=SOFT_MEMBRANE)
    opts = static_options(scene, progress=False)
    t0 = time.perf_counter()
    try:
        settled = solve_static(soft, options=opts)
        t1 = time.perf_counter()
        res = solve_static(model, U0=settled.U, options=opts.from_state())
    except ConvergenceError as exc:
        return {"sets": sets, "converged": False, "error": str(exc)[:200], "time_s": time.perf_counter() - t0}
    wall = time.perf_counter() - t0
    drape = drape_summary(scene, model, extras, res.U)
    return {"sets": sets, "converged": bool(res.converged), "error": None, "time_s": wall, "settle_time_s": t1 - t0,
            "dc": drape.get("drape_coefficient_percent"), "folds": drape.get("fold_count"),
            "fold_angles": drape.get("fold_angles_deg"), "energy_mJ": 1e3 * res.energies["total"],
            "route": f"relax (membrane x {SOFT_MEMBRANE:g}) + newton", "explicit_steps": settled.relax.get("steps", 0),
            "newton": settled.iterations + res.iterations, "stable": res.stable}


def _runs(label: str, sets: list, seeds: list, rows: list, study: str, routes=None):
    for seed in seeds:
        for route, rsets in (routes or ROUTES).items():
            r = solve([*sets, *rsets, f"solver.seed={seed}"])
            r.update(study=study, case=label, route_name=route, seed=seed)
            rows.append(r)
            _keep(r)
            print(json.dumps({k: r.get(k) for k in ("study", "case", "route_name", "seed", "dc", "folds",
                                                     "energy_mJ", "explicit_steps", "newton", "route_steps", "stable", "time_s")}), flush=True)


def study_rows(studies, seeds: int, cases=None) -> list:
    rows = []
    if "routes" in studies:
        for a in AMPLITUDES:
            _runs(f"wool, lift {a:g} element sizes", [f"solver.perturbation={a}"], list(range(1, seeds + 1)), rows,
                  "routes")
    if "fabrics" in studies:
        for label, sets in FABRICS:
            if cases is None or label in cases:
                _runs(label, sets, list(range(1, min(seeds, 2) + 1)), rows, "fabrics")
    if "branches" in studies:
        for n in range(3, 13):
            r = solve(["solver.start=load-steps", "solver.perturbation=1.0", f"solver.perturbation_folds={n}"])
            r.update(study="branches", case=f"wool, {n}-fold lift", route_name="load steps", seed=1)
            rows.append(r)
            _keep(r)
            print(json.dumps({k: r.get(k) for k in ("case", "dc", "folds", "energy_mJ", "time_s")}), flush=True)
    if "soft" in studies:
        for label, sets in FABRICS:
            if cases is None or label in cases:
                r = soft_then_newton(sets)
                r.update(study="soft", case=label, route_name=f"soft settle x {SOFT_MEMBRANE:g} + Newton", seed=1)
                rows.append(r)
                _keep(r)
                print(json.dumps({k: r.get(k) for k in ("case", "dc", "folds", "energy_mJ", "explicit_steps",
                                                         "time_s")}), flush=True)
    if "release" in studies:
        for label, sets in RELEASE_CASES:
            if cases is None or label in cases:
                _runs(label, sets, list(range(1, seeds + 1)), rows, "release", routes=RELEASE_ROUTE)
    if "causes" in studies:
        for label, sets in CAUSES:
            if cases is None or label in cases:
                _runs(label, sets, [1], rows, "causes")
    return rows


def _fmt(x, spec):
    return "" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, spec)


def table(rows: list) -> list:
    """Markdown: one line per (case, route) with the fold counts, DC range and the lowest energy over seeds."""
    lines = ["| case | route | seeds | fold counts | DC [%] | energy [mJ] (lowest: folds, DC) | explicit steps | "
             "Newton iterations | stable | solve time [s] |", "|" + "---|" * 10]
    keys = list(dict.fromkeys((r["case"], r["route_name"]) for r in rows))
    for case, route in keys:
        rs = [r for r in rows if r["case"] == case and r["route_name"] == route]
        good = [r for r in rs if r["converged"]]
        if not good:
            lines.append(f"| {case} | {route} | {len(rs)} | not converged: {rs[0].get('error')} | | | | | | |")
            continue
        best = min(good, key=lambda r: r["energy_mJ"])
        dcs = [r["dc"] for r in good]
        lines.append(
            f"| {case} | {route} | {len(rs)} | {', '.join(str(r['folds']) for r in good)} | "
            f"{min(dcs):.2f}-{max(dcs):.2f} | {min(r['energy_mJ'] for r in good):.4f} .. "
            f"{max(r['energy_mJ'] for r in good):.4f} ({best['folds']}, {best['dc']:.2f}) | "
            f"{_fmt(float(np.mean([r['explicit_steps'] for r in good])), '.0f')} | "
            f"{_fmt(float(np.mean([r['newton'] for r in good])), '.0f')} | "
            f"{all(bool(r['stable']) for r in good)} | "
            f"{_fmt(float(np.mean([r['time_s'] for r in rs])), '.1f')} |")
    return lines


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default=str(Path(__file__).resolve().parent.parent / "validation"))
    p.add_argument("--study", action="append", choices=["routes", "fabrics", "branches", "soft", "release",
                                                              "causes"])
    p.add_argument("--seeds", type=int, default=5, help="seeds of the routes study (the fabrics study: at most 2)")
    p.add_argument("--case", action="append", help="only these cases of the fabrics and causes studies (labels)")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    studies = args.study or ["routes", "fabrics", "branches", "soft", "causes"]
    t0 = time.perf_counter()
    out = Path(args.out)
    global LOG
    LOG = out / "cusick_route.jsonl"
    rows = study_rows(studies, args.seeds, args.case)
    (out / "cusick_route.json").write_text(json.dumps({"scene": SCENE, "rows": rows}, indent=1, default=str))
    print("\n".join(table(rows)))
    print(f"\n{len(rows)} solves, {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
