"""Benchmark of the dynamic scenes end to end: wall time, peak memory and element-steps per second.

``python -m rftstatic.bench.scenes [NAME ...]`` runs ``hang-20`` and ``hang-100`` (§4.6, Figs. 12-13)
as ``python -m rftstatic case NAME`` would -- build, step estimate, explicit run, VTU series, PNG
frames, GIF, energy plot -- each in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`),
so that the peak resident memory (``ru_maxrss``) and the start-up costs (imports, numba
compilation) are those a user sees.

Targets on the 2-core reference machine: hang-100 in under 60 s, hang-20 in under 120 s.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

TARGETS_S = {"hang-20": 120.0, "hang-100": 60.0}
TIMEOUT_S = 1200.0  # a scene's child is killed after this long [s] (10 x the largest target)


def child(name: str, out: str) -> dict:
    """Run one scene in this process; return its measures (see :func:`bench_dynamic_scenes`)."""
    from rftstatic.app.registry import run_scene
    from rftstatic.scenes.schema import load_scene

    t0 = time.perf_counter()
    s = run_scene(load_scene(name), out, progress=False, figures=True)
    wall = time.perf_counter() - t0
    return {"scene": name, "nodes": s["nodes"], "elements": s["elements"], "steps": s["steps"], "dt": s["dt"],
            "wall_s": wall, "run_s": s["wall_time_s"], "element_steps_per_second": s["element_steps_per_second"],
            "loop_element_steps_per_second": s["loop_element_steps_per_second"],
            "time_at_rest": s["time_at_rest"]}


def bench_dynamic_scenes(names=("hang-20", "hang-100"), *, out_root=None, verbose=True,
                         timeout: float = TIMEOUT_S) -> list[dict]:
    """Run each scene end to end in a fresh interpreter; return (and print) its measures.

    Returns
    -------
    list of dicts: scene, nodes, elements, steps, dt [s], wall_s (end to end in the child, imports
    excluded), process_s (whole child process), cpu_s (its user + system time), run_s (explicit loop
    with step estimate), element_steps_per_second, time_at_rest [s], peak_rss_mb (the child's),
    target_s, within_target. A failed run raises :class:`rftstatic.bench.harness.ChildError` naming
    the scene; one still running after ``timeout`` [s] is killed.
    """
    from rftstatic.bench.harness import run_child

    results = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(out_root) if out_root else Path(tmp)
        for name in names:
            run = run_child("rftstatic.bench.scenes:child", {"name": name, "out": str(root / name)},
                            name=f"dynamic scene bench of {name}", timeout=timeout)
            r = run.result
            process = run.wall_s
            r.update(process_s=process, cpu_s=run.cpu_s, peak_rss_mb=run.peak_rss_mb)
            r["target_s"] = TARGETS_S.get(name)
            r["within_target"] = r["target_s"] is None or process < r["target_s"]
            results.append(r)
            if verbose:
                print(f"{name:10s} {r['nodes']:5d} nodes {r['elements']:5d} elements {r['steps']:6d} steps  "
                      f"end to end {process:6.1f} s (target {r['target_s']} s), run {r['run_s']:5.1f} s, "
                      f"{r['element_steps_per_second'] / 1e6:.2f} M element-steps/s, peak {r['peak_rss_mb']:.0f} MB, "
                      f"at rest at t = {r['time_at_rest']}", flush=True)
    return results


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", default=["hang-20", "hang-100"])
    ap.add_argument("--out", default=None, help="keep the outputs in this folder")
    args = ap.parse_args(argv)
    results = bench_dynamic_scenes(args.names, out_root=args.out)
    return 0 if all(r["within_target"] for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
