"""The explicit step planner (rftstatic.solvers.step_plan) and the explicit and relaxation options."""

import math

import numpy as np
import pytest

from rftstatic.errors import ParameterError, StepLimitError
from rftstatic.material import preset
from rftstatic.mesh.trimesh import rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.relaxation import RelaxOptions
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.step_plan import plan_steps
from rftstatic.solvers.timestep import stable_time_step

WOOL = preset("wool-kang-yu")
FREE = {"alpha": 0.0, "mass_scale": 1.0}  # undamped, real mass


@pytest.fixture(scope="module")
def model():
    """A 5 x 1 cm wool strip clamped at x = 0 under its weight."""
    mesh = rectangle(0.05, 0.01, 7, 3)
    sup = Supports(mesh.nodes_in_box(0, 0, -1, 1), np.zeros(0, dtype=np.int64), np.zeros((mesh.n_nodes, 3), bool))
    return Model(mesh, WOOL, supports=sup, load=gravity_load(mesh, WOOL.weight))


def test_a_given_step_is_shortened_to_end_at_t_end(model):
    plan = plan_steps(model, t_end=1.0, dt=0.003, **FREE, check_dt=False)
    assert plan.steps == 334 and plan.dt == 1.0 / 334 and plan.t_end == 1.0  # ceil(333.3)
    assert plan.estimate is None and plan.reason == "the given step"
    assert plan_steps(model, t_end=1.0, dt=0.25, **FREE, check_dt=False).steps == 4  # a whole number: no extra step


def test_without_a_step_the_plan_takes_the_stable_estimate(model):
    est = stable_time_step(model, alpha=5.0, mass_scale=100.0, safety=0.5)
    plan = plan_steps(model, t_end=0.2, alpha=5.0, mass_scale=100.0, safety=0.5)
    assert plan.estimate == est
    assert plan.steps == math.ceil(0.2 / est.dt - 1e-9) and plan.dt <= est.dt
    assert plan.dt == pytest.approx(0.2 / plan.steps, rel=1e-15) and "critical step" in plan.reason


def test_a_step_above_the_estimate_is_planned_with_a_warning(model, caplog):
    est = stable_time_step(model)
    plan = plan_steps(model, t_end=100 * est.dt, dt=2 * est.dt, **FREE)
    assert plan.steps == 50 and "above the stable estimate" in plan.reason
    assert "exceeds the stable estimate" in caplog.text


def test_a_run_over_the_step_limit_is_refused_naming_the_key(model):
    with pytest.raises(StepLimitError, match=r"needs 1e\+03 explicit steps, more than the limit of 999 "
                                             r"\(dynamics.max_steps\); shorten t_end or lengthen dt"):
        plan_steps(model, t_end=1.0, dt=1e-3, **FREE, max_steps=999, check_dt=False)
    with pytest.raises(StepLimitError, match=r"\(the segment limit\)"):
        plan_steps(model, t_end=1.0, dt=1e-3, **FREE, max_steps=10, limit_name="the segment limit", check_dt=False)
    assert plan_steps(model, t_end=1.0, dt=1e-3, **FREE, max_steps=1000, check_dt=False).steps == 1000  # at the limit


def test_a_relaxation_over_the_step_limit_stops_there(model):
    plan = plan_steps(model, t_end=1.0, dt=1e-3, **FREE, max_steps=400, check_dt=False, stop_at_limit=True)
    assert plan.steps == 400 and plan.t_end == pytest.approx(0.4, rel=1e-11) and plan.t_end < 0.4
    assert plan.dt == pytest.approx(1e-3, rel=1e-11) and "stops there" in plan.reason


@pytest.mark.parametrize("kw, key", [({"t_end": 0.0}, "t_end"), ({"t_end": 1.0, "dt": -1e-3}, "dt")])
def test_the_planner_names_a_bad_time(model, kw, key):
    with pytest.raises(ParameterError, match=key):
        plan_steps(model, check_dt=False, **FREE, **kw)


@pytest.mark.parametrize("kw, key", [
    ({"t_end": -1.0}, "t_end"), ({"t_end": 1.0, "dt": 0.0}, "dt"), ({"t_end": 1.0, "alpha": -5.0}, "alpha"),
    ({"t_end": 1.0, "mass_scale": 0.0}, "mass_scale"), ({"t_end": 1.0, "start": "warm"}, "start"),
    ({"t_end": 1.0, "sample_every": 0}, "sample_every"), ({"t_end": 1.0, "energy_tol": float("nan")}, "energy_tol"),
    ({"t_end": 1.0, "rest_tol": 2.0}, "rest_tol"), ({"t_end": 1.0, "safety": 1.5}, "safety"),
    ({"t_end": 1.0, "backend": "cuda"}, "backend"), ({"t_end": 1.0, "max_steps": 2.5}, "max_steps"),
])
def test_explicit_options_name_a_bad_value(kw, key):
    with pytest.raises(ParameterError) as err:
        ExplicitOptions(**kw)
    assert err.value.key == key


@pytest.mark.parametrize("kw, key", [({"max_time": 0.0}, "max_time"), ({"alpha": -1.0}, "alpha"),
                                     ({"rest": 1e-8}, "rest"), ({"sample_every": -3}, "sample_every")])
def test_relax_options_name_a_bad_value(kw, key):
    with pytest.raises(ParameterError) as err:
        RelaxOptions(**{"alpha": 5.0, "max_time": 10.0, **kw})
    assert err.value.key == key


def test_options_are_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        ExplicitOptions(1.0)
    o = RelaxOptions(alpha=5.0, max_time=10.0, rest=RestCriterion(1e-4, tol_force=1e-3))
    with pytest.raises(AttributeError):
        o.alpha = 1.0
    run = o.explicit(given_velocity=True)
    assert (run.t_end, run.alpha, run.mass_scale, run.start, run.sample_every) == (10.0, 5.0, 100.0, "given", 20)


def test_run_explicit_takes_the_callers_plan_and_refuses_one_for_another_end_time(model):
    from rftstatic.solvers.explicit import run_explicit

    plan = plan_steps(model, t_end=0.01, dt=1e-4, **FREE, check_dt=False)
    run = run_explicit(model, ExplicitOptions(t_end=0.01, dt=1e-4, energy_check=False, progress=False), plan=plan)
    assert run.steps == plan.steps == 100 and run.dt == plan.dt and run.t == pytest.approx(0.01)
    with pytest.raises(ParameterError, match="plan"):
        run_explicit(model, ExplicitOptions(t_end=0.02, progress=False), plan=plan)
