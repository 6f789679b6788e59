"""Sewn meshes at the level of mathematics: per-element flat references (TriMesh.element_X), RF patches unfolded
across the seams, and the placed reference (TriMesh.placed) that displacements are measured from."""

import numpy as np
import pytest

from rftstatic import material
from rftstatic.element import membrane, patch
from rftstatic.errors import MeshError
from rftstatic.mesh import trimesh
from rftstatic.model.model import Model


@pytest.fixture(params=["numpy", "numba"])
def backend(request, monkeypatch):
    if request.param == "numba":
        pytest.importorskip("numba")
    else:
        monkeypatch.setattr(membrane, "numba_available", lambda: False)
    return request.param


def _orthotropic():
    return material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, C12=0.4, B_warp=0.03, B_weft=0.02,
                           B_twist=0.01, B12=0.005, weight=0.1)


def _isotropic():
    return material.fabric(C_warp=3.0, C_weft=3.0, C_shear=1.0, C12=1.0, B_warp=0.03, B_weft=0.03,
                           B_twist=0.01, B12=0.01, weight=0.1)


def _cut(flat, angle=0.0, shift=(0.3, -0.2)):
    """The flat mesh ``flat`` as a sewn mesh: elements left of x = 0 keep their coordinates, those right of it
    are given in a frame turned by ``angle`` [rad] and shifted (a second panel), the nodes shared (sewn along
    the cut), placed where the flat mesh is."""
    P = flat.X[flat.tri].copy()
    right = P.mean(axis=1)[:, 0] > 0
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    P[right] = P[right] @ R.T + np.asarray(shift)
    return trimesh.TriMesh(flat.X, flat.tri, element_X=P, placed=flat.X3)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_a_cut_and_resewn_flat_mesh_is_the_flat_mesh(element, backend):
    # shifting one panel's frame leaves every element's shape and axes: the same model to round-off
    flat = trimesh.rectangle(2.0, 1.0, 9, 5, origin=(-1.0, -0.5), pattern="alternate")
    mat = _orthotropic()
    a, b = Model(flat, mat, element=element), Model(_cut(flat), mat, element=element)
    rng = np.random.default_rng(0)
    U = 0.05 * rng.normal(size=(flat.n_nodes, 3))
    np.testing.assert_allclose(b.patches.L, a.patches.L, rtol=1e-9, atol=1e-9 * np.abs(a.patches.L).max())
    np.testing.assert_allclose(b.potential(U), a.potential(U), rtol=1e-11)
    np.testing.assert_allclose(b.internal_force(U), a.internal_force(U), rtol=1e-9, atol=1e-11)
    _, Ka = a.tangent(U)
    _, Kb = b.tangent(U)
    assert abs(Ka - Kb).max() <= 1e-9 * abs(Ka).max()


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_a_panel_turned_in_its_own_frame_changes_nothing_for_an_isotropic_fabric(element, backend):
    flat = trimesh.rectangle(2.0, 1.0, 9, 5, origin=(-1.0, -0.5), pattern="right")
    mat = _isotropic()
    a, b = Model(flat, mat, element=element), Model(_cut(flat, angle=0.8), mat, element=element)
    rng = np.random.default_rng(1)
    U = 0.05 * rng.normal(size=(flat.n_nodes, 3))
    np.testing.assert_allclose(b.potential(U), a.potential(U), rtol=1e-10)
    np.testing.assert_allclose(b.internal_force(U), a.internal_force(U), rtol=1e-8, atol=1e-10)


def _tube(n_around=16, n_along=5, length=1.0, radius=None, *, seam_angle=0.0):
    """A rectangle panel (circumference 2 pi R along x, ``length`` along y) sewn into a tube along its two
    x-ends, placed on the cylinder of radius R about the z axis (nodes on the circle: chords)."""
    radius = 1.0 / (2 * np.pi) if radius is None else radius
    circ = 2 * np.pi * radius
    panel = trimesh.rectangle(circ, length, n_around + 1, n_along, pattern="alternate")
    nx = n_around + 1
    i = np.arange(panel.n_nodes) % nx
    j = np.arange(panel.n_nodes) // nx
    merged = np.where(i == n_around, j * nx, np.arange(panel.n_nodes))  # the last column is the first
    keep = np.unique(merged)
    new = np.full(panel.n_nodes, -1)
    new[keep] = np.arange(len(keep))
    tri = new[merged[panel.tri]]
    theta = 2 * np.pi * panel.X[keep, 0] / circ + seam_angle
    placed = np.column_stack([radius * np.cos(theta), radius * np.sin(theta), panel.X[keep, 1]])
    return trimesh.TriMesh(panel.X[keep], tri, element_X=panel.X[panel.tri], placed=placed), radius


def test_a_sewn_tube_bends_alike_across_its_seam():
    mesh, R = _tube(32, 5)
    mod = Model(mesh, _isotropic(), element="RFT6")
    k = mod.curvature(np.zeros((mesh.n_nodes, 3)))  # (E, 3): k_xx around the tube, k_yy along it
    seam = np.abs(mesh.corners[:, :, 0] - 0.0).min(axis=1) < 1e-12  # elements touching x = 0 (the seam)
    seam |= np.abs(mesh.corners[:, :, 0] - 2 * np.pi * R).min(axis=1) < 1e-12
    assert seam.sum() >= 8
    # the nodes lie on the circle: the patches see the inscribed polygon, curvature 1/R to O(h^2)
    np.testing.assert_allclose(np.abs(k[:, 0]), 1.0 / R, rtol=0.02)
    np.testing.assert_allclose(np.abs(k[seam, 0]).mean(), np.abs(k[~seam, 0]).mean(), rtol=1e-3)
    assert np.abs(k[:, 1:]).max() < 1e-6 / R


