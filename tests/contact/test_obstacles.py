"""Exact signed distances of the analytic obstacles: values, gradients, Hessians, projection, input."""

import numpy as np
import pytest

from rftstatic.contact.obstacles import (
    Floor,
    Obstacle,
    RoundPedestal,
    Sphere,
    SquarePedestal,
    from_spec,
    obstacle_types,
)

STEP = 1e-6  # [m], central differences on geometry of size ~1-10 cm


def _obstacles():
    """One instance of every obstacle type, including finite and rectangular variants [m]."""
    return {
        "floor": Floor(-0.02),
        "sphere": Sphere([0.01, -0.02, 0.03], 0.05),
        "square": SquarePedestal([0.01, 0.02], 0.05, top_z=0.0, edge_radius=0.005),
        "rect-finite": SquarePedestal([0.0, 0.0], (0.05, 0.03), top_z=0.01, edge_radius=0.004, height=0.06),
        "round": RoundPedestal([0.01, -0.01], 0.1, top_z=0.0, edge_radius=0.005),
        "round-finite": RoundPedestal([0.0, 0.0], 0.04, top_z=0.02, edge_radius=0.006, height=0.05),
    }


def _sample(obstacle, rng):
    """Points outside, inside and within one edge radius of the surface (near rounded edges) [m]."""
    lo, hi = obstacle.bounding_box()
    lo = np.where(np.isfinite(lo), lo, -0.15) - 0.03
    hi = np.where(np.isfinite(hi), hi, 0.15) + 0.03
    box = rng.uniform(lo, hi, size=(400, 3))
    # Near the surface: project random points on it and move them off by +-1 mm along the normal, which
    # samples the rounded edges densely because the projections of the box points cluster there.
    surf = obstacle.closest_point(box[:100])
    _, n = obstacle.signed_distance(surf)
    near = surf + rng.uniform(-1e-3, 1e-3, size=(100, 1)) * n
    x = np.vstack([box, near])
    phi, _ = obstacle.signed_distance(x)
    assert np.any(phi < 0) and np.any(phi > 0)
    return x


def _fd_jacobian(f, x, step=STEP):
    """Central-difference d f(x)[n, ...] / d x[n, j] for a pointwise f, shape (N, ..., 3)."""
    cols = []
    for j in range(3):
        e = np.zeros(3)
        e[j] = step
        cols.append((f(x + e) - f(x - e)) / (2 * step))
    return np.stack(cols, axis=-1)


@pytest.mark.parametrize("name", list(_obstacles()))
def test_normal_is_unit_gradient_of_phi(name):
    obstacle = _obstacles()[name]
    x = _sample(obstacle, np.random.default_rng(1))
    phi, n = obstacle.signed_distance(x)
    assert phi.shape == (len(x),) and n.shape == (len(x), 3)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    fd = _fd_jacobian(lambda y: obstacle.signed_distance(y)[0], x)
    np.testing.assert_allclose(fd, n, atol=1e-6)


@pytest.mark.parametrize("name", list(_obstacles()))
def test_normal_gradient_is_hessian(name):
    obstacle = _obstacles()[name]
    x = _sample(obstacle, np.random.default_rng(2))
    H = obstacle.normal_gradient(x)
    assert H.shape == (len(x), 3, 3)
    np.testing.assert_allclose(H, np.swapaxes(H, 1, 2), atol=1e-12)
    fd = _fd_jacobian(lambda y: obstacle.signed_distance(y)[1], x)
    scale = np.maximum(np.abs(H).max(axis=(1, 2)), 1.0)[:, None, None]
    np.testing.assert_allclose(fd / scale, H / scale, atol=1e-6)
    # The normal is a unit vector field: H n = 0 wherever phi is smooth.
    _, n = obstacle.signed_distance(x)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", H, n) / scale[:, :, 0], 0.0, atol=1e-9)


@pytest.mark.parametrize("name", list(_obstacles()))
def test_closest_point_is_on_surface_and_exact(name):
    obstacle = _obstacles()[name]
    rng = np.random.default_rng(3)
    x = _sample(obstacle, rng)
    phi, n = obstacle.signed_distance(x)
    y = obstacle.closest_point(x)
    np.testing.assert_allclose(obstacle.signed_distance(y)[0], 0.0, atol=1e-12)
    # |x - y| = |phi| and the normal at y is the normal at x (exact signed distance).
    np.testing.assert_allclose(np.linalg.norm(x - y, axis=1), np.abs(phi), atol=1e-12)
    np.testing.assert_allclose(obstacle.signed_distance(y)[1], n, atol=1e-9)
    # project: only penetrated points move.
    p = obstacle.project(x)
    outside = phi >= 0
    np.testing.assert_array_equal(p[outside], x[outside])
    np.testing.assert_allclose(p[~outside], y[~outside], atol=1e-15)


