"""Linear solvers for the Newton step ``K d = -r`` on the free degrees of freedom.

- ``cholmod``: CHOLMOD sparse Cholesky (scikit-sparse); the symbolic analysis (fill-reducing
  ordering) is done once and reused by every factorisation, and a tangent that is not positive
  definite is detected (:class:`NotPositiveDefinite`), which the Newton solver uses to switch to
  its safeguarded tangent. CHOLMOD's own OpenMP loops run on the calling thread
  (:class:`SerialOpenMP`: Debian's build opens 4-thread regions per supernode, which on 2 cores took
  73 ms per factorisation of a 6,300-unknown tangent against 30 ms) and its BLAS on one thread.
- ``scipy``: SuperLU from scipy, the fallback when scikit-sparse is not installed (logged).
- ``amg``: conjugate gradients preconditioned by pyamg's smoothed aggregation, given the six
  rigid-body modes of the free nodes, for very large meshes.
"""

from __future__ import annotations

import ctypes
import functools
import logging
import os

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

SOLVERS = ("auto", "cholmod", "scipy", "amg")


class NotPositiveDefinite(ArithmeticError):
    """The tangent is not positive definite (detected by the Cholesky factorisation)."""


class LinearSolveError(ArithmeticError):
    """The linear solver failed (singular matrix, no convergence)."""


