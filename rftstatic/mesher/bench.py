"""Benchmark of the mesher: wall time, triangles per second and peak memory (max RSS).

``python -m rftstatic.mesher.bench [--nodes 2000 20000 200000]`` meshes a unit
square with a uniform size chosen for about that many nodes, and a graded
(1:20) disc of about the same count, and prints one line per mesh.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from . import BackgroundGrid, Domain, generate

__all__ = ["main", "run_case"]


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
    yield "square uniform", square, BackgroundGrid.uniform(h, square)
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
    yield "disc graded 1:20", disc, BackgroundGrid.from_function(field(h0), disc, spacing=0.005)


def main(argv=None):
    """Print wall time, triangles/s and peak memory for each requested size."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[2_000, 20_000, 200_000],
                    help="approximate node counts (default: 2000 20000 200000)")
    args = ap.parse_args(argv)
    print(f"{'case':18s} {'nodes':>8s} {'tris':>8s} {'wall[s]':>8s} {'tri/s':>9s} {'maxRSS[MB]':>10s} "
          f"{'minang':>6s} {'meanmin':>7s} {'band':>5s}")
    for n in args.nodes:
        for name, domain, field in _cases(n):
            res, wall, rss = run_case(domain, field)
            q = res.quality
            print(f"{name:18s} {q.n_nodes:8d} {q.n_triangles:8d} {wall:8.2f} {q.n_triangles / wall:9.0f} "
                  f"{rss:10.1f} {q.min_angle:6.1f} {q.mean_min_angle:7.1f} {q.band_share:5.3f}", flush=True)


if __name__ == "__main__":
    main()
