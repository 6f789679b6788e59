"""Wall time and peak memory of the static path: ``python -m rftstatic bench [NAMES]``.

Benchmarks (each a function of its size, so tests can run them tiny):

- ``strip``: full static solve of the §4.1 wool strip, RFT6 and RFT3, at 51 x 11 and 101 x 21 nodes
  (target: 51 x 11 < 1 s);
- ``newton``: :mod:`rftstatic.bench.newton` (iterations, increments, factorisations, times of the
  strip, the stiff strip cells, pedestal-square-20, and of the Kratos peer);
- ``iteration``: one Newton iteration on an 81 x 81-node 20 x 20 cm wool sheet under its weight,
  pinned at two corners, from a small random out-of-plane state: tangent assembly, CHOLMOD (or
  scipy) factorisation and solve, timed separately (target < 0.5 s);
- ``profile SCENE [--set ...]``: :mod:`rftstatic.bench.profile` (wall time by phase of one scene's run);
- ``scenes [--quick]``: :mod:`rftstatic.bench.paper_scenes` (every paper scene, each in a fresh process);
- ``construction``: patches with image nodes and the constant bending stiffness of a 708 x 708-node
  rectangle, ~1.0e6 triangles (target < 30 s).

Peak memory: the process's ``ru_maxrss`` (a high-water mark over the whole run, so later lines can
only be larger) and, for the construction step, the ``tracemalloc`` peak of the numpy allocations.
"""

from __future__ import annotations

import resource
import sys
import time
import tracemalloc

import numpy as np

TARGETS = {"strip 51x11": 1.0, "newton": 0.5, "construction": 30.0}


def _rss_mb() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / 1024**2 if sys.platform == "darwin" else r / 1024  # bytes on macOS, KiB on Linux


def _line(name, seconds, target=None, extra=""):
    t = f"  (target < {target:g} s: {'ok' if seconds < target else 'MISSED'})" if target else ""
    print(f"{name:42s} {seconds:8.3f} s{t}  peak RSS {_rss_mb():7.0f} MB {extra}", flush=True)


def bench_strip(nx=51, ny=11, element="RFT6") -> dict:
    """Full static solve of the clamped wool strip with ``nx`` x ``ny`` nodes."""
    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers import static

    t0 = time.perf_counter()
    mod = strip_model(nx, ny, element=element)
    t1 = time.perf_counter()
    res = static.solve_static(mod, options=static.StaticOptions(progress=False))
    t2 = time.perf_counter()
    return {"build_s": t1 - t0, "solve_s": t2 - t1, "total_s": t2 - t0, "converged": res.converged,
            "iterations": res.iterations, "load_steps": len(res.load_steps), "linear_solver": res.linear_solver}


def bench_newton(n=81, side=0.2, element="RFT6") -> dict:
    """One Newton iteration on an n x n-node wool sheet: assembly, factorisation, solve [s]."""
    from rftstatic.bench.problems import sheet_model
    from rftstatic.solvers import linear as linsolve

    mod = sheet_model(side, n, element)
    rng = np.random.default_rng(0)
    U = np.zeros((mod.mesh.n_nodes, 3))
    U[:, 2] = 1e-3 * side * rng.uniform(-1, 1, mod.mesh.n_nodes) * mod.free[:, 2]
    mod.tangent(U, psd=True)  # first call builds the plan and the bending data (once per model)
    t0 = time.perf_counter()
    f, K = mod.tangent(U, psd=True)
    t1 = time.perf_counter()
    r = (f - mod.load).ravel()[mod.free.ravel()]
    solver = linsolve.make_solver("auto")
    out = {"dofs": K.shape[0], "nnz": K.nnz, "linear_solver": type(solver).__name__, "assembly_s": t1 - t0}
    if isinstance(solver, linsolve.CholmodSolver):
        from sksparse.cholmod import analyze

        A = K.T  # as linsolve.CholmodSolver: the symbolic analysis once per model, then numeric only
        mode, ordering = linsolve.CholmodSolver.choose_mode(A.shape[0])
        with linsolve.SerialOpenMP():  # as the solver does: CHOLMOD's OpenMP regions on this thread
            ta = time.perf_counter()
            factor = analyze(A, mode=mode, ordering_method=ordering)
            t2 = time.perf_counter()
            factor.cholesky_inplace(A)
            t3 = time.perf_counter()
            d = factor(-r)
            t4 = time.perf_counter()
        out.update(analysis_once_s=t2 - ta, factorisation_s=t3 - t2, solve_s=t4 - t3)
    else:
        from scipy.sparse.linalg import splu

        t2 = time.perf_counter()
        lu = splu(K.tocsc())
        t3 = time.perf_counter()
        d = lu.solve(-r)
        t4 = time.perf_counter()
        out.update(factorisation_s=t3 - t2, solve_s=t4 - t3)
    out["total_s"] = out["assembly_s"] + out["factorisation_s"] + out["solve_s"]
    out["finite"] = bool(np.all(np.isfinite(d)))
    return out


