"""Sparse Cholesky of the static tangent: which CHOLMOD mode and ordering, and what threads cost.

``run()`` prints, for the strip and sheet tangents the static benchmarks solve (§4.1 strip 51 x 11 and
101 x 21 nodes, §4.6 sheet 33 x 33 and 81 x 81, RFT6; two small strips for the simplicial/supernodal
switch), the time of one numeric factorisation
(``cholesky_inplace``, the step a Newton iteration repeats) for each mode / ordering, with CHOLMOD's
OpenMP loops as compiled (``built``) and run on the calling thread (``serial``, what
:class:`rftstatic.solvers.linear.CholmodSolver` does), interleaved in one process so that the ratios
hold on a machine whose other core is busy; then the simpler paths (scipy's ``splu``, sksparse's
``cholesky`` with analysis every time, a rank-1 ``update_inplace``), the libraries and threads that are
live, and optionally (``solve=True``) the factorisations inside a full static solve of the 101 x 21
strip, before and after. Each time is the median and the best of ``reps`` calls [ms].

The factorisation's cost does not depend on the values, only on the pattern and the ordering, so the
tangent is taken at the flat state (plus ``beta`` times the identity, ``cholesky_inplace``'s shift, so
the pinned sheet's flat tangent, singular for the rotation about its pinned corners, factorises).
"""

from __future__ import annotations

import os
import time

import numpy as np

MODES = (("simplicial", "amd"), ("supernodal", "amd"), ("supernodal", "metis"), ("supernodal", "default"))
"""(mode, ordering) pairs of ``sksparse.cholmod.analyze``; ``"default"`` is CHOLMOD's own choice (AMD,
then METIS when AMD's fill is poor)."""

PROBLEMS = {"strip 21x5": ("strip", 21, 5), "strip 31x7": ("strip", 31, 7), "strip 51x11": ("strip", 51, 11),
            "sheet 33x33": ("sheet", 33, 33), "strip 101x21": ("strip", 101, 21), "sheet 81x81": ("sheet", 81, 81)}


def tangent(name: str):
    """The free-dof tangent (scipy CSR) of a benchmark problem at its flat state."""
    from rftstatic.bench.problems import sheet_model, strip_model

    kind, nx, ny = PROBLEMS[name]
    model = strip_model(nx, ny, element="RFT6") if kind == "strip" else sheet_model(0.2, nx)
    _, K = model.tangent(np.zeros((model.mesh.n_nodes, 3)), psd=False, lam=1.0)
    return K


def _stats(times) -> str:
    t = 1e3 * np.asarray(times)
    return f"{np.median(t):7.1f} {t.min():7.1f}"


def time_modes(K, *, reps: int = 10, modes=MODES) -> list[dict]:
    """Analysis time, nnz(L), flops (sum of the squared column counts of L) and factorisation times
    of each mode, OpenMP ``built`` and ``serial``."""
    from sksparse.cholmod import analyze

    from rftstatic.solvers.linear import SerialOpenMP

    A = K.T  # as CholmodSolver: the CSC view of the symmetric matrix
    beta = 1e-9 * float(np.abs(K.diagonal()).mean())
    rows, factors = [], []
    for mode, ordering in modes:
        t0 = time.perf_counter()
        with SerialOpenMP():
            F = analyze(A, mode=mode, ordering_method=ordering)
        t1 = time.perf_counter()
        with SerialOpenMP():
            F.cholesky_inplace(A, beta)
        counts = np.diff(F.L().tocsc().indptr).astype(float)  # entries of each column of L
        rows.append({"mode": mode, "ordering": ordering, "analysis_s": t1 - t0, "nnz_L": int(counts.sum()),
                     "flops": float((counts**2).sum()), "built": [], "serial": []})
        factors.append(F)
    for _ in range(reps):  # interleaved: a busy neighbour slows every column alike
        for row, F in zip(rows, factors):
            for key in ("built", "serial"):
                with SerialOpenMP(enabled=key == "serial"):
                    t = time.perf_counter()
                    F.cholesky_inplace(A, beta)
                    row[key].append(time.perf_counter() - t)
    return rows


