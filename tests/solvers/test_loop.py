"""The one Newton loop (rftstatic.solvers.loop): its contract on a scalar problem, and that every Newton
iteration of the static solver (mixed, displacement, Krylov, arc-length corrector) runs through it."""

import numpy as np
import pytest

from rftstatic.bench.problems import strip_model
from rftstatic.solvers import continuation, displacement, mixed
from rftstatic.solvers.loop import Direction, Iterate, StepFailure, newton_loop
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.static import solve_static


def _cube_root_parts(tol=1e-14):
    """Newton on r(u) = u^3 - 2 (the root 2^(1/3)), a full step per iteration."""
    def residual(u):
        r = np.array([u ** 3 - 2.0])
        return r, float(abs(r[0]))

    def test(x):
        return x.rnorm <= tol

    def direction(x):
        return Direction(np.array([-x.r[0] / (3.0 * x.U ** 2)]), "exact")

    def globalise(x, dn):
        u = x.U + dn.d[0]
        r, rnorm = residual(u)
        return Iterate(u, 1.0, r, rnorm), {"step": float(dn.d[0])}

    r, rnorm = residual(1.0)
    return Iterate(1.0, 1.0, r, rnorm), test, direction, globalise


def test_the_loop_converges_quadratically_and_counts_its_steps():
    x, test, direction, globalise = _cube_root_parts()
    out = newton_loop(x, test=test, direction=direction, globalise=globalise, max_iterations=20)
    assert out.converged and out.reason == "" and out.x.U == pytest.approx(2 ** (1 / 3), rel=1e-15)
    res = [h["residual"] for h in out.history]
    assert out.iterations == len(res)  # the start is not tested (first_test = 2): every step is counted
    # quadratic: log r_{k+1} / log r_k -> 2 in the last steps above round-off
    rates = [np.log(res[k + 1]) / np.log(res[k]) for k in range(len(res) - 1) if res[k] < 0.1 and res[k + 1] > 1e-14]
    assert rates and 1.8 < rates[-1] < 2.3


def test_the_loop_stops_where_a_part_fails_and_when_the_iterations_run_out():
    x, test, direction, globalise = _cube_root_parts()

    def failing(x, dn):
        raise StepFailure("no decrease", Iterate(-1.0, 1.0))

    out = newton_loop(x, test=test, direction=direction, globalise=failing, max_iterations=5)
    assert not out.converged and out.iterations == 1 and out.reason == "no decrease" and out.x.U == -1.0
    out = newton_loop(x, test=test, direction=direction, globalise=globalise, max_iterations=2)
    assert not out.converged and out.reason is None and out.iterations == 2
    # a start that passes is taken with no step only when the start is tested
    done = Iterate(2 ** (1 / 3), 1.0, np.zeros(1), 0.0)
    assert newton_loop(done, test=test, direction=direction, globalise=globalise, max_iterations=3,
                       first_test=1).iterations == 0
    assert newton_loop(done, test=test, direction=direction, globalise=globalise, max_iterations=3).iterations == 1


@pytest.mark.parametrize("keys, module", [
    ({"iteration": "mixed"}, mixed),
    ({"iteration": "displacement"}, displacement),
    ({"iteration": "displacement", "step_solver": "krylov"}, displacement),
    ({"continuation": "arc-length", "relax_fallback": False}, continuation),
])
def test_every_newton_iteration_runs_the_one_loop(monkeypatch, keys, module):
    calls = []

    def spy(*a, **kw):
        calls.append(1)
        return newton_loop(*a, **kw)

    monkeypatch.setattr(module, "newton_loop", spy)
    res = solve_static(strip_model(11, 3), options=StaticOptions.from_keys(progress=False, **keys))
    assert res.converged and calls
