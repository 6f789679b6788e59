"""Benchmark of the mesher: wall time, triangles per second and peak memory (max RSS).

``python -m rftstatic.bench.mesher [--nodes 2000 20000 200000]`` meshes a unit
square with a uniform size chosen for about that many nodes, and a graded
(1:20) disc of about the same count, and prints one line per mesh. Each mesh is
made in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`;
``--in-process`` to use this one), so that its peak resident memory is its own
and not that of an earlier, larger mesh.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from rftstatic.mesh.mesher import BackgroundGrid, Domain, generate

__all__ = ["main", "measure", "run_case"]

CASES = ("square uniform", "disc graded 1:20")
TIMEOUT_S = 1800.0  # a mesh's child is killed after this long [s]
HEADER = (f"{'case':18s} {'nodes':>8s} {'tris':>8s} {'wall[s]':>8s} {'tri/s':>9s} {'maxRSS[MB]':>10s} "
          f"{'minang':>6s} {'meanmin':>7s} {'band':>5s}")


def run_case(domain, field):
    """Mesh once; return (result, wall time [s], peak resident memory of the process so far [MB]).

    Memory is ``getrusage`` maxrss rather than tracemalloc, whose per-allocation
    hook would slow the pure-Python front loop severalfold and falsify the timing.
    """
    t0 = time.perf_counter()
    res = generate(domain, field)
    wall = time.perf_counter() - t0
    return res, wall, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _cases(n_nodes):
    # uniform square: N ~ 2 / (sqrt(3) h^2) * area (equilateral triangles)
    square = Domain.rectangle(0.0, 0.0, 1.0, 1.0)
    h = np.sqrt(2.0 / (np.sqrt(3.0) * n_nodes))
    yield CASES[0], square, BackgroundGrid.uniform(h, square)
    # graded disc, sizes 1:20 from a point source; h0 tuned so that the
    # equilateral node density 2 / (sqrt(3) h^2) integrates to n_nodes
    disc = Domain.disc(0.0, 0.0, 1.0)
    x, y = np.meshgrid(np.linspace(-1, 1, 401), np.linspace(-1, 1, 401))
    inside = np.hypot(x, y) <= 1.0
    r = np.hypot(x - 0.5, y)[inside]

    def field(h0):
        return lambda x, y: np.minimum(20 * h0, h0 + 0.25 * np.hypot(x - 0.5, y))

    lo, hi = 1e-5, 0.5
    for _ in range(60):
        h0 = np.sqrt(lo * hi)
        n = np.sum(2.0 / (np.sqrt(3.0) * np.minimum(20 * h0, h0 + 0.25 * r) ** 2)) * (2.0 / 400) ** 2
        lo, hi = (h0, hi) if n > n_nodes else (lo, h0)
    yield CASES[1], disc, BackgroundGrid.from_function(field(h0), disc, spacing=0.005)


def measure(n_nodes: int, case: str) -> dict:
    """Mesh ``case`` (one of :data:`CASES`) at about ``n_nodes`` in this process; return its figures."""
    for name, domain, field in _cases(n_nodes):
        if name == case:
            rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            res, wall, rss = run_case(domain, field)
            q = res.quality
            return {"case": name, "nodes": q.n_nodes, "triangles": q.n_triangles, "wall_s": wall,
                    "triangles_per_s": q.n_triangles / wall, "peak_rss_mb": rss, "rss_before_mb": rss0,
                    "min_angle": q.min_angle, "mean_min_angle": q.mean_min_angle, "band_share": q.band_share}
    raise ValueError(f'unknown case "{case}"; use one of {CASES}')


def _fresh(n_nodes: int, case: str, *, timeout: float = TIMEOUT_S) -> dict:
    """:func:`measure` in a fresh interpreter (its own peak memory); killed after ``timeout`` [s]."""
    from rftstatic.bench.harness import run_child

    return run_child("rftstatic.bench.mesher:measure", {"n_nodes": n_nodes, "case": case},
                     name=f"mesher bench {case} at {n_nodes} nodes", timeout=timeout).result


def main(argv=None) -> list[dict]:
    """Print wall time, triangles/s and peak memory for each requested size; return the records."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[2_000, 20_000, 200_000],
                    help="approximate node counts (default: 2000 20000 200000)")
    ap.add_argument("--in-process", action="store_true", help="mesh in this interpreter (peak memory cumulative)")
    args = ap.parse_args(argv)
    print(HEADER)
    records = []
    for n in args.nodes:
        for case in CASES:
            r = measure(n, case) if args.in_process else _fresh(n, case)
            records.append(r)
            print(f"{r['case']:18s} {r['nodes']:8d} {r['triangles']:8d} {r['wall_s']:8.2f} {r['triangles_per_s']:9.0f} "
                  f"{r['peak_rss_mb']:10.1f} {r['min_angle']:6.1f} {r['mean_min_angle']:7.1f} {r['band_share']:5.3f}",
                  flush=True)
    return records


if __name__ == "__main__":
    main()