def time_alternatives(K, *, reps: int = 3) -> dict:
    """scipy's splu, sksparse's ``cholesky`` (analysis each time) and one rank-1 ``update_inplace``."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu
    from sksparse.cholmod import analyze, cholesky

    from rftstatic.solvers.linear import SerialOpenMP

    A = K.T
    beta = 1e-9 * float(np.abs(K.diagonal()).mean())
    Ab = (A + beta * sp.identity(A.shape[0], format="csc")).tocsc()
    out = {"splu": [], "cholesky": [], "update_rank1": []}
    for _ in range(reps):
        t = time.perf_counter()
        splu(Ab, permc_spec="MMD_AT_PLUS_A")
        out["splu"].append(time.perf_counter() - t)
        with SerialOpenMP():
            t = time.perf_counter()
            cholesky(A, beta, mode="supernodal", ordering_method="amd")
            out["cholesky"].append(time.perf_counter() - t)
    with SerialOpenMP():
        F = analyze(A, mode="simplicial", ordering_method="amd")
        F.cholesky_inplace(A, beta)
        c = sp.csc_matrix(np.full((A.shape[0], 1), 1e-3 * np.sqrt(beta + 1.0)))
        for _ in range(reps):
            t = time.perf_counter()
            F.update_inplace(c)
            out["update_rank1"].append(time.perf_counter() - t)
    return out


def live_libraries() -> dict:
    """The BLAS / LAPACK / OpenMP / METIS / CHOLMOD libraries mapped into this process and its threads."""
    keys = ("gomp", "omp", "blas", "lapack", "metis", "cholmod", "tbb")
    try:
        with open("/proc/self/maps") as fh:
            libs = sorted({os.path.basename(line.split(None, 5)[-1].strip()) for line in fh if ".so" in line})
        threads = len(os.listdir("/proc/self/task"))
    except OSError:
        return {"libraries": [], "threads": None}
    return {"libraries": [n for n in libs if any(k in n.lower() for k in keys)], "threads": threads}


class _TimedFactor:
    """A CHOLMOD factor whose ``cholesky_inplace`` calls are timed (the benchmark's stand-in)."""

    def __init__(self, factor, times):
        self._factor, self._times = factor, times

    def cholesky_inplace(self, *args, **kwargs):
        t = time.perf_counter()
        try:
            return self._factor.cholesky_inplace(*args, **kwargs)
        finally:
            self._times.append(time.perf_counter() - t)

    def __call__(self, *args):
        return self._factor(*args)

    def __getattr__(self, name):
        return getattr(self._factor, name)


def solve_factor_times(nx: int = 101, ny: int = 21, *, openmp: str = "serial") -> dict:
    """Full static solve of the strip: count and times of its ``cholesky_inplace`` calls.

    ``openmp`` is :data:`rftstatic.solvers.linear.OPENMP_ENV` for the solve (``"built"``: as before
    the fix). The factors that ``sksparse.cholmod.analyze`` returns are wrapped for the timing, for
    this call only (cProfile does not see the Cython method).
    """
    import sksparse.cholmod as skc

    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers import static
    from rftstatic.solvers.linear import OPENMP_ENV

    model = strip_model(nx, ny, element="RFT6")
    times: list[float] = []
    analyze, before = skc.analyze, os.environ.get(OPENMP_ENV)
    skc.analyze = lambda *a, **k: _TimedFactor(analyze(*a, **k), times)
    os.environ[OPENMP_ENV] = openmp
    try:
        t0 = time.perf_counter()
        static.solve_static(model, options=static.StaticOptions(progress=False))
        wall = time.perf_counter() - t0
    finally:
        skc.analyze = analyze
        if before is None:
            os.environ.pop(OPENMP_ENV, None)
        else:
            os.environ[OPENMP_ENV] = before
    t = np.asarray(times)
    return {"wall_s": wall, "factorisations": len(t), "factor_s": float(t.sum()),
            "median_ms": 1e3 * float(np.median(t)) if len(t) else float("nan"),
            "per_factorisation_ms": 1e3 * float(t.sum()) / max(len(t), 1)}


def run(problems=tuple(PROBLEMS), *, reps: int = 10, solve: bool = False) -> None:
    """Print the factorisation figures (see the module docstring)."""
    from rftstatic.solvers.linear import CholmodSolver, cholmod_available

    if not cholmod_available():
        print("factor: scikit-sparse (CHOLMOD) is not installed; nothing to measure")
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    for name in problems:
        K = tangent(name)
        print(f"\n{name}: {K.shape[0]} unknowns, nnz(K) {K.nnz}; CholmodSolver picks "
              f"{CholmodSolver.choose_mode(K.shape[0])}; factorisation [ms] median best of {reps}")
        print(f"  {'mode':10s} {'ordering':8s} {'nnz(L)':>9s} {'Mflops':>8s} {'analysis':>9s}   "
              f"{'OpenMP built':>15s}   {'OpenMP serial':>15s}")
        for r in time_modes(K, reps=reps):
            print(f"  {r['mode']:10s} {r['ordering']:8s} {r['nnz_L']:9d} {r['flops'] / 1e6:8.1f} "
                  f"{1e3 * r['analysis_s']:9.1f}   {_stats(r['built'])}   {_stats(r['serial'])}")
        alt = time_alternatives(K, reps=max(1, reps // 4))
        print(f"  scipy splu (MMD_AT_PLUS_A) {_stats(alt['splu'])}; sksparse cholesky (analysis + "
              f"factorisation) {_stats(alt['cholesky'])}; rank-1 update_inplace {_stats(alt['update_rank1'])}")
    live = live_libraries()
    print(f"\nlive: {live['threads']} threads; {', '.join(live['libraries'])}")
    if solve:
        for openmp in ("built", "serial"):
            r = solve_factor_times(openmp=openmp)
            print(f"strip 101x21 full solve, CHOLMOD OpenMP {openmp:6s}: {r['wall_s']:6.2f} s, "
                  f"{r['factorisations']} factorisations {r['factor_s']:6.2f} s, "
                  f"{r['per_factorisation_ms']:5.1f} ms each (median {r['median_ms']:5.1f})")


if __name__ == "__main__":
    run(solve=True)
