"""The material-axes curvature terms together (rftstatic.element.axis_terms): the compiled kernels
(rftstatic.element._axis_numba) against the numpy reference, their derivatives by finite differences, rigid
motion, and the explicit force."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element.axis_terms import AxisTerms
from rftstatic.element.hysteresis import friction_law, friction_yield
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from tests.element.test_hysteresis import derivative_errors

pytest.importorskip("numba")

TOL = 1e-12
"""Compiled against numpy: largest difference over the largest entry (the sums run in another order)."""

TERMS = {"friction": (True, False), "softening": (False, True), "both": (True, True)}


def _material(friction=True, softening=True):
    base = material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, B_warp=0.03, B_weft=0.02, B_twist=0.01,
                           weight=0.1, warp_angle=0.3)
    return replace(base, nonlinear_bending=material.NonlinearBending(-0.006, -0.003, 0.2) if softening else None,
                   hysteresis=material.BendingHysteresis(0.004, 0.003, 10.0) if friction else None)


def _models(terms, element="RFT6", membrane=False):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mat = _material(*TERMS[terms])
    load = model.gravity_load(m, 0.1)
    return tuple(model.Model(m, mat, element=element, membrane=membrane, load=load, kernels=k)
                 for k in ("numpy", "compiled"))


def _state(mod, rng):
    """A bent sheet with both branches of each law in use, and a committed slip leaving about half the
    element-directions sticking (None without friction)."""
    X = mod.X3
    U = 0.12 * rng.normal(size=X.shape)
    U[:, 2] += 0.9 * X[:, 0] ** 2 - 0.6 * X[:, 0] * X[:, 1]
    if mod.bending_friction is None:
        return U, None
    km = mod.axis_terms.curvature(U, mod.positions(U))
    return U, km + mod.bending_friction.y * rng.uniform(-2.0, 2.0, size=km.shape)


def _close(a, b):
    np.testing.assert_allclose(a, b, rtol=0, atol=TOL * np.abs(a).max())


@pytest.mark.parametrize("terms", TERMS)
def test_compiled_terms_equal_the_numpy_reference(terms):
    ref, comp = _models(terms)
    assert comp.axis_terms.backend == "numba" and ref.axis_terms.backend == "numpy"
    U, slip = _state(ref, np.random.default_rng(2))
    x = ref.positions(U)
    a, b = ref.axis_terms, comp.axis_terms
    _close(a.curvature(U, x), b.curvature(U, x))
    fa, fb = np.zeros_like(U), np.zeros_like(U)
    Wa, Wb = a.add_forces(U, x, fa, slip), b.add_forces(U, x, fb, slip)
    assert Wb == pytest.approx(Wa, rel=TOL) and b.energy(U, x, slip) == pytest.approx(Wa, rel=TOL)
    _close(fa, fb)
    for psd in (False, True):
        Wa, fea, kea = a.evaluate(U, x, slip, tangent=True, psd=psd)
        Wb, feb, keb = b.evaluate(U, x, slip, tangent=True, psd=psd)
        assert Wb == pytest.approx(Wa, rel=TOL)
        _close(fea, feb)
        _close(kea, keb)
    for psd in (False, True):  # straight into the sparse values, as Model.tangent does
        da, db = np.zeros(ref.plan.nnz), np.zeros(ref.plan.nnz)
        fea = a.add_tangents(U, x, ref._patch_map, da, slip, psd=psd)
        feb = b.add_tangents(U, x, comp._patch_map, db, slip, psd=psd)
        _close(fea, feb)
        _close(da, db)
        _close(da, np.bincount(ref._patch_map.ravel(), a.evaluate(U, x, slip, tangent=True, psd=psd)[2].ravel(),
                               minlength=ref.plan.nnz))
    if slip is not None:
        (sa, da), (sb, db) = a.commit(U, x, slip), b.commit(U, x, slip)
        _close(sa, sb)
        assert db == pytest.approx(da, rel=TOL) and da > 0


@pytest.mark.parametrize("terms", TERMS)
@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_compiled_force_and_tangent_are_derivatives_of_the_energy(terms, element):
    _, mod = _models(terms, element, membrane=True)
    rng = np.random.default_rng(4)
    U, slip = _state(mod, rng)
    x = mod.positions(U)
    if mod.bending_softening is not None:
        assert 0.2 < mod.bending_softening.on_floor(U, x).mean() < 0.8  # both branches of (N3)
    if slip is not None:
        stick = np.abs(mod.axis_terms.curvature(U, x) - slip) <= mod.bending_friction.y
        assert 0.2 < stick.mean() < 0.8  # both branches of (H2)
    kw = {} if slip is None else {"slip": slip}
    err_f, err_k, r, f, K = derivative_errors(mod, U, 0.6, rng, **kw)
    assert err_f < 1e-6 * np.abs(r).max()
    assert err_k < 1e-6 * np.abs(K).max()


def test_compiled_psd_tangent_is_positive_semi_definite():
    _, mod = _models("both")
    U, slip = _state(mod, np.random.default_rng(6))
    _, _, ke = mod.axis_terms.evaluate(U, mod.positions(U), slip, tangent=True, psd=True)
    k = ke.reshape(len(ke), 18, 18)
    assert np.abs(k - k.transpose(0, 2, 1)).max() < 1e-14 * np.abs(k).max()
    assert np.linalg.eigvalsh(k).min() > -1e-12 * np.abs(k).max()


def test_compiled_force_is_zero_under_rigid_motion_and_turns_with_the_body():
    _, mod = _models("both")
    terms = mod.axis_terms
    R = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
    shift = np.array([0.3, -2.0, 5.0])
    U, slip = _state(mod, np.random.default_rng(7))
    x = mod.positions(U)
    x2 = x @ R.T + shift
    f, f2 = np.zeros_like(x), np.zeros_like(x)
    W, W2 = terms.add_forces(U, x, f, slip), terms.add_forces(x2 - mod.X3, x2, f2, slip)
    assert W2 == pytest.approx(W, rel=1e-12)
    np.testing.assert_allclose(f2, f @ R.T, atol=1e-12 * np.abs(f).max())
    x = mod.X3 @ R.T + shift  # the flat sheet moved rigidly: no curvature, no energy, no force (round-off)
    f0 = np.zeros_like(x)
    W0 = terms.add_forces(x - mod.X3, x, f0, np.zeros_like(slip))
    assert abs(W0) < 1e-12 * abs(W) and np.abs(f0).max() < 1e-12 * np.abs(f).max()


def test_explicit_force_uses_the_compiled_terms():
    from rftstatic.element.explicit_force import ForceKernel

    ref, comp = _models("both", membrane=True)
    U, slip = _state(ref, np.random.default_rng(8))
    kern = ForceKernel(comp, backend="numba")
    assert kern.axis_terms.backend == "numba"
    f, W = kern(U, energy=True, slip=slip)
    _close(ref.internal_force(U, slip=slip), f)
    E = ref.energies(U, slip=slip)
    assert W == pytest.approx(E["bending"] + E["membrane"] + E["contact"] + E["self_contact"], rel=1e-12)


def test_the_friction_law_is_h3_on_both_branches():
    K, M0 = np.array([2.0, 3.0]), np.array([0.5, 0.3])
    y = friction_yield(K, M0)
    e = np.array([[0.1, -0.05], [0.4, -0.2], [-0.3, 0.11]])
    psi, m, dm = friction_law(e, K, M0, y)
    stick = np.abs(e) <= y
    np.testing.assert_allclose(psi, np.where(stick, 0.5 * K * e * e, M0 * np.abs(e) - 0.5 * M0 * y), rtol=1e-14)
    np.testing.assert_allclose(m, np.clip(K * e, -M0, M0), rtol=0)
    np.testing.assert_array_equal(dm, np.where(stick, K, 0.0))
    assert stick.any() and not stick.all()


def test_compiled_loops_are_named_after_the_laws_code():
    """numba keys a cache entry on its function's own file: the loops carry a hash of the laws (other files)."""
    from rftstatic.element import _axis_numba as nb_terms

    for f in (nb_terms.add_forces, nb_terms.tangents, nb_terms.curvatures):
        assert f.py_func.__qualname__.endswith("_" + nb_terms.LAW_KEY)
    assert len(nb_terms.LAW_KEY) == 12


def test_backends_are_checked():
    _, mod = _models("both")
    with pytest.raises(ValueError, match="backend"):
        AxisTerms(mod.bending_friction, None, backend="fortran")
    with pytest.raises(ValueError, match="friction or a softening"):
        AxisTerms(None, None)
