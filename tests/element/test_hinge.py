"""Fold hinges (rftstatic.element.hinge) and creased meshes (rftstatic.mesh.folds) at the level of mathematics:
the dihedral angle against geometry, force = gradient of energy, tangent = gradient of force, zero force under
rigid motions, the RF patches ending at a crease, and the model's and the explicit kernel's forces agreeing."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element.explicit_force import ForceKernel
from rftstatic.element.hinge import FoldHinges, dihedral_angles
from rftstatic.errors import MeshError
from rftstatic.mesh import trimesh
from rftstatic.mesh.folds import FoldLines
from rftstatic.model.model import Model


def _hinge_points(phi):
    """A unit hinge along x: triangle 1 (a, b, c) in the plane y > 0, triangle 2's d turned by ``phi`` about x."""
    a, b = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    c = np.array([0.4, 0.8, 0.0])
    d = np.array([0.7, -0.9 * np.cos(phi), -0.9 * np.sin(phi)])
    return a, b, c, d


@pytest.mark.parametrize("phi", [0.0, 0.3, -1.1, np.pi / 2, 3.0])
def test_dihedral_angle_is_the_turn_of_the_second_triangle(phi):
    a, b, c, d = (p[None] for p in _hinge_points(phi))
    theta = dihedral_angles(a, b, c, d)[0]
    assert abs(abs(theta) - abs(phi)) < 1e-12
    # the same hinge seen from the other triangle (a <-> b, c <-> d) has the same angle
    assert abs(dihedral_angles(b, a, d, c)[0] - theta) < 1e-12


def _random_hinges(rng, n=5):
    x = rng.normal(size=(4 * n, 3))
    nodes = np.arange(4 * n).reshape(n, 4)
    return x, FoldHinges(nodes, rng.uniform(-np.pi, np.pi, n), rng.uniform(0.5, 2.0, n))