def _single_threaded_blas() -> None:
    """CHOLMOD's BLAS (Debian's OpenBLAS) busy-waits with threads; on the small supernodes of a
    sheet's tangent one thread is faster (measured: 81 x 81 nodes, 400 ms against 670 ms on 2 cores
    shared with another process; again: 143 ms against 184 ms, best of 10, 81 x 81 supernodal
    AMD with one OpenMP thread). Set before the library loads; an explicit user setting wins."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


OPENMP_ENV = "RFTSTATIC_CHOLMOD_OPENMP"
"""``"built"`` leaves CHOLMOD's OpenMP loops as compiled (Debian: teams of 4 threads); unset or
``"serial"`` (the default) runs them on the calling thread, see :class:`SerialOpenMP`."""


@functools.cache
def _openmp_runtimes() -> tuple:
    """The OpenMP runtimes (libgomp, libomp, libiomp5) mapped into this process, as ctypes handles.

    Read from ``/proc/self/maps`` (Linux), so a runtime that a wheel vendors under another file name
    is found too; ``()`` elsewhere or when none is loaded. sksparse is imported first, so CHOLMOD's
    runtime is among them.
    """
    cholmod_available()
    try:
        with open("/proc/self/maps") as fh:
            paths = {line.split(None, 5)[-1].strip() for line in fh if ".so" in line}
    except OSError:
        return ()
    found = []
    for path in sorted(paths):
        name = os.path.basename(path)
        if not name.startswith(("libgomp", "libomp", "libiomp5")):
            continue
        try:
            lib = ctypes.CDLL(path, mode=getattr(os, "RTLD_NOLOAD", 0) | ctypes.RTLD_LOCAL)
            for fn in ("omp_get_dynamic", "omp_set_dynamic", "omp_get_max_threads", "omp_set_num_threads"):
                getattr(lib, fn)
        except (OSError, AttributeError):
            continue
        found.append(lib)
    return tuple(found)


class SerialOpenMP:
    """Context manager: OpenMP parallel regions that this thread opens inside it get one thread.

    Why (measured on the 2-core AMD EPYC KVM machine, Debian 12, SuiteSparse 5.12 /
    CHOLMOD 3.0.14, OpenBLAS 0.3.21 pthread, scikit-sparse 0.4.16; the other core busy with another
    job, so compare ratios): Debian's CHOLMOD is compiled with OpenMP, and its supernodal numeric
    factorisation opens ``#pragma omp parallel for num_threads(CHOLMOD_OMP_NUM_THREADS)`` regions
    (compiled-in default 4, a clause, so ``OMP_NUM_THREADS`` does not change it) around the
    clearing and assembly of every supernode: 2,900-3,700 regions per factorisation of the 101 x 21
    strip's tangent (6,300 unknowns; METIS / AMD ordering). On 2 cores each region wakes 3 libgomp
    workers and waits at a barrier for threads that are not running: 1.06e6 futex calls in a full
    solve of that strip (99.8 % of them from libgomp, called from libcholmod: ``perf record -e
    syscalls:sys_enter_futex``), 6.5 s of system time, and per factorisation 3,300 voluntary context
    switches, 35 ms user + 18 ms system time, 44-55 ms wall against 22 ms (20 user + 2 system, no
    context switch) with one thread; the BLAS does the flops, those OpenMP loops only move memory,
    and a team of 2 (``OMP_THREAD_LIMIT=2``) is no faster than 1 (21 against 19 ms). In the full
    solve of the strip: 62-68 ms per factorisation before, 20-23 ms after (135 factorisations, 8.4 s
    of 15-22 s before, 2.9 s of 8.4-9.4 s after). Numba's ``parallel=True`` kernels take libgomp too
    (threading layer ``omp``: tbb is not installed), so the explicit route's force kernel and
    CHOLMOD share one thread pool that is resized each time one follows the other.

    Inside the context libgomp's dynamic adjustment is on and the thread's nthreads-var is 1, which
    bounds even a ``num_threads`` clause (libgomp: ``gomp_resolve_num_threads`` caps the team by
    ``gomp_dynamic_max_threads() <= nthreads-var``); on exit both are restored, so numba's OpenMP
    threading layer (which shares libgomp) keeps its threads. Unlike ``OMP_THREAD_LIMIT=1`` this does
    not depend on being set before libgomp loads, and does not serialise numba's parallel kernels.
    Costs a few microseconds. Does nothing when :data:`OPENMP_ENV` is ``"built"`` or no OpenMP
    runtime is loaded.
    """

    def __init__(self, enabled: bool | None = None):
        if enabled is None:
            enabled = os.environ.get(OPENMP_ENV, "serial").strip().lower() != "built"
        self._runtimes = _openmp_runtimes() if enabled else ()
        self._saved = []

    def __enter__(self):
        self._saved = [(rt, rt.omp_get_dynamic(), rt.omp_get_max_threads()) for rt in self._runtimes]
        for rt in self._runtimes:
            rt.omp_set_dynamic(1)
            rt.omp_set_num_threads(1)
        return self

    def __exit__(self, *exc):
        for rt, dynamic, threads in self._saved:
            rt.omp_set_dynamic(dynamic)
            rt.omp_set_num_threads(threads)
        self._saved = []
        return False


def cholmod_available() -> bool:
    _single_threaded_blas()
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def make_solver(name: str = "auto", *, coordinates=None, free_dofs=None):
    """A linear solver by name; ``"auto"`` takes CHOLMOD when it imports, else scipy (logged).

    Parameters
    ----------
    coordinates : (N, 3) node positions [m], for the rigid-body modes given to AMG
    free_dofs : indices of the free degrees of freedom (3 n + i), for AMG
    """
    if name not in SOLVERS:
        raise ValueError(f'unknown linear solver "{name}"; use one of {", ".join(SOLVERS)}')
    if name == "auto":
        if cholmod_available():
            return CholmodSolver()
        log.info("scikit-sparse (CHOLMOD) is not installed: using scipy's SuperLU. "
                 "Install rftstatic[cholmod] for faster, definiteness-checking factorisations.")
        return ScipySolver()
    if name == "cholmod":
        if not cholmod_available():
            raise ValueError('linear solver "cholmod" needs scikit-sparse: pip install "rftstatic[cholmod]" '
                             "(on Debian first apt-get install libsuitesparse-dev), or use solver.linear_solver = \"scipy\"")
        return CholmodSolver()
    if name == "scipy":
        return ScipySolver()
    return AmgSolver(coordinates, free_dofs)


class CholmodSolver:
    """CHOLMOD Cholesky: analysis once per sparsity pattern, then ``cholesky_inplace`` per tangent.

    Mode and ordering by size (:meth:`choose_mode`); every call into CHOLMOD runs inside
    :class:`SerialOpenMP`. A tangent that is not positive definite raises
    :class:`NotPositiveDefinite` and leaves no factorisation for :meth:`resolve`.
    """

    name = "cholmod"
    detects_indefinite = True
    cheap_resolve = True  # resolve() is a back-substitution

    SIMPLICIAL_BELOW = 500
    """Unknowns below which the factorisation is simplicial; supernodal from there on."""

    NESTED_DISSECTION_FROM = 10_000
    """Unknowns from which the supernodal factorisation is ordered by CHOLMOD's nested dissection
    (``nesdis``: METIS separators, CAMD on the parts); below, CHOLMOD's default (AMD here). Measured
    (2026-12-05, near idle; one tangent of each scene's Newton walk shifted by 1e-2 x its mean diagonal so
    that every factorisation runs to its end, median of 8 interleaved ``cholesky_inplace`` calls in
    :class:`SerialOpenMP`, AMD / METIS / nested dissection [ms]): pedestal-round-50 (16,548 unknowns) 97.7 /
    78.9 / 78.3; pedestal-square-80 (19,680) 82.1 / 79.6 / 75.9; sphere-30 (11,160) 40.2 / 37.6 / 37.0;
    cusick-30 (5,760) 10.5 / 10.4 / 10.5 (a tie); the 80 cm drape carried to 201 x 201 nodes (121,200
    unknowns): AMD 4.0-4.5 s, METIS 3.2 s, nested dissection 2.6-2.9 s. The back-substitution gains
    alike (pedestal-round-50 7.0 against 6.0 ms). The analysis costs 50 instead of 20 ms at 16,548
    unknowns; it is done once per pattern (again when self-contact changes it). Below 10,000 unknowns
    the strips and sheets measured fill less with AMD (the strip 101 x 21: 0.76e6 against 0.97e6 entries
    of L with METIS)."""

    def __init__(self):
        self._factor = None
        self._pattern = None
        self.analyses = 0  # symbolic analyses done (one per sparsity pattern met)

    def _same_pattern(self, K) -> bool:
        """Whether ``K`` has the sparsity pattern of the analysed matrix. Compared entry by entry, not by
        shape and nnz alone: self-contact (:meth:`rftstatic.model.model.Model.tangent`) adds blocks
        outside the patch pattern, and two pair sets can give the same nnz in different places (the
        old analysis would then not fit). Costs O(nnz), a few percent of a factorisation."""
        if self._pattern is None:
            return False
        shape, indptr, indices = self._pattern
        return (K.shape == shape and K.indptr.shape == indptr.shape and K.indices.shape == indices.shape
                and np.array_equal(K.indptr, indptr) and np.array_equal(K.indices, indices))

    @classmethod
    def choose_mode(cls, n: int) -> tuple[str, str]:
        """(mode, ordering) of ``sksparse.cholmod.analyze`` for a tangent of ``n`` unknowns.

        Measured (``python -m rftstatic.bench.factor``, one run; 2-core AMD EPYC KVM, load
        average 1.3-1.9 from another job, so compare within a row): one ``cholesky_inplace`` of the
        flat-state RFT6 tangent, median of 10 [ms], CHOLMOD's OpenMP serial as :meth:`solve` runs it,
        and in the last column as built (4-thread regions, what the old rule was measured with):

        ==============  ========  ==========  ==========  ==========  ======================
        tangent         unknowns  simplicial  supernodal  supernodal  supernodal AMD,
                                  AMD         AMD         METIS       OpenMP as built
        ==============  ========  ==========  ==========  ==========  ======================
        strip 21 x 5    300       0.4         0.4         0.4         0.5
        strip 31 x 7    630       1.6         1.3         1.3         2.4
        strip 51 x 11   1,650     11.0        4.7         5.3         10.3
        sheet 33 x 33   3,261     71.7        12.6        13.4        29.4
        strip 101 x 21  6,300     63.5        16.2        23.1        44.0
        sheet 81 x 81   19,677    1,464       135         151         265
        ==============  ========  ==========  ==========  ==========  ======================

        The old rule (simplicial AMD below 2,500 unknowns, supernodal METIS above) came from timings
        with CHOLMOD's 4-thread OpenMP regions on (see :class:`SerialOpenMP`), which cost the
        supernodal mode 2-3x and hid that it wins from a few hundred unknowns (below, the two tie;
        90 unknowns: 0.07 against 0.09 ms). AMD fills less than METIS on every one of these strips and
        sheets (strip 101 x 21: 0.76e6 against 0.97e6 entries of L, 1.0e8 against 1.8e8 flops; sheet
        81 x 81: 4.60e6 against 4.70e6), so the supernodal mode takes CHOLMOD's default ordering,
        which is AMD here (same L) and tries METIS only where AMD fills badly, keeping the better;
        the analysis is done once per pattern (6,300 unknowns: 12 ms, METIS 26 ms). From
        :data:`NESTED_DISSECTION_FROM` unknowns nested dissection fills and costs less (measured there).
        The ordering
        changes the round-off of the steps, which matters where the tangent is nearly singular: the
        33 x 33 sheet's load steps from the flat start now get through (193 Newton iterations, 6.8 s)
        where with METIS they failed at load factor 1e-5 and fell back to dynamic relaxation (359
        iterations, 30 s), to the same equilibrium (8e-11 m); the strips take the same 135 steps.
        """
        if n < cls.SIMPLICIAL_BELOW:
            return "simplicial", "amd"
        if n >= cls.NESTED_DISSECTION_FROM:
            return "supernodal", "nesdis"
        return "supernodal", "default"

    def solve(self, K: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        from sksparse.cholmod import CholmodError, CholmodNotPositiveDefiniteError, analyze

        A = K.T  # CSR of a symmetric matrix = its CSC transpose, no copy
        with SerialOpenMP():
            if self._factor is None or not self._same_pattern(K):
                mode, ordering = self.choose_mode(A.shape[0])
                try:
                    self._factor = analyze(A, mode=mode, ordering_method=ordering)
                except CholmodError:  # a CHOLMOD built without its Partition module (METIS): no nesdis
                    self._factor = analyze(A, mode=mode, ordering_method="default")
                self._pattern = (K.shape, K.indptr.copy(), K.indices.copy())
                self.analyses += 1
            try:
                self._factor.cholesky_inplace(A)
            except CholmodNotPositiveDefiniteError as exc:
                self._valid = False
                raise NotPositiveDefinite(str(exc)) from None
            self._valid = True
            return self._factor(b)

    def resolve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last factorisation (modified Newton)."""
        if self._factor is None or not getattr(self, "_valid", False):
            raise LinearSolveError("no factorisation to reuse")
        with SerialOpenMP():
            return self._factor(b)


