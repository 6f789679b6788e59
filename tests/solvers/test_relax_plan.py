"""The relaxation route's plan (rftstatic.solvers.relax_plan): a long expected need is attempted within the planned
steps, a hopeless one refused."""

import pytest

from rftstatic.errors import ConvergenceError
from rftstatic.scenes.build import build_model
from rftstatic.scenes.schema import load_scene
from rftstatic.solvers.relax_plan import MAX_RELAX_STEPS, RELAX_ATTEMPT_FACTOR, RELAX_TIME_ALLOWANCE, relax_plan
from rftstatic.solvers.timestep import stable_time_step


def _strip(C):
    scene = load_scene("strip", ["mesh.nodes=[11,3]", "solver.start=relax", f"material.C_warp={C}",
                                 f"material.C_weft={C}"])
    return build_model(scene, quiet=True)[0]


def test_a_need_past_the_planned_steps_is_cut_to_them_and_attempted():
    model = _strip(3e5)  # a stiff membrane: 100 damping times are about 4.5e5 steps
    plan = relax_plan(model, None)
    dt = stable_time_step(model, mass_scale=plan.mass_scale, alpha=plan.alpha).dt
    need = 100.0 / plan.alpha / dt
    assert MAX_RELAX_STEPS < need <= RELAX_ATTEMPT_FACTOR * MAX_RELAX_STEPS
    assert plan.max_time / dt == pytest.approx(0.95 * RELAX_TIME_ALLOWANCE * MAX_RELAX_STEPS)


def test_a_need_within_the_planned_steps_is_kept():
    model = _strip(1e3)
    plan = relax_plan(model, None)
    assert plan.max_time == pytest.approx(RELAX_TIME_ALLOWANCE * 100.0 / plan.alpha)


def test_a_hopeless_need_is_refused_naming_the_route_past_it():
    with pytest.raises(ConvergenceError, match="would need up to") as err:
        relax_plan(_strip(1e9), None)
    assert 'solver.start = "load-steps"' in str(err.value)
