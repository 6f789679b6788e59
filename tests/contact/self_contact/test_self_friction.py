"""Coulomb friction between layers of the sheet in self-contact (issue 36 ``self_friction``,
rftstatic.contact.self_contact.friction): the mathematics (force = gradient of the energy, tangent = gradient of the
force, every pair block positive semi-definite; the closest points' coefficients from the distance's gradient) and
the drag test between two layers: a top layer dragged over a bottom one pulls back with mu times its weight, and
with nothing without friction."""

import numpy as np
import pytest

from rftstatic.contact.friction import FrictionLaw
from rftstatic.contact.self_contact.friction import _active_pairs, commit_pairs, empty_pairs_lag, pair_friction_terms
from rftstatic.contact.self_contact.law import SelfContact, auto_stiffness
from rftstatic.material import preset
from rftstatic.mesh.trimesh import TriMesh, rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.solvers import static

EPS = 1e-4
FACTOR = 0.02
TURN = 0.3  # [rad]


def _lag(rng, P=5, N=12, scale=3e-5):
    nodes = np.array([rng.choice(N, 4, replace=False) for _ in range(P)])
    w = rng.uniform(-1, 1, (P, 4))
    w[:, 3] = -w[:, :3].sum(axis=1)  # as the closest points' coefficients: they sum to 0
    n = rng.standard_normal((P, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    x = rng.standard_normal((N, 3)) * 0.01
    anchor = np.einsum("pa,pai->pi", w, x[nodes]) + rng.standard_normal((P, 3)) * scale
    return x, {"nodes": nodes, "kind": np.zeros(P, np.int8), "w": w, "normal": n, "normal_force": rng.uniform(.5, 2, P),
               "anchor": anchor, "slid": np.zeros(P, bool), "mu": rng.uniform(.1, .8, P), "eps": EPS}


@pytest.mark.parametrize("scale", [0.3 * EPS, 3 * EPS])  # sticking (y < eps) and sliding (y > eps) pairs
def test_self_friction_force_and_tangent_are_the_derivatives_of_its_energy(scale):
    x, lag = _lag(np.random.default_rng(7), scale=scale)
    E, f, K = pair_friction_terms(lag, x)
    N, P, h = x.shape[0], len(lag["nodes"]), 1e-8
    fd, Kfd = np.zeros_like(f), np.zeros((3 * N, 3 * N))
    for a in range(N):
        for i in range(3):
            d = np.zeros_like(x)
            d[a, i] = h
            Ep, fp, _ = pair_friction_terms(lag, x + d, tangent=False)
            Em, fm, _ = pair_friction_terms(lag, x - d, tangent=False)
            fd[a, i] = (Ep - Em) / (2 * h)
            Kfd[:, 3 * a + i] = ((fp - fm) / (2 * h)).ravel()
    Kg = np.zeros((3 * N, 3 * N))
    idx = (3 * lag["nodes"][:, :, None] + np.arange(3)).reshape(P, 12)
    for p in range(P):
        Kg[np.ix_(idx[p], idx[p])] += K[p]
    assert np.abs(fd - f).max() < 1e-6 * np.abs(f).max()
    assert np.abs(Kfd - Kg).max() < 1e-6 * np.abs(Kg).max()
    assert np.linalg.eigvalsh(K).min() > -1e-12 * np.abs(K).max()  # every pair block PSD
    # a rigid translation changes nothing (the coefficients sum to 0), and rigid motion is force-free in total
    assert pair_friction_terms(lag, x + [3e-3, -2e-3, 1e-3], tangent=False)[0] == pytest.approx(E, rel=1e-12)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12 * np.abs(f).max())


def _layers(mu, d=2e-3, n=9, m=5, gap=0.7):
    """A 10 cm wool square (held in every dof) and a 5 cm one laid on it ``gap * d`` above (one mesh, two layers in
    self-contact, a quarter cell off the lower one's nodes), its edge x = min held in x and y: the model and the
    start displacements (the upper square is placed from beside the lower one in the flat chart)."""
    low, up = rectangle(0.1, 0.1, n, n), rectangle(0.05, 0.05, m, m, origin=(0.2, 0.0))
    mesh = TriMesh(np.vstack([low.X, up.X]), np.vstack([low.tri, up.tri + low.n_nodes]))
    top = np.arange(low.n_nodes, mesh.n_nodes)
    U0 = np.zeros((mesh.n_nodes, 3))
    c, s = np.cos(TURN), np.sin(TURN)  # turned, so that no edge of one layer is parallel to one of the other
    rel = up.X - [0.225, 0.025]
    U0[top, :2] = np.column_stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]]) + 0.05 - up.X
    U0[top, 2] = gap * d
    mat = preset("wool-kang-yu")
    k = auto_stiffness(weight=mat.weight, node_area=float(mesh.node_area.mean()), thickness=d, factor=FACTOR)
    law = None if mu == 0 else FrictionLaw(np.array([mu]), np.array([mu]), eps=1e-5)
    sc = SelfContact(mesh, d, k, friction=law, kernels="numpy")
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[:low.n_nodes] = True
    edge = top[np.abs(up.X[:, 0] - 0.2) < 1e-12]
    fixed[edge, :2] = True
    load = gravity_load(mesh, mat.weight)
    model = Model(mesh, mat, supports=Supports(np.zeros(0, np.int64), np.zeros(0, np.int64), fixed), load=load,
                  self_contact=sc, quiet=True)
    return model, U0, top, edge


