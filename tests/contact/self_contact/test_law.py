"""Self-contact law: energy, force and tangent against finite differences on a folded sheet, the PSD
projection, the automatic stiffness, and the step bound that stops a point moving through a triangle
and an edge through an edge."""

import numpy as np
import pytest
import scipy.sparse as sp

from rftstatic.contact.self_contact.law import BARRIER_GAP, SelfContact, auto_stiffness, pair_law
from rftstatic.mesh.trimesh import rectangle

D = 0.02  # thickness [m]; edges 0.1 m


def folded(seed=0, gap=0.6 * D):
    """A 11 x 3 strip of 0.1 m elements folded in two, the upper half ``gap`` above the lower one,
    shifted a little in-plane and perturbed, so that point-face, edge and crossing-edge pairs are within D."""
    mesh = rectangle(1.0, 0.2, 11, 3, pattern="alternate")
    X = mesh.X3.copy()
    right = X[:, 0] > 0.55
    X[right, 0] = 1.0 - X[right, 0] + 0.033
    X[right, 1] += 0.021
    X[right, 2] = gap
    rng = np.random.default_rng(seed)
    X[:, 2] += 0.1 * D * rng.standard_normal(len(X))
    X[:, :2] += 0.004 * rng.standard_normal((len(X), 2))
    return mesh, X


def assembled(sc, st, n):
    rows = (3 * st.nodes[:, :, None] + np.arange(3)).reshape(-1, 12)
    r = np.repeat(rows, 12, axis=1).ravel()
    c = np.tile(rows, (1, 12)).ravel()
    return sp.coo_matrix((st.blocks.ravel(), (r, c)), shape=(3 * n, 3 * n)).toarray()


def test_force_and_tangent_match_finite_differences():
    mesh, X = folded()
    sc = SelfContact(mesh, D, 50.0)
    st = sc.evaluate(X, project=False)
    assert st.n_active > 20 and st.energy > 0
    rng = np.random.default_rng(1)
    v = rng.standard_normal(X.shape)
    h = 1e-7
    dE = (sc.energy(X + h * v) - sc.energy(X - h * v)) / (2 * h)
    assert dE == pytest.approx(float(np.sum(st.force * v)), rel=1e-6)
    K = assembled(sc, st, mesh.n_nodes)
    df = (sc.force(X + h * v) - sc.force(X - h * v)).ravel() / (2 * h)
    err = np.linalg.norm(df - K @ v.ravel()) / np.linalg.norm(df)
    assert err < 1e-5
    np.testing.assert_allclose(st.force.sum(axis=0), 0.0, atol=1e-12)  # internal: no net force


def test_pair_law_derivatives_and_the_barrier_below_a_quarter_of_the_thickness():
    d, k = 5e-4, 3.0
    delta = np.concatenate([np.geomspace(1e-6 * d, 0.999 * d, 400), BARRIER_GAP * d * np.array([0.999, 1.001])])
    e, e1, e2 = pair_law(delta, d, k)
    h = 1e-7 * delta
    ep, e1p, _ = pair_law(delta + h, d, k)
    em, e1m, _ = pair_law(delta - h, d, k)
    np.testing.assert_allclose((ep - em) / (2 * h), e1, rtol=1e-6, atol=1e-12 * k * d)
    np.testing.assert_allclose((e1p - e1m) / (2 * h), e2, rtol=1e-6, atol=1e-9 * k)
    cubic = k / (3 * d) * (d - delta) ** 3
    above = delta >= BARRIER_GAP * d
    np.testing.assert_array_equal(e[above], cubic[above])  # the cubic penalty alone down to d / 4
    # C2 at the barrier's edge: value, slope and curvature continuous
    for f in pair_law(BARRIER_GAP * d * np.array([1 - 1e-9, 1 + 1e-9]), d, k):
        assert f[0] == pytest.approx(f[1], rel=1e-6)
    # the cubic pushes with at most k d; the barrier's push grows without bound as the pair closes
    assert -e1[-3] < k * d
    assert -pair_law(np.array([1e-6 * d]), d, k)[1][0] > 1e3 * k * d
    assert np.all(np.diff(e[:400]) < 0) and np.all(e1 < 0) and np.all(e2 > 0)


def test_force_and_tangent_match_finite_differences_inside_the_barrier():
    mesh, X = folded(seed=3, gap=0.12 * D)
    sc = SelfContact(mesh, D, 50.0)
    st = sc.evaluate(X, project=False)
    assert st.min_distance < BARRIER_GAP * D and st.n_active > 20
    v = np.random.default_rng(4).standard_normal(X.shape)
    h = 1e-8
    dE = (sc.energy(X + h * v) - sc.energy(X - h * v)) / (2 * h)
    assert dE == pytest.approx(float(np.sum(st.force * v)), rel=1e-6)
    df = (sc.force(X + h * v) - sc.force(X - h * v)).ravel() / (2 * h)
    K = assembled(sc, st, mesh.n_nodes)
    assert np.linalg.norm(df - K @ v.ravel()) / np.linalg.norm(df) < 1e-5


def test_projected_blocks_are_psd_and_exact_where_already_psd():
    mesh, X = folded(seed=2)
    sc = SelfContact(mesh, D, 50.0)
    exact = sc.evaluate(X, project=False).blocks
    proj = sc.evaluate(X).blocks
    assert np.linalg.eigvalsh(proj).min() > -1e-9 * np.abs(proj).max()
    lam = np.linalg.eigvalsh(exact)
    assert lam.min() < 0  # the exact blocks are indefinite (repulsion times the distance's curvature)
    scale = np.abs(exact).max()
    # the projection clamps the eigenvalues at zero and keeps the rest: the nearest PSD matrix
    np.testing.assert_allclose(np.linalg.eigvalsh(proj), np.maximum(lam, 0.0), atol=1e-9 * scale)
    assert np.linalg.eigvalsh(proj - exact).min() > -1e-9 * scale


