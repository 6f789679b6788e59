"""Shear hysteresis that grows with the shear angle (KES 2HG5; rftstatic.element.shear_threshold, S7-S10): the law's
derivatives, the element's on both branches with the growing threshold, rigid motion, compiled == numpy, the KES loop
cycled to +-8 deg (width 2HG at 0.5 deg, 2HG5 at 5 deg), the explicit energy balance, and the element without 2HG5
unchanged to the bit against numbers stored from the code before the growth."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element.shear_threshold import KES_ANGLES, growing_friction_law, max_slope, threshold
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from rftstatic.model.state import State
from tests.element.test_shear_friction import (TAU0, _corner_hung, _material, _mixed_slip, _sheared,
                                               friction_derivative_errors)

TAU5 = 2.5 * TAU0  # N/m: 2HG5 = 2.5 x 2HG
GA, GB = KES_ANGLES


def _grown(angle=0.3, ratio=10.0, bending=False, tau5=TAU5):
    base = _material(angle, ratio, bending)
    return replace(base, shear_hysteresis=material.ShearHysteresis(TAU0, ratio, tau5))


def _ramped(mod, rng, scale=0.035):
    """A displacement whose elements' shear angles spread over the ramp of (S7), both signs."""
    X = mod.X3
    U = 0.01 * rng.normal(size=X.shape)
    U[:, 0] += scale * X[:, 1] * np.sign(X[:, 0])
    U[:, 2] += 0.3 * X[:, 0] ** 2 - 0.2 * X[:, 0] * X[:, 1]
    return U


def test_threshold_is_2hg_then_2hg5_and_c1():
    g = np.array([0.0, GA / 2, GA, GB, 2 * GB, -GA, -GB, -0.2])
    tau, d1, d2 = threshold(g, 1.0, 2.5, GA, GB)
    np.testing.assert_array_equal(tau, [1.0, 1.0, 1.0, 2.5, 2.5, 1.0, 2.5, 2.5])
    np.testing.assert_array_equal(d1, 0.0)  # flat at both readings and beyond
    assert np.degrees(np.arctan(GA)) == pytest.approx(0.5, rel=1e-12) and np.degrees(np.arctan(GB)) == pytest.approx(5)
    gm = np.linspace(-0.12, 0.12, 2001)
    h = 1e-7
    t, d1, d2 = threshold(gm, 1.0, 2.5, GA, GB)
    tp, d1p, _ = threshold(gm + h, 1.0, 2.5, GA, GB)
    tm, d1m, _ = threshold(gm - h, 1.0, 2.5, GA, GB)
    np.testing.assert_allclose((tp - tm) / (2 * h), d1, atol=1e-6 * np.abs(d1).max())
    inside = np.abs(np.abs(np.abs(gm) - (GA + GB) / 2) - (GB - GA) / 2) > 1e-5  # away from tau_0'' jumps
    np.testing.assert_allclose(((d1p - d1m) / (2 * h))[inside], d2[inside], atol=1e-5 * np.abs(d2).max())
    assert np.abs(d1).max() == pytest.approx(max_slope(1.0, 2.5, GA, GB), rel=1e-5)