def test_sphere_values_and_curvature():
    s = Sphere([0.0, 0.0, 0.0], 0.05)
    x = np.array([[0.0, 0.0, 0.08], [0.03, 0.0, 0.0], [0.0, 0.0, 0.0]])
    phi, n = s.signed_distance(x)
    np.testing.assert_allclose(phi, [0.03, -0.02, -0.05])
    np.testing.assert_allclose(n[:2], [[0, 0, 1], [1, 0, 0]])
    H = s.normal_gradient(x)
    np.testing.assert_allclose(H[0], np.diag([1, 1, 0]) / 0.08)
    np.testing.assert_array_equal(H[2], 0.0)  # one-sided choice at the centre
    np.testing.assert_allclose(n[2], [0, 0, 1])


def test_square_pedestal_values():
    b = SquarePedestal([0.0, 0.0], 0.05, top_z=0.0, edge_radius=0.005)
    x = np.array([
        [0.0, 0.0, 0.01],  # above the top face
        [0.07, 0.0, -0.1],  # beside a side face
        [0.0, 0.0, -0.002],  # just under the top face
        [0.05 + 0.003, 0.0, 0.003],  # outside the rounded top edge: distance to the edge centre line
        [0.08, 0.08, -1.0],  # beside a vertical (rounded) edge
    ])
    phi, n = b.signed_distance(x)
    d_edge = np.hypot(0.008, 0.008) - 0.005
    d_vert = np.hypot(0.035, 0.035) - 0.005
    np.testing.assert_allclose(phi, [0.01, 0.02, -0.002, d_edge, d_vert], atol=1e-15)
    s = np.sqrt(0.5)
    np.testing.assert_allclose(n, [[0, 0, 1], [1, 0, 0], [0, 0, 1], [s, 0, s], [s, s, 0]], atol=1e-12)
    # Rectangles: half widths per axis, size = 2 * half_width.
    r = SquarePedestal([0.0, 0.0], size=(0.1, 0.06), top_z=0.0, edge_radius=0.0)
    np.testing.assert_allclose(r.signed_distance([[0.0, 0.05, -0.5]])[0], [0.02])
    np.testing.assert_allclose(r.bounding_box()[1], [0.05, 0.03, 0.0])


def test_round_pedestal_values():
    c = RoundPedestal([0.0, 0.0], 0.1, top_z=0.0, edge_radius=0.005)
    x = np.array([
        [0.03, 0.04, 0.02],  # above the top
        [0.0, 0.12, -0.2],  # beside the wall
        [0.0, 0.0, -0.001],  # on the axis, under the top
        [0.1 + 0.004, 0.0, 0.004],  # outside the rounded rim
    ])
    phi, n = c.signed_distance(x)
    d_rim = np.hypot(0.009, 0.009) - 0.005
    np.testing.assert_allclose(phi, [0.02, 0.02, -0.001, d_rim], atol=1e-15)
    s = np.sqrt(0.5)
    np.testing.assert_allclose(n, [[0, 0, 1], [0, 1, 0], [0, 0, 1], [s, 0, s]], atol=1e-12)
    # The wall has curvature 1/rho around the axis.
    H = c.normal_gradient(np.array([[0.12, 0.0, -0.2]]))
    np.testing.assert_allclose(H[0], np.diag([0.0, 1 / 0.12, 0.0]), atol=1e-12)


def test_finite_height_has_a_bottom():
    c = RoundPedestal([0.0, 0.0], 0.04, top_z=0.02, edge_radius=0.006, height=0.05)
    phi, n = c.signed_distance(np.array([[0.0, 0.0, -0.04]]))
    np.testing.assert_allclose(phi, [0.01])
    np.testing.assert_allclose(n, [[0, 0, -1]])


