"""Benchmarks of adaptive remeshing: ``python -m rftstatic.bench.remesh [--nodes ...] [--scenes ...] [--json F]``.

1. The advancing-front mesher at about 2 000, 20 000 and 200 000 nodes (uniform square and graded
   disc; :mod:`rftstatic.bench.mesher`): wall time, triangles per second, peak memory, each mesh
   in a fresh interpreter.
2. Each remeshed scene of ``cases/`` end to end (meshing, relaxation, transfers, summary; no
   figures), each in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`) as
   ``python -m rftstatic case NAME`` would run it: the
   process's wall time (imports and the compiled kernel's loading included) against the target of
   3 minutes on a 2-core machine, its CPU time, peak resident memory, final nodes, remeshes, the
   simulated time at rest and whether it came to rest.
"""

from __future__ import annotations

import argparse
import json
import time

SCENES = ("remesh-pedestal-square-20", "remesh-pedestal-round-50", "remesh-sphere-30")
TARGET_S = 180.0
TIMEOUT_S = 1800.0  # a scene's child is killed after this long [s] (10 x the target)


def child(name: str, overrides) -> dict:
    """Run one remeshed scene in this process, without figures; return its figures.

    scene, overrides, wall_time_s [s] (in this process, imports excluded), solve_time_s [s], nodes,
    initial_nodes, remeshes, converged (at rest), t [s] (simulated time at rest), steps,
    alpha_final [1/s], drape_coefficient, fold_count. (:func:`bench_scene` adds the process's CPU
    time and peak memory.)
    """
    import tempfile

    from rftstatic.app.remeshed import run_remesh_scene
    from rftstatic.scenes.schema import load_scene

    t0 = time.perf_counter()
    scene = load_scene(name, list(overrides))
    s = run_remesh_scene(scene, tempfile.mkdtemp(prefix="bench-remesh-"), progress=False, figures=False)
    drape = s.get("drape", {})
    return {"scene": name, "overrides": list(overrides), "wall_time_s": time.perf_counter() - t0,
            "solve_time_s": s["wall_time_s"], "nodes": s["nodes"], "initial_nodes": s["initial_nodes"],
            "remeshes": s["remeshes"], "converged": s["converged"], "t": s.get("t"), "steps": s.get("steps"),
            "alpha_final": s.get("alpha_final"), "drape_coefficient": drape.get("drape_coefficient"),
            "fold_count": drape.get("fold_count")}


def bench_scene(name: str, overrides=(), *, timeout: float = TIMEOUT_S) -> dict:
    """Run one remeshed scene end to end in a fresh interpreter; return its figures (:func:`child`)
    with ``process_s`` [s] (the whole process), ``cpu_time_s`` [s] (its user + system time),
    ``peak_rss_mb`` [MB] (its peak resident memory) and ``within_target`` (process_s <= 3 min).

    A failed run raises :class:`rftstatic.bench.harness.ChildError` naming the scene; one still
    running after ``timeout`` [s] is killed (:class:`~rftstatic.bench.harness.ChildTimeout`).
    """
    from rftstatic.bench.harness import run_child

    run = run_child("rftstatic.bench.remesh:child", {"name": name, "overrides": list(overrides)},
                    name=f"remesh bench of {name} {list(overrides)}", timeout=timeout)
    r = run.result
    r.update(process_s=run.wall_s, cpu_time_s=run.cpu_s, peak_rss_mb=run.peak_rss_mb)
    r["within_target"] = run.wall_s <= TARGET_S
    return r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="*", default=[2_000, 20_000, 200_000],
                    help="mesher sizes (approximate node counts); none to skip")
    ap.add_argument("--scenes", nargs="*", default=list(SCENES), help="remeshed scenes to time; none to skip")
    ap.add_argument("--json", default=None, help="also write the records to this JSON file")
    ap.add_argument("--report", default=None, metavar="DIR",
                    help="also write DIR/bench_remesh.md and DIR/bench_remesh.json (e.g. validation)")
    args = ap.parse_args(argv)
    out = {"mesher": [], "scenes": [], "machine": _machine()}
    if args.nodes:
        from rftstatic.bench import mesher as bench

        out["mesher"] = bench.main(["--nodes", *map(str, args.nodes)])
    if args.scenes:
        print(f"\n{'scene':28s} {'wall[s]':>8s} {'target':>7s} {'cpu[s]':>7s} {'peak[MB]':>8s} {'nodes':>11s} "
              f"{'remesh':>6s} {'t[s]':>7s} {'steps':>7s} {'DC':>6s} {'folds':>5s} at rest")
        for name in args.scenes:
            r = bench_scene(name)
            out["scenes"].append(r)
            t = "-" if r["t"] is None else f"{r['t']:.2f}"
            dc = "-" if r["drape_coefficient"] is None else f"{r['drape_coefficient']:.3f}"
            print(f"{name:28s} {r['process_s']:8.1f} {'ok' if r['within_target'] else 'MISSED':>7s} "
                  f"{r['cpu_time_s']:7.1f} {r['peak_rss_mb']:8.0f} {r['initial_nodes']:5d}->{r['nodes']:<5d} "
                  f"{r['remeshes']:6d} {t:>7s} {r['steps'] or '-':>7} {dc:>6s} {r['fold_count'] or '-':>5} "
                  f"{r['converged']}", flush=True)
    out["machine"]["load_after"] = _load()
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(out, f, indent=1, default=float)
    if args.report:
        write_report(out, args.report)
    return 0 if all(r["within_target"] and r["converged"] for r in out["scenes"]) else 1


