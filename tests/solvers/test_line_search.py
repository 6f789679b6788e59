"""The displacement iteration's line search (rftstatic.solvers.displacement.line_search): Armijo backtracking on
the energy; on the walk from a given state (``refine``) a shortened step refined to the lowest energy near it
(lowest_near) and the damping raised only after a step shortened below SHORT_STEP."""

from types import SimpleNamespace

import numpy as np
import pytest

from rftstatic.solvers.displacement import LINE_REFINE_FACTOR, line_search, lowest_near


class LineModel:
    """A model whose energy along the x displacement of its one node is ``Pi(a) = -a + c2 a^2 + c4 a^4`` [J]
    (slope -1 at a = 0: the Newton model ``-a + a^2 / 2`` has its minimum at the full step when c2 = 1/2 and
    c4 = 0; the quartic term is the membrane's strain, quadratic in the step). Counts its evaluations."""

    def __init__(self, c2, c4):
        self.c2, self.c4, self.calls = c2, c4, []

    def pi(self, a):
        return -a + self.c2 * a * a + self.c4 * a ** 4

    def energies(self, U, lam, **caches):
        a = float(U[0, 0])
        self.calls.append(a)
        return {"total": self.pi(a), "bending": 0.0, "membrane": 0.0, "contact": 0.0, "external_work": 0.0}

    def minimiser(self):
        roots = np.roots([4.0 * self.c4, 0.0, 2.0 * self.c2, -1.0])
        return float(min(r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0))


STATE = SimpleNamespace(candidates=None, self_pairs=None, slip=None, load_branches=None)
OPTS = SimpleNamespace(line_search=True)


def _search(model, refine=True):
    U, step = np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]])
    return line_search(model, U, step, 1.0, 0.0, -1.0, OPTS, STATE, scale=1.0, refine=refine)


def test_a_full_step_that_passes_is_taken_as_it_is():
    model = LineModel(0.5, 0.01)
    alpha, parts = _search(model)
    assert alpha == 1.0 and model.calls == [1.0]
    assert parts["total"] == pytest.approx(model.pi(1.0), rel=1e-15)


@pytest.mark.parametrize("c4", [2.0, 20.0, 200.0])
def test_a_shortened_step_lands_within_the_refine_factor_of_the_minimum(c4):
    model = LineModel(0.5, c4)
    a_min = model.minimiser()
    alpha, parts = _search(model)
    # the plain backtracking's Armijo point: the first trial that passes the sufficient decrease
    calls = list(model.calls)
    armijo = next(a for a in calls if model.pi(a) <= 1e-4 * a * -1.0 + 1e-13)
    assert alpha < 1.0 and a_min / LINE_REFINE_FACTOR <= alpha <= a_min * LINE_REFINE_FACTOR
    assert parts["total"] == pytest.approx(model.pi(alpha), rel=1e-15)
    assert parts["total"] <= model.pi(armijo)
    assert len(calls) - calls.index(armijo) - 1 <= 2 * 4  # at most LINE_REFINE_TRIALS each way


def test_without_refine_the_first_armijo_point_stands():
    model = LineModel(0.5, 20.0)
    alpha, parts = _search(model, refine=False)
    assert alpha == model.calls[-1] < 1.0 and parts["total"] == pytest.approx(model.pi(alpha), rel=1e-15)
    assert not model.minimiser() / LINE_REFINE_FACTOR <= alpha  # refined, it lands near the minimiser (above)


def test_lowest_near_never_rises_and_stays_below_the_full_step():
    model = LineModel(0.5, 2.0)

    def parts_at(a):
        return model.energies(np.array([[a, 0.0, 0.0]]), 1.0)

    for alpha in (0.05, 0.3, 0.9):
        a, parts = lowest_near(parts_at, alpha, parts_at(alpha))
        assert 0.0 < a < 1.0 and parts["total"] <= model.pi(alpha)
    # the trials run out after 4 in each direction: from far below the minimum, 4 x sqrt(2) longer
    model.calls.clear()
    a, _ = lowest_near(parts_at, 1e-3, parts_at(1e-3))
    assert a == pytest.approx(1e-3 * LINE_REFINE_FACTOR ** 4) and len(model.calls) == 1 + 4


def test_a_non_finite_trial_ends_the_refinement():
    model = LineModel(0.5, 2.0)
    state = {"a": None}

    def parts_at(a):
        state["a"] = a
        return {"total": np.nan if a > 0.3 else model.pi(a)}

    a, parts = lowest_near(parts_at, 0.25, parts_at(0.25))
    assert a == 0.25 or a < 0.25  # the longer trial was NaN: it went shorter (or stayed)
    assert np.isfinite(parts["total"]) and parts["total"] <= model.pi(0.25)


def _damping_after(mu, alpha, actual, predicted=1.0, refine=True):
    """The damping after a step of length ``alpha`` [-] that lowered Pi by ``actual`` [J], the quadratic model
    of the full step predicting ``predicted`` [J] (slope -2 predicted, curvature 2 predicted: -(s + c/2))."""
    from rftstatic.solvers.displacement import Damping, LineSearch

    search = object.__new__(LineSearch)
    search.damping, search.work0, search.refine = Damping(), 1.0, refine
    search.damping.mu = mu
    search._trust_region(0.0, -actual, alpha, -2.0 * predicted, 1.0, 2.0 * predicted)
    return search.damping.mu


def test_only_a_step_shortened_below_short_step_damps_the_next_direction():
    from rftstatic.solvers.displacement import SHORT_STEP

    assert 0.0 < SHORT_STEP < 1.0
    assert _damping_after(1e-5, 0.9 * SHORT_STEP, 0.1) == pytest.approx(4e-5)
    assert _damping_after(0.0, 0.9 * SHORT_STEP, 0.1) == pytest.approx(1e-6)
    assert _damping_after(1e-5, SHORT_STEP, 0.1) == 1e-5  # refined to half its length or more: as it was
    assert _damping_after(1e-5, 0.99, 0.1) == 1e-5
    assert _damping_after(1e-5, 0.99, 0.1, refine=False) == pytest.approx(4e-5)  # off the valley walk: every one
    # full steps: More's ratio of the actual to the predicted decrease
    assert _damping_after(1e-5, 1.0, 0.1) == pytest.approx(4e-5)  # rho = 0.1
    assert _damping_after(1e-5, 1.0, 0.5) == 1e-5  # rho = 0.5
    assert _damping_after(3e-5, 1.0, 0.9) == pytest.approx(1e-5)  # rho = 0.9
    assert _damping_after(1e-10, 1.0, 0.9) == 0.0
