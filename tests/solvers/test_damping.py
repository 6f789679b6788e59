"""The velocity laws of dynamic relaxation (rftstatic.solvers.damping): FIRE and kinetic damping."""

import numpy as np
import pytest

from rftstatic.errors import ParameterError
from rftstatic.solvers.checkpoint import read_checkpoint
from rftstatic.solvers.damping import DampingLaw, make_law
from rftstatic.solvers.explicit import run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.relaxation import RelaxOptions, relax
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.static import compare_with_static
from tests.solvers.test_explicit import STIFF, WOOL, _checkpointed, _resume, strip, tip

LAWS = ("fire", "kinetic")


def _w1():
    """First bending frequency of the 5 cm wool cantilever [rad/s] (beam theory, 1.875^2 / L^2 sqrt(B / m))."""
    return 1.875**2 / 0.05**2 * np.sqrt(WOOL.Db[0, 0] / WOOL.mass_per_area)


def _relax(model, damping):
    s = 100.0
    return relax(model, RelaxOptions(mass_scale=s, alpha=2 * _w1() / np.sqrt(s), max_time=100.0, damping=damping,
                                      rest=RestCriterion(1e-8, tol_force=1e-5), progress=False))


@pytest.mark.parametrize("damping", LAWS)
def test_velocity_law_relaxes_to_the_static_solution(damping):
    """0.05 x 0.01 m wool strip, 11 x 3 nodes, clamped, own weight (a 4 cm tip drop: nonlinear): the law's rest
    state is Newton's equilibrium within 1e-4, in fewer explicit steps than critical viscous damping."""
    model = strip()
    r = _relax(model, damping)
    assert r.converged
    cmp = compare_with_static(model, r.U)
    assert cmp["max_displacement"] > 0.04
    assert cmp["relative"] < 1e-4
    assert r.steps < _relax(model, "viscous").steps


@pytest.mark.parametrize("damping", LAWS)
def test_velocity_law_is_stable_at_the_stable_step(damping):
    """From a rough start (random displacements of 1e-4 m, every mode excited: the stiff membrane modes at up to
    0.9 of the critical step) the law never gains energy: the run's energy check passes and the total (kinetic +
    potential + what the law took) ends at most at its start; the potential energy falls."""
    model = strip(STIFF)
    rng = np.random.default_rng(3)
    U0 = 1e-4 * rng.standard_normal((model.mesh.n_nodes, 3)) * model.free
    r = run_explicit(model, ExplicitOptions(t_end=0.5, mass_scale=100.0, damping=damping, sample_every=1,
                                            progress=False), U0=U0)
    h = r.history
    assert r.steps > 500 and np.all(np.isfinite(h["total"]))
    assert h["total"][-1] <= h["total"][0] + 1e-6 * abs(h["potential"][0])
    assert h["potential"][-1] < h["potential"][0]
    assert h["dissipated"][-1] > 0


def test_fire_resume_reproduces_the_uninterrupted_run(tmp_path):
    """FIRE's state (mixing factor, count of positive-power steps, swings) is saved with the run: a run cut at
    step 250 and resumed from its checkpoint is the uninterrupted one bit for bit."""
    model = strip(STIFF)
    options = ExplicitOptions(t_end=0.2, damping="fire", mass_scale=100.0, sample_every=7, progress=False)
    full = run_explicit(model, options, probes=[tip(model)])
    path = tmp_path / "run.npz"

    def interrupt(state, rec):
        if state.step >= 250:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _checkpointed(model, options, path, callback=interrupt, probes=[tip(model)])
    saved = read_checkpoint(path)[1]
    assert saved["step"] == 200
    res = _resume(path, model)
    assert np.array_equal(res.U, full.U) and np.array_equal(res.V, full.V)
    for k in full.history:
        assert np.array_equal(res.history[k], full.history[k]), k


def test_bad_damping_values_are_refused():
    with pytest.raises(ParameterError, match="damping.*unknown.*viscous, fire, kinetic"):
        ExplicitOptions(t_end=1.0, damping="fir")
    with pytest.raises(ParameterError, match="alpha.*must be 0 with damping = 'fire'"):
        ExplicitOptions(t_end=1.0, damping="fire", alpha=2.0)
    with pytest.raises(ParameterError, match="damping.*unknown"):
        RelaxOptions(alpha=1.0, max_time=1.0, damping="none")
    with pytest.raises(ParameterError, match="a_start.*must lie in"):
        DampingLaw("fire", a_start=1.5)
    with pytest.raises(ParameterError, match="no velocity law"):
        DampingLaw("viscous")
    assert make_law("viscous") is None and make_law("kinetic").name == "kinetic"


def test_rest_test_sees_the_last_swing():
    """Right after a reset the kinetic energy is near zero: the rest test sees the larger swing before it."""
    law = make_law("fire")
    s = law.begin({})
    assert law.rest_kinetic(s, 5.0) == 5.0
    law._reset(s)
    assert law.rest_kinetic(s, 1e-9) == 5.0  # the swing before the reset still counts
    law._reset(s)
    assert law.rest_kinetic(s, 1e-9) == pytest.approx(1e-9)


