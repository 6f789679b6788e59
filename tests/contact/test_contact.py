"""Penalty and kinematic contact: gradients by finite differences, physics of the penalty size."""

import numpy as np
import pytest

from rftstatic.contact.kinematic import kinematic_contact
from rftstatic.contact.obstacles import Floor, RoundPedestal, Sphere, SquarePedestal
from rftstatic.contact.penalty import ContactState, PenaltyContact, auto_penalty, estimate_penetration

# Wool of §4 (Kang & Yu 1995) in SI: 1118.2 gf/cm, 0.083 gf cm, 0.019 gf/cm^2.
GF = 9.80665e-3  # [N]
WOOL_C = 1118.2 * GF / 1e-2  # [N/m]
WOOL_B = 0.083 * GF * 1e-2  # [N m]
WOOL_W = 0.019 * GF / 1e-4  # [N/m^2]
H = 5e-3  # element size [m]
K = auto_penalty(membrane_rigidity=WOOL_C, bending_rigidity=WOOL_B, weight=WOOL_W, h=H)

OBSTACLES = {
    "floor": Floor(-0.05),
    "sphere": Sphere([0.0, 0.0, -0.05], 0.05),
    "square": SquarePedestal([0.0, 0.0], 0.05, top_z=0.0, edge_radius=0.005),
    "round": RoundPedestal([0.0, 0.0], 0.1, top_z=0.0, edge_radius=0.005),
}


def _nodes(obstacle, rng, n=30):
    """Nodes penetrating by 10-300 um (incl. the rounded edges), plus nodes well outside [m]."""
    lo, hi = obstacle.bounding_box()
    lo = np.maximum(lo, -0.12) - 0.02
    hi = np.minimum(hi, 0.12) + 0.02
    surf = obstacle.closest_point(rng.uniform(lo, hi, size=(2 * n, 3)))
    _, normal = obstacle.signed_distance(surf)
    depth = np.concatenate([-rng.uniform(1e-5, 3e-4, n), rng.uniform(1e-4, 1e-2, n)])
    return surf + depth[:, None] * normal, depth


def _contact(obstacles, n, rng):
    return PenaltyContact(obstacles, rng.uniform(0.5, 1.5, n) * H**2, K)


@pytest.mark.parametrize("name", list(OBSTACLES))
def test_force_is_gradient_of_energy(name):
    rng = np.random.default_rng(10)
    x, depth = _nodes(OBSTACLES[name], rng)
    contact = _contact(OBSTACLES[name], len(x), rng)
    f = contact.force(x)
    step = 1e-8
    fd = np.zeros_like(x)
    for a in range(len(x)):  # small test mesh: loop over its nodes to perturb one at a time
        for i in range(3):
            xp, xm = x.copy(), x.copy()
            xp[a, i] += step
            xm[a, i] -= step
            fd[a, i] = (contact.energy(xp) - contact.energy(xm)) / (2 * step)
    np.testing.assert_allclose(fd, f, rtol=1e-6, atol=1e-6 * np.abs(f).max())
    # Nodes outside carry no force and no stiffness; penetrating ones are pushed out: -f along +n.
    outside = depth > 0
    assert np.all(f[outside] == 0.0)
    assert np.all(contact.tangent_blocks(x)[outside] == 0.0)
    _, n = OBSTACLES[name].signed_distance(x)
    assert np.all(np.einsum("ni,ni->n", -f[~outside], n[~outside]) > 0)


@pytest.mark.parametrize("name", list(OBSTACLES))
def test_tangent_is_gradient_of_force(name):
    rng = np.random.default_rng(11)
    x, _ = _nodes(OBSTACLES[name], rng)
    contact = _contact(OBSTACLES[name], len(x), rng)
    K_blocks = contact.tangent_blocks(x)
    np.testing.assert_allclose(K_blocks, np.swapaxes(K_blocks, 1, 2), atol=1e-12 * np.abs(K_blocks).max())
    step = 1e-8
    fd = np.zeros_like(K_blocks)
    for j in range(3):  # the force is node-local: perturb component j of every node at once
        e = np.zeros(3)
        e[j] = step
        fd[:, :, j] = (contact.force(x + e) - contact.force(x - e)) / (2 * step)
    np.testing.assert_allclose(fd, K_blocks, rtol=1e-6, atol=1e-6 * np.abs(K_blocks).max())


