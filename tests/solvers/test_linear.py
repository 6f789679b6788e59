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
