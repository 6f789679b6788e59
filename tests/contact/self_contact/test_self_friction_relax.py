"""The relaxation's rest test with friction between layers (issue 36): what the self-contact pairs' static friction
can hold is taken off the out-of-balance force (rftstatic.contact.friction.held_by_contacts with
rftstatic.contact.self_contact.friction.pair_holds), and the relaxed layers are handed to Newton with the pairs' lag
anchored where they rest. The exact case: a layer on an incline over another, held by friction alone, stays put
below its friction angle (tan theta <= mu); above it friction takes off at most mu times the pairs' normal forces.
Before: the rest test counted the held downhill load, so the relaxation ran to its time limit (79.8 s, 48,677
steps) and the final Newton failed; now it rests after 1,001 steps and Newton converges in 7 iterations."""

import numpy as np
import pytest

from rftstatic.contact.friction import held_by_contacts
from rftstatic.contact.self_contact.friction import pair_holds
from rftstatic.mesh.trimesh import TriMesh
from rftstatic.model.model import Model, Supports
from rftstatic.solvers import static

from tests.contact.self_contact.test_self_friction import _layers

MU = 0.4
SIZE = 0.05  # [m] the upper layer


def _incline_layers(theta):
    """The two layers of the drag test (a 5 cm wool square on a 10 cm one held in every dof, 106 nodes), the upper
    one free (no edge held) and the weight tilted by ``theta`` [rad] along +x: only the friction between the layers
    holds it. The layers are the mesh's placed reference, so the route starts stacked (``U = 0``)."""
    model, U0, top, _ = _layers(MU)
    fixed = np.zeros_like(model.supports.fixed)
    fixed[:top[0]] = True
    w = model.load
    load = np.zeros_like(w)
    load[:, 0] = -w[:, 2] * np.sin(theta)
    load[:, 2] = w[:, 2] * np.cos(theta)
    mesh = TriMesh(model.mesh.X, model.mesh.tri, element_X=model.mesh.X[model.mesh.tri], placed=model.mesh.X3 + U0)
    return Model(mesh, model.material, supports=Supports(np.zeros(0, np.int64), np.zeros(0, np.int64), fixed),
                 load=load, self_contact=model.self_contact, quiet=True), top


@pytest.fixture(scope="module")
def relaxed():
    """The default route (relaxation, then Newton) on the layers at 0.9 of the friction angle (~6 s)."""
    model, top = _incline_layers(0.9 * np.arctan(MU))
    res = static.solve_static(model, options=static.StaticOptions(progress=False).replace(start="relax"))
    return model, top, res


def _measures(model, res, load):
    """The out-of-balance force ``(N, 3)`` [N] at the route's result under ``load``, on the free dofs, and the same
    with what the pairs' static friction can hold taken off (the rest test's measure)."""
    sc = model.self_contact
    r = np.where(model.free, -model.residual(res.U, 1.0) - model.load + load, 0.0)
    held = held_by_contacts(r, [pair_holds(sc.friction, sc, model.positions(res.U))], model.free.any(axis=1))
    return r, np.where(model.free, held, 0.0)


def test_a_layer_below_its_friction_angle_rests_on_another_and_newton_keeps_it(relaxed):
    """The relaxation rests at its first rest test (before the fix it ran to its end, 48,677 steps) and hands over
    to Newton once, which converges to a stable minimum; the upper layer moves less than 1e-3 of its size. The
    rest test's measure there is below 1e-3 of the load, the old one (obstacle friction only: none here) a third."""
    model, top, res = relaxed
    assert res.converged and res.stable and res.route == "relax+newton"
    assert len(res.relax["handovers"]) == 1 and res.relax["handovers"][0]["at_rest"]
    assert res.relax["steps"] < 2000
    assert np.abs(res.U[top, :2].mean(axis=0)).max() < 1e-3 * SIZE
    P = np.linalg.norm(np.where(model.free, model.load, 0.0))
    r, held = _measures(model, res, model.load)
    assert np.linalg.norm(r) > 0.3 * P  # the downhill load, 0.34 |P|: what the old rest test counted
    assert np.linalg.norm(held) < 1e-3 * P