def test_law_force_and_slope_are_derivatives_of_its_potential():
    """(S9) = d(S8)/dgamma and (S10) = d(S9)/dgamma with the committed slip held, on both branches, loading (|gamma|
    growing) and unloading, inside and outside the ramp."""
    rng = np.random.default_rng(1)
    K, ta, tb = 400.0, 0.5, 1.25
    g = rng.uniform(-0.12, 0.12, 4000)
    s = g - rng.uniform(-3.0, 3.0, g.size) * threshold(g, ta, tb, GA, GB)[0] / K
    h = 1e-8
    psi, f, k, tau = growing_friction_law(g - s, g, K, ta, tb, GA, GB)
    pp, fp, _, _ = growing_friction_law(g + h - s, g + h, K, ta, tb, GA, GB)
    pm, fm, _, _ = growing_friction_law(g - h - s, g - h, K, ta, tb, GA, GB)
    slip = np.abs(g - s) > tau / K
    ramp = (np.abs(g) > GA) & (np.abs(g) < GB)
    assert 0.3 < slip.mean() < 0.8 and (slip & ramp & (np.sign(g - s) != np.sign(g))).sum() > 100
    np.testing.assert_allclose((pp - pm) / (2 * h), f, atol=1e-6 * np.abs(f).max())
    # central differences across a kink (stick/slip, the ramp's ends) are not derivatives: leave those points out
    tp, tm = threshold(g + h, ta, tb, GA, GB)[0], threshold(g - h, ta, tb, GA, GB)[0]
    smooth = (slip == (np.abs(g + h - s) > tp / K)) & (slip == (np.abs(g - h - s) > tm / K))
    smooth &= np.abs(np.abs(g) - GA) > 2 * h
    smooth &= np.abs(np.abs(g) - GB) > 2 * h
    np.testing.assert_allclose(((fp - fm) / (2 * h))[smooth], k[smooth], atol=1e-5 * np.abs(k).max())
    assert (k[slip & ramp] < 0).any() and (k[slip & ramp] > 0).any()  # unloading falls, loading rises


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_element_force_and_tangent_are_derivatives_with_the_growing_threshold(element):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _grown(), element=element)
    fr = mod.shear_friction
    rng = np.random.default_rng(4)
    U = _ramped(mod, rng)
    gamma = fr.shear_angle(U)
    slip = gamma + fr.threshold(gamma) / fr.K * rng.uniform(-2.0, 2.0, size=gamma.shape)
    e = gamma - slip
    sliding = np.abs(e) > fr.threshold(gamma) / fr.K
    ramp = (np.abs(gamma) > GA) & (np.abs(gamma) < GB)
    assert 0.2 < sliding.mean() < 0.8 and (sliding & ramp).sum() >= 5  # the growth acts on slipping elements
    err_f, err_k = friction_derivative_errors(fr, U, slip, rng, 16)
    assert err_f < 1e-6 and err_k < 1e-6
    assert (fr._law(gamma, slip)[2] < 0).any()  # unloading slips in the ramp: psi'' < 0 (S10)
    # the psd tangent: positive semi-definite although psi'' < 0 on the unloading slips
    kp, n = fr.evaluate(U, slip, tangent=True, psd=True)[2], 3 * fr.nodes.shape[1]
    k = kp.reshape(len(kp), n, n)
    assert np.linalg.eigvalsh(0.5 * (k + k.transpose(0, 2, 1))).min() > -1e-12 * np.abs(k).max()


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_rigid_motion_with_the_growing_threshold(element):
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _grown(), element=element)
    fr = mod.shear_friction
    rng = np.random.default_rng(7)
    R = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
    U = _ramped(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    x2 = mod.positions(U) @ R.T + np.array([0.3, -2.0, 5.0])
    e, fe, _ = fr.evaluate(U, slip)
    e2, fe2, _ = fr.evaluate(x2 - mod.X3, slip)
    assert e2 == pytest.approx(e, rel=1e-12)
    np.testing.assert_allclose(fe2, fe @ R.T, atol=1e-12 * np.abs(fe).max())
    turned = mod.X3 @ R.T - mod.X3
    e0, f0, _ = fr.evaluate(turned, fr.initial_slip())
    assert abs(e0) < 1e-12 * TAU0 * fr.area.sum() and np.abs(f0).max() < 1e-12 * np.abs(fe).max()


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_compiled_nodal_force_equals_numpy_with_the_growing_threshold(element):
    pytest.importorskip("numba")
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    fr = model.Model(m, _grown(), element=element, kernels="compiled").shear_friction
    assert fr.compiled and fr.tau5 == TAU5
    rng = np.random.default_rng(11)
    mod = model.Model(m, _grown(), element=element)
    U = _ramped(mod, rng)
    gamma = fr.shear_angle(U)
    slip = gamma + fr.threshold(gamma) / fr.K * rng.uniform(-2.0, 2.0, size=gamma.shape)
    W, f = fr.nodal_force(U, slip)
    W0, f0 = fr.nodal_force_numpy(U, slip)
    np.testing.assert_allclose(f, f0, atol=1e-12 * np.abs(f0).max())
    assert W == pytest.approx(W0, rel=1e-12)
    ref = np.zeros_like(U)
    np.add.at(ref, fr.nodes, fr.evaluate(U, slip)[1])
    np.testing.assert_allclose(f0, ref, atol=1e-12 * np.abs(ref).max())
    # with the same slips and a constant threshold the forces differ: the growth reaches the compiled loop
    assert np.abs(replace(fr, tau5=None).nodal_force(U, slip)[1] - f).max() > 1e-3 * np.abs(f).max()


def _kes_cycle(mod, st, angles):
    """Simple shear of the warp-aligned square through ``angles`` [deg], committing at each: the mean friction force
    per width [N/m] at each angle."""
    fr, X = mod.shear_friction, mod.X3
    out = []
    for a in angles:
        U = np.zeros_like(X)
        U[:, 0] = np.tan(np.radians(a)) * X[:, 1]
        out.append(float(fr.force(U, mod.split_slip(st.slip)[1]).mean()))
        st.commit_slip(mod, U)
    return np.array(out)


def test_kes_loop_to_8_deg_has_width_2hg_at_half_a_degree_and_2hg5_at_5():
    """The KES-FB1 cycle (simple shear to +8, -8, +8 deg in steps of 0.05 deg): on the second cycle the loop's width
    (loading minus unloading branch at the same angle) is 2HG = 2 tau0 at +-0.5 deg and 2HG5 = 2 tau5 at +-5 deg, and
    the dissipation per cycle is the area between the branches (the integral of the width over the angle)."""
    m = mesh.rectangle(0.02, 0.02, 5, 5, origin=(0.0, 0.0))
    mod = model.Model(m, _grown(angle=0.0, ratio=100.0), element="RFT6")
    st = State.initial(mod)
    step = 0.05
    up = np.arange(-8.0, 8.0 + step / 2, step)
    _kes_cycle(mod, st, np.arange(0.0, 8.0 + step / 2, step))
    _kes_cycle(mod, st, up[::-1])
    d0 = st.dissipated
    f_up = _kes_cycle(mod, st, up)
    f_down = _kes_cycle(mod, st, up[::-1])[::-1]
    width = f_up - f_down
    for a, tau in ((0.5, TAU0), (5.0, TAU5)):
        for sign in (1, -1):
            i = int(np.argmin(np.abs(up - sign * a)))
            assert width[i] == pytest.approx(2 * tau, rel=1e-6), (sign * a, width[i] / 2)
    # between the readings the width follows 2 tau_0(gamma) of (S7), to the variational term's O(step)
    fr = mod.shear_friction
    mid = int(np.argmin(np.abs(up - 2.75)))
    assert width[mid] == pytest.approx(2 * fr.threshold(np.tan(np.radians(2.75))), rel=1e-3)  # measured 3e-4
    area = np.sum(0.5 * (width[1:] + width[:-1]) * np.diff(np.tan(np.radians(up)))) * fr.area.sum()
    assert st.dissipated - d0 == pytest.approx(area, rel=1e-3)  # measured 5e-5


def test_explicit_motion_with_the_growing_threshold_keeps_the_energy_balance():
    """The corner-hung sheet of test_shear_friction with 2HG5 = 3 x 2HG: kinetic + potential + dissipated constant to
    the scheme's error, the shear reaching into the ramp."""
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    base = _corner_hung(True)
    sh = base.material.shear_hysteresis
    mat = replace(base.material, shear_hysteresis=replace(sh, tau5=3.0 * sh.tau0))
    mod = model.Model(base.mesh, mat, supports=base.supports, load=base.load, element="RFT3")
    assert mod.shear_friction.tau5 == pytest.approx(0.03)
    run = run_explicit(mod, ExplicitOptions(t_end=0.15, alpha=2.0, progress=False, sample_every=50))
    h = run.history
    scale = max(np.abs(h["external_work"]).max(), 1e-30)
    assert np.abs(h["total"] - h["total"][0]).max() < 1e-3 * scale  # measured 6.8e-5 (6.7e-5 without 2HG5)
    assert run.state.dissipated > 5e-3 * scale  # measured 0.0191 (0.0187 without)
    assert np.abs(mod.shear_friction.shear_angle(run.state.U)).max() > 1.5 * GA  # measured 2.2 deg


def test_the_stable_step_bound_counts_the_growth():
    from rftstatic.solvers.timestep import element_bound

    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    plain = model.Model(m, _material(), element="RFT6")
    fr = plain.shear_friction
    assert fr.stiffest() is fr
    steep = model.Model(m, _grown(ratio=1.0, tau5=400.0 * TAU0), element="RFT6")
    assert steep.shear_friction.stiffest().K == pytest.approx(steep.shear_friction.K + 2 * max_slope(
        TAU0, 400.0 * TAU0, GA, GB), rel=1e-12)
    assert element_bound(steep) > element_bound(model.Model(m, _material(ratio=1.0), element="RFT6"))


def _fingerprint(a):
    a = np.asarray(a, float)
    return float(np.sum(a.ravel() * np.cos(np.arange(a.size))))


STORED = {  # the code before 2HG5 (commit 78b55c8), on the inputs of test_without_2hg5_nothing_changes
    ("RFT3", "numpy"): (0.0004404959384308498, 0.012217629505273518, 95.88021422110559, 96.02802701928734,
                        0.0004404959384308498, 0.020868263925361275, -1.8853475183763653, 0.00019106909918959448,
                        0.49295473381377647, 377.7921034346637),
    ("RFT3", "compiled"): (0.0004404959384308497, 0.012217629505273449, 95.88021422110559, 96.02802701928734,
                           0.00044049593843084985, 0.020868263925361268, -1.8853475183763655, 0.0001910690991895946,
                           0.49295473381377647, 377.7921034346637),
    ("RFT6", "numpy"): (0.00044049593843085023, -0.0036034214748157448, 46.052584501783535, 46.303587357455626,
                        0.00044049593843085023, 0.014081346971539656, -1.2496666002752048, 0.00019106909918959492,
                        0.4929547338137765, 405.39944122289893),
    ("RFT6", "compiled"): (0.00044049593843084985, -0.003603421474815849, 46.05258450178354, 46.30358735745562,
                           0.00044049593843085034, 0.014081346971539661, -1.2496666002752048, 0.00019106909918959505,
                           0.4929547338137765, 405.39944122289893),
}
"""Energy, fingerprints of the element forces, tangent and psd tangent, the nodal force's energy and forces, the
committed slip, the dissipation, the friction force and the stable-step bound, computed by the test below at commit
78b55c8 (the full arrays of that code and of the growth's, on these inputs, were also compared: equal to the bit)."""


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("kernels", ["numpy", "compiled"])
def test_without_2hg5_nothing_changes(element, kernels):
    """Without 2HG5 the element computes what it computed before the growth was built (numbers stored from commit
    78b55c8; equal to the bit on the machine they were made on, here compared to 4e-16 relative)."""
    from rftstatic.solvers.timestep import element_bound

    if kernels == "compiled":
        pytest.importorskip("numba")
    m = mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5))
    mod = model.Model(m, _material(), element=element, kernels=kernels)
    fr = mod.shear_friction
    assert fr.tau5 is None
    rng = np.random.default_rng(4)
    U = _sheared(mod, rng)
    slip = _mixed_slip(mod, U, rng)
    e, fe, ke = fr.evaluate(U, slip, tangent=True)
    kp = fr.evaluate(U, slip, tangent=True, psd=True)[2]
    W, f = fr.nodal_force(U, slip)
    s, d = fr.commit(U, slip)
    got = (e, _fingerprint(fe), _fingerprint(ke), _fingerprint(kp), W, _fingerprint(f), _fingerprint(s), d,
           _fingerprint(fr.force(U, slip)), element_bound(mod))
    for g, want in zip(got, STORED[element, kernels]):
        assert g == pytest.approx(want, rel=4e-16, abs=0.0)