def test_closest_point_coefficients_give_the_pairs_distance_vector():
    """The coefficients w from the squared distance's gradient: sum_a w_a x_a is the vector between the closest
    points, of length delta along n, the first primitive's weights sum to 1 and the second's to -1."""
    model, U0, _, _ = _layers(0.3)
    x = model.positions(U0)
    sc = model.self_contact
    nodes, kind, w, n, lam = _active_pairs(sc, x, sc.new_pairs())
    assert len(nodes) > 20 and set(kind.tolist()) == {0, 1}
    r = np.einsum("pa,pai->pi", w, x[nodes])
    delta = np.einsum("pi,pi->p", r, n)
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), delta, rtol=1e-9)
    assert np.all(delta < sc.thickness) and np.all(lam > 0)
    first = np.where(kind == 0, w[:, 0], w[:, 0] + w[:, 1])
    np.testing.assert_allclose(first, 1.0, rtol=1e-9)
    np.testing.assert_allclose(w.sum(axis=1), 0.0, atol=1e-9)


def drag_layers(mu, steps=4, step=0.5e-3):
    """The upper layer settled on the lower one under its weight, then its held edge dragged along -x by ``step``
    [m] ``steps`` times: the edge's reaction along x over the upper layer's weight after each step [-]."""
    from rftstatic.solvers.load_steps import solve_load_steps
    from rftstatic.solvers.newton import start_state

    model, U0, top, edge = _layers(mu)
    opts = static.StaticOptions(progress=False).from_state(relax_fallback=False)
    state = start_state(model, opts.newton.linear_solver)
    U = solve_load_steps(model, U0=U0, options=opts, state=state).U.copy()
    weight = -model.load[top, 2].sum()
    ratios = []
    for _ in range(steps):
        U[edge, 0] -= step
        res = solve_load_steps(model, U0=U, options=opts, state=state)
        assert res.converged
        U = res.U.copy()
        ratios.append(model.residual(U, 1.0, pairs=state.self_pairs)[edge, 0].sum() / weight)
    return np.array(ratios)


def test_a_layer_dragged_over_another_pulls_back_with_mu_times_its_weight():
    """The drag test between layers: without friction the reaction only ripples (the lower layer's facets, within
    2 % of the weight W); with self friction mu = 0.3 the layer slides from the first step and friction adds -mu W to
    the reaction of the same drag (measured 0.296-0.299 W)."""
    free = drag_layers(0.0)
    assert np.abs(free).max() < 0.02, free
    held = drag_layers(0.3)
    np.testing.assert_allclose(held - free, -0.3, rtol=0.02)


