"""Command line: ``python -m rftstatic {case, list, bench, validate}``, on the Python API (:mod:`rftstatic.api`)."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="rftstatic", description="Rotation-free triangle drape simulation "
                                     "(Sze & Zhou 2016).")
    parser.add_argument("-v", "--verbose", action="store_true", help="log solver progress")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("case", help="run a scene: cases/NAME.toml or a path to a .toml file")
    p.add_argument("name")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene key, e.g. --set element=RFT3 --set mesh.nodes=[21,101]")
    p.add_argument("--out", default=None, help="output folder (default out/NAME)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG views")
    p.add_argument("--resume", action="store_true", help="continue a dynamic run from its last checkpoint")

    sub.add_parser("list", help="list the scenes in cases/")

    b = sub.add_parser("bench", help="print wall time and peak memory of the benchmarks")
    b.add_argument("names", nargs="*", help="benchmarks to run (default: all)")

    v = sub.add_parser("validate", help="regenerate the validation reports in validation/")
    v.add_argument("names", nargs="*")
    v.add_argument("--quick", action="store_true", help="coarse meshes only (about a minute)")
    v.add_argument("--out", default=None)

    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    from rftstatic import api

    try:
        if args.command == "list":
            for name, title in api.list_scenes():
                print(f"{name:32s} {title}")
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
            if summary.get("analysis", "static") != "static":  # trajectories are too long to print
                keys = ("scene", "element", "nodes", "analysis", "dt", "steps", "wall_time_s",
                        "element_steps_per_second", "time_at_rest", "at_rest", "converged")
            brief = {k: summary.get(k) for k in keys}
            print(json.dumps(brief, indent=1, default=str))
            print(f"outputs written to {out}/")
            return 0
        if args.command == "bench":
            from rftstatic.bench.main import main as bench_main

            return bench_main(args.names)
        if args.command == "validate":
            from rftstatic.validate import main as validate_main

            return validate_main(args.names, quick=args.quick, out=args.out)
    except api.SceneError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except api.ConvergenceError as exc:
        print(f"error: the solve did not converge: {exc}\nThe last equilibrium was written, labelled "
              "converged = false.", file=sys.stderr)
        return 3
    return 1
