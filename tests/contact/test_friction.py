"""Coulomb friction on rigid obstacles (rftstatic.contact.friction, the static lag of
rftstatic.solvers.friction_lag): the mathematics (force = gradient of the energy, tangent = gradient of the force,
positive semi-definite) and the exact incline: a sheet on a plane tilted below its friction angle stays put,
above it there is no equilibrium."""

import numpy as np
import pytest

from rftstatic.contact.friction import FrictionLaw, commit, friction_terms, initial_lag
from rftstatic.contact.obstacles.floor import Floor
from rftstatic.contact.penalty import PenaltyContact, auto_penalty
from rftstatic.errors import ConvergenceError
from rftstatic.material import preset
from rftstatic.mesh.trimesh import rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.solvers import static

EPS = 1e-4


def _lag(rng, n=7):
    nodes = np.arange(n)
    normal = rng.standard_normal((n, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return {"nodes": nodes, "obstacle": np.zeros(n, int), "normal_force": rng.uniform(0.5, 2.0, n), "normal": normal,
            "anchor": rng.standard_normal((n, 3)) * 1e-4, "slid": np.zeros(n, bool), "mu": rng.uniform(0.1, 0.8, n),
            "eps": EPS}


@pytest.mark.parametrize("scale", [0.3e-4, 3e-4])  # sticking (y < eps) and sliding (y > eps) nodes
def test_friction_force_and_tangent_are_the_derivatives_of_its_energy(scale):
    rng = np.random.default_rng(1)
    lag = _lag(rng)
    x = lag["anchor"] + scale * rng.standard_normal(lag["anchor"].shape)
    E, f, K = friction_terms(lag, x)
    h = 1e-9
    for i in range(x.shape[0]):
        for j in range(3):
            d = np.zeros_like(x)
            d[i, j] = h
            Ep, fp, _ = friction_terms(lag, x + d, tangent=False)
            Em, fm, _ = friction_terms(lag, x - d, tangent=False)
            assert (Ep - Em) / (2 * h) == pytest.approx(f[i, j], rel=1e-5, abs=1e-9)
            np.testing.assert_allclose((fp[i] - fm[i]) / (2 * h), K[i, :, j], rtol=1e-4, atol=1e-6 * np.abs(K).max())
    assert np.linalg.eigvalsh(K).min() >= -1e-9 * np.abs(K).max()  # positive semi-definite (F4)
    # along the normal the friction does nothing, and at the anchor it is zero
    E0, f0, _ = friction_terms(lag, lag["anchor"] + 1e-3 * lag["normal"], tangent=False)
    assert np.abs(f0).max() < 1e-12 * (lag["mu"] * lag["normal_force"]).max()  # round-off of the projection


def test_the_force_is_capped_at_mu_times_the_normal_force():
    rng = np.random.default_rng(2)
    lag = _lag(rng)
    t = np.cross(lag["normal"], [0.0, 0.0, 1.0])
    t /= np.linalg.norm(t, axis=1)[:, None]
    _, f, _ = friction_terms(lag, lag["anchor"] + 10 * EPS * t, tangent=False)
    np.testing.assert_allclose(np.linalg.norm(f, axis=1), lag["mu"] * lag["normal_force"], rtol=1e-12)


def _incline(theta_deg, mu, n=9):
    """A 10 cm wool square lying on the floor, its weight tilted by theta: the exact incline, in the plane's
    frame. No in-plane hold: only friction keeps it."""
    mesh = rectangle(0.1, 0.1, n, n)
    mat = preset("wool-kang-yu")
    th = np.radians(theta_deg)
    w = gravity_load(mesh, mat.weight)
    load = np.zeros_like(w)
    load[:, 0] = -w[:, 2] * np.sin(th)  # the downhill component, along +x
    load[:, 2] = w[:, 2] * np.cos(th)
    h = float(mesh.element_size.mean())
    k = auto_penalty(membrane_rigidity=mat.membrane_scale, bending_rigidity=mat.bending_scale, weight=mat.weight, h=h)
    law = FrictionLaw(np.array([mu]), np.array([mu]), eps=EPS * 0.1)
    contact = PenaltyContact([Floor(0.0)], mesh.node_area, k, smoothing=0.05 * h, friction=law)
    return Model(mesh, mat, supports=Supports.none(mesh.n_nodes), load=load, contact=contact)


def test_a_sheet_below_its_friction_angle_stays_put():
    mu = 0.4
    theta = 0.9 * np.degrees(np.arctan(mu))
    model = _incline(theta, mu)
    res = static.solve_static(model, options=static.StaticOptions(progress=False))
    assert res.converged
    drift = np.abs(res.U[:, :2].mean(axis=0)).max()
    assert drift < 1e-3 * 0.1  # the test: the centroid moves less than 1e-3 of the sheet's size


def test_a_sheet_above_its_friction_angle_has_no_equilibrium():
    mu = 0.4
    theta = 1.1 * np.degrees(np.arctan(mu))
    model = _incline(theta, mu)
    with pytest.raises(ConvergenceError, match="friction does not hold the sheet.*no static equilibrium"):
        static.solve_static(model, options=static.StaticOptions(progress=False).replace(relax_fallback=False))