@pytest.mark.parametrize("factor", [1.1, 1.5])
def test_above_the_friction_angle_the_pairs_take_off_at_most_mu_times_their_normal_forces(relaxed, factor):
    """At the rested layers, under the weight tilted beyond the friction angle: the pairs' reaction on the upper
    layer is at most mu_s sum lambda_p along the slope (admissible forces) and the sweeps use nearly all of it
    (within 2 % of the downhill load); their tangent planes being nearly level, the vertical load stays."""
    model, top, res = relaxed
    steeper, _ = _incline_layers(factor * np.arctan(MU))
    r, held = _measures(model, res, steeper.load)
    sc = model.self_contact
    cap = pair_holds(sc.friction, sc, model.positions(res.U))[3].sum()
    taken = r[:, 0].sum() - held[:, 0].sum()
    assert taken <= cap * (1 + 1e-9)
    assert taken == pytest.approx(cap, abs=0.02 * r[:, 0].sum())
    assert abs(held[:, 2].sum() - r[:, 2].sum()) < 0.02 * taken  # the pairs' tangent planes: nearly level


def test_held_by_contacts_sweeps_are_admissible_and_do_not_overshoot():
    """Two free nodes in one pair pushed apart tangentially are held after one sweep (no overshoot, H1: s_p = 2); a
    pair whose two sides accelerate together needs no friction (left as it is); with a cap below the demand the
    reaction is the cap; a node on an obstacle loses mu_s lambda of its tangential load (``held_residual``)."""
    nodes, w = np.array([[0, 1]]), np.array([[1.0, -1.0]])
    normal = np.array([[0.0, 0.0, 1.0]])
    r = np.array([[2.0, 0.0, 0.5], [-2.0, 0.0, 0.0]])
    np.testing.assert_allclose(held_by_contacts(r, [(nodes, w, normal, np.array([5.0]))]), [[0, 0, 0.5], [0, 0, 0]],
                               atol=1e-12)
    same = np.array([[1.0, 2.0, 0.0], [1.0, 2.0, 0.0]])
    np.testing.assert_allclose(held_by_contacts(same, [(nodes, w, normal, np.array([5.0]))]), same, atol=1e-12)
    capped = held_by_contacts(r, [(nodes, w, normal, np.array([0.5]))])
    np.testing.assert_allclose(capped[:, 0], [1.5, -1.5], rtol=1e-9)
    one = held_by_contacts(r[:1], [(np.array([[0]]), np.array([[1.0]]), normal, np.array([0.5]))])
    np.testing.assert_allclose(one, [[1.5, 0.0, 0.5]], rtol=1e-12)


@pytest.mark.parametrize("slope", [0.4, 0.49, 0.6])
def test_a_stack_on_a_frictional_floor_is_held_through_both_contacts(slope):
    """Two free nodes of weight 1 (normal), one on the other (a pair, mu_s 0.5, lambda 1) and the lower on a floor
    (mu_s 0.5, lambda 2), both pulled by ``slope`` along x: held (below 1e-3 of the load) while slope <= mu_s, since
    the upper's load goes through the pair into the floor; above, each keeps slope - mu_s exactly. The floor alone
    (the rest test before) holds only the lower node."""
    n = np.array([[0.0, 0.0, 1.0]])
    r = np.array([[slope, 0.0, 0.0], [slope, 0.0, 0.0]])
    pair = (np.array([[0, 1]]), np.array([[1.0, -1.0]]), n, np.array([0.5]))
    floor = (np.array([[1]]), np.array([[1.0]]), n, np.array([1.0]))
    held = held_by_contacts(r, [pair, floor])
    if slope <= 0.5:
        assert np.abs(held).max() < 1e-3 * slope
    else:
        np.testing.assert_allclose(held[:, 0], slope - 0.5, rtol=1e-3)
    np.testing.assert_allclose(held_by_contacts(r, [floor])[:, 0], [slope, max(slope - 1.0, 0.0)], atol=1e-12)
