"""Linear solvers for the Newton step ``K d = -r`` on the free degrees of freedom.

- ``cholmod``: CHOLMOD sparse Cholesky (scikit-sparse); the symbolic analysis (fill-reducing
  ordering) is done once and reused by every factorisation, and a tangent that is not positive
  definite is detected (:class:`NotPositiveDefinite`), which the Newton solver uses to switch to
  its safeguarded tangent.
- ``scipy``: SuperLU from scipy, the fallback when scikit-sparse is not installed (logged).
- ``amg``: conjugate gradients preconditioned by pyamg's smoothed aggregation, given the six
  rigid-body modes of the free nodes, for very large meshes.
"""

from __future__ import annotations

import logging

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
    shared with another process). Set before the library loads; an explicit user setting wins."""
    import os

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


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
    name = "cholmod"
    detects_indefinite = True
    cheap_resolve = True  # resolve() is a back-substitution

    def __init__(self):
        self._factor = None
        self._pattern = None

    def solve(self, K: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        from sksparse.cholmod import CholmodNotPositiveDefiniteError, analyze

        A = K.T  # CSR of a symmetric matrix = its CSC transpose, no copy
        pattern = (A.shape, A.nnz)
        if self._factor is None or pattern != self._pattern:
            # measured on RF tangents (2 cores): simplicial AMD is fastest for small problems
            # (strip 11 x 51, 1683 unknowns: 5.5 ms against 13 ms supernodal), supernodal METIS
            # from a few thousand (pedestal 33 x 33, 3264 unknowns: 22 ms against 53 ms simplicial)
            if A.shape[0] < 2_500:
                self._factor = analyze(A, mode="simplicial", ordering_method="amd")
            else:
                self._factor = analyze(A, mode="supernodal", ordering_method="metis")
            self._pattern = pattern
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