def test_several_obstacles_add_up_and_evaluate_agrees():
    rng = np.random.default_rng(12)
    obstacles = [OBSTACLES["round"], Floor(-0.02)]
    # Nodes pressed into the pedestal's rim and into the floor beside it.
    x = np.vstack([_nodes(obstacles[0], rng, 10)[0], _nodes(obstacles[1], rng, 10)[0]])
    area = np.full(len(x), H**2)
    both = PenaltyContact(obstacles, area, K)
    parts = [PenaltyContact(ob, area, K) for ob in obstacles]
    state = both.evaluate(x)
    assert isinstance(state, ContactState)
    assert state.energy == pytest.approx(sum(p.energy(x) for p in parts), rel=1e-14)
    np.testing.assert_allclose(state.force, sum(p.force(x) for p in parts), rtol=1e-14, atol=0)
    blocks = sum(p.tangent_blocks(x) for p in parts)
    np.testing.assert_allclose(state.tangent_blocks, blocks, rtol=1e-14, atol=0)
    gaps = np.minimum(*(ob.signed_distance(x)[0] for ob in obstacles))
    np.testing.assert_array_equal(state.gap, gaps)
    np.testing.assert_array_equal(both.active(x), gaps < 0)
    assert both.max_penetration(x) == pytest.approx(-gaps.min()) == pytest.approx(state.max_penetration)
    assert state.n_active == np.count_nonzero(gaps < 0)


def test_flat_floor_values():
    """Hand values on a plane: E = k A d^2 / 2, force = -k A d e_z, tangent = k A e_z e_z^T."""
    x = np.array([[0.0, 0.0, -1e-4], [0.1, 0.0, 2e-3]])
    area = np.array([2e-5, 3e-5])
    c = PenaltyContact([Floor(0.0)], area, 1e7)
    assert c.energy(x) == pytest.approx(0.5 * 1e7 * 2e-5 * 1e-8)
    np.testing.assert_allclose(c.force(x), [[0, 0, -1e7 * 2e-5 * 1e-4], [0, 0, 0]])
    np.testing.assert_allclose(c.tangent_blocks(x)[0], np.diag([0, 0, 1e7 * 2e-5]))
    assert c.max_penetration(x) == pytest.approx(1e-4)
    np.testing.assert_array_equal(c.active(x), [True, False])


def test_auto_penalty_keeps_wool_penetration_small():
    """§4 wool at h = 0.5 cm: 10x its weight as contact pressure penetrates < 1e-2 h (here < 1e-3 h)."""
    assert WOOL_C == pytest.approx(1096.6, rel=1e-4)
    assert WOOL_B == pytest.approx(8.14e-6, rel=1e-3)
    assert WOOL_W == pytest.approx(1.863, rel=1e-3)
    d = estimate_penetration(10 * WOOL_W, K)
    assert d < 1e-2 * H and d < 1e-3 * H
    # The penalty spring of a node (k h^2) is the membrane stiffness: the tangent stays well conditioned.
    assert K * H**2 == pytest.approx(WOOL_C)
    # A resting sheet in a static penalty solution: a floor node under the sheet's weight penetrates w / k.
    c = PenaltyContact(Floor(0.0), np.array([H**2]), K)
    d_eq = WOOL_W / K  # equilibrium: k A d = w A
    x = np.array([[0.0, 0.0, -d_eq]])
    np.testing.assert_allclose(c.force(x), [[0, 0, -WOOL_W * H**2]], rtol=1e-12)
    # Finer meshes get stiffer penalties; factor scales linearly.
    assert auto_penalty(membrane_rigidity=WOOL_C, bending_rigidity=WOOL_B, weight=WOOL_W, h=H / 2) > K
    assert auto_penalty(membrane_rigidity=WOOL_C, bending_rigidity=WOOL_B, weight=WOOL_W, h=H, factor=3) == (
        pytest.approx(3 * K)
    )
    # The weight condition governs a very limp sheet.
    k_limp = auto_penalty(membrane_rigidity=0.0, bending_rigidity=0.0, weight=WOOL_W, h=H)
    assert estimate_penetration(10 * WOOL_W, k_limp) == pytest.approx(1e-3 * H)


@pytest.mark.parametrize("name", list(OBSTACLES))
def test_kinematic_contact(name):
    obstacle = OBSTACLES[name]
    rng = np.random.default_rng(13)
    x, depth = _nodes(obstacle, rng)
    v = rng.normal(size=x.shape)
    _, n = obstacle.signed_distance(x)
    x_new, v_new, n_active = kinematic_contact([obstacle], x, v)
    inside = depth < 0
    assert n_active == np.count_nonzero(inside)
    phi_new, n_new = obstacle.signed_distance(x_new)
    assert np.all(phi_new >= -1e-12)
    np.testing.assert_allclose(phi_new[inside], 0.0, atol=1e-12)
    # Moved along the normal by the penetration depth; untouched nodes stay put with their velocity.
    np.testing.assert_allclose(x_new[inside], x[inside] - depth[inside, None] * n[inside], atol=1e-13)
    np.testing.assert_array_equal(x_new[~inside], x[~inside])
    np.testing.assert_array_equal(v_new[~inside], v[~inside])
    # Only the inward normal velocity is removed: tangential part kept, outward normal part kept.
    vn = np.einsum("ni,ni->n", v, n)
    vn_new = np.einsum("ni,ni->n", v_new, n)
    np.testing.assert_allclose(v_new - vn_new[:, None] * n, v - vn[:, None] * n, atol=1e-14)
    np.testing.assert_allclose(vn_new[inside], np.maximum(vn[inside], 0.0), atol=1e-14)
    assert np.any(vn[inside] < 0) and np.any(vn[inside] > 0)


