"""The compiled twins of the rounded pedestals (rftstatic.contact.obstacles.pedestal_kernels) against the numpy
methods: the same distance, normal and Hessian at points outside, inside, near the rounded edges, on the round
pedestal's axis and on the square's medial planes; the FD checks of tests/contact/test_obstacles.py run on the
compiled path (their 500 points are above COMPILED_MIN_POINTS)."""

import numpy as np
import pytest

from rftstatic.compiled import numba_available
from rftstatic.contact.obstacles import RoundPedestal, SquarePedestal, pedestal_kernels

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")

PEDESTALS = {
    "square": SquarePedestal([0.01, 0.02], 0.05, top_z=0.0, edge_radius=0.005),
    "rect-finite": SquarePedestal([0.0, 0.0], (0.05, 0.03), top_z=0.01, edge_radius=0.004, height=0.06),
    "sharp": SquarePedestal([0.0, 0.0], 0.05, top_z=0.0, edge_radius=0.0),
    "round": RoundPedestal([0.01, -0.01], 0.1, top_z=0.0, edge_radius=0.005),
    "round-finite": RoundPedestal([0.0, 0.0], 0.04, top_z=0.02, edge_radius=0.006, height=0.05),
}


def _points(ob, rng, n=2000):
    """Points in a box around the pedestal, some near its surface, on its axis / centre lines and on the
    diagonal medial planes, [m]."""
    lo, hi = ob.bounding_box()
    lo = np.where(np.isfinite(lo), lo, -0.15) - 0.03
    hi = np.where(np.isfinite(hi), hi, 0.15) + 0.03
    x = rng.uniform(lo, hi, size=(n, 3))
    surf = ob.closest_point(x[:300])
    x[300:600] = surf + rng.uniform(-1e-3, 1e-3, (300, 1)) * ob.signed_distance(surf)[1]
    x[600:620, :2] = ob.centre_xy  # the axis: one-sided choices
    x[620:640, 1] = x[620:640, 0] - ob.centre_xy[0] + ob.centre_xy[1]  # a medial (diagonal) plane
    return x


def _both(ob, x, monkeypatch):
    out = []
    for threshold in (10 ** 12, 1):
        monkeypatch.setattr(pedestal_kernels, "COMPILED_MIN_POINTS", threshold)
        out.append((*ob.signed_distance(x), ob.normal_gradient(x)))
    return out


@pytest.mark.parametrize("name", list(PEDESTALS))
def test_compiled_twin_equals_numpy(name, monkeypatch):
    ob = PEDESTALS[name]
    x = _points(ob, np.random.default_rng(3))
    (phi0, n0, H0), (phi1, n1, H1) = _both(ob, x, monkeypatch)
    scale = max(1.0, float(np.abs(H0).max()))
    np.testing.assert_allclose(phi1, phi0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(n1, n0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(H1 / scale, H0 / scale, rtol=0, atol=1e-13)
    assert np.any(phi0 < 0) and np.any(phi0 > 0) and np.any(np.abs(H0).sum(axis=(1, 2)) > 0)


def test_small_calls_stay_numpy_large_ones_compiled():
    assert not pedestal_kernels.compiled_for(pedestal_kernels.COMPILED_MIN_POINTS - 1)
    assert pedestal_kernels.compiled_for(pedestal_kernels.COMPILED_MIN_POINTS)


def test_compiled_normal_is_gradient_and_hessian_is_its_jacobian(monkeypatch):
    """Central differences of the compiled phi and normal (every call above the threshold) [m]."""
    monkeypatch.setattr(pedestal_kernels, "COMPILED_MIN_POINTS", 1)
    rng = np.random.default_rng(5)
    for ob in PEDESTALS.values():
        x = _points(ob, rng, 700)
        phi, n = ob.signed_distance(x)
        H = ob.normal_gradient(x)
        h = 1e-6
        fd_n = np.stack([(ob.signed_distance(x + h * e)[0] - ob.signed_distance(x - h * e)[0]) / (2 * h)
                         for e in np.eye(3)], axis=1)
        fd_H = np.stack([(ob.signed_distance(x + h * e)[1] - ob.signed_distance(x - h * e)[1]) / (2 * h)
                         for e in np.eye(3)], axis=2)
        # away from the kinks (medial planes, region boundaries within h, the sharp box's edges)
        tol_H = 1e-3 * (1 + np.abs(H).max())
        smooth = (np.abs(fd_n - n).max(axis=1) < 1e-5) & (np.abs(fd_H - H).max(axis=(1, 2)) < tol_H)
        assert smooth.mean() > 0.9
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
