"""Throughput of a study: ``python -m rftstatic bench study``.

A 16-point sweep of the §4.1 strip (``material.B_warp`` on 16 values from 0.05 to 0.12 gf cm, the
scene's 51 x 11 mesh, no figures) three ways, each from scratch (a new study folder, nothing cached):

- one by one in one fresh interpreter (:func:`sequential`, through :func:`rftstatic.bench.harness.run_child`):
  ``api.run`` in a loop, the reference;
- on a LocalCluster of 1 and of 2 worker processes (:class:`rftstatic.study.runner.Engine`), the
  cluster's start-up timed apart from the points.

Printed: points per minute (with and without the start-up) and the overhead per point, (workers x
wall time of the points - the sequential time) / points: what Dask, the worker processes and the
study's bookkeeping (keys, results.csv rewritten per point) add to each point's own run; and the part
of it outside the points' runs as their workers timed them, (workers x wall time - the sum of the
points' own wall times) / points, which a machine shared with other jobs disturbs far less (the
sequential and the Dask runs do not run at the same moment, so the load on the cores differs).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

SCENE = "strip"
POINTS = 16


def _values(points: int) -> list[float]:
    return [round(0.05 + 0.07 * i / (points - 1), 6) for i in range(points)]


def sequential(values, out, sets=()) -> dict:
    """Run the points one after the other in this process; wall time of the loop [s]."""
    from rftstatic import api

    t0 = time.perf_counter()
    for i, b in enumerate(values):
        api.run(SCENE, Path(out) / f"p{i}", overrides=[*sets, f"material.B_warp={b!r}"], figures=False)
    return {"wall_s": time.perf_counter() - t0}


def dask_sweep(values, out, workers: int, sets=()) -> dict:
    """Run the points on a LocalCluster of ``workers`` processes: start-up and points timed apart [s]."""
    from rftstatic.study.measures import standard_columns
    from rftstatic.study.runner import Engine
    from rftstatic.study.store import Store
    from rftstatic.study.sweep import Study, load_base

    study = Study(SCENE, list(sets), Path(out), standard_columns(load_base(SCENE, sets)))
    specs = [study.spec({"material.B_warp": b}) for b in values]
    store = Store(Path(out), ["material.B_warp", *study.measures])
    engine = Engine(None, workers)
    try:
        t0 = time.perf_counter()
        engine.client()
        t1 = time.perf_counter()
        rows = engine.run(specs, store.add, label=f"bench {workers} workers")
        t2 = time.perf_counter()
    finally:
        engine.close()
    return {"startup_s": t1 - t0, "points_s": t2 - t1, "failed": sum(r["status"] != "ok" for r in rows),
            "point_wall_s": sum(r["wall_time_s"] for r in rows)}


def run(points: int = POINTS, sets=(), workers=(1, 2)) -> list[dict]:
    """Print and return the figures (module docstring)."""
    from rftstatic.bench.harness import run_child

    values = _values(points)
    print(f"study bench: {points}-point sweep of {SCENE} {' '.join(sets) or '(51 x 11 nodes)'}, load "
          f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores", flush=True)
    with tempfile.TemporaryDirectory(prefix="rftstatic-bench-study-") as tmp:
        seq = run_child("rftstatic.bench.study:sequential", {"values": values, "out": f"{tmp}/seq", "sets": list(sets)},
                        name="study bench, sequential", timeout=600).result["wall_s"]
        print(f"  one by one, in-process     {seq:7.2f} s  {60 * points / seq:7.1f} points/min  "
              f"({seq / points:.3f} s a point)", flush=True)
        out = [{"workers": 0, "wall_s": seq}]
        for n in workers:
            r = dask_sweep(values, f"{tmp}/dask{n}", n, sets)
            total = r["startup_s"] + r["points_s"]
            overhead = (n * r["points_s"] - seq) / points
            dask_share = (n * r["points_s"] - r["point_wall_s"]) / points
            print(f"  Dask, {n} worker{'s' if n > 1 else ' '}            {total:7.2f} s  {60 * points / total:7.1f} "
                  f"points/min  (start-up {r['startup_s']:.2f} s; points {r['points_s']:.2f} s = "
                  f"{60 * points / r['points_s']:.1f} points/min; overhead {overhead:+.3f} s a point against one by "
                  f"one, of which outside the points' own runs {dask_share:+.3f} s; {r['failed']} failed)", flush=True)
            out.append({"workers": n, **r, "overhead_per_point_s": overhead, "dask_share_per_point_s": dask_share})
    return out


def main(argv=None) -> int:
    run()
    return 0
