"""The rotation-lifted curve of a Newton step (rftstatic.solvers.rotation_lift, (R1)-(R4))."""

import numpy as np
import pytest

from rftstatic.mesh.trimesh import rectangle as rectangle_mesh
from rftstatic.solvers.rotation_lift import RotationLift


def _sheet(nx=9, ny=7):
    mesh = rectangle_mesh(0.4, 0.3, nx, ny, pattern="right")
    x = mesh.X3.copy()
    x[:, 2] = 0.3 * x[:, 0] ** 2 - 0.2 * x[:, 0] * x[:, 1]  # a curved sheet: no special plane
    return mesh, x


def _lengths(x, edges):
    return np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)


def _lift(mesh, held=None):
    return RotationLift(mesh.topology.edges, mesh.n_nodes, held)


def test_tangent_at_zero_is_the_step():
    """y(alpha) = x + alpha d + O(alpha^2): the remainder falls 4x when alpha halves."""
    mesh, x = _sheet()
    d = np.random.default_rng(1).standard_normal(x.shape) * 0.01
    curve = _lift(mesh).path(x, d)
    rem = [np.abs(curve(a) - a * d).max() for a in (1e-2, 5e-3, 2.5e-3)]
    assert rem[0] > 0
    assert rem[0] / rem[1] == pytest.approx(4.0, rel=0.05)
    assert rem[1] / rem[2] == pytest.approx(4.0, rel=0.05)


def test_rigid_turn_keeps_every_edge_length():
    """The rate of a rigid rotation lifts to a rotation: edge lengths kept where the straight step stretches them."""
    mesh, x = _sheet()
    E = mesh.topology.edges
    omega = np.array([0.3, -0.5, 0.8])  # rad per unit alpha, |omega| ~ 1 rad
    d = np.cross(omega, x - x.mean(axis=0))
    curve = _lift(mesh).path(x, d)
    L0 = _lengths(x, E)
    lifted = np.abs(_lengths(x + curve(1.0), E) / L0 - 1.0).max()
    straight = np.abs(_lengths(x + d, E) / L0 - 1.0).max()
    assert straight > 0.2
    assert lifted < 1e-5


def test_hinge_fold_stretches_only_near_the_hinge():
    """Two halves of a flat sheet turning in opposite senses about the mid line: the lifted curve keeps the edges
    away from the hinge to round-off and stretches the sheet far less than the straight step."""
    mesh = rectangle_mesh(0.4, 0.2, 21, 11, pattern="right")
    x = mesh.X3.copy()
    E = mesh.topology.edges
    xm = 0.5 * (x[:, 0].min() + x[:, 0].max())
    sign = np.where(x[:, 0] < xm, 1.0, -1.0)
    d = np.zeros_like(x)
    d[:, 2] = -sign * (x[:, 0] - xm) * 0.5  # each half turns by 0.5 rad about the hinge line x = xm
    curve = _lift(mesh).path(x, d)
    L0 = _lengths(x, E)
    s_lift = _lengths(x + curve(1.0), E) / L0 - 1.0
    s_line = _lengths(x + d, E) / L0 - 1.0
    mid = 0.5 * (x[E[:, 0], 0] + x[E[:, 1], 0])
    far = np.abs(mid - xm) > 0.1
    assert np.abs(s_line[far]).max() > 0.1
    assert np.abs(s_lift[far]).max() < 0.02
    assert np.sum(s_lift**2) < 0.1 * np.sum(s_line**2)


def test_translation_zero_step_and_held_nodes():
    mesh, x = _sheet()
    lift = _lift(mesh)
    shift = np.tile([0.01, -0.02, 0.03], (mesh.n_nodes, 1))
    np.testing.assert_allclose(lift.path(x, shift)(0.7), 0.7 * shift, atol=1e-14)
    assert np.array_equal(lift.path(x, np.zeros_like(x))(1.0), np.zeros_like(x))
    held = x[:, 0] < x[:, 0].min() + 1e-9  # a clamped edge: its nodes move exactly as the step says
    d = np.random.default_rng(2).standard_normal(x.shape) * 0.01
    d[held] = 0.0
    out = _lift(mesh, held).path(x, d)(0.9)
    assert np.array_equal(out[held], np.zeros((held.sum(), 3)))
    assert np.abs(out[~held]).max() > 0


def test_bad_edges_are_refused():
    with pytest.raises(ValueError, match="edges must be"):
        RotationLift(np.array([[0, 5]]), 3)
