"""Benchmarks of adaptive remeshing: ``python -m rftstatic.bench_remesh [--skip-scenes] [--nodes ...]``.

1. The advancing-front mesher at about 2 000, 20 000 and 200 000 nodes (uniform square and graded
   disc; :mod:`rftstatic.mesher.bench`): wall time, triangles per second, peak memory.
2. Each remeshed scene of ``cases/`` end to end (meshing, relaxation, transfers, no figures): wall
   time against the target of 3 minutes on a 2-core machine, final nodes, remeshes, converged.
"""

from __future__ import annotations

import argparse
import time

SCENES = ("remesh-pedestal-square-20", "remesh-pedestal-round-50", "remesh-sphere-30")
TARGET_S = 180.0


def bench_scene(name: str, overrides=()) -> dict:
    """Run one remeshed scene without figures; return its wall time [s] and figures."""
    import tempfile

    from .remesh_run import run_remesh_scene
    from .scene import load_scene

    scene = load_scene(name, list(overrides))
    t0 = time.perf_counter()
    s = run_remesh_scene(scene, tempfile.mkdtemp(prefix="bench-remesh-"), progress=False, figures=False)
    wall = time.perf_counter() - t0
    return {"scene": name, "wall_time_s": wall, "nodes": s["nodes"], "initial_nodes": s["initial_nodes"],
            "remeshes": s["remeshes"], "converged": s["converged"], "t": s.get("t"), "steps": s.get("steps"),
            "within_target": wall <= TARGET_S}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="*", default=[2_000, 20_000, 200_000],
                    help="mesher sizes (approximate node counts); none to skip")
    ap.add_argument("--scenes", nargs="*", default=list(SCENES), help="remeshed scenes to time; none to skip")
    args = ap.parse_args(argv)
    if args.nodes:
        from .mesher import bench

        bench.main(["--nodes", *map(str, args.nodes)])
    if args.scenes:
        print(f"\n{'scene':28s} {'wall[s]':>8s} {'target':>7s} {'nodes':>11s} {'remesh':>6s} {'t[s]':>7s} "
              f"{'steps':>7s} converged")
        for name in args.scenes:
            r = bench_scene(name)
            t = "-" if r["t"] is None else f"{r['t']:.2f}"
            print(f"{name:28s} {r['wall_time_s']:8.1f} {'ok' if r['within_target'] else 'MISSED':>7s} "
                  f"{r['initial_nodes']:5d}->{r['nodes']:<5d} {r['remeshes']:6d} {t:>7s} {r['steps'] or '-':>7} "
                  f"{r['converged']}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
