"""Newton benchmark: ``python -m rftstatic bench newton``.

Prints, for each problem, the Newton iterations, load increments, factorisations, the solve's wall time
(first solve in a fresh process: one-time costs such as loading compiled kernels included; for the
strips also a second, warm solve in the same process with the compiled kernels, as a study's later
runs) and the whole process (interpreter start, imports, build, solve, outputs without figures), every run
in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`) one after the other, so that the
figures of one table come from one run on one machine state, every child on one thread (:data:`ONE_THREAD`:
``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS``, ``NUMBA_NUM_THREADS`` = 1; Kratos also
``ParallelUtilities.SetNumThreads(1)``), so that the ratio to the peer is stable on a shared machine:

- the §4.1 wool strip (5 x 1 cm, RFT6) at 51 x 11 and 101 x 21 nodes, and at 101 x 5 nodes, the
  mesh whose tip-drop error (0.015 %) equals Kratos's on 51 x 11 (the error depends on the nodes
  along the strip only);
- the 21 x 5 stiff strip cells of the stability matrix, RFT3 and RFT6, C/B = 1e2 to 1e9 /cm^2;
- ``pedestal-square-20`` at 33 x 33 nodes (the scene as it ships: relaxation, then Newton);
- the peer: Kratos Multiphysics (:mod:`rftstatic.bench.kratos_peer`, one OpenMP thread) on the
  strip at 51 x 11 nodes in 5 increments, when it is installed.

Targets: the 51 x 11 strip in at most 40 iterations; the stiff cells within 3 x the iterations of the
C/B = 1e2 cell; at equal error, both on one thread, the solve at least 5 x faster than Kratos's and the whole
process at least 2 x (issue 34).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

STRIPS = ((51, 11), (101, 21), (101, 5))
TARGETS = ("Targets: the 51 x 11 strip in at most 40 iterations; the stiff cells within 3 x the iterations of the "
           "C/B = 1e2 cell (RFT3 and RFT6); at equal error, both on one thread, the solve at least 5 x faster than "
           "Kratos's and the whole process at least 2 x (issue 34).")
RATIOS = (1e2, 1e5, 1e7, 1e8, 1e9)
TIMEOUT_S = 600.0


def strip_solve(nx: int, ny: int, element: str = "RFT6", ratio: float | None = None, warm: bool = False) -> dict:
    """Child: build and solve the §4.1 strip (``ratio``: C/B [1/cm^2], None: wool); iterations,
    increments, factorisations, times [s], the tip drop [cm] and its error against 4.34468 cm.
    ``warm``: also ``warm_solve_s``, the same solve again with the compiled kernels loaded and warm."""
    import numpy as np

    from rftstatic.bench.problems import STRIP_LENGTH, strip_model
    from rftstatic.solvers import static

    t0 = time.perf_counter()
    model = strip_model(nx, ny, element=element, ratio=ratio)
    t1 = time.perf_counter()
    res = static.solve_static(model, options=static.StaticOptions(progress=False))
    t2 = time.perf_counter()
    tip = np.flatnonzero(np.abs(model.mesh.X[:, 0] - STRIP_LENGTH) < 1e-9 * STRIP_LENGTH)
    drop_cm = -100.0 * float(res.U[tip, 2].mean())
    out = {"converged": res.converged, "iterations": res.iterations, "increments": len(res.load_steps),
           "factorisations": res.factorisations, "build_s": t1 - t0, "solve_s": t2 - t1,
           "tip_drop_cm": drop_cm, "error": drop_cm / 4.34468 - 1.0, "dofs": int(model.free.sum())}
    if warm:  # a later solve in the same process, compiled kernels loaded (a study's second run)
        from rftstatic.compiled import numba_available

        if numba_available():
            import rftstatic.element._kernels_numba  # noqa: F401

        static.solve_static(model, options=static.StaticOptions(progress=False))
        t3 = time.perf_counter()
        static.solve_static(model, options=static.StaticOptions(progress=False))
        out["warm_solve_s"] = time.perf_counter() - t3
    return out


def case_process(name: str, overrides: list[str]) -> dict:
    """Child: run scene ``name`` with ``overrides`` as ``python -m rftstatic case NAME --set ...
    --no-figures`` does (:func:`rftstatic.api.run`); its iterations and times."""
    from rftstatic.api import run

    with tempfile.TemporaryDirectory() as tmp:
        summary = run(name, f"{tmp}/out", overrides=overrides, figures=False).summary
    return {"iterations": summary.get("newton_iterations"), "increments": summary.get("load_steps"),
            "factorisations": summary.get("factorisations"), "solve_s": summary.get("wall_time_s"),
            "build_s": summary.get("build_time_s"), "route": summary.get("route")}


ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
"""Environment of every child of this bench, rftstatic's and Kratos's alike: one thread each (OpenMP, BLAS,
numba), so that the ratio of the two does not depend on what else the machine is running."""


def _child(target: str, kwargs: dict, name: str):
    from rftstatic.bench.harness import ChildError, run_child

    try:
        return run_child(f"rftstatic.bench.newton:{target}" if ":" not in target else target, kwargs, name=name,
                         timeout=TIMEOUT_S, env=ONE_THREAD)
    except ChildError as exc:
        print(f"{name:34s} FAILED: {exc}", flush=True)
        return None


HEADER = f"{'problem':34s} {'its':>5s} {'incs':>5s} {'facts':>6s} {'solve s':>8s} {'process':>8s}"


def _row(rows, label, r, run, extra=""):
    """Print one line and keep it for the report."""
    rows.append({"problem": label, "iterations": r.get("iterations"), "increments": r.get("increments"),
                 "factorisations": r.get("factorisations"), "solve_s": r["solve_s"], "process_s": run.wall_s,
                 "note": extra})
    print(f"{label:34s} {str(r.get('iterations')):>5s} {str(r.get('increments', '')):>5s} "
          f"{str(r.get('factorisations', '')):>6s} {r['solve_s']:8.3f} {run.wall_s:8.3f}  {extra}", flush=True)


def _strips(rows, results):
    for nx, ny in STRIPS:
        run = _child("strip_solve", {"nx": nx, "ny": ny, "warm": True}, f"strip {nx}x{ny}")
        if run:
            r = run.result
            results[f"strip {nx}x{ny}"] = (r, run)
            warm = (f", warm solve {r['warm_solve_s']:.3f} s (the process includes the two warm solves)"
                    if "warm_solve_s" in r else "")
            _row(rows, f"strip {nx}x{ny} RFT6", r, run, f"error {100 * r['error']:+.4f} %, {r['dofs']} dofs{warm}")
    run = _child("case_process", {"name": "strip", "overrides": ["mesh.nodes=[101,5]"]}, "case strip 101x5")
    if run:
        results["case strip 101x5"] = (run.result, run)
        _row(rows, "case strip 101x5 (whole CLI run)", run.result, run)
    from rftstatic.bench.kratos_peer import kratos_available

    if not kratos_available():
        print("Kratos Multiphysics not installed: pip install KratosMultiphysics "
              "KratosStructuralMechanicsApplication KratosLinearSolversApplication for the peer row")
        return
    run = _child("rftstatic.bench.kratos_peer:solve_strip", {"nx": 51, "ny": 11, "increments": 5, "threads": 1},
                 "kratos 51x11")
    if run:
        r = run.result
        results["kratos 51x11"] = (r, run)
        _row(rows, "Kratos strip 51x11 (1 thread)", r, run, f"error {100 * r['error']:+.4f} %, {r['dofs']} dofs")


def _cells(rows):
    for element in ("RFT3", "RFT6"):
        base = None
        for ratio in RATIOS:
            run = _child("strip_solve", {"nx": 21, "ny": 5, "element": element, "ratio": ratio},
                         f"cell {element} {ratio:g}")
            if run:
                r = run.result
                base = base or r["iterations"]
                _row(rows, f"strip 21x5 {element} C/B {ratio:.0e}", r, run,
                     f"converged {r['converged']}, {r['iterations'] / base:.2f} x the C/B = 1e2 cell")


def _comparison(results) -> str:
    """The equal-error comparison with Kratos (one run), or '' without the peer."""
    if not all(k in results for k in ("kratos 51x11", "strip 101x5", "case strip 101x5")):
        return ""
    k, kr = results["kratos 51x11"]
    s, _ = results["strip 101x5"]
    whole = results["case strip 101x5"][1]
    return (f"equal error (rftstatic 101x5 {100 * s['error']:+.4f} %, Kratos 51x11 {100 * k['error']:+.4f} %): "
            f"solve {k['solve_s'] / s['solve_s']:.2f} x faster, whole process {kr.wall_s / whole.wall_s:.2f} x "
            "faster (CLI run)")


def write_report(folder, rows, comparison, load) -> Path:
    """``newton.md`` and ``newton.json`` in ``folder``: the table of one run, its machine load."""
    import json
    import platform

    from rftstatic.provenance import code_fingerprint

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    lines = ["# Newton: iterations, factorisations and time (strip, stiff cells, pedestal, Kratos peer)", "",
             "Benchmark `newton`; regenerate with `python -m rftstatic.bench.newton --report validation`.", "",
             f"One run, {stamp}, {platform.node()}, {os.cpu_count()} cores, load average before / after: "
             f"{load[0]} / {load[1]}; code {code_fingerprint()}. Every row a fresh interpreter, one after the "
             "other; compare as ratios within this run. Solve: the first solve in the process (loading compiled "
             "kernels included); process: the child's whole wall time.", "",
             "| problem | Newton iterations | increments | factorisations | solve [s] | process [s] | note |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['problem']} | {r['iterations']} | {r['increments'] or ''} | {r['factorisations'] or ''} "
                     f"| {r['solve_s']:.3f} | {r['process_s']:.3f} | {r['note']} |")
    lines += ["", comparison or "Kratos not installed: no peer comparison.", "", TARGETS]
    (folder / "newton.md").write_text("\n".join(lines) + "\n")
    (folder / "newton.json").write_text(json.dumps({"rows": rows, "comparison": comparison, "load": load,
                                                    "date": stamp}, indent=1))
    return folder / "newton.md"


def main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="rftstatic bench newton", description=__doc__.split("\n")[0])
    parser.add_argument("--report", metavar="DIR", help="also write DIR/newton.md and DIR/newton.json")
    args = parser.parse_args(argv)
    load_before = " ".join(f"{x:.2f}" for x in os.getloadavg())
    print(HEADER)
    rows, results = [], {}
    _strips(rows, results)
    _cells(rows)
    run = _child("case_process", {"name": "pedestal-square-20", "overrides": []}, "pedestal-square-20")
    if run:
        _row(rows, "pedestal-square-20 33x33 (CLI)", run.result, run, f"route {run.result['route']}")
    comparison = _comparison(results)
    if comparison:
        print(comparison)
    if args.report:
        path = write_report(args.report, rows, comparison, (load_before, " ".join(f"{x:.2f}" for x in os.getloadavg())))
        print(f"report -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
