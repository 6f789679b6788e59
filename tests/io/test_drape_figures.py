"""Drape figures and measures of the validation reports: boundary distance, obstacle outlines, drawers."""

import numpy as np
import pytest

from rftstatic.contact.obstacles import RoundPedestal, Sphere, SquarePedestal
from rftstatic.io.drape_figures import boundary_distance, boundary_xy, obstacle_drawers
from rftstatic.mesh.trimesh import rectangle


def _circle(r, n=400, c=(0.0, 0.0)):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)])


def test_boundary_distance_concentric_circles_is_radius_difference():
    assert boundary_distance(_circle(10.0), _circle(10.3)) == pytest.approx(0.3, abs=2e-3)


def test_boundary_distance_is_symmetric_and_zero_on_itself():
    a, b = _circle(5.0), _circle(5.0, c=(0.2, -0.1))
    assert boundary_distance(a, a) == pytest.approx(0.0, abs=1e-9)
    assert boundary_distance(a, b) == pytest.approx(boundary_distance(b, a))
    assert boundary_distance(a, b) == pytest.approx(np.hypot(0.2, 0.1), abs=5e-3)


def test_boundary_distance_sees_a_fold_between_vertices():
    """A spike of one extra vertex is the Hausdorff distance, not its neighbours' offset."""
    sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    spike = np.array([[0, 0], [1, -0.5], [2, 0], [2, 2], [0, 2]], float)
    assert boundary_distance(sq, spike) == pytest.approx(0.5, abs=2e-3)


def test_boundary_xy_of_flat_square_is_its_perimeter():
    m = rectangle(2.0, 2.0, 5, 5, pattern="union-jack")
    x = np.column_stack([m.X, np.zeros(m.n_nodes)])
    c = boundary_xy(x, m.tri)
    assert len(c) == 16
    assert np.allclose(np.abs(c).max(axis=0), [2.0, 2.0]) and np.allclose(c.min(axis=0), [0.0, 0.0])


def test_plan_outlines_come_from_the_signed_distance_of_any_obstacle():
    from rftstatic.contact.obstacles import Floor

    sq, z = SquarePedestal([0.0, 0.0], 0.05, top_z=0.01, edge_radius=0.002).plan_outline()
    assert 0.01 - 0.002 - 0.1 / 32 <= z <= 0.01  # at the top, below the edge rounding (33 heights)
    assert np.abs(sq).max() == pytest.approx(0.05, rel=1e-6)  # the sides at +-5 cm (the corners rounded)
    corner = np.hypot(*sq[np.argmax(np.abs(sq[:, 0]) + np.abs(sq[:, 1]))])
    assert corner == pytest.approx(np.hypot(0.048, 0.048) + 0.002, rel=1e-3)  # corner radius 0.2 cm
    rd, _ = RoundPedestal([0.1, 0.0], 0.1).plan_outline()
    assert np.linalg.norm(rd - [0.1, 0.0], axis=1) == pytest.approx(np.full(len(rd), 0.1), rel=1e-6)
    sp, z = Sphere([0.0, 0.0, -0.05], 0.05).plan_outline()  # the equator, not the pole
    assert np.linalg.norm(sp, axis=1) == pytest.approx(np.full(len(sp), 0.05), rel=1e-6)
    assert z == pytest.approx(-0.05, abs=0.05 / 32)
    assert Floor(0.0).plan_outline() is None


def test_obstacle_drawers_draw_every_view():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    draws = obstacle_drawers([SquarePedestal([0.0, 0.0], 0.05), Sphere([0.0, 0.0, -0.05], 0.05)], 0.01)
    assert len(draws) == 2
    fig = plt.figure()
    ax2, ax3 = fig.add_subplot(121), fig.add_subplot(122, projection="3d")
    for d in draws:
        d(ax2, "top"), d(ax2, "side"), d(ax3, "iso")
    assert ax2.patches or ax2.collections or ax2.lines
    assert ax3.lines
    plt.close(fig)