def test_floor():
    f = Floor(0.01)
    phi, n = f.signed_distance(np.array([[1.0, 2.0, 0.0], [0.0, 0.0, 0.5]]))
    np.testing.assert_allclose(phi, [-0.01, 0.49])
    np.testing.assert_array_equal(n, [[0, 0, 1], [0, 0, 1]])


def test_from_spec_scales_and_round_trips():
    spec = {"type": "round-pedestal", "centre": [0, 0], "radius": 10, "top": 0, "edge_radius": 0.5}
    ped = from_spec(spec, 0.01)
    assert isinstance(ped, RoundPedestal) and isinstance(ped, Obstacle)
    assert ped.radius == pytest.approx(0.1) and ped.edge_radius == pytest.approx(0.005)
    assert np.isinf(ped.height)
    sq = from_spec({"type": "square_pedestal", "size": 10, "top": 2, "edge_radius": 0.2}, 0.01)
    np.testing.assert_allclose(sq.half_width, [0.05, 0.05])
    assert sq.top_z == pytest.approx(0.02)
    sphere = from_spec({"type": "sphere", "centre": [0, 0, -5], "radius": 5}, 0.01)
    np.testing.assert_allclose(sphere.centre, [0, 0, -0.05])
    x = np.random.default_rng(4).uniform(-0.2, 0.2, size=(50, 3))
    floor = from_spec({"type": "floor", "height": -3}, 0.01)
    for obstacle in [ped, sq, sphere, floor, *_obstacles().values()]:
        d = obstacle.as_dict()
        assert d["type"] in obstacle_types()
        again = from_spec(d, 1.0)
        assert type(again) is type(obstacle)
        np.testing.assert_allclose(again.signed_distance(x)[0], obstacle.signed_distance(x)[0], atol=1e-15)
        assert d["type"] in obstacle.describe()


@pytest.mark.parametrize(
    "spec, words",
    [
        ({"radius": 1}, ["'type'"]),
        ({"type": "cone"}, ["'type'", "cone", "round-pedestal"]),
        ({"type": "sphere", "radius": 1}, ["missing", "centre"]),
        ({"type": "floor", "hieght": 1}, ["unknown", "hieght"]),
        ({"type": "round-pedestal", "radius": -10}, ["'radius'", "-10", "> 0"]),
        ({"type": "round-pedestal", "radius": 1, "edge_radius": 2}, ["'edge_radius'", "2"]),
        ({"type": "square-pedestal", "half_width": 1, "edge_radius": 1.5}, ["'edge_radius'", "half width"]),
        ({"type": "square-pedestal", "half_width": 1, "size": 2}, ["half_width", "size"]),
        ({"type": "square-pedestal", "size": [1, 2, 3]}, ["'size'", "shape"]),
        ({"type": "sphere", "centre": [0, 0], "radius": 1}, ["'centre'", "shape (3,)"]),
        ({"type": "sphere", "centre": "origin", "radius": 1}, ["'centre'", "origin"]),
        (
            {"type": "round-pedestal", "radius": 1, "edge_radius": 0.5, "height": 0.5},
            ["'height'", "edge_radius"],
        ),
    ],
)
def test_from_spec_errors_name_the_key(spec, words):
    with pytest.raises(ValueError) as info:
        from_spec(spec, 0.01)
    for word in words:
        assert word in str(info.value)


@pytest.mark.parametrize(
    "make, word",
    [
        (lambda: Sphere([0, 0, 0], -1.0), "radius"),
        (lambda: Sphere([0, 0, np.nan], 1.0), "centre"),
        (lambda: RoundPedestal([0, 0], 0.1, edge_radius=-0.01), "edge_radius"),
        (lambda: RoundPedestal([0, 0], 0.1, edge_radius=0.2), "edge_radius"),
        (lambda: RoundPedestal([0, 0], 0.1, height=0.0), "height"),
        (lambda: SquarePedestal([0, 0], 0.05, edge_radius=0.06), "edge_radius"),
        (lambda: SquarePedestal([0, 0], (0.05, -0.01)), "half_width"),
        (lambda: SquarePedestal([0, 0, 0], 0.05), "centre_xy"),
        (lambda: Floor("low"), "height"),
        (lambda: Floor(0.0).signed_distance(np.zeros((4, 2))), "(N, 3)"),
    ],
)
def test_constructor_errors_name_the_parameter(make, word):
    with pytest.raises(ValueError, match=None) as info:
        make()
    assert word in str(info.value)