def test_kinematic_contact_on_sphere_is_radial():
    """§6.3: a node inside the sphere goes radially to its surface."""
    sphere = Sphere([0.0, 0.0, 0.0], 0.05)
    x = np.array([[0.0, 0.03, 0.04 * 0.9], [0.1, 0.0, 0.0]])
    v = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
    x_new, v_new, n_active = kinematic_contact(sphere, x, v)
    assert n_active == 1
    np.testing.assert_allclose(x_new[0], x[0] / np.linalg.norm(x[0]) * 0.05)
    np.testing.assert_allclose(np.dot(v_new[0], x_new[0]), 0.0, atol=1e-15)
    np.testing.assert_array_equal(v_new[1], v[1])


@pytest.mark.parametrize(
    "make, word",
    [
        (lambda: PenaltyContact([Floor()], np.ones(3), -1.0), "stiffness"),
        (lambda: PenaltyContact([Floor()], np.ones(3), np.nan), "stiffness"),
        (lambda: PenaltyContact([Floor()], np.array([1.0, -1.0]), 1.0), "node_area[1]"),
        (lambda: PenaltyContact([Floor()], np.ones((3, 1)), 1.0), "node_area"),
        (lambda: PenaltyContact(["floor"], np.ones(3), 1.0), "obstacles[0]"),
        (lambda: PenaltyContact(Floor(), np.ones(3), 1.0).force(np.zeros((4, 3))), "(3, 3)"),
        (lambda: auto_penalty(membrane_rigidity=-1.0, bending_rigidity=0, weight=1, h=0.01), "membrane_rigidity"),
        (lambda: auto_penalty(membrane_rigidity=1.0, bending_rigidity=0.0, weight=1.0, h=0.0), "h"),
        (lambda: auto_penalty(membrane_rigidity=1.0, bending_rigidity="x", weight=1, h=0.01), "bending_rigidity"),
        (lambda: auto_penalty(membrane_rigidity=0.0, bending_rigidity=0.0, weight=0.0, h=0.01), "all zero"),
        (lambda: estimate_penetration(1.0, 0.0), "k"),
        (lambda: estimate_penetration(-1.0, 1.0), "pressure"),
        (lambda: kinematic_contact(Floor(), np.zeros((4, 3)), np.zeros((3, 3))), "v must"),
    ],
)
def test_bad_input_names_the_parameter(make, word):
    with pytest.raises(ValueError) as info:
        make()
    assert word in str(info.value)


@pytest.mark.parametrize("name", sorted(OBSTACLES))
def test_candidate_list_is_exact_along_a_motion(name):
    """The near-node list (refreshed after a move of margin / 2) gives the full evaluation's numbers."""
    rng = np.random.default_rng(5)
    ob = OBSTACLES[name]
    x0, _ = _nodes(ob, rng, 40)
    area = np.full(len(x0), H**2)
    contact = PenaltyContact(ob, area, K, smoothing=0.05 * H)
    cand = contact.new_candidates()  # the solve's cache (held in its State); the contact holds none
    direction = rng.normal(size=x0.shape)
    velocity = 0.1 * contact.margin * direction / np.linalg.norm(direction, axis=1)[:, None]
    for step in range(40):  # every node moves 4 margins in all, each step a tenth of one
        x = x0 + step * velocity
        full = contact.evaluate(x)  # no list: every node
        state = contact.evaluate(x, candidates=cand)
        assert state.energy == pytest.approx(full.energy, rel=1e-13, abs=1e-300)
        np.testing.assert_allclose(state.force, full.force, rtol=1e-13, atol=0)
        np.testing.assert_allclose(contact.force(x, candidates=cand), full.force, rtol=1e-13, atol=0)  # force only
        np.testing.assert_allclose(state.tangent_blocks, full.tangent_blocks, rtol=1e-13, atol=0)
        np.testing.assert_array_equal(state.active, full.active)
        near = full.gap < contact.margin / 2
        np.testing.assert_array_equal(state.gap[near], full.gap[near])
        assert np.all(state.gap <= full.gap + 1e-15)  # elsewhere a lower bound
    assert 1 < cand.refreshes < 40 and 0 < len(cand) < len(x0)
