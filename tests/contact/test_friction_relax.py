"""Coulomb friction on the relaxation route (issue 36): impulses on the penalty contact in the explicit steps
(rftstatic.contact.friction.penalty_impulses, F5), the sheet seated on the penalty before a relaxation from rest,
the rest test that measures what friction does not hold, the lag anchored at every Newton handover; and the
exact incline through the default route: it stays put below its friction angle, slides with
g (sin - mu_k cos) above it, and a relaxation interrupted mid-segment resumes to the bit."""

import numpy as np
import pytest

from rftstatic.contact.friction import FrictionLaw, held_residual, penalty_impulses, seated
from rftstatic.contact.obstacles.floor import Floor
from rftstatic.contact.penalty import PenaltyContact
from rftstatic.solvers import rest, static

from tests.contact.test_friction import _case, _incline

MU = 0.4


def _pressed(n=6, mu_s=0.5, mu_k=0.3):
    """``n`` nodes pressed 1e-4 m into a floor by a penalty of k A = 1e3 N/m (normal force 0.1 N + the onset's
    share), their friction law, the positions, their penalty normal forces [N] and inverse masses 1/(2 kg)."""
    contact = PenaltyContact([Floor(0.0)], np.full(n, 1.0), 1e3, smoothing=1e-5,
                             friction=FrictionLaw(np.array([mu_s]), np.array([mu_k]), eps=1e-6))
    x = np.zeros((n, 3))
    x[:, 0] = np.arange(n)
    x[:, 2] = -1e-4
    lam = -contact.stiffness * contact.node_area * contact._slope(np.full(n, -1e-4))
    return contact, x, lam, np.full((n, 3), 0.5)


def test_friction_impulses_stick_inside_the_cone_and_slide_with_the_kinetic_coefficient():
    """(F5): a tangential velocity within mu_s lambda dt / m is removed, a larger one loses mu_k lambda dt / m
    along itself; the normal velocity is kept, a supported dof keeps its velocity, and the energy returned is the
    kinetic energy taken away."""
    contact, x, lam, minv = _pressed()
    law, dt = contact.friction, 1e-3
    cap = lam[0] * dt * 0.5  # [m/s]
    speeds = np.array([0.2, 0.9, 0.99, 1.01, 2.0, 5.0]) * law.mu_static[0] * cap
    v = np.zeros((6, 3))
    v[:, 0], v[:, 1], v[:, 2] = 0.6 * speeds, 0.8 * speeds, 0.3
    minv[5, 1] = 0.0  # node 5 held in y
    v0 = v.copy()
    lost = penalty_impulses(law, contact, x, v, minv, dt)
    np.testing.assert_array_equal(v[:, 2], v0[:, 2])
    stick = speeds[:5] <= law.mu_static[0] * cap
    assert stick.tolist() == [True, True, True, False, False]
    assert np.all(v[:5][stick, :2] == 0.0)
    slid = np.linalg.norm(v[:5][~stick, :2], axis=1)
    np.testing.assert_allclose(slid, speeds[:5][~stick] - law.mu_kinetic[0] * cap, rtol=1e-12)
    assert v[5, 1] == v0[5, 1] and v[5, 0] < v0[5, 0]
    m = 1.0 / minv.max(axis=1)
    assert lost == pytest.approx(0.5 * float(np.sum(m * (np.sum(v0**2, 1) - np.sum(v**2, 1)))), rel=1e-12)
    assert lost > 0


def test_a_seated_node_is_pushed_by_the_penalty_with_the_load_that_presses_it():
    """``seated``: nodes deeper than the penalty's balance of their load are moved out along the normal until
    k A |d1(phi)| equals the pressing load (in the onset width and below it); others are left alone."""
    contact, x, _, _ = _pressed()
    load = np.zeros_like(x)
    load[:, 2] = -np.array([1e-6, 1e-4, 1e-3, 2e-2, 0.05, 0.0])  # [N] (onset width, below it); the last: none
    y = seated(contact, x, load)
    np.testing.assert_array_equal(y[:, :2], x[:, :2])
    push = -contact.stiffness * contact.node_area * contact._slope(y[:, 2])
    np.testing.assert_allclose(push[:5], -load[:5, 2], rtol=1e-9)
    assert y[5, 2] == pytest.approx(contact.smoothing, rel=1e-12)  # unpressed: out to the onset, no push
    np.testing.assert_allclose(seated(contact, y, load), y, rtol=0, atol=1e-18)  # seated already: stays
    lifted = y + [0.0, 0.0, 1e-6]  # above the balance: left alone
    np.testing.assert_array_equal(seated(contact, lifted, load), lifted)


def test_the_held_residual_takes_off_what_static_friction_can_carry():
    contact, x, lam, _ = _pressed()
    r = np.zeros_like(x)
    r[:, 0] = np.array([0.2, 0.9, 1.0, 1.1, 3.0, 0.0]) * 0.5 * lam
    r[:, 2] = 7.0
    h = held_residual(contact.friction, contact, x, r)
    np.testing.assert_array_equal(h[:, 2], r[:, 2])
    np.testing.assert_allclose(h[:, 0], np.maximum(r[:, 0] - 0.5 * lam, 0.0), atol=1e-15)


