"""The Newton step by preconditioned CG (rftstatic.solvers.krylov) and its use in the displacement iteration."""


import numpy as np
import pytest
import scipy.sparse as sp

from rftstatic.bench.problems import strip_model
from rftstatic.solvers import static
from rftstatic.solvers.krylov import LEAST_FORCING, REFRESH_ITERATIONS, forcing, truncated_cg
from rftstatic.solvers.linear import AmgSolver, CholmodSolver, ScipySolver, cholmod_available
from rftstatic.solvers.krylov import uses_krylov
from rftstatic.solvers.options import NewtonOptions, StaticOptions


def spd(n, seed=0, condition=1e3):
    """A random SPD matrix with eigenvalues in [1, condition]."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return sp.csr_matrix(Q @ np.diag(np.geomspace(1.0, condition, n)) @ Q.T)


def test_cg_with_the_exact_inverse_as_preconditioner_takes_one_iteration():
    A = spd(30)
    r = np.random.default_rng(1).standard_normal(30)
    step = truncated_cg(A, r, lambda b: np.linalg.solve(A.toarray(), b), rtol=1e-10)
    assert step.outcome == "converged" and step.iterations == 1
    assert np.allclose(A @ step.d, -r, atol=1e-9 * np.linalg.norm(r))


def test_cg_meets_its_tolerance_and_the_galerkin_condition():
    """Each CG iterate minimises the quadratic model over its Krylov space: d.A.d = -r.d, so the step is a
    descent direction and the model's predicted decrease is -r.d / 2."""
    A = spd(60, condition=1e4)
    r = np.random.default_rng(2).standard_normal(60)
    D = A.diagonal()
    for rtol in (0.5, 1e-2, 1e-8):
        step = truncated_cg(A, r, lambda b: b / D, rtol=rtol, max_iterations=200)
        assert step.outcome == "converged"
        assert np.linalg.norm(A @ step.d + r) <= rtol * np.linalg.norm(r)
        assert step.curvature == pytest.approx(-float(r @ step.d), rel=1e-3)  # round-off over many iterations
        assert float(r @ step.d) < 0.0


def test_cg_stops_at_negative_curvature_with_a_descent_direction():
    A = spd(40).toarray()
    A[0, 0] = -50.0  # an indefinite matrix
    A = sp.csr_matrix(A)
    r = np.ones(40)
    step = truncated_cg(A, r, lambda b: b, rtol=1e-12, max_iterations=100)
    assert step.outcome == "negative curvature"
    assert float(r @ step.d) < 0.0
    # negative curvature on the first direction: the preconditioned steepest descent
    N = -sp.identity(5, format="csr")
    first = truncated_cg(N, np.arange(1.0, 6.0), lambda b: 2.0 * b)
    assert first.outcome == "negative curvature" and first.iterations == 1
    assert np.allclose(first.d, -2.0 * np.arange(1.0, 6.0))


def test_a_slow_or_truncated_solve_asks_for_a_new_factorisation():
    A = spd(80, condition=1e6)
    r = np.random.default_rng(3).standard_normal(80)
    slow = truncated_cg(A, r, lambda b: b, rtol=1e-10, max_iterations=REFRESH_ITERATIONS + 1)
    assert slow.outcome == "iterations" and slow.stale
    fast = truncated_cg(A, r, lambda b: np.linalg.solve(A.toarray(), b), rtol=1e-10)
    assert not fast.stale


def test_forcing_term_tightens_with_the_residual_within_its_bounds():
    assert forcing(1.0, 1.0) == 0.5
    assert forcing(1e-2, 1.0) == pytest.approx(0.1)
    assert forcing(1e-12, 1.0) == LEAST_FORCING
    assert forcing(1.0, 0.0) == 0.5


def test_auto_takes_krylov_on_large_meshes_with_a_cheap_resolve_only():
    auto, direct, krylov = NewtonOptions(), NewtonOptions(step_solver="direct"), NewtonOptions(step_solver="krylov")
    chol = CholmodSolver() if cholmod_available() else ScipySolver()
    assert not uses_krylov(auto, 30_600, chol) and uses_krylov(auto, 121_200, chol)
    assert uses_krylov(krylov, 10, chol) and not uses_krylov(direct, 121_200, chol)
    amg = AmgSolver(np.zeros((2, 3)), np.arange(6))  # its re-solve is a whole CG solve
    assert not uses_krylov(krylov, 121_200, amg)


def test_step_solver_option_is_checked():
    with pytest.raises(ValueError, match=r'solver.step_solver: "lu" is not one of auto, direct, krylov'):
        StaticOptions.from_keys(step_solver="lu")


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_krylov_steps_reach_the_direct_equilibrium(element):
    """The displacement iteration with preconditioned-CG steps converges to the equilibrium of the direct
    one (the §4.1 strip under its weight, load steps from flat), with fewer factorisations."""
    mod = strip_model(21, 5, element=element)
    base = StaticOptions.from_keys(progress=False, iteration="displacement", relax_fallback=False)
    a = static.solve_static(mod, options=base.replace(step_solver="direct"))
    b = static.solve_static(mod, options=base.replace(step_solver="krylov"))
    assert a.converged and b.converged and b.stable
    assert b.tangent_modes.get("krylov", 0) > 0 and b.tangent_modes["CG iterations"] >= b.tangent_modes["krylov"]
    assert "krylov" not in a.tangent_modes
    assert np.abs(a.U - b.U).max() < 1e-6 * np.abs(a.U).max()
    assert b.factorisations < a.factorisations