def bench_construction(n=708) -> dict:
    """Patch topology/curvature operator and bending stiffness of an n x n-node rectangle [s]."""
    from rftstatic.element.patch import bending_stiffness, build_patches
    from rftstatic.material import preset
    from rftstatic.mesh.trimesh import rectangle

    mesh = rectangle(1.0, 1.0, n, n)
    mesh.topology  # edge topology is part of the mesh, built before the timing
    tracemalloc.start()
    t0 = time.perf_counter()
    patches = build_patches(mesh)
    t1 = time.perf_counter()
    Kb = bending_stiffness(mesh, patches, preset("wool-kang-yu").Db)
    t2 = time.perf_counter()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {"triangles": mesh.n_elements, "patches_s": t1 - t0, "bending_stiffness_s": t2 - t1,
            "total_s": t2 - t0, "tracemalloc_peak_mb": peak / 1024**2, "nnz": Kb.nnz}


def run_strip(sizes=((51, 11), (101, 21))):
    for nx, ny in sizes:
        for element in ("RFT6", "RFT3"):
            r = bench_strip(nx, ny, element)
            target = TARGETS["strip 51x11"] if (nx, ny) == (51, 11) else None
            _line(f"strip {nx}x{ny} {element} (build+solve)", r["total_s"], target,
                  f"[{r['load_steps']} load steps, {r['iterations']} Newton its, {r['linear_solver']}, "
                  f"converged {r['converged']}]")


def run_newton(n=81):
    r = bench_newton(n)
    print(f"one Newton iteration, {n}x{n} nodes, {r['dofs']} dofs, nnz {r['nnz']}, {r['linear_solver']}:")
    _line("  tangent assembly", r["assembly_s"])
    if "analysis_once_s" in r:
        _line("  symbolic analysis (once per model)", r["analysis_once_s"])
    _line("  numeric factorisation", r["factorisation_s"])
    _line("  solve", r["solve_s"])
    _line("  total", r["total_s"], TARGETS["newton"] if n == 81 else None)


def run_construction(n=708):
    r = bench_construction(n)
    print(f"construction, {n}x{n} nodes, {r['triangles']} triangles:")
    _line("  build_patches", r["patches_s"])
    _line("  bending_stiffness", r["bending_stiffness_s"])
    _line("  total", r["total_s"], TARGETS["construction"] if n == 708 else None,
          f"[tracemalloc peak {r['tracemalloc_peak_mb']:.0f} MB]")


def _lazy(module: str, call):
    """A bench that lives in another module, imported only when it runs."""

    def run():
        import importlib

        call(importlib.import_module(f"rftstatic.{module}"))

    return run


BENCHES = {
    "strip": run_strip,
    "iteration": run_newton,  # one Newton iteration of the 81 x 81 sheet, by part
    "newton": _lazy("bench.newton", lambda m: m.main([])),  # strip, stiff cells, pedestal, Kratos peer
    "construction": run_construction,
    "factor": _lazy("bench.factor", lambda m: m.run(solve=True)),  # CHOLMOD modes and orderings by size
    "explicit": _lazy("bench.explicit", lambda m: m.main([])),  # element-steps per second
    "dynamic": _lazy("bench.scenes", lambda m: m.bench_dynamic_scenes()),  # hang-20, hang-100
    "mesher": _lazy("bench.mesher", lambda m: m.main([])),  # triangles per second
    "drape": _lazy("bench.drape", lambda m: m.main([])),  # static drape scenes, each in a fresh process
    "remesh": _lazy("bench.remesh", lambda m: m.main([])),  # mesher sizes and the remeshed scenes
    "self-contact": _lazy("bench.self_contact_scenes", lambda m: m.main([])),  # run time with / without it
    "study": _lazy("bench.study", lambda m: m.main([])),  # points per minute of a sweep on 1 and 2 Dask workers
}


COMMANDS = {
    "profile": "bench.profile",  # profile SCENE [--set KEY=VALUE ...]: wall time by phase of one scene's run
    "scenes": "bench.paper_scenes",  # the paper scenes' wall time, iterations, factorisations, steps, memory
}
"""Benchmarks with arguments of their own: ``bench NAME ARGS...`` calls the module's ``main(ARGS)``."""


def main(names=None) -> int:
    """Run the named benchmarks (all when empty) and print their figures; ``profile ...`` and ``scenes ...``
    take their own arguments (:data:`COMMANDS`)."""
    names = list(names or [])
    if names and names[0] in COMMANDS:
        import importlib

        return importlib.import_module(f"rftstatic.{COMMANDS[names[0]]}").main(names[1:])
    options = [n for n in names if n.startswith("-")]
    if options:
        print(f'error: bench {" ".join(options)}: options belong to a command ({", ".join(COMMANDS)}), '
              f"e.g. bench profile SCENE --set KEY=VALUE")
        return 2
    names = names or list(BENCHES)
    unknown = [n for n in names if n not in BENCHES]
    if unknown:
        print(f'error: unknown bench {", ".join(unknown)}; use {", ".join(BENCHES)}')
        return 2
    for name in names:
        BENCHES[name]()
    return 0