def test_the_default_route_holds_a_sheet_below_its_friction_angle():
    """start = "relax" with friction: the sheet at 0.9 of the friction angle rests after the first rest test
    (seated, the impulses hold it) and Newton with the lag anchored there keeps it, as the load steps do: the
    centroid moves less than 1e-3 of the size (issue 36), the equilibrium a stable minimum."""
    model = _incline(0.9 * np.degrees(np.arctan(MU)), MU)
    res = static.solve_static(model, options=static.StaticOptions(progress=False).replace(start="relax"))
    assert res.converged and res.stable and res.route == "relax+newton"
    assert len(res.relax["handovers"]) == 1 and res.relax["steps"] < 100
    drift = np.abs(res.U[:, :2].mean(axis=0)).max()
    assert drift < 1e-3 * 0.1
    steps = static.solve_static(model, options=static.StaticOptions(progress=False).replace(start="load-steps"))
    assert np.abs(res.U - steps.U).max() < 1e-3 * 0.1


@pytest.mark.parametrize("mu_s, mu_k", [(0.4, 0.4), (0.5, 0.3)])
def test_penalty_friction_impulses_slide_a_sheet_at_g_sin_minus_mu_k_cos(mu_s, mu_k):
    """The exact incline on the penalty contact, explicit and undamped from the seated sheet: at 1.2 x the
    static friction angle its mean velocity grows at g (sin theta - mu_k cos theta) (within 2 %); at 0.9 x it
    does not move."""
    from rftstatic.model.model import Model
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    for factor in (1.2, 0.9):
        theta = factor * np.arctan(mu_s)
        base = _incline(np.degrees(theta), mu_s)
        c = base.contact
        law = FrictionLaw(np.array([mu_s]), np.array([mu_k]), eps=1e-6)
        contact = PenaltyContact(c.obstacles, c.node_area, c.stiffness, smoothing=c.smoothing, friction=law)
        model = Model(base.mesh, base.material, supports=base.supports, load=base.load, contact=contact)
        U0 = seated(contact, model.mesh.X3, model.load) - model.mesh.X3
        r = run_explicit(model, ExplicitOptions(t_end=0.05, alpha=0.0, progress=False, energy_check=False), U0=U0)
        if factor > 1:
            expected = 9.80665 * (np.sin(theta) - mu_k * np.cos(theta))
            assert float(r.V[:, 0].mean()) / r.t == pytest.approx(expected, rel=0.02)
        else:
            assert np.abs(r.U[:, :2] - U0[:, :2]).max() < 1e-9


def test_the_incline_scene_by_the_default_route(tmp_path):
    """cases/incline.toml with solver.start = "relax" (no longer refused): stays put at 19.6 deg."""
    import json

    rc, out = _case(tmp_path, "solver.start=relax")
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["converged"] and s["stable_minimum"] and s["route"] == "relax+newton"


@pytest.mark.slow
def test_the_incline_scene_by_the_default_route_has_no_equilibrium_above_its_friction_angle(tmp_path, capsys):
    """At 24 deg (1.1 x the friction angle) the relaxation slides to its time limit (35 s wall) and the final
    Newton fails: exit 3 naming friction and the missing static equilibrium."""
    rc, _ = _case(tmp_path, "solver.start=relax", "loads.gravity_tilt=24")
    assert rc == 3
    assert "no static equilibrium" in capsys.readouterr().err


def test_a_frictional_relaxation_interrupted_mid_segment_resumes_bit_identical(tmp_path, monkeypatch):
    """The default route with friction 0.3 on pedestal-square-20 (9 x 9): cut by Ctrl-C at the 25th rest test of
    the relaxation, resumed from its checkpoint, it ends where the uninterrupted run did, to the bit."""
    import signal

    from rftstatic.app import static as app
    from rftstatic.scenes.schema import load_scene

    scene = load_scene("pedestal-square-20", ["mesh.nodes=[9,9]", "contact.friction=0.3"])
    full = app.run(scene, tmp_path / "full", progress=False, figures=False)
    assert full.summary["converged"] and full.summary["stable_minimum"] and full.summary["route"] == "relax+newton"
    test, seen = rest.AtRest.__call__, []

    def call(self, state, rec):
        seen.append(1)
        if len(seen) == 25:
            signal.raise_signal(signal.SIGINT)
        return test(self, state, rec)

    monkeypatch.setattr(rest.AtRest, "__call__", call)
    with pytest.raises(KeyboardInterrupt, match="checkpoint saved"):
        app.run(scene, tmp_path / "cut", progress=False, figures=False, checkpoint_seconds=1e9)
    monkeypatch.undo()
    resumed = app.run(scene, tmp_path / "cut", progress=False, figures=False, resume=True)
    assert np.array_equal(resumed.U, full.U)
    assert resumed.summary["relax"]["steps"] == full.summary["relax"]["steps"]


def test_the_cusick_friction_scene_holds_the_specimen_by_friction_alone():
    """cases/cusick-30-friction.toml: the specimen on the support disc (a round pedestal) with the disc's own
    friction 0.5, no clamp, no support and no in-plane hold; the default route."""
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene

    scene = load_scene("cusick-30-friction")
    model, _ = build_model(scene)
    law = model.contact.friction
    assert law.mu_static.tolist() == [0.5] and law.mu_kinetic.tolist() == [0.5]
    assert model.free.all()  # nothing clamped or held: friction alone keeps the specimen on the disc
    assert scene.get("solver.start") == "relax"


@pytest.mark.slow
def test_the_cusick_friction_scene_converges_with_and_without_the_discs_friction(tmp_path):
    """Coarse (h = 3 cm, 100 nodes; 10-15 s each): with and without the disc's friction the default route converges
    to a stable drape whose outline surrounds the disc (the drape measures apply)."""
    import json

    for mu in (0.5, 0.0):
        rc, out = _case(tmp_path / str(mu), "mesh.h=3.0", f"obstacles.0.friction={mu}", name="cusick-30-friction")
        s = json.loads((out / "summary.json").read_text())
        assert rc == 0 and s["converged"] and s["stable_minimum"]
        assert 0.0 < s["drape"]["drape_coefficient_percent"] < 100.0