def test_no_energy_far_apart_and_repulsive_close():
    mesh, X = folded(gap=3 * D)
    sc = SelfContact(mesh, D, 50.0)
    assert sc.evaluate(X).n_active == 0 and sc.energy(X) == 0.0
    mesh, X = folded(gap=0.5 * D)
    f = sc.force(X)
    top = X[:, 2] > 0.2 * D
    assert f[top, 2].sum() < 0  # gradient points down on the upper layer: the force pushes it up


def test_auto_stiffness_keeps_half_the_thickness_under_the_design_load():
    w, A, d = 1.863, 1e-4, 5e-4
    k = auto_stiffness(weight=w, node_area=A, thickness=d)
    F = 10 * w * A  # design load of one pair
    delta = d - np.sqrt(F * d / k)
    assert delta == pytest.approx(0.5 * d)
    assert d - np.sqrt(w * A * d / k) > 0.8 * d  # own weight
    with pytest.raises(ValueError, match="thickness"):
        auto_stiffness(weight=w, node_area=A, thickness=0.0)


def test_thickness_above_half_the_smallest_edge_is_an_error():
    mesh = rectangle(1.0, 0.2, 11, 3)
    with pytest.raises(ValueError, match=r"0\.06.*half the smallest edge"):
        SelfContact(mesh, 0.06, 1.0)


def test_step_bound_stops_a_point_through_a_triangle():
    mesh = rectangle(1.0, 1.0, 5, 5, pattern="right")
    sc = SelfContact(mesh, 0.05, 1.0)
    X = mesh.X3.copy()
    # lift node 24 (corner) over the triangle 0's interior and push it straight down through it
    t0 = mesh.tri[0]
    centre = X[t0].mean(axis=0)
    X[24] = centre + [0, 0, 0.3]
    dx = np.zeros_like(X)
    dx[24] = [0, 0, -0.6]  # ends 0.3 below: straight through
    alpha = sc.max_step_fraction(X, dx)
    z = X[24, 2] + alpha * dx[24, 2]
    assert 0 < alpha < 0.5
    assert z == pytest.approx(sc.min_fraction * 0.3, rel=1e-2)  # stops at 20 % of its distance
    # a rigid motion of the whole sheet is never limited
    assert sc.max_step_fraction(X, np.broadcast_to([0.0, 0.0, -5.0], X.shape).copy()) == 1.0
    # sliding parallel to the triangle at constant height is not limited
    dx[24] = [0.05, 0.05, 0]
    assert sc.max_step_fraction(X, dx) == 1.0


def test_step_bound_stops_an_edge_through_an_edge():
    mesh = rectangle(1.0, 1.0, 5, 5, pattern="right")
    sc = SelfContact(mesh, 0.05, 1.0)
    X = mesh.X3.copy()
    e = sc.prims.edges
    # the top boundary edge (nodes 23, 24) turned across edge (0, 1), 0.2 above it
    ea = np.flatnonzero((e[:, 0] == 23) & (e[:, 1] == 24))
    assert len(ea) == 1
    X[23] = [0.125, -0.2, 0.2]
    X[24] = [0.125, 0.2, 0.2]
    dx = np.zeros_like(X)
    dx[[23, 24]] = [0, 0, -0.4]  # through the edge (0, 1) at y = 0
    alpha = sc.max_step_fraction(X, dx)
    gap = 0.2 + alpha * -0.4
    assert 0 < alpha < 0.5 and gap >= sc.min_fraction * 0.2 * (1 - 1e-6)
    assert gap == pytest.approx(sc.min_fraction * 0.2, rel=2e-2)


def test_a_step_too_long_to_sweep_is_bounded_to_the_sweep_limit():
    """The swept broad phase keeps its pair budget: a step whose relative motion exceeds
    ``sweep_limit`` is tested over its first ``sweep_limit / spread`` and bounded there, and a point
    driven through a triangle still stops short of it."""
    mesh = rectangle(1.0, 1.0, 5, 5, pattern="right")
    sc = SelfContact(mesh, 0.05, 1.0)
    assert sc.sweep_limit == pytest.approx(0.25 * np.sqrt(1e6 / 32), rel=0.3)  # h sqrt(budget / E)
    X = mesh.X3.copy()
    centre = X[mesh.tri[0]].mean(axis=0)
    X[24] = centre + [0, 0, 0.3]
    dx = np.zeros_like(X)
    dx[24] = [0, 0, -0.6]
    free = sc.max_step_fraction(X, dx)
    sc = SelfContact(mesh, 0.05, 1.0, sweep_limit=0.1)  # [m]: the relative motion of the step (2 x its
    # largest departure from the midrange motion, 2 x 0.3 m) is 0.6 m
    alpha = sc.max_step_fraction(X, dx)
    assert alpha == pytest.approx(0.1 / 0.6, rel=1e-12) and alpha < free
    assert sc.stats.sweeps_limited == 1
    sc = SelfContact(mesh, 0.05, 1.0, sweep_limit=0.5)  # the bounded part reaches the triangle: the
    # collision bound still holds
    alpha = sc.max_step_fraction(X, dx)
    assert alpha == pytest.approx(free, rel=1e-9)
    assert X[24, 2] + alpha * dx[24, 2] >= sc.min_fraction * 0.3 * (1 - 1e-6)