def _load():
    try:
        import os

        return list(os.getloadavg())
    except OSError:
        return None


def _machine() -> dict:
    import os
    import platform

    from rftstatic.provenance import __version__

    return {"cpus": os.cpu_count(), "python": platform.python_version(), "rftstatic": __version__,
            "date": time.strftime("%Y-%m-%d %H:%M"), "load_before": _load()}


def write_report(out: dict, folder) -> None:
    """``bench_remesh.md`` (tables) and ``bench_remesh.json`` (the records) in ``folder``."""
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    m = out["machine"]
    load = lambda v: "-" if not v else " / ".join(f"{x:.1f}" for x in v)  # noqa: E731
    lines = ["# Remeshing benchmarks", "",
             ("Generated by `python -m rftstatic.bench.remesh --report validation` (the mesher at three sizes "
             "and the three remeshed scenes of §6, each in a fresh interpreter). Machine: "
             f"{m['cpus']} cores, Python {m['python']}, rftstatic {m['rftstatic']}, {m['date']}; load average "
             f"(1/5/15 min) {load(m.get('load_before'))} before, {load(m.get('load_after'))} after: the machine "
             "was shared with other jobs, so the wall times are pessimistic (CPU times are given too)."), ""]
    if out["mesher"]:
        lines += ["## Mesher (advancing front)", "",
                  ("| case | nodes | triangles | wall [s] | triangles/s | peak RSS [MB] | min angle [deg] | "
                  "mean min angle [deg] | edges in [0.7, 1.4] h |"), "|---|---|---|---|---|---|---|---|---|"]
        for r in out["mesher"]:
            lines.append(f"| {r['case']} | {r['nodes']} | {r['triangles']} | {r['wall_s']:.2f} | "
                         f"{r['triangles_per_s']:.0f} | {r['peak_rss_mb']:.0f} | {r['min_angle']:.1f} | "
                         f"{r['mean_min_angle']:.1f} | {100 * r['band_share']:.1f} % |")
        lines += ["", ("Targets (issue 6): at least 5,000 triangles/s; minimum angle >= 30 deg, mean minimum angle "
                  ">= 50 deg, >= 90 % of edges in the band."), ""]
    if out["scenes"]:
        lines += ["## Remeshed scenes end to end (dynamic relaxation with adaptive remeshing, §6)", "",
                  ("| scene | process wall [s] | target 180 s | CPU [s] | peak RSS [MB] | nodes (start -> end) | "
                  "remeshes | at rest at t [s] | explicit steps | final alpha [1/s] | DC | folds | at rest |"),
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in out["scenes"]:
            t = "-" if r["t"] is None else f"{r['t']:.1f}"
            dc = "-" if r["drape_coefficient"] is None else f"{r['drape_coefficient']:.3f}"
            a = "-" if r.get("alpha_final") is None else f"{r['alpha_final']:.2f}"
            lines.append(f"| {r['scene']} | {r['process_s']:.1f} | {'met' if r['within_target'] else '**MISSED**'} | "
                         f"{r['cpu_time_s']:.1f} | {r['peak_rss_mb']:.0f} | {r['initial_nodes']} -> {r['nodes']} | "
                         f"{r['remeshes']} | {t} | {r['steps']} | {a} | {dc} | {r['fold_count']} | "
                         f"{'yes' if r['converged'] else '**no**'} |")
        lines.append("")
    (folder / "bench_remesh.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    with open(folder / "bench_remesh.json", "w", encoding="utf-8") as f:
        json.dump(out, f, indent=1, default=float)


if __name__ == "__main__":
    raise SystemExit(main())
