"""The CHOLMOD wrapper: solves, reuse of the factorisation, definiteness check, OpenMP ICVs restored."""

import numpy as np
import pytest
import scipy.sparse as sp

from rftstatic.solvers import linear

pytestmark = pytest.mark.skipif(not linear.cholmod_available(), reason="scikit-sparse is not installed")


def _laplacian(n, shift):
    """1-D Laplacian plus ``shift`` times the identity (CSR): positive definite for shift > 0."""
    main = np.full(n, 2.0 + shift)
    return sp.diags([main, -np.ones(n - 1), -np.ones(n - 1)], [0, -1, 1], format="csr")


@pytest.mark.parametrize("n", [50, 2000])  # simplicial and supernodal
def test_cholmod_solves_and_reuses(n):
    K = _laplacian(n, 0.1)
    b = np.sin(np.arange(n))
    s = linear.CholmodSolver()
    x = s.solve(K, b)
    assert np.allclose(K @ x, b, rtol=0, atol=1e-10)
    assert np.allclose(s.resolve(2 * b), 2 * x, rtol=1e-12, atol=0)
    x2 = s.solve(K * 3.0, b)  # same pattern: numeric factorisation only
    assert np.allclose(x2, x / 3.0, rtol=1e-10, atol=0)


@pytest.mark.parametrize("n", [50, 2000])
def test_cholmod_detects_indefinite(n):
    s = linear.CholmodSolver()
    s.solve(_laplacian(n, 0.1), np.ones(n))
    with pytest.raises(linear.NotPositiveDefinite):
        s.solve(_laplacian(n, -1.0), np.ones(n))
    with pytest.raises(linear.LinearSolveError):
        s.resolve(np.ones(n))


def test_modes_by_size():
    assert linear.CholmodSolver.choose_mode(100) == ("simplicial", "amd")
    assert linear.CholmodSolver.choose_mode(6300)[0] == "supernodal"
    assert linear.CholmodSolver.choose_mode(121_200) == ("supernodal", "nesdis")


def test_nested_dissection_solves_a_large_system():
    n = linear.CholmodSolver.NESTED_DISSECTION_FROM + 10
    K, b = _laplacian(n, 0.5), np.cos(np.arange(n))
    s = linear.CholmodSolver()
    x = s.solve(K, b)
    assert s.analyses == 1 and np.allclose(K @ x, b, rtol=0, atol=1e-10)
    with pytest.raises(linear.NotPositiveDefinite):
        s.solve(_laplacian(n, -1.0), b)


def _grid_laplacian(m, shift, pairs=()):
    """2-D grid Laplacian (m x m nodes) + ``shift`` I, with each ``(i, j)`` of ``pairs`` coupled by a unit
    spring (the long-range blocks self-contact adds): positive definite for shift > 0."""
    L1 = sp.diags([2.0 * np.ones(m), -np.ones(m - 1), -np.ones(m - 1)], [0, -1, 1])
    K = sp.kronsum(L1, L1) + shift * sp.identity(m * m)
    if pairs:
        i, j = np.array(pairs).T
        n = m * m
        S = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
        D = sp.diags(np.asarray(S.sum(axis=1)).ravel() + np.asarray(S.sum(axis=0)).ravel())
        K = K + D - S - S.T
    K = sp.csr_matrix(K)
    K.sum_duplicates()
    K.sort_indices()
    return K


def test_a_changed_pattern_keeps_the_last_ordering_and_solves_exactly(monkeypatch):
    """From NESTED_DISSECTION_FROM unknowns a new pattern (self-contact pairs come and go) is analysed with the
    last fresh ordering (the tangent permuted, natural order) up to ORDERING_REUSE times; every solve and
    back-substitution is exact, and the ordering is renewed after that."""
    monkeypatch.setattr(linear.CholmodSolver, "NESTED_DISSECTION_FROM", 100)
    monkeypatch.setattr(linear.CholmodSolver, "ORDERING_REUSE", 2)
    m = 30
    rng = np.random.default_rng(3)
    b = rng.standard_normal(m * m)
    s = linear.CholmodSolver()
    for k in range(5):
        pairs = [tuple(rng.choice(m * m, 2, replace=False)) for _ in range(5 + k)]
        K = _grid_laplacian(m, 0.05, pairs)
        x = s.solve(K, b)
        assert np.allclose(K @ x, b, rtol=0, atol=1e-9)
        assert np.allclose(K @ s.resolve(3 * b), 3 * b, rtol=0, atol=1e-9)
        x2 = s.solve(2.0 * K, b)  # same pattern: no analysis, the kept map gathers the new entries
        assert np.allclose(x2, x / 2.0, rtol=1e-10, atol=0)
    assert s.analyses == 5 and s.orderings == 2  # fresh, 2 kept, fresh, 1 kept
    with pytest.raises(linear.NotPositiveDefinite):
        s.solve(_grid_laplacian(m, -1.0, pairs), b)
    with pytest.raises(linear.LinearSolveError):
        s.resolve(b)


def test_serial_openmp_restores_the_threads():
    linear.CholmodSolver().solve(_laplacian(10, 1.0), np.ones(10))  # CHOLMOD (and its OpenMP) loaded
    runtimes = linear._openmp_runtimes()
    if not runtimes:
        pytest.skip("CHOLMOD is built without OpenMP here")
    rt = runtimes[0]
    before = (rt.omp_get_dynamic(), rt.omp_get_max_threads())
    with linear.SerialOpenMP(enabled=True):
        assert (rt.omp_get_dynamic(), rt.omp_get_max_threads()) == (1, 1)
    assert (rt.omp_get_dynamic(), rt.omp_get_max_threads()) == before
    with linear.SerialOpenMP(enabled=False):
        assert (rt.omp_get_dynamic(), rt.omp_get_max_threads()) == before
