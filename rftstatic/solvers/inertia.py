"""Inertia of a sparse symmetric tangent: how many of its eigenvalues are negative, and its lowest modes.

Path following (:mod:`rftstatic.solvers.continuation`) needs, at every converged point of the path, the
number of negative eigenvalues of the tangent K: it changes exactly where the path crosses a limit point
or a bifurcation. By Sylvester's law of inertia a factorisation ``P K P^T = L D L^T`` (L unit lower
triangular, D diagonal) has as many negative pivots ``D_ii < 0`` as K has negative eigenvalues.

Method (named, as the issue asks): CHOLMOD through scikit-sparse 0.4.

1. supernodal ``L L^T`` of K (the fast mode, :class:`~rftstatic.solvers.linear.CholmodSolver`): when it
   succeeds K is positive definite, inertia 0 negative pivots;
2. when CHOLMOD reports "not positive definite", a *simplicial* ``L D L^T`` of the same K (CHOLMOD's
   up-looking LDL^T, no pivoting, the fill-reducing ordering of its analysis), whose ``D()`` gives the
   pivots. Without pivoting the factorisation of an indefinite matrix can meet a tiny pivot (the matrix
   exactly singular in a leading block); a pivot that is zero or not finite is reported as
   :class:`~rftstatic.solvers.linear.LinearSolveError`. On the mildly indefinite tangents of a path
   (a few negative eigenvalues next to a positive definite bulk) the counts agree with dense
   eigenvalues (tests/solvers/test_inertia.py).

The simplicial mode is 5-10 x slower than the supernodal one (linear.py's table: 33 x 33 sheet 72
against 13 ms), so it runs only when the tangent is indefinite.

:func:`lowest_modes`: the eigenpairs of K nearest a shift (default 0) by ARPACK in shift-invert mode
(scipy ``eigsh``), the inverse operator applied with the factorisation itself: the critical mode at a
limit point or bifurcation, along which the branch is switched.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rftstatic.solvers.linear import LinearSolveError, SerialOpenMP, cholmod_available


@dataclass
class InertiaFactor:
    """One factorisation of a symmetric K with its inertia.

    Attributes
    ----------
    negative : number of negative pivots = negative eigenvalues of K [-]
    method : ``"cholesky"`` (supernodal L L^T: K positive definite) or ``"ldl"`` (simplicial L D L^T)
    smallest_pivot : smallest |D_ii| relative to the largest (``ldl`` only; 1 for ``cholesky``) [-]
    """

    factor: object
    negative: int
    method: str
    smallest_pivot: float = 1.0

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``K^-1 b`` for ``b (n,)`` or ``(n, k)``."""
        with SerialOpenMP():
            x = self.factor(b)
        if not np.all(np.isfinite(x)):
            raise LinearSolveError("the factorisation gave a non-finite solution (singular tangent)")
        return x


class InertiaSolver:
    """Factorises tangents with their inertia (module docstring); the symbolic analyses (one per mode and
    sparsity pattern) are reused. ``factorisations`` counts numeric factorisations, ``ldl`` those that
    needed the simplicial L D L^T."""

    name = "cholmod-inertia"

    def __init__(self):
        if not cholmod_available():
            raise ValueError('path following (solver.continuation = "arc-length") counts the negative pivots of '
                             'the tangent with CHOLMOD: pip install "rftstatic[cholmod]" or use solver.continuation '
                             '= "load"')
        self._analyses = {}
        self.factorisations = 0
        self.ldl = 0

    def _analysis(self, A, mode):
        from sksparse.cholmod import analyze

        key = (mode, A.shape, A.indptr.tobytes(), A.indices.tobytes())
        if key not in self._analyses:
            if len(self._analyses) > 8:  # self-contact changes the pattern: keep a few
                self._analyses.clear()
            ordering = "amd" if mode == "simplicial" else "default"
            self._analyses[key] = analyze(A, mode=mode, ordering_method=ordering)
        return self._analyses[key]

    def factor(self, K: sp.spmatrix) -> InertiaFactor:
        """Factorise ``K`` (symmetric, CSR or CSC) and count its negative pivots."""
        from sksparse.cholmod import CholmodNotPositiveDefiniteError

        A = sp.csc_matrix(K)
        A.sort_indices()
        self.factorisations += 1
        with SerialOpenMP():
            f = self._analysis(A, "supernodal").copy()
            try:
                f.cholesky_inplace(A)
                return InertiaFactor(f, 0, "cholesky")
            except CholmodNotPositiveDefiniteError:
                pass
            self.ldl += 1
            f = self._analysis(A, "simplicial").copy()
            try:
                f.cholesky_inplace(A)
            except CholmodNotPositiveDefiniteError as exc:  # a zero pivot
                raise LinearSolveError(f"L D L^T: {exc}") from None
            D = f.D()
        aD = np.abs(D)
        if not (np.all(np.isfinite(D)) and aD.min() > 0):
            raise LinearSolveError("L D L^T met a zero or non-finite pivot (singular tangent)")
        return InertiaFactor(f, int(np.count_nonzero(D < 0)), "ldl", float(aD.min() / aD.max()))


def count_negative(K: sp.spmatrix) -> int:
    """Number of negative eigenvalues of the sparse symmetric ``K`` (one factorisation)."""
    return InertiaSolver().factor(K).negative


DENSE_BELOW = 20
"""Unknowns up to which :func:`lowest_modes` takes dense eigenvalues."""


def lowest_modes(K: sp.spmatrix, fac: InertiaFactor, k: int = 1, *, seed: int = 0):
    """The ``k`` eigenpairs of ``K`` nearest 0, ascending: ``(values (k,), vectors (n, k))``.

    ARPACK shift-invert Lanczos (``eigsh(K, k, sigma=0, OPinv=K^-1)``) with ``fac`` as ``K^-1``; the
    start vector is seeded, so the result does not depend on the run.
    """
    from scipy.sparse.linalg import LinearOperator, eigsh

    n = K.shape[0]
    if n <= DENSE_BELOW:  # ARPACK needs k < n - 1
        vals, vecs = np.linalg.eigh(sp.csr_matrix(K).toarray())
        order = np.argsort(np.abs(vals))[:k]
        order = order[np.argsort(vals[order])]
        return vals[order], vecs[:, order]
    k = int(min(max(k, 1), n - 2))
    op = LinearOperator((n, n), matvec=fac.solve, dtype=float)
    v0 = np.random.default_rng(seed).standard_normal(n)
    vals, vecs = eigsh(sp.csr_matrix(K), k=k, sigma=0.0, OPinv=op, which="LM", v0=v0, tol=1e-8)
    order = np.argsort(vals)
    return vals[order], vecs[:, order]