class ScipySolver:
    name = "scipy"
    detects_indefinite = False
    cheap_resolve = True

    def solve(self, K: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        from scipy.sparse.linalg import splu

        try:
            lu = splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise LinearSolveError(f"SuperLU: {exc}") from None
        x = lu.solve(b)
        if not np.all(np.isfinite(x)):
            raise LinearSolveError("SuperLU returned non-finite values (singular tangent)")
        self._lu = lu
        return x

    def resolve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last factorisation (modified Newton)."""
        if getattr(self, "_lu", None) is None:
            raise LinearSolveError("no factorisation to reuse")
        return self._lu.solve(b)


class AmgSolver:
    name = "amg"
    detects_indefinite = False
    cheap_resolve = False  # resolve() is a whole preconditioned CG solve

    def __init__(self, coordinates, free_dofs, *, rtol=1e-10, maxiter=2000):
        if coordinates is None or free_dofs is None:
            raise ValueError("the AMG solver needs node coordinates and the free dofs (rigid-body modes)")
        x = np.asarray(coordinates, float)
        x = x - x.mean(axis=0)
        n = len(x)
        B = np.zeros((n, 3, 6))
        for i in range(3):
            B[:, i, i] = 1.0
        # rotations: e_k x x
        B[:, 1, 3], B[:, 2, 3] = -x[:, 2], x[:, 1]
        B[:, 0, 4], B[:, 2, 4] = x[:, 2], -x[:, 0]
        B[:, 0, 5], B[:, 1, 5] = -x[:, 1], x[:, 0]
        self.B = B.reshape(3 * n, 6)[free_dofs]
        self.rtol, self.maxiter = rtol, maxiter
        self.iterations = 0

    def solve(self, K: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        import pyamg
        from scipy.sparse.linalg import cg

        ml = pyamg.smoothed_aggregation_solver(K, B=self.B, symmetry="symmetric", max_coarse=500)
        count = [0]

        def cb(_):
            count[0] += 1

        x, info = cg(K, b, rtol=self.rtol, maxiter=self.maxiter, M=ml.aspreconditioner(), callback=cb)
        self._last = (K, ml)
        self.iterations = count[0]
        if info != 0:
            raise LinearSolveError(f"AMG-preconditioned CG did not converge in {self.maxiter} iterations")
        return x

    def resolve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last matrix and hierarchy (modified Newton)."""
        from scipy.sparse.linalg import cg

        if getattr(self, "_last", None) is None:
            raise LinearSolveError("no matrix to reuse")
        K, ml = self._last
        x, info = cg(K, b, rtol=self.rtol, maxiter=self.maxiter, M=ml.aspreconditioner())
        if info != 0:
            raise LinearSolveError(f"AMG-preconditioned CG did not converge in {self.maxiter} iterations")
        return x
