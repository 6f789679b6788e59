"""Nonlinear (softening) bending (rftstatic.element.nonlinear_bending): the scalar law, derivatives of the patch
term by finite differences with both branches, invariance, the explicit force, and the strip's moment."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element.nonlinear_bending import floor_curvature, softening
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from tests.element.test_hysteresis import derivative_errors

K2 = (-0.006, -0.003)  # [N m^2]: kappa_f = 0.8 B / (2 |k2|) = 2.0 and 2.67 /m for B = 0.03, 0.02 N m


def _material(angle=0.3, k2=K2, floor=0.2, hysteresis=False):
    base = material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, B_warp=0.03, B_weft=0.02, B_twist=0.01,
                           weight=0.1, warp_angle=angle)
    h = material.BendingHysteresis(0.004, 0.003, 10.0) if hysteresis else None
    return replace(base, nonlinear_bending=material.NonlinearBending(*k2, floor), hysteresis=h)


def _bent(mod, rng):
    X = mod.X3
    U = 0.12 * rng.normal(size=X.shape)
    U[:, 2] += 0.9 * X[:, 0] ** 2 - 0.6 * X[:, 0] * X[:, 1]
    return U


def test_the_law_is_n1_up_to_the_floor_curvature_and_slope_phi_b_beyond():
    B, k2, phi = np.array([2.0, 1.0]), np.array([-0.5, -0.1]), 0.2
    kf = floor_curvature(B, k2, phi)
    np.testing.assert_allclose(kf, [1.6, 4.0])  # (1 - phi) B / (2 |k2|)
    k = np.linspace(-12.0, 12.0, 4801)[:, None] * np.ones(2)
    psi, m, dm = softening(k, B, k2, phi)
    inside = np.abs(k) <= kf
    np.testing.assert_allclose(m[inside], (k2 * k * np.abs(k))[inside], rtol=1e-14)  # (N1)
    slope = B + dm
    assert slope.min() == pytest.approx(phi * B.min()) and np.all(slope >= phi * B - 1e-14)
    np.testing.assert_allclose(slope[~inside], (phi * B * np.ones_like(k))[~inside])
    h = k[1, 0] - k[0, 0]
    assert np.abs(np.gradient(psi, h, axis=0) - m)[1:-1].max() < 1e-4  # psi' = m
    assert np.abs(np.gradient(m, h, axis=0) - dm)[1:-1].max() < 2 * h * np.abs(k2).max() + 1e-12  # m' = psi''
    # at (N1)'s own peak kappa_0 = B / (2 |k2|) the floor law lies phi^2 of that peak moment above it
    k0 = B / (2 * np.abs(k2))
    M = B * k0 + softening(k0[None], B, k2, phi)[1][0]
    np.testing.assert_allclose(M / (B * k0 / 2) - 1.0, phi ** 2)
    # no k2: no term
    assert not np.any(softening(k, B, np.zeros(2), phi)[0])


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_force_and_tangent_are_derivatives_of_the_energy_on_both_branches(element):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element=element, load=model.gravity_load(m, 0.1))
    rng = np.random.default_rng(4)
    U = _bent(mod, rng)
    term = mod.bending_softening
    floor = term.on_floor(U, mod.positions(U))
    assert 0.2 < floor.mean() < 0.8  # the k2 branch and the floor branch of (N3) both exercised
    err_f, err_k, r, f, K = derivative_errors(mod, U, 0.6, rng)
    assert err_f < 1e-6 * np.abs(r).max()
    assert err_k < 1e-6 * np.abs(K).max()
    np.testing.assert_allclose(f - 0.6 * mod.load, r, atol=1e-12 * np.abs(r).max())
    # the term itself (not only the sum with K_b) by finite differences of its own energy
    x = mod.positions(U)
    _, fe, _ = term.evaluate(U, x)
    h = 1e-7
    for e, a, i in ((3, 4, 2), (11, 0, 0), (17, 5, 1)):
        n = term.nodes[e, a]
        Up, Um = U.copy(), U.copy()
        Up[n, i] += h
        Um[n, i] -= h
        fd = (term.evaluate(Up, mod.positions(Up))[0] - term.evaluate(Um, mod.positions(Um))[0]) / (2 * h)
        full = np.zeros_like(U)
        np.add.at(full, term.nodes, fe)
        assert fd == pytest.approx(full[n, i], rel=1e-6, abs=1e-9 * np.abs(fe).max())


def test_with_hysteresis_both_terms_add():
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    both = model.Model(m, _material(hysteresis=True), membrane=False)
    soft = model.Model(m, _material(), membrane=False)
    hyst = model.Model(m, replace(_material(hysteresis=True), nonlinear_bending=None), membrane=False)
    U = _bent(both, np.random.default_rng(5))
    f = both.internal_force(U)
    np.testing.assert_allclose(f, soft.internal_force(U) + hyst.internal_force(U) - both.Kb @ U,
                               atol=1e-12 * np.abs(f).max())
    e = both.energies(U)["bending"]
    assert e == pytest.approx(soft.energies(U)["bending"] + hyst.energies(U)["bending"]
                              - 0.5 * float(np.einsum("ni,ni->", U, both.Kb @ U)), rel=1e-12)


def test_psd_tangent_drops_the_softening_and_stays_positive():
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), membrane=False)
    U = _bent(mod, np.random.default_rng(6))
    _, _, ke = mod.bending_softening.evaluate(U, mod.positions(U), tangent=True, psd=True)
    assert not np.any(ke)
    _, K = mod.tangent(U, psd=True)
    assert np.linalg.eigvalsh(K.toarray()).min() > -1e-10 * abs(K).max()


def test_zero_force_under_rigid_motion_and_the_force_turns_with_the_body():
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), membrane=False)
    term = mod.bending_softening
    R = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
    shift = np.array([0.3, -2.0, 5.0])
    x = mod.X3 @ R.T + shift  # the flat sheet moved rigidly: no curvature, no energy, no force
    W, fe, _ = term.evaluate(x - mod.X3, x)
    assert abs(W) < 1e-30 and np.abs(fe).max() < 1e-14
    U = _bent(mod, np.random.default_rng(7))
    x = mod.positions(U)
    x2 = x @ R.T + shift
    U2 = x2 - mod.X3
    np.testing.assert_allclose(term.curvature(U2, x2), term.curvature(U, x), atol=1e-12)
    f = mod.internal_force(U) - mod.Kb @ U
    f2 = mod.internal_force(U2) - mod.Kb @ U2
    np.testing.assert_allclose(f2, f @ R.T, atol=1e-12 * np.abs(f).max())


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_explicit_force_equals_the_model_internal_force(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    from rftstatic.element.explicit_force import ForceKernel

    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(hysteresis=True), element="RFT6")
    U = _bent(mod, np.random.default_rng(8))
    f, W = ForceKernel(mod, backend=backend)(U, energy=True)
    ref = mod.internal_force(U)
    np.testing.assert_allclose(f, ref, atol=1e-10 * np.abs(ref).max())
    e = mod.energies(U)
    assert W == pytest.approx(e["bending"] + e["membrane"], rel=1e-10)


def _cylinder(X3, kappa):
    x = X3.copy()
    x[:, 0] = np.sin(kappa * X3[:, 0]) / kappa
    x[:, 2] = (1.0 - np.cos(kappa * X3[:, 0])) / kappa
    return x


def test_a_strip_bent_on_a_cylinder_carries_the_moment_of_the_law():
    """Interior patches of a warp strip on a cylinder: the term's moment is (N3) less B kappa at the RF curvature,
    below and above the floor curvature."""
    m = mesh.rectangle(0.01, 0.005, 21, 5)
    mat = _material(angle=0.0, k2=(-0.02 * 0.03, -0.01 * 0.02))  # kappa_f = 20 /m (warp)
    mod = model.Model(m, mat, membrane=False)
    term = mod.bending_softening
    interior = mod.patches.has_opposite.all(axis=1)
    for kappa in (8.0, 45.0):
        U = _cylinder(mod.X3, kappa) - mod.X3
        x = mod.positions(U)
        km = term.curvature(U, x)[interior, 0]
        np.testing.assert_allclose(km, kappa, rtol=2e-3)
        Mk = term.moment(U, x)[interior, 0]
        ref = softening(np.stack([km, km], 1), term.B, term.k2, term.floor)[1][:, 0]
        np.testing.assert_allclose(Mk, ref, rtol=1e-12)
        assert np.all(term.on_floor(U, x)[interior, 0] == (kappa > term.kappa_floor[0]))


def test_material_refuses_stiffening_and_non_finite_values():
    with pytest.raises(ValueError, match="k2_warp"):
        material.NonlinearBending(1e-6, -1e-6)
    with pytest.raises(ValueError, match="k2_weft"):
        material.NonlinearBending(-1e-6, float("nan"))
    with pytest.raises(ValueError, match="floor"):
        material.NonlinearBending(-1e-6, -1e-6, 1.0)
    mod = model.Model(mesh.rectangle(1.0, 1.0, 3, 3), _material(k2=(0.0, 0.0)))
    assert mod.bending_softening is None
