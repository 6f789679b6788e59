"""Command line: ``python -m rftstatic {case, view, pattern, list, fabrics, options, sweep, fit, bench,
validate}``, on the Python API (:mod:`rftstatic.api`), the run viewer (:mod:`rftstatic.io.viewer`), the
sewing patterns (:mod:`rftstatic.garment`) and the studies on Dask (:mod:`rftstatic.study`). ``fabrics
--explain [SCENE --set ...]`` prints the lab keys, their ranges and the rules that fill a lab fabric's missing
values, and where each value of a scene's fabric comes from (:mod:`rftstatic.scenes.fabric_explain`).

Exit statuses (:data:`EXIT`): 0 done; 2 invalid input (scene, options, mesh or checkpoint file); 3 goal
not reached (no convergence, instability, no rest by t_end; the last state is written); 4 the outputs
cannot be written (``sweep``/``fit``: 2 also for a bad ``--vary``/``--free``/``--target`` or an
unreachable ``--scheduler``; 3 a fit whose evaluation failed); 130 interrupted; 1 an internal error, printed as one line (``-v``: the traceback).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

EXIT = {"done": 0, "internal": 1, "input": 2, "goal": 3, "output": 4, "interrupted": 130}
"""Exit status of each outcome (docs/howto/scenes.md, "Exit statuses")."""


def main(argv=None) -> int:
    from rftstatic.provenance import __version__

    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                        help="log solver progress; print tracebacks")
    parser = argparse.ArgumentParser(prog="rftstatic", parents=[common],
                                     description="Rotation-free triangle drape simulation (Sze & Zhou 2016).")
    parser.add_argument("--version", action="version", version=f"rftstatic {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("case", parents=[common], help="run a scene: cases/NAME.toml or a path to a .toml file")
    p.add_argument("name")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key, e.g. --set element=RFT3 --set mesh.nodes=[21,101]")
    p.add_argument("--out", default=None, help="output folder (default out/NAME)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG views and view.html")
    p.add_argument("--resume", action="store_true", help="continue a run (static, dynamic, relax) from its last checkpoint")

    w = sub.add_parser("view", parents=[common], help="write RUN_DIR/view.html: the run's sheet in 3-D, rotatable, "
                       "with its obstacles, one file that opens offline in a browser",
                       description="Write an interactive 3-D view of a finished run (its summary.json and VTU "
                       "files): the deformed sheet coloured by a field, with a colour bar naming the field and "
                       "its unit, the obstacles and a tester's disc translucent, equal axis scales, and for "
                       "dynamic and remeshed runs a slider over the saved states. A run writes it by default "
                       "(--no-figures skips it).")
    w.add_argument("run_dir", help="a run's output folder (e.g. out/cusick-30)")
    w.add_argument("--field", default="relative_curvature",
                   help="colour the sheet by relative_curvature (|kappa| h, default), curvature (|kappa|), "
                   "displacement (|u|), membrane_strain (largest principal), height (z) or gap (to the "
                   "nearest obstacle), as the run has them")
    w.add_argument("--out", default=None, help="the HTML file to write (default RUN_DIR/view.html)")
    pt = sub.add_parser("pattern", parents=[common], help="read a sewing pattern (GarmentCode JSON or TOML), mesh "
                        "its panels with matching seam nodes, check it and write the placed panels as VTU",
                        description="Read a sewing pattern (GarmentCode's JSON specification or the TOML form of "
                        "rftstatic.garment.readers), check it (seam lengths, missing panels or edges, outlines, "
                        "placement), mesh every panel with the same node count along both sides of each seam, "
                        "print its panels and seams, and write the panels as placed, OUT/pattern.vtu.")
    pt.add_argument("file", help="a pattern file (.json or .toml), e.g. cases/patterns/skirt-a-line.toml")
    pt.add_argument("--h", type=float, default=2.0, help="target element size [cm] (default 2)")
    pt.add_argument("--out", default=None, help="output folder (default out/pattern-NAME)")
    sub.add_parser("list", parents=[common], help="list the scenes in cases/")
    fb = sub.add_parser("fabrics", parents=[common], help="list the fabric library with bending lengths and sources")
    fb.add_argument("--explain", action="store_true", help="the lab keys, their ranges and the rules that fill what a "
                    "lab fabric does not give, with sources; with SCENE: where each of its fabric's values comes from")
    fb.add_argument("scene", nargs="?", default=None, help="with --explain: a scene (cases/NAME.toml or a path)")
    fb.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="with SCENE: override a key")
    o = sub.add_parser("options", parents=[common], help="list a scene table's keys with type, unit, range, default "
                       "and meaning (e.g. options solver)")
    o.add_argument("section", nargs="?", default=None, help="the scene table (default: every declared one)")
    o.add_argument("--format", default="text", choices=("text", "markdown"), help="plain text or a Markdown table")
    _study_parsers(sub, common)

    b = sub.add_parser("bench", parents=[common], help="print wall time and peak memory of the benchmarks")
    b.add_argument("names", nargs=argparse.REMAINDER, help="benchmarks to run (default: all); or profile SCENE "
                   "[--set KEY=VALUE ...] [--format markdown], or scenes [--quick] (each with its own --help)")

    v = sub.add_parser("validate", parents=[common], help="regenerate the validation reports in validation/")
    v.add_argument("names", nargs="*")
    v.add_argument("--quick", action="store_true", help="coarse meshes only (about a minute)")
    v.add_argument("--out", default=None)

    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)  # what a study records in study.json
    verbose = getattr(args, "verbose", False)
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return _command(args)
    except KeyboardInterrupt:
        if args.command in ("sweep", "fit"):
            print("interrupted: the finished points are kept in results.csv; run the same command again to "
                  "continue", file=sys.stderr)
        else:
            print("interrupted (the run resumes from its last checkpoint with --resume)", file=sys.stderr)
        return EXIT["interrupted"]
    except Exception as exc:  # noqa: BLE001 - the one place an unexpected error is reported
        if verbose:
            raise
        print(f"internal error: {type(exc).__name__}: {exc} (run with -v for the traceback)", file=sys.stderr)
        return EXIT["internal"]


def _study_parsers(sub, common) -> None:
    """The ``sweep`` and ``fit`` sub-commands (:mod:`rftstatic.study`)."""
    shared = argparse.ArgumentParser(add_help=False)
    shared.add_argument("scene", help="cases/NAME.toml or a path to a .toml file")
    shared.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a scene key for every point, as for case")
    shared.add_argument("--out", default=None, help="study folder (default out/sweep-NAME, out/fit-NAME)")
    shared.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: a LocalCluster)")
    shared.add_argument("--workers", type=int, default=None, metavar="N",
                        help="LocalCluster worker processes (default: the cores); with --scheduler: wait for N")
    shared.add_argument("--figures", action="store_true", help="each point writes its PNG views (off: faster)")
    shared.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                        help="a point running longer is a failed row and its worker is restarted (default: no limit)")
    s = sub.add_parser("sweep", parents=[common, shared], help="run a scene over a grid or a Latin hypercube of keys")
    s.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2|LO:HI[:log]",
                   help="values of a scene key (a grid), or a range sampled with --samples")
    s.add_argument("--samples", type=int, default=None, metavar="N", help="Latin-hypercube samples of the ranges")
    s.add_argument("--seed", type=int, default=0, help="seed of the Latin hypercube (default 0)")
    s.add_argument("--no-plots", action="store_true", help="skip the measure-against-key plots")
    s.add_argument("--retry-failed", action="store_true", help="run the failed points again")
    f = sub.add_parser("fit", parents=[common, shared], help="fit scene keys to measured values")
    f.add_argument("--run", action="append", default=[], metavar="LABEL[@SCENE]:[KEY=VALUE,...]",
                   help="a run of the scene (or of SCENE) with its own overrides (repeat: one fit over several runs, "
                        "e.g. --run warp: --run weft:material.warp_angle=90); targets then name it, LABEL:MEASURE=VALUE")
    f.add_argument("--free", action="append", default=[], metavar="KEY=LO:HI", help="a key to fit, within bounds")
    f.add_argument("--target", action="append", default=[], metavar="[LABEL:]MEASURE=VALUE",
                   help="a measured value: probes.NAME.x|y|z, drape.drape_coefficient, cantilever.bending_length, ...")
    f.add_argument("--max-evaluations", type=int, default=100, help="most evaluations of the optimiser")


def _study_command(args) -> int:
    from rftstatic.study.runner import Execution

    execution = Execution(scheduler=args.scheduler, workers=args.workers, timeout=args.timeout, figures=args.figures)
    if args.command == "sweep":
        from rftstatic.study.sweep import run_sweep

        rows = run_sweep(args.scene, args.vary, samples=args.samples, seed=args.seed, sets=args.set, out=args.out,
                         execution=execution, plots=not args.no_plots, retry_failed=args.retry_failed,
                         argv=args.argv)
        failed = sum(r.get("status") == "failed" for r in rows)
        return EXIT["done"] if not failed else EXIT["goal"]
    from rftstatic.study.fit import run_fit

    result = run_fit(args.scene, args.free, args.target, runs=args.run, sets=args.set, out=args.out,
                     execution=execution, max_evaluations=args.max_evaluations, argv=args.argv)
    return EXIT["done"] if result["success"] else EXIT["goal"]


def _goal_missed(summary: dict) -> str:
    """Why a run that ended labelled ``converged = false`` fell short (from its summary)."""
    if summary.get("route") == "remesh_static":
        return (f"the mesh still changed after remesh.max_cycles = {summary['remesh'].get('max_cycles')} remeshing "
                "cycles (node count change above remesh.tol)")
    if summary.get("analysis") == "dynamic":
        return f"the run stopped at t = {summary.get('t'):.4g} s, before t_end = {summary.get('t_end')} s"
    if summary.get("stopped_by") == "max_steps":
        return (f"the sheet did not come to rest within dynamics.max_steps = {summary.get('max_steps')} explicit "
                f"steps (t = {summary.get('t'):.4g} s)")
    if summary.get("stopped_by") == "max_remesh":
        return "the sheet came to rest, but its mesh still changed after the most remeshes the run allows"
    return f"the sheet did not come to rest by t_end = {summary.get('t_end')} s"


def _command(args) -> int:
    from rftstatic import api
    from rftstatic.errors import CheckpointError, MeshError, MeshingError, PatchError

    try:
        if args.command == "list":
            for name, title in api.list_scenes():
                print(f"{name:32s} {title}")
            return 0
        if args.command == "fabrics" and (args.explain or args.scene):
            from rftstatic.scenes.fabric_explain import explain_fabrics

            print(explain_fabrics(api.load_scene(args.scene, args.set) if args.scene else None))
            return 0
        if args.command == "fabrics":
            rows = api.list_fabrics()
            print(f"{'preset':22s} {'B warp/weft [gf cm]':>20s} {'W [gf/cm2]':>11s} {'c warp/weft [cm]':>17s}  "
                  "not from the source             source")
            for f in rows:
                print(f"{f['name']:22s} {f['B_warp']:>9.4g} / {f['B_weft']:<8.4g} {f['weight']:>11.4g} "
                      f"{f['c_warp']:>7.4g} / {f['c_weft']:<7.4g}  {','.join(f['derived']) or '-':30s}  "
                      f"{f['short_source']}")
            for rule in dict.fromkeys(f["derived_rule"] for f in rows if f["derived_rule"]):
                print(f"not from the source: {rule}")
            print("sources in full: rftstatic.fabrics.library.FABRICS[name].source")
            print("nonlinear (softening) bending: the ctd-* presets carry their data row's k2 on request, [material] "
                  "nonlinear_bending = true (python -m rftstatic fabrics --explain)")
            return 0
        if args.command == "pattern":
            return _pattern(args)
        if args.command == "view":
            from rftstatic.io.viewer import ViewError, write_view

            try:
                path = write_view(args.run_dir, field=args.field, path=args.out)
            except ViewError as exc:
                print(f"error: {exc}", file=sys.stderr)
                return EXIT["input"]
            print(f"view written to {path} (open it in a browser)")
            return EXIT["done"]
        if args.command == "options":
            print(api.format_rows(api.option_rows(args.section), args.format))
            return 0
        if args.command == "case":
            scene = api.load_scene(args.name, args.set)
            out = Path(args.out) if args.out else Path("out") / scene.name
            if args.resume:
                summary = api.resume(scene, out, progress=True, figures=not args.no_figures)
            else:
                summary = api.run(scene, out, progress=True, figures=not args.no_figures).summary
            keys = ("scene", "element", "nodes", "converged", "load_steps", "newton_iterations", "wall_time_s",
                    "probes")
            if summary.get("analysis") == "cantilever":
                keys = ("scene", "element", "nodes", "converged", "wall_time_s")
            elif summary.get("analysis", "static") != "static":  # trajectories are too long to print
                keys = ("scene", "element", "nodes", "analysis", "dt", "steps", "wall_time_s",
                        "element_steps_per_second", "time_at_rest", "at_rest", "converged")
            brief = {k: summary.get(k) for k in keys}
            if "cantilever" in summary:  # the tester's reading, without the solves
                brief["cantilever"] = {k: v for k, v in summary["cantilever"].items() if k != "solves"}
            if isinstance(summary.get("drape"), dict) and "drape_coefficient_percent" in summary["drape"]:
                brief["drape"] = {k: summary["drape"].get(k) for k in ("drape_coefficient_percent", "fold_count",
                                                                       "fold_angles_deg")}
            if "seeds" in summary:
                brief["seeds"] = {k: v for k, v in summary["seeds"].items() if k != "specimens"}
            print(json.dumps(brief, indent=1, default=str))
            print(f"outputs written to {out}/")
            if summary.get("converged") is False:  # the run ended, short of its goal
                print(f"error: {_goal_missed(summary)}; the last state was written, labelled converged = false",
                      file=sys.stderr)
                return EXIT["goal"]
            return EXIT["done"]
        if args.command in ("sweep", "fit"):
            from rftstatic.study.fit import FitFailed
            from rftstatic.study.space import StudyError

            try:
                return _study_command(args)
            except StudyError as exc:
                print(f"error: {exc}", file=sys.stderr)
                return EXIT["input"]
            except FitFailed as exc:
                print(f"error: {exc}", file=sys.stderr)
                return EXIT["goal"]
        if args.command == "bench":
            from rftstatic.bench.main import main as bench_main

            return bench_main(args.names)
        if args.command == "validate":
            from rftstatic.validate import main as validate_main

            return validate_main(args.names, quick=args.quick, out=args.out)
    except (api.SceneError, MeshError, MeshingError, PatchError, CheckpointError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT["input"]
    except api.ConvergenceError as exc:
        print(f"error: the solve did not converge (the last equilibrium, if any, was written, labelled converged = "
              f"false): {exc}", file=sys.stderr)
        return EXIT["goal"]
    except api.InstabilityError as exc:
        print(f"error: the explicit run became unstable: {exc}", file=sys.stderr)
        return EXIT["goal"]
    except OSError as exc:
        print(f"error: the outputs cannot be written: {exc}", file=sys.stderr)
        return EXIT["output"]
    return EXIT["internal"]


def _pattern(args) -> int:
    """``pattern FILE``: read, mesh, check and describe a sewing pattern; write its placed panels as VTU."""
    import numpy as np

    from rftstatic.garment.meshing import check_placement, mesh_pattern, place
    from rftstatic.garment.readers import read_pattern
    from rftstatic.garment.report import describe
    from rftstatic.io.files import write_vtu

    path = Path(args.file)
    pmesh = mesh_pattern(read_pattern(path), args.h / 100.0)
    check_placement(pmesh)
    print(describe(pmesh))
    out = Path(args.out) if args.out else Path("out") / f"pattern-{path.stem}"
    out.mkdir(parents=True, exist_ok=True)
    combined = pmesh.combined()
    X3 = place(pmesh)
    vtu = write_vtu(out / "pattern.vtu", X3, np.zeros_like(X3), combined.mesh.tri, length_unit_scale=0.01,
                    point_data={"panel": combined.panel_of_node.astype(float)},
                    cell_data={"panel": combined.panel_of_element.astype(float),
                               "warp_angle_deg": np.degrees(combined.warp_angle)})
    print(f"placed panels written to {vtu} (cm)")
    return EXIT["done"]
