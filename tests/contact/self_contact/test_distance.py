"""Self-contact distances: finite-difference gradient and Hessian of every feature, the distance
against brute-force sampling of the two elements, invariance under rigid motion."""

import numpy as np
import pytest

from rftstatic.contact.self_contact.distance import (edge_edge, edge_edge_distance2, point_triangle,
                                                     point_triangle_distance2)

pytestmark = pytest.mark.usefixtures("backend")

TRI = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _pt_configs():
    """Points over the face, beside each edge and beyond each vertex, slightly perturbed."""
    rng = np.random.default_rng(0)
    pts = [[0.2, 0.3, 0.4], [0.6, 0.6, 0.3], [0.5, -0.4, 0.2], [-0.3, 0.5, -0.3], [-0.4, -0.3, 0.2],
           [1.5, -0.2, 0.1], [-0.2, 1.4, 0.3], [0.3, 0.3, -0.7]]
    out = []
    for p in pts:
        x = np.vstack([p, TRI]) + 0.05 * rng.standard_normal((4, 3))
        out.append(x)
    return np.array(out)


def _ee_configs():
    rng = np.random.default_rng(1)
    base = [
        [[0, 0, 0], [1, 0, 0], [0.5, -0.5, 0.3], [0.5, 0.5, 0.4]],  # crossing interiors
        [[0, 0, 0], [1, 0, 0], [1.4, -0.5, 0.3], [1.5, 0.5, 0.2]],  # end point a1 - interior b
        [[0, 0, 0], [1, 0, 0], [1.4, 0.2, 0.3], [2.0, 0.7, 0.2]],  # a1 - b0
        [[0, 0, 0], [1, 0, 0], [0.3, 0.5, 0.3], [0.3, 1.5, 0.2]],  # b0 - interior a
    ]
    out = [np.array(b, float) + 0.03 * rng.standard_normal((4, 3)) for b in base]
    return np.array(out)


@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_gradient_and_hessian_match_finite_differences(central_differences, kind):
    f, x4 = (point_triangle, _pt_configs()) if kind == "pt" else (edge_edge, _ee_configs())
    s, g, H, code = f(x4)
    assert set(code.tolist()) == {0, 1, 2}  # every feature is exercised
    g_fd = central_differences(lambda y: f(y, hessian=False)[0], x4)
    np.testing.assert_allclose(g.reshape(-1, 12), g_fd, rtol=1e-6, atol=1e-8)
    H_fd = central_differences(lambda y: f(y, hessian=False)[1].reshape(-1, 12), x4)
    np.testing.assert_allclose(H, H_fd, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(H, H.transpose(0, 2, 1), atol=1e-12)


def test_point_triangle_distance_against_sampling():
    rng = np.random.default_rng(2)
    x4 = rng.standard_normal((200, 4, 3))
    s = point_triangle_distance2(x4)
    uv = rng.random((20000, 2))
    flip = uv.sum(axis=1) > 1
    uv[flip] = 1 - uv[flip]
    q = (x4[:, 1, None] + uv[None, :, 0, None] * (x4[:, 2] - x4[:, 1])[:, None]
         + uv[None, :, 1, None] * (x4[:, 3] - x4[:, 1])[:, None])
    brute = np.min(np.sum((q - x4[:, 0, None]) ** 2, axis=2), axis=1)
    assert np.all(s <= brute + 1e-12)  # the exact minimum is below every sample
    np.testing.assert_allclose(np.sqrt(s), np.sqrt(brute), atol=2e-2)


def test_edge_edge_distance_against_sampling_including_parallel():
    rng = np.random.default_rng(3)
    x4 = rng.standard_normal((200, 4, 3))
    # parallel and anti-parallel pairs, overlapping or not
    d = rng.standard_normal((50, 3))
    x4[:50, 1] = x4[:50, 0] + d
    x4[:50, 3] = x4[:50, 2] + rng.choice([-1.0, 0.5, 2.0], size=(50, 1)) * d
    s = edge_edge_distance2(x4)
    t = np.linspace(0, 1, 401)
    pa = x4[:, 0, None] + t[None, :, None] * (x4[:, 1] - x4[:, 0])[:, None]
    pb = x4[:, 2, None] + t[None, :, None] * (x4[:, 3] - x4[:, 2])[:, None]
    brute = np.min(np.sum((pa[:, :, None] - pb[:, None]) ** 2, axis=3), axis=(1, 2))
    assert np.all(s <= brute + 1e-12)
    np.testing.assert_allclose(np.sqrt(s), np.sqrt(brute), atol=2e-2)
    # exactly parallel overlapping edges at distance 0.3: the end-point fallback is exact
    par = np.array([[[0, 0, 0], [1, 0, 0], [0.5, 0.3, 0], [1.5, 0.3, 0]]], float)
    s, g, H, code = edge_edge(par)
    assert s[0] == pytest.approx(0.09) and np.all(np.isfinite(H)) and code[0] == 1


@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_rigid_motion_invariance(kind):
    f, x4 = (point_triangle, _pt_configs()) if kind == "pt" else (edge_edge, _ee_configs())
    s, g, _, _ = f(x4)
    rng = np.random.default_rng(4)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    s2, g2, _, _ = f(x4 @ Q.T + rng.standard_normal(3))
    np.testing.assert_allclose(s2, s, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(g2, g @ Q.T, atol=1e-12)
    np.testing.assert_allclose(g.sum(axis=1), 0.0, atol=1e-12)  # no net force from a distance


def test_bad_shape_is_an_error():
    with pytest.raises(ValueError, match=r"\(P, 4, 3\)"):
        point_triangle(np.zeros((3, 3)))