@pytest.mark.parametrize("damping", ["fire", "kinetic", "viscous-fire"])
def test_relax_route_with_a_velocity_law_reaches_the_newton_equilibrium(damping):
    """solver.relax_damping on the static route (strip, one equilibrium): the load steps' Newton solution within
    1e-6, the route's record names the law, and a guided first stage runs under it too."""
    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers import static

    mod = strip_model(11, 3)
    a = static.solve_static(mod, options=static.StaticOptions(progress=False))
    b = static.solve_static(mod, options=static.StaticOptions.from_keys(
        progress=False, start="relax", relax_damping=damping, guide_folds=3, guide_weight=0.5, seed=2))
    assert b.route == "relax+newton" and b.relax["damping"] == damping and b.relax["guide"]["steps"] > 0
    assert np.abs(a.U - b.U).max() < 1e-6 * np.abs(a.U).max()


def test_viscous_fire_hands_over_when_the_motion_has_died_down():
    """viscous-fire: the mass damping alone (the viscous run step for step) until a sample's kinetic energy has
    fallen to 0.1 of the peak, FIRE after."""
    model = strip()
    opts = dict(t_end=3.0, mass_scale=100.0, alpha=2 * _w1() / 10.0, sample_every=5, progress=False)
    viscous = run_explicit(model, ExplicitOptions(**opts))
    mixed = run_explicit(model, ExplicitOptions(damping="viscous-fire", **opts))
    kin = viscous.history["kinetic"]
    peak = np.maximum.accumulate(kin)
    below = np.flatnonzero((kin <= 0.1 * peak) & (peak > 0))
    assert below.size and below[0] > 10
    first = below[0]  # the sample at which FIRE takes over (it acts from the step after)
    for k in ("kinetic", "potential", "total"):
        np.testing.assert_array_equal(mixed.history[k][: first + 1], viscous.history[k][: first + 1])
    assert not np.array_equal(mixed.history["kinetic"][first + 2:], viscous.history["kinetic"][first + 2:])
    with pytest.raises(ParameterError, match="after.*must lie in"):
        DampingLaw("fire", after=1.0)


def test_friction_relaxes_with_viscous_damping(monkeypatch):
    """With Coulomb friction the relaxation keeps the mass damping (its rest test measures the impulses' leftover
    velocities): the route's plan takes the law only without friction."""
    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers import friction_lag
    from rftstatic.solvers.relax_plan import relax_plan

    mod = strip_model(11, 3)
    assert relax_plan(mod, None, "fire").damping == "fire"
    monkeypatch.setattr(friction_lag, "active", lambda model: True)
    assert relax_plan(mod, None, "fire").damping == "viscous"


def test_a_sheet_that_nothing_holds_stops_as_a_fall():
    """The wool strip with no support under its weight: the relaxation stops with a FallError once its mass centre
    is FALL_DIAGONALS reference diagonals below the reference (instead of relaxing to its time limit); the
    clamped strip (test_velocity_law_relaxes_to_the_static_solution) is at rest within a diagonal."""
    from rftstatic.errors import FallError
    from rftstatic.model.model import Model
    from rftstatic.solvers.relaxation import FALL_DIAGONALS

    held = strip()
    free = Model(held.mesh, WOOL, element="RFT6", load=held.load)
    with pytest.raises(FallError, match="the sheet fell") as info:
        _relax(free, "viscous")
    diagonal = float(np.linalg.norm(np.ptp(held.X3, axis=0)))
    assert f"{FALL_DIAGONALS * diagonal:.3g} m" in str(info.value)


def test_a_relaxation_segment_that_goes_unstable_runs_again_with_a_shorter_step(monkeypatch):
    """The explicit step taken 3 x the stable one (a stiffness the estimate leaves out): the route's segment goes
    unstable, runs again from its start with the step the explicit run names (twice: 1.5 x, then 0.75 x the stable
    step), and ends at the load steps' Newton solution; the cuts are in the route's record."""
    from dataclasses import replace

    from rftstatic.bench.problems import strip_model
    from rftstatic.solvers import static, step_plan

    real = step_plan.stable_time_step
    monkeypatch.setattr(step_plan, "stable_time_step", lambda *a, **k: replace(real(*a, **k), dt=3 * real(*a, **k).dt))
    mod = strip_model(11, 3)
    a = static.solve_static(mod, options=static.StaticOptions(progress=False))
    b = static.solve_static(mod, options=static.StaticOptions.from_keys(progress=False, start="relax"))
    cuts = b.relax["step_cuts"]
    assert len(cuts) == 2 and cuts[1]["new_dt_s"] == pytest.approx(0.25 * cuts[0]["dt_s"])
    assert b.relax["dt_s"] == cuts[1]["new_dt_s"]
    assert np.abs(a.U - b.U).max() < 1e-6 * np.abs(a.U).max()


@pytest.mark.parametrize("damping", LAWS)
def test_what_a_law_takes_closes_the_energy_balance_at_every_sample(damping):
    """The clamped wool strip falling from flat under a velocity law (mass scale 100, 2 s, every step sampled):
    kinetic + stored - gravity's work + dissipated stays at its start within 1e-4 of gravity's work (measured
    2.6e-5 FIRE, 6.8e-7 kinetic). Booked as the kinetic energy the law took from step n's sample alone, 19 % of
    gravity's work went missing by 2 s (0.195 FIRE, 0.189 kinetic)."""
    r = run_explicit(strip(WOOL), ExplicitOptions(t_end=2.0, mass_scale=100.0, damping=damping, sample_every=1,
                                                  progress=False))
    h = r.history
    assert h["kinetic"][-1] < 1e-4 * h["external_work"][-1]  # settled: the law did its work
    assert np.abs(h["total"] - h["total"][0]).max() < 1e-4 * h["external_work"][-1]