def test_sewn_tube_bending_energy_converges_to_the_shell_value():
    # E_b = 1/2 B (1/R)^2 A for a cylinder (B the isotropic bending rigidity), at second order in h
    errors = []
    for n in (16, 32, 64):
        mesh, R = _tube(n, 5)
        mod = Model(mesh, _isotropic(), element="RFT6")
        Eb = mod.energies(np.zeros((mesh.n_nodes, 3)))["bending"]
        exact = 0.5 * 0.03 / R**2 * float(mesh.area.sum())
        errors.append(abs(Eb - exact) / exact)
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 2e-3 and (rates > 1.8).all(), (errors, rates)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_sewn_tube_force_is_the_gradient_and_tangent_the_hessian(element, backend):
    mesh, _ = _tube(8, 4, seam_angle=0.4)
    mod = Model(mesh, _orthotropic(), element=element)
    rng = np.random.default_rng(2)
    U = 0.01 * rng.normal(size=(mesh.n_nodes, 3))
    f, K = mod.tangent(U)
    h = 1e-6
    for d in rng.choice(3 * mesh.n_nodes, 12, replace=False):
        dU = np.zeros(3 * mesh.n_nodes)
        dU[d] = h
        dU = dU.reshape(-1, 3)
        fd = (mod.potential(U + dU) - mod.potential(U - dU)) / (2 * h)
        assert abs(fd - f.ravel()[d]) <= 1e-6 * np.abs(f).max()
        col = (mod.internal_force(U + dU) - mod.internal_force(U - dU)).ravel() / (2 * h)
        np.testing.assert_allclose(K[:, d].toarray().ravel(), col, atol=1e-6 * abs(K).max())


def test_a_rigidly_placed_cut_sheet_is_stress_free_and_stays_so_under_rigid_motion():
    flat = trimesh.rectangle(1.0, 0.6, 7, 5, pattern="union-jack")
    cut = _cut(flat, angle=0.5)
    rot = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])  # the sheet turned upright
    placed = flat.X3 @ rot.T + [0.1, 0.2, 0.3]
    mesh = trimesh.TriMesh(flat.X, flat.tri, element_X=cut.element_X, placed=placed)
    mod = Model(mesh, _orthotropic(), element="RFT6")
    zero = np.zeros((mesh.n_nodes, 3))
    scale = 0.5 * 0.03 * 0.6  # the bending energy of a unit curvature [J]: round-off of |x| ~ 1 m sums below it
    assert abs(mod.potential(zero)) < 1e-11 * scale and np.abs(mod.internal_force(zero)).max() < 1e-11
    c, s = np.cos(1.1), np.sin(1.1)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    U = placed @ R.T + [0.5, -0.3, 0.2] - placed
    assert abs(mod.potential(U)) < 1e-11 * scale and np.abs(mod.internal_force(U)).max() < 1e-11


def test_unfolded_opposites_of_a_flat_mesh_are_its_nodes():
    flat = trimesh.rectangle(1.0, 0.6, 7, 5, pattern="alternate")
    cut = _cut(flat, angle=0.3, shift=(0.0, 0.0))
    inner = ~flat.topology.is_boundary
    opp = flat.tri[np.maximum(flat.topology.neighbour, 0), np.maximum(flat.topology.neighbour_vertex, 0)]
    np.testing.assert_allclose(patch.unfolded_opposites(trimesh.TriMesh(flat.X, flat.tri, element_X=flat.X[flat.tri],
                                                                        placed=flat.X3))[inner],
                               flat.X[opp][inner], atol=1e-14)
    assert cut.element_X is not None


def test_sewn_mesh_input_errors_name_the_problem():
    flat = trimesh.rectangle(1.0, 0.6, 4, 3)
    with pytest.raises(MeshError, match="both element_X"):
        trimesh.TriMesh(flat.X, flat.tri, element_X=flat.X[flat.tri])
    with pytest.raises(MeshError, match="shape"):
        trimesh.TriMesh(flat.X, flat.tri, element_X=flat.X[flat.tri][:-1], placed=flat.X3)
    with pytest.raises(MeshError, match="clockwise"):
        trimesh.TriMesh(flat.X, flat.tri, element_X=flat.X[flat.tri][:, ::-1], placed=flat.X3)


@pytest.mark.parametrize("kernel", ["numpy", "numba"])
def test_the_explicit_force_of_a_sewn_mesh_is_the_models(kernel):
    if kernel == "numba":
        pytest.importorskip("numba")
    from rftstatic.element.explicit_force import ForceKernel

    mesh, _ = _tube(12, 4, seam_angle=0.4)
    mod = Model(mesh, _orthotropic(), element="RFT6")
    U = 0.01 * np.random.default_rng(3).normal(size=(mesh.n_nodes, 3))
    f, W = ForceKernel(mod, backend=kernel, threads=1)(U, energy=True)
    np.testing.assert_allclose(f, mod.internal_force(U), rtol=1e-9, atol=1e-12 * np.abs(f).max())
    np.testing.assert_allclose(W, mod.potential(U), rtol=1e-12)


def test_a_sewn_mesh_locates_points_only_in_a_flat_chart():
    tube, _ = _tube(8, 3)
    assert not tube.chart_is_flat
    with pytest.raises(MeshError, match="no flat chart"):
        tube.locate([[0.1, 0.1]])
    flat = trimesh.rectangle(1.0, 0.6, 5, 4)
    cut = _cut(flat, angle=0.3)
    assert flat.chart_is_flat and cut.chart_is_flat  # a sewn mesh whose chart is a flat layout of it
    elem, _ = cut.locate([[0.3, 0.2]])
    assert elem[0] >= 0