def test_hinge_force_is_the_gradient_of_its_energy_and_tangent_that_of_its_force():
    rng = np.random.default_rng(3)
    x, h = _random_hinges(rng)
    f = h.force(x)
    eps = 1e-6
    fd = np.zeros_like(x)
    for i in range(x.shape[0]):
        for j in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, j] += eps
            xm[i, j] -= eps
            fd[i, j] = (h.energy(xp) - h.energy(xm)) / (2 * eps)
    np.testing.assert_allclose(f, fd, atol=1e-7 * np.abs(f).max())
    fe, K = h.element_tangents(x)
    for e in range(len(h)):
        Kfd = np.zeros((12, 12))
        for j in range(12):
            xp, xm = x.copy(), x.copy()
            xp[h.nodes[e, j // 3], j % 3] += eps
            xm[h.nodes[e, j // 3], j % 3] -= eps
            Kfd[:, j] = ((h.force(xp) - h.force(xm))[h.nodes[e]] / (2 * eps)).ravel()
        Ke = K[e].reshape(12, 12)
        np.testing.assert_allclose(Ke, Kfd, atol=1e-6 * np.abs(Ke).max())
        np.testing.assert_allclose(Ke, Ke.T, atol=1e-12 * np.abs(Ke).max())


def test_rigid_motions_leave_the_hinge_unloaded():
    rng = np.random.default_rng(4)
    x, h = _random_hinges(rng)
    R = Rotation.from_rotvec([0.3, -1.2, 0.8]).as_matrix()
    y = x @ R.T + np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(h.energy(y), h.energy(x), rtol=1e-12)
    f = h.force(x)
    # the force is a sum of interior forces: no net force, no net moment
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12 * np.abs(f).max())
    np.testing.assert_allclose(np.cross(x, f).sum(axis=0), 0.0, atol=1e-11 * np.abs(f).max())
    rest = FoldHinges(h.nodes, h.angles(x), h.stiffness)
    np.testing.assert_allclose(rest.force(y), 0.0, atol=1e-13)


def test_a_turned_back_rest_angle_is_smooth_through_plus_minus_pi():
    pts = [p[None] for p in _hinge_points(np.pi - 0.01)]
    x = np.concatenate(pts)
    h = FoldHinges([[0, 1, 2, 3]], np.pi, 1.0)
    t = h.excess(x)[0]
    assert abs(abs(t) - 0.01) < 1e-12
    pts = [p[None] for p in _hinge_points(-np.pi + 0.01)]
    assert abs(abs(h.excess(np.concatenate(pts))[0]) - 0.01) < 1e-12


def _creased(nx=9, ny=5, angle=np.pi / 2, width=np.nan):
    """A 2 x 1 m rectangle creased along x = 0 (the vertical grid line)."""
    flat = trimesh.rectangle(2.0, 1.0, nx, ny, origin=(-1.0, -0.5), pattern="right")
    e = flat.topology.edges
    on = np.abs(flat.X[e, 0]).max(axis=1) < 1e-12
    return trimesh.TriMesh(flat.X, flat.tri, folds=FoldLines(e[on], angle, width)), flat


def _fabric():
    return material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, C12=0.4, B_warp=0.03, B_weft=0.02,
                           B_twist=0.01, B12=0.005, weight=0.1)


def test_patches_end_at_a_crease_and_the_hinge_stiffness_is_B_across_it():
    mesh, flat = _creased()
    m, f = Model(mesh, _fabric()), Model(flat, _fabric())
    cut = ~m.patches.has_opposite & f.patches.has_opposite
    assert cut.sum() == 2 * len(mesh.folds)  # both sides of every crease edge
    assert len(m.hinges) == len(mesh.folds)
    # the crease runs along y: across it is x, the warp: k = B_warp |e| / w, w the mean height over the edge
    length = 1.0 / 4
    w = 2.0 / 8
    np.testing.assert_allclose(m.hinges.stiffness, 0.03 * length / w, rtol=1e-12)


def _folded(mesh, phi):
    """Positions of ``mesh`` with its half x > 0 turned by ``phi`` about the crease (the y axis)."""
    x = mesh.X3.copy()
    right = x[:, 0] > 0
    r = x[right, 0]
    x[right, 0], x[right, 2] = r * np.cos(phi), r * np.sin(phi)
    return x


def test_a_sheet_folded_to_its_rest_angle_is_stress_free_and_elsewhere_loaded():
    mesh, _ = _creased(angle=np.pi / 2)
    m = Model(mesh, _fabric())
    sign = np.sign(m.hinges.angles(_folded(mesh, np.pi / 2))[0])
    m = Model(trimesh.TriMesh(mesh.X, mesh.tri, folds=FoldLines(mesh.folds.edges, sign * np.pi / 2, np.nan)),
              _fabric())
    U = _folded(mesh, np.pi / 2) - mesh.X3
    np.testing.assert_allclose(m.internal_force(U), 0.0, atol=1e-12)
    assert m.energies(U)["bending"] < 1e-12 * m.hinges.stiffness.sum()
    U = _folded(mesh, np.pi / 3) - mesh.X3
    k = m.hinges.stiffness.sum()
    np.testing.assert_allclose(m.energies(U)["bending"], 0.5 * k * (np.pi / 6) ** 2, rtol=1e-10)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_model_force_and_tangent_of_a_creased_sheet_are_consistent(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    mesh, _ = _creased(angle=2.5)
    m = Model(mesh, _fabric())
    rng = np.random.default_rng(5)
    U = _folded(mesh, 2.0) - mesh.X3 + 0.01 * rng.normal(size=(mesh.n_nodes, 3))
    f = m.internal_force(U)
    kernel = ForceKernel(m, backend=backend, threads=1)
    fk, W = kernel(U, energy=True)
    np.testing.assert_allclose(fk, f, atol=1e-10 * np.abs(f).max())
    np.testing.assert_allclose(W, m.energies(U)["total"], rtol=1e-10)
    f_t, K = m.tangent(U)
    np.testing.assert_allclose(f_t, f, atol=1e-12 * np.abs(f).max())
    dU = 1e-6 * rng.normal(size=U.shape)
    df = (m.internal_force(U + dU) - m.internal_force(U - dU)) / 2
    np.testing.assert_allclose(K @ dU.ravel(), df.ravel(), atol=1e-6 * np.abs(df).max())


def test_a_fold_on_the_boundary_is_refused_naming_it():
    flat = trimesh.rectangle(1.0, 1.0, 3, 3, pattern="right")
    e = flat.topology.edges
    on = np.abs(flat.X[e, 0]).max(axis=1) < 1e-12  # the left edge x = 0: boundary
    with pytest.raises(MeshError, match="boundary"):
        trimesh.TriMesh(flat.X, flat.tri, folds=FoldLines(e[on], np.pi, np.nan))
    with pytest.raises(MeshError, match="not an edge"):
        trimesh.TriMesh(flat.X, flat.tri, folds=FoldLines([[0, 8]], np.pi, np.nan))