def test_self_friction_scene_key_needs_the_self_contact(tmp_path, capsys):
    from rftstatic.cli import main

    rc = main(["case", "strip", "--no-figures", "--out", str(tmp_path / "r"), "--set", "contact.self_friction=0.3"])
    assert rc == 2 and "contact.self_friction" in capsys.readouterr().err


def test_the_models_force_and_tangent_carry_the_lagged_self_friction():
    """Through the Model (the solve's pair cache carrying the lag): its internal force and free-dof tangent with
    the lag minus those without are the friction's force (S2) and its pair blocks, assembled; after a drag step
    the friction force on the upper layer is mu times the sum of the pairs' normal forces (within 5 %: the pairs
    that entered in the step stick), against the drag."""
    from rftstatic.solvers.load_steps import solve_load_steps
    from rftstatic.solvers.newton import start_state

    model, U0, top, edge = _layers(0.3)
    opts = static.StaticOptions(progress=False).from_state(relax_fallback=False)
    state = start_state(model, opts.newton.linear_solver)
    U = solve_load_steps(model, U0=U0, options=opts, state=state).U.copy()
    U[edge, 0] -= 0.5e-3
    U = solve_load_steps(model, U0=U, options=opts, state=state).U
    pairs, lag = state.self_pairs, state.contact_history["self_friction"]
    f1, K1 = model.tangent(U, pairs=pairs)
    pairs.friction = None
    f0, K0 = model.tangent(U, pairs=pairs)
    pairs.friction = lag
    x = model.positions(U)
    _, ff, blocks = pair_friction_terms(lag, x)
    np.testing.assert_allclose(f1 - f0, ff, atol=1e-12 * np.abs(ff).max())
    free = model.free.ravel()
    Kf = np.zeros((3 * model.mesh.n_nodes,) * 2)
    idx = (3 * lag["nodes"][:, :, None] + np.arange(3)).reshape(-1, 12)
    for p in range(len(idx)):
        Kf[np.ix_(idx[p], idx[p])] += blocks[p]
    np.testing.assert_allclose((K1 - K0).toarray(), Kf[np.ix_(free, free)], atol=1e-9 * np.abs(Kf).max())
    assert lag["slid"].mean() > 0.8  # the layer slides (the pairs that entered in the step stick)
    # the gradient on the layer dragged along -x points along -x: friction pulls it back along +x
    assert ff[top, 0].sum() == pytest.approx(-0.3 * lag["normal_force"].sum(), rel=0.05)


def drag_layers_explicit(mu, v=0.01, t_end=0.2):
    """The layers of :func:`_layers` on the explicit route: undamped from the start, the upper layer's edge held in
    x and y and moving along -x at ``v`` [m/s] (``Supports.velocity``) for ``t_end`` [s], Coulomb impulses between
    the layers (:func:`rftstatic.contact.self_contact.friction.pair_impulses`): the mean reaction along x over the
    run's second half over the weight of the upper layer's nodes not held [-]."""
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    model, U0, top, edge = _layers(mu)
    velocity = np.zeros_like(U0)
    velocity[edge, 0] = -v
    s = model.supports
    model = Model(model.mesh, model.material, supports=Supports(s.clamped, s.pinned, s.fixed, velocity),
                  load=model.load, self_contact=model.self_contact, quiet=True)
    res = run_explicit(model, ExplicitOptions(t_end=t_end, alpha=0.0, progress=False), U0=U0)
    pulled = -model.load[np.setdiff1d(top, edge), 2].sum()
    return res.drive_reaction[0] / pulled


@pytest.mark.slow
def test_a_layer_dragged_over_another_on_the_explicit_route_pulls_back_with_mu_times_its_weight():
    """Issue 36's drag between layers on the explicit route: friction mu = 0.3 adds -mu W to the frictionless
    reaction within 2 % (measured 0.995; 0.987 at mu = 0.5). Slow (two runs of 1,218 steps with the numpy pair
    kernels: ~14 s); tools/friction_report.py runs it for validation/friction_obstacles.md."""
    free, held = drag_layers_explicit(0.0), drag_layers_explicit(0.3)
    assert abs(free) < 0.05, free  # the lower layer's facets: a ripple
    assert (held - free) / -0.3 == pytest.approx(1.0, abs=0.02)
