"""Shear hysteresis (rftstatic.element.shear_friction): derivatives on both branches, rigid-motion invariance, the
explicit force, the KES shear loop's width and the slips committed with the bending friction's."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element.explicit_force import ForceKernel
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from rftstatic.model.state import State
from tests.element.test_hysteresis import derivative_errors

TAU0 = 0.05  # N/m (2HG = 0.1 N/m ~ 0.1 gf/cm on this toy fabric)


def _material(angle=0.3, ratio=10.0, bending=False):
    base = material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, B_warp=0.03, B_weft=0.02, B_twist=0.01,
                           weight=0.1, warp_angle=angle)
    h = material.BendingHysteresis(0.004, 0.003, 10.0) if bending else None
    return replace(base, shear_hysteresis=material.ShearHysteresis(TAU0, ratio), hysteresis=h)


def _sheared(mod, rng):
    X = mod.X3
    U = 0.03 * rng.normal(size=X.shape)
    U[:, 0] += 0.1 * X[:, 1]  # a shear of the sheet
    U[:, 2] += 0.3 * X[:, 0] ** 2 - 0.2 * X[:, 0] * X[:, 1]
    return U


def _mixed_slip(mod, U, rng):
    """A committed slip (both frictions' columns) that leaves about half the elements sticking at ``U``."""
    fr = mod.shear_friction
    s = fr.shear_angle(U) + (fr.tau0 / fr.K) * rng.uniform(-2.0, 2.0, size=(fr.n_elements, 1))
    if mod.bending_friction is None:
        return s
    bf = mod.bending_friction
    km = bf.curvature(U, mod.positions(U))[:, :2]
    return np.concatenate([km + (bf.M0 / bf.K) * rng.uniform(-2.0, 2.0, size=km.shape), s], axis=1)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("bending", [False, True])
def test_force_and_tangent_are_derivatives_on_both_branches(element, bending):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(bending=bending), element=element, load=model.gravity_load(m, 0.1))
    rng = np.random.default_rng(4)
    U = _sheared(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    fr = mod.shear_friction
    stick = np.abs(fr.shear_angle(U) - mod.split_slip(slip)[1]) <= fr.tau0 / fr.K
    assert 0.2 < stick.mean() < 0.8  # both branches of (S3) are exercised
    err_f, err_k, r, f, K = derivative_errors(mod, U, 0.6, rng, slip=slip)
    assert err_f < 1e-6 * np.abs(r).max()
    assert err_k < 1e-6 * np.abs(K).max()
    # the friction term alone, whose forces are small next to the membrane's
    err_f, err_k = friction_derivative_errors(fr, U, mod.split_slip(slip)[1], rng, 12)
    assert err_f < 1e-6 and err_k < 1e-6


def friction_derivative_errors(fr, U, slip, rng, n, h=1e-7):
    """The shear friction's assembled force against central differences of its energy, and its assembled tangent
    against those of its force, at ``n`` random dofs of ``U (N, 3)`` [m] with the committed ``slip (E,)``: the
    largest errors relative to the largest force and tangent entry."""
    _, fe, ke = fr.evaluate(U, slip, tangent=True)
    dofs = 3 * fr.nodes[..., None] + np.arange(3)

    def assembled(f):
        out = np.zeros(U.size)
        np.add.at(out, dofs.ravel(), f.ravel())
        return out

    g = assembled(fe)
    Kd = np.zeros((U.size, U.size))
    for k in range(len(ke)):
        d = dofs[k].ravel()
        Kd[np.ix_(d, d)] += ke[k].reshape(d.size, d.size)
    err_f = err_k = 0.0
    for c in rng.choice(U.size, n, replace=False):
        Up, Um = U.ravel().copy(), U.ravel().copy()
        Up[c] += h
        Um[c] -= h
        (ep, fp), (em, fm) = fr.evaluate(Up.reshape(-1, 3), slip)[:2], fr.evaluate(Um.reshape(-1, 3), slip)[:2]
        err_f = max(err_f, abs((ep - em) / (2 * h) - g[c]))
        err_k = max(err_k, np.abs((assembled(fp) - assembled(fm)) / (2 * h) - Kd[:, c]).max())
    return err_f / np.abs(g).max(), err_k / np.abs(Kd).max()


def test_psd_tangent_is_positive_semi_definite():
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element="RFT6")
    rng = np.random.default_rng(6)
    U = _sheared(mod, rng)
    _, _, ke = mod.shear_friction.evaluate(U, _mixed_slip(mod, U, rng), tangent=True, psd=True)
    k = ke.reshape(len(ke), 18, 18)
    assert np.linalg.eigvalsh(0.5 * (k + k.transpose(0, 2, 1))).min() > -1e-12 * np.abs(k).max()


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_a_rigid_motion_does_not_shear_and_turns_the_force(element):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element=element)
    fr = mod.shear_friction
    rng = np.random.default_rng(7)
    R = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
    flat_turned = mod.X3 @ R.T + np.array([0.3, -2.0, 5.0]) - mod.X3
    np.testing.assert_allclose(fr.shear_angle(flat_turned), 0.0, atol=1e-14)
    slip = fr.initial_slip() + 1e-3 * rng.uniform(-1, 1, size=(fr.n_elements, 1))  # a held slip: a force at rest
    f0 = fr.evaluate(np.zeros_like(mod.X3), slip)[1]
    np.testing.assert_allclose(fr.evaluate(flat_turned, slip)[1], f0 @ R.T, atol=1e-12 * np.abs(f0).max())
    e_rest, f_rest, _ = fr.evaluate(flat_turned, fr.initial_slip())  # no slip: no force, no energy (round-off)
    assert abs(e_rest) < 1e-12 * TAU0 * fr.area.sum() and np.abs(f_rest).max() < 1e-10 * np.abs(f0).max()
    U = _sheared(mod, rng)
    x2 = mod.positions(U) @ R.T
    np.testing.assert_allclose(fr.shear_angle(x2 - mod.X3), fr.shear_angle(U), atol=1e-12)
    f = mod.internal_force(U, slip=slip)
    np.testing.assert_allclose(mod.internal_force(x2 - mod.X3, slip=slip), f @ R.T, atol=1e-10 * np.abs(f).max())


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_explicit_force_equals_the_model_force(element, backend):
    pytest.importorskip("numba") if backend == "numba" else None
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(bending=True), element=element)
    rng = np.random.default_rng(8)
    U = _sheared(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    kern = ForceKernel(mod, backend=backend)
    f, W = kern(U, energy=True, slip=slip)
    ref = mod.internal_force(U, slip=slip)
    np.testing.assert_allclose(f, ref, atol=1e-10 * np.abs(ref).max())
    e = mod.energies(U, slip=slip)
    assert W == pytest.approx(e["bending"] + e["membrane"], rel=1e-10)


def test_kes_shear_loop_has_width_2hg_and_slips_commit_with_the_bending_frictions():
    """A 2 cm x 2 cm warp-aligned square sheared to +-0.5 deg and back by prescribed displacements (simple shear,
    the KES-FB1 test's small cycle): the friction shear force per width at +-0.5 deg differs by 2 tau0 between the
    loading and unloading branches, and the dissipated energy is the loop's area."""
    m = mesh.rectangle(0.02, 0.02, 5, 5, origin=(0.0, 0.0))
    mat = _material(angle=0.0, ratio=100.0, bending=True)
    mod = model.Model(m, mat, element="RFT6")
    fr = mod.shear_friction
    st = State.initial(mod)
    assert st.slip.shape == (m.n_elements, 3)
    X = mod.X3
    loop = np.radians(np.concatenate([np.linspace(0, 0.5, 11), np.linspace(0.5, -0.5, 41), np.linspace(-0.5, 0.5, 41)]))
    forces = []
    for g in loop:
        U = np.zeros_like(X)
        U[:, 0] = np.tan(g) * X[:, 1]
        forces.append(float(fr.force(U, mod.split_slip(st.slip)[1]).mean()))
        st.commit_slip(mod, U)
    forces = np.array(forces)
    down = forces[11 + 40]  # at -0.5 deg coming down
    up = forces[-1]  # at +0.5 deg going up
    assert up == pytest.approx(fr.tau0, rel=1e-9) and down == pytest.approx(-fr.tau0, rel=1e-9)
    assert st.dissipated > 0
    # a full cycle -0.5 -> +0.5 -> -0.5 deg dissipates A 2 tau0 (2 * 1 deg - 2 * stick range) per element
    y = fr.tau0 / fr.K
    expect_per_cycle = 2 * fr.tau0 * (np.radians(1.0) - 2 * y) * fr.area.sum()
    d0 = st.dissipated
    for g in np.radians(np.concatenate([np.linspace(0.5, -0.5, 41), np.linspace(-0.5, 0.5, 41)])):
        U = np.zeros_like(X)
        U[:, 0] = np.tan(g) * X[:, 1]
        st.commit_slip(mod, U)
    assert st.dissipated - d0 == pytest.approx(expect_per_cycle, rel=2e-2)


def test_the_stable_step_bound_counts_the_stick_stiffness():
    """The guaranteed bound of omega_max (rftstatic.solvers.timestep.element_bound) sees the sticking friction: a
    stick stiffness far above the membrane's (ratio 1e4 x G) raises it, the default barely."""
    from rftstatic.solvers.timestep import element_bound

    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    elastic = model.Model(m, replace(_material(), shear_hysteresis=None), element="RFT6")
    stiff = model.Model(m, _material(ratio=1e4), element="RFT6")
    assert element_bound(stiff) > 2.0 * element_bound(elastic)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_nodal_force_is_the_element_forces_summed(element):
    """The explicit path's sparse-gradient force (ShearFriction.nodal_force) against the element forces (S4)."""
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element=element)
    fr = mod.shear_friction
    rng = np.random.default_rng(9)
    U = _sheared(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    e, fe, _ = fr.evaluate(U, slip)
    W, f = fr.nodal_force(U, slip)
    ref = np.zeros_like(U)
    np.add.at(ref, fr.nodes, fe)
    np.testing.assert_allclose(f, ref, atol=1e-12 * np.abs(ref).max())
    assert W == pytest.approx(e, rel=1e-12)
    np.testing.assert_allclose(fr.shear_angle(U)[:, 0], mod.membrane_strain(U) @ fr.t, atol=1e-15)  # the membrane's eps



def test_newton_takes_the_displacement_iteration_with_shear_hysteresis():
    """MIP Newton cycles across the friction's kink (rftstatic.solvers.newton.mixed_scheme): a model with shear
    hysteresis runs the displacement iteration whatever ``solver.iteration`` says; one without keeps the mixed."""
    from rftstatic.solvers.newton import mixed_scheme

    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    assert not mixed_scheme(model.Model(m, _material()), "mixed")
    assert mixed_scheme(model.Model(m, replace(_material(), shear_hysteresis=None)), "mixed")
    assert not mixed_scheme(model.Model(m, replace(_material(), shear_hysteresis=None)), "displacement")


def _corner_hung(shear):
    """A 4 x 4 cm sheet held at one corner (shear-soft: C_shear 0.5 N/m), with or without shear hysteresis."""
    m = mesh.rectangle(0.04, 0.04, 9, 9)
    clamped = m.nodes_in_box(-1e-9, 0.0051, -1e-9, 0.0051)
    sup = model.Supports(clamped, np.zeros(0, int), np.zeros((m.n_nodes, 3), bool))
    gf = 9.80665e-3
    mat = material.fabric(C_warp=50.0, C_weft=50.0, C_shear=0.5, B_warp=0.083 * gf * 1e-2, B_weft=0.063 * gf * 1e-2,
                          B_twist=0.027 * gf * 1e-2, weight=0.19)
    if shear:
        mat = replace(mat, shear_hysteresis=material.ShearHysteresis(0.01, 10.0))
    return model.Model(m, mat, supports=sup, load=model.gravity_load(m, mat.weight), element="RFT3")


def test_explicit_motion_with_shear_friction_keeps_the_energy_balance():
    """The sheet swinging down from its corner: kinetic + potential + dissipated (damping and the shear friction's
    committed slip, S6) stays constant to the scheme's error, and the friction dissipates."""
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    mod = _corner_hung(True)
    run = run_explicit(mod, ExplicitOptions(t_end=0.15, alpha=2.0, progress=False, sample_every=50))
    h = run.history
    scale = max(np.abs(h["external_work"]).max(), 1e-30)
    assert np.abs(h["total"] - h["total"][0]).max() < 1e-3 * scale  # measured 6.7e-5
    assert run.state.dissipated > 5e-3 * scale  # measured 0.019: the balance fails without the friction's share
    assert np.degrees(np.abs(mod.shear_friction.shear_angle(run.state.U)).max()) > 0.5  # measured 2.2 deg


def test_load_steps_commit_the_shear_slip_and_the_friction_resists():
    """The load steps on the corner-hung sheet: the slip is committed, energy is dissipated, Newton takes the
    displacement iteration, and the far corner droops less than the elastic sheet's."""
    from rftstatic.solvers.load_steps import solve_load_steps
    from rftstatic.solvers.newton import start_state
    from rftstatic.solvers.options import StaticOptions

    out = {}
    for shear in (False, True):
        mod = _corner_hung(shear)
        state = start_state(mod)
        res = solve_load_steps(mod, options=StaticOptions(), state=state)
        assert res.converged
        out[shear] = (res, state, mod)
    far = np.argmax(out[True][2].X3[:, :2].sum(axis=1))
    res, state, mod = out[True]
    assert np.abs(state.slip).max() > 0 and state.dissipated > 0
    assert {s["scheme"] for s in res.load_steps} == {"displacement"}
    assert res.U[far, 2] > out[False][0].U[far, 2]  # measured -2.458 cm against -2.504 cm


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("sewn", [False, True])
def test_compiled_nodal_force_equals_numpy(element, sewn):
    """The compiled loop (rftstatic.element._shear_numba) against the sparse-gradient reference, on both branches
    of (S3), with and without a sewn mesh's reference offsets."""
    pytest.importorskip("numba")
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element=element, kernels="compiled")
    fr = mod.shear_friction
    assert fr.compiled
    rng = np.random.default_rng(11)
    if sewn:
        fr = replace(fr, offset=1e-2 * rng.normal(size=(fr.nodes.shape[1], 3, fr.n_elements)))
    U = _sheared(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    W, f = fr.nodal_force(U, slip)
    W0, f0 = fr.nodal_force_numpy(U, slip)
    assert np.abs(f0).max() > 0 and W0 > 0
    np.testing.assert_allclose(f, f0, atol=1e-12 * np.abs(f0).max())
    assert W == pytest.approx(W0, rel=1e-12)
    assert not model.Model(m, _material(), element=element, kernels="numpy").shear_friction.compiled
    gamma = fr.shear_angle(U)
    np.testing.assert_allclose(gamma, replace(fr, compiled=False).shear_angle(U), atol=1e-12 * np.abs(gamma).max())
