"""RF triangle at the level of mathematics: curvature operator, rigid motions, gradients."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rftstatic import material
from rftstatic.element import kernels, membrane, patch
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model

ELEMENTS = ["RFT3", "RFT6"]


@pytest.fixture(params=["numpy", "numba"])
def backend(request, monkeypatch):
    """The membrane back end that the model's ``"auto"`` picks: the compiled kernels (skipped without
    numba) or the vectorised numpy run of the same kernels."""
    if request.param == "numba":
        pytest.importorskip("numba")
    else:
        monkeypatch.setattr(membrane, "numba_available", lambda: False)
    return request.param


def _mesh(pattern="right"):
    return mesh.rectangle(2.0, 1.0, 7, 5, origin=(-1.0, -0.5), pattern=pattern)


def _material():
    return material.fabric(C_warp=3.0, C_weft=2.0, C_shear=0.7, C12=0.4, B_warp=0.03, B_weft=0.02,
                           B_twist=0.01, B12=0.005, weight=0.1, warp_angle=0.3)


@pytest.mark.parametrize("pattern", ["right", "left", "union-jack", "alternate"])
def test_curvature_operator_exact_for_quadratic_fields(pattern):
    m = _mesh(pattern)
    p = patch.build_patches(m)
    rng = np.random.default_rng(1)
    c = rng.normal(size=6)
    w = patch.quadratic_basis(p.X_patch[..., 0], p.X_patch[..., 1]) @ c  # exact values, image nodes too
    kappa = np.einsum("eka,ea->ek", p.L_geom, w)
    assert np.abs(kappa - c[3:]).max() < 1e-10 * np.abs(c).max()
    boundary = ~p.has_opposite.all(axis=1)
    assert boundary.any() and (~boundary).any()  # both interior and boundary patches were checked


def test_folded_operator_annihilates_linear_fields_and_keeps_interior_exact():
    m = _mesh()
    p = patch.build_patches(m)
    lin = 0.3 + 1.7 * m.X[:, 0] - 0.8 * m.X[:, 1]
    assert np.abs(np.einsum("eka,ea->ek", p.L, lin[p.nodes])).max() < 1e-10
    c = np.array([0.0, 0.0, 0.0, 0.9, -0.4, 0.25])
    quad = patch.quadratic_basis(m.X[:, 0], m.X[:, 1]) @ c
    interior = p.has_opposite.all(axis=1)
    kappa = np.einsum("eka,ea->ek", p.L[interior], quad[p.nodes[interior]])
    assert np.abs(kappa - c[3:]).max() < 1e-10


def test_free_edge_image_rule_carries_no_moment_across_the_edge():
    # a field that is linear in the direction across a free edge bends no boundary element across it
    m = mesh.rectangle(1.0, 1.0, 6, 6, origin=(0, 0))
    p = patch.build_patches(m)
    w = 0.5 * m.X[:, 0] ** 2  # curvature about y only: the edges y = 0, 1 see kappa_yy = 0
    kappa = np.einsum("eka,ea->ek", p.L, w[p.nodes])
    assert np.abs(kappa[:, 1]).max() < 1e-10


def test_singular_patch_is_reported_with_element_and_location():
    # six points on one conic: the middle triangle of a regular hexagon, whose three neighbours
    # add the other three hexagon vertices, so all six patch points lie on one circle
    t = 2 * np.pi * np.arange(6) / 6
    X = np.c_[np.cos(t), np.sin(t)]
    m = mesh.TriMesh(X, np.array([[0, 2, 4], [0, 1, 2], [2, 3, 4], [4, 5, 0]]))
    with pytest.raises(patch.PatchError, match=r"element \d+ at \("):
        patch.build_patches(m)


@pytest.mark.parametrize("element", ELEMENTS)
def test_rigid_motions_give_zero_internal_force(element, backend):
    m = _mesh()
    mod = model.Model(m, _material(), element=element)
    X = mod.X3
    for rotvec in ([0.0, 0.0, 0.0], [0.4, 1.2, -0.7], [np.pi / 2, 0.0, 0.0], [2.5, -1.0, 0.3]):
        R = Rotation.from_rotvec(rotvec).as_matrix()
        U = X @ R.T - X + np.array([0.3, -2.0, 5.0])
        f = mod.internal_force(U)
        assert np.abs(f).max() < 1e-12, (rotvec, np.abs(f).max())
        scale = abs(mod.Kb).max() * (U**2).sum()  # round-off scale of U.Kb.U
        assert abs(mod.energies(U)["bending"]) + abs(mod.energies(U)["membrane"]) < 1e-12 * scale


def _energy_fd(mod, U, lam, h=1e-6):
    r = mod.residual(U, lam)
    err = 0.0
    rng = np.random.default_rng(5)
    for n in rng.choice(mod.mesh.n_nodes, 8, replace=False):
        for i in range(3):
            Up, Um = U.copy(), U.copy()
            Up[n, i] += h
            Um[n, i] -= h
            fd = (mod.potential(Up, lam) - mod.potential(Um, lam)) / (2 * h)
            err = max(err, abs(fd - r[n, i]))
    return err / np.abs(r).max()


@pytest.mark.parametrize("element", ELEMENTS)
def test_force_is_gradient_of_energy_at_large_deformation(element, backend):
    m = _mesh()
    mod = model.Model(m, _material(), element=element, load=model.gravity_load(m, 0.1))
    rng = np.random.default_rng(2)
    R = Rotation.from_rotvec([0.3, -0.8, 0.5]).as_matrix()
    U = mod.X3 @ R.T - mod.X3 + 0.15 * rng.normal(size=mod.X3.shape)
    assert _energy_fd(mod, U, 0.7) < 1e-7


@pytest.mark.parametrize("element", ELEMENTS)
def test_tangent_is_gradient_of_force_at_large_deformation(element, backend):
    m = _mesh()
    sup = model.Supports(m.nodes_in_box(-1, -1, -1, 1), np.zeros(0, int), np.zeros((m.n_nodes, 3), bool))
    mod = model.Model(m, _material(), element=element, supports=sup)
    rng = np.random.default_rng(3)
    U = 0.2 * rng.normal(size=mod.X3.shape) * mod.free
    _, K = mod.tangent(U)
    K = K.toarray()
    free = mod.free.ravel()
    h = 1e-6
    cols = rng.choice(int(free.sum()), 12, replace=False)
    dofs = np.flatnonzero(free)
    for c in cols:
        Up, Um = U.ravel().copy(), U.ravel().copy()
        Up[dofs[c]] += h
        Um[dofs[c]] -= h
        fd = (mod.internal_force(Up.reshape(-1, 3)) - mod.internal_force(Um.reshape(-1, 3))).ravel()[free] / (2 * h)
        assert np.abs(fd - K[:, c]).max() < 1e-6 * np.abs(K).max()
    assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()


@pytest.mark.parametrize("element", ELEMENTS)
def test_compiled_kernels_equal_the_numpy_kernels(element):
    """The compiled kernels (one element at a time) and their numpy run (all elements at once) give
    the same energies, forces and tangents, exact and PSD, with tension, compression and shear in the mix."""
    pytest.importorskip("numba")
    m = _mesh()
    mod = model.Model(m, _material(), element=element)
    rng = np.random.default_rng(11)
    shrink = -0.1 * np.c_[mod.X3[:, 0], 0.5 * mod.X3[:, 1], np.zeros(m.n_nodes)]
    U = shrink + 0.05 * rng.normal(size=mod.X3.shape)
    Dm = mod.material.Dm
    mem = mod.membrane
    e1, e2 = mem.element_energy(U, Dm, backend="numpy"), mem.element_energy(U, Dm, backend="numba")
    np.testing.assert_allclose(e2, e1, rtol=0, atol=1e-12 * np.abs(e1).max())
    f1, f2 = mem.element_forces(U, Dm, backend="numpy"), mem.element_forces(U, Dm, backend="numba")
    np.testing.assert_allclose(f2, f1, rtol=0, atol=1e-12 * np.abs(f1).max())
    for psd in (False, True):
        f1, K1 = mem.element_tangents(U, Dm, psd=psd, backend="numpy")
        f2, K2 = mem.element_tangents(U, Dm, psd=psd, backend="numba")
        np.testing.assert_allclose(f2, f1, rtol=0, atol=1e-12 * np.abs(f1).max())
        np.testing.assert_allclose(K2, K1, rtol=0, atol=1e-12 * np.abs(K1).max())
    _, Kx = mem.element_tangents(U, Dm, psd=False, backend="numba")
    assert np.abs(Kx - K2).max() > 1e-6 * np.abs(Kx).max()  # the mix has compression: PSD differs


def test_positive_part_of_the_stress_is_its_eigen_decomposition():
    """The closed form of the kernels: negative principal stresses dropped, eigenvectors kept
    (isotropic, uniaxial, mixed and negative stress states)."""
    rng = np.random.default_rng(4)
    S = np.r_[rng.normal(size=(200, 3)), [[1.0, 1.0, 0.0], [-2.0, -2.0, 0.0], [0.0, 0.0, 0.0], [3.0, 0.0, 0.0]]]
    pxx, pyy, pxy = kernels.positive_part(S[:, 0], S[:, 1], S[:, 2])
    St = np.stack([np.stack([S[:, 0], S[:, 2]], -1), np.stack([S[:, 2], S[:, 1]], -1)], -2)
    w, v = np.linalg.eigh(St)
    P = np.matmul(v * np.maximum(w, 0.0)[:, None, :], v.transpose(0, 2, 1))
    assert np.abs(np.c_[pxx, pyy, pxy] - P[:, [0, 1, 0], [0, 1, 1]]).max() < 1e-14 * np.abs(S).max()


@pytest.mark.parametrize("element", ELEMENTS)
def test_psd_tangent_is_positive_semidefinite_under_compression(element, backend):
    m = _mesh()
    mod = model.Model(m, _material(), element=element)
    U = -0.2 * np.c_[mod.X3[:, :2], np.zeros(m.n_nodes)]  # uniform 20 % shrink: compressive stress
    _, K = mod.tangent(U, psd=False)
    _, Kp = mod.tangent(U, psd=True)
    assert np.linalg.eigvalsh(K.toarray()).min() < -1e-8
    assert np.linalg.eigvalsh(Kp.toarray()).min() > -1e-10 * np.abs(Kp).max()


@pytest.mark.parametrize("element", ELEMENTS)
def test_membrane_patch_test_uniform_strain(element, backend):
    # a homogeneous stretch gives the exact Green strain in every element, boundary ones included
    m = _mesh("union-jack")
    mod = model.Model(m, _material(), element=element)
    Fm = np.array([[1.1, 0.05], [-0.02, 0.95], [0.1, 0.2]])
    U = m.X @ Fm.T - mod.X3  # x = Fm X: the deformation gradient Fm (3 x 2) everywhere
    C = Fm.T @ Fm
    exact = [0.5 * (C[0, 0] - 1), 0.5 * (C[1, 1] - 1), C[0, 1]]
    assert np.abs(mod.membrane_strain(U) - exact).max() < 1e-12
    # interior nodes are in equilibrium under a homogeneous stress
    f = mod.internal_force(U)
    interior = np.setdiff1d(np.arange(m.n_nodes), m.boundary_nodes)
    assert np.abs(f[interior]).max() < 1e-10 * np.abs(f).max()


def test_bias_cut_fabric_has_warp_stiffness_along_its_warp():
    kw = dict(C_warp=3.0, C_weft=2.0, C_shear=0.7, C12=0.4, B_warp=0.03, B_weft=0.02, B_twist=0.01,
              B12=0.005, weight=0.1)
    theta = 0.7
    m0, mt = material.fabric(**kw), material.fabric(**kw, warp_angle=theta)
    c, s_ = np.cos(theta), np.sin(theta)
    for a, b in ((1.0, 0.0), (0.0, 1.0), (0.3, -0.5)):  # strain a along the warp, b along the weft
        # the same strain state written in global axes (engineering shear)
        exx = a * c * c + b * s_ * s_
        eyy = a * s_ * s_ + b * c * c
        gxy = 2 * (a - b) * c * s_
        e_glob, e_mat = np.array([exx, eyy, gxy]), np.array([a, b, 0.0])
        assert np.isclose(e_glob @ mt.Dm @ e_glob, e_mat @ m0.Dm @ e_mat)
        assert np.isclose(e_glob @ mt.Db @ e_glob, e_mat @ m0.Db @ e_mat)


def test_wool_preset_in_si():
    w = material.preset("wool-kang-yu")
    assert np.isclose(w.Dm[0, 0], 1118.2 * 9.80665e-3 / 1e-2)  # gf/cm -> N/m
    assert np.isclose(w.Db[0, 0], 0.083 * 9.80665e-3 * 1e-2)  # gf cm -> N m
    assert np.isclose(w.mass_per_area, 0.019e-3 / 1e-4)  # g/cm^2 -> kg/m^2


def test_bad_material_is_reported():
    with pytest.raises(ValueError, match="not positive semi-definite"):
        material.fabric(C_warp=1.0, C_weft=1.0, C_shear=1.0, C12=5.0, B_warp=1, B_weft=1, B_twist=1, weight=0)
    with pytest.raises(ValueError, match="nu"):
        material.isotropic_shell(E=1.0, nu=0.7, thickness=1.0)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("psd", [False, True])
@pytest.mark.parametrize("carried", [False, True])
def test_numpy_tangent_agrees_with_the_compiled_kernel(element, psd, carried):
    # the numpy twin writes the element tangent as whole-array products; the compiled kernel loops
    pytest.importorskip("numba")
    import rftstatic.element._kernels_numba as compiled
    from rftstatic.bench.problems import strip_model
    from rftstatic.element import kernels_numpy

    model = strip_model(11, 5, element=element)
    op = model.membrane
    rng = np.random.default_rng(3)
    U = 0.05 * rng.normal(size=(model.mesh.n_nodes, 3))
    E, A = op.nodes.shape
    S = rng.normal(size=(E, 3)) if carried else np.zeros((0, 3))
    fe1, ke1 = kernels_numpy.tangents_numpy(op.G_last, op.nodes, op.area, model.material.Dm, U, psd,
                                            S if carried else None)
    fe2, ke2 = np.empty((E, A, 3)), np.empty((E, A, 3, A, 3))
    compiled.membrane_tangents(*op._compiled_args, model.material.Dm, U, psd, S, fe2, ke2)
    assert np.abs(ke1 - ke2).max() <= 1e-13 * np.abs(ke2).max() and np.array_equal(fe1, fe2)
