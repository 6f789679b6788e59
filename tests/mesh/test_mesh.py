"""Meshes of the flat reference configuration: generators, reading, topology, errors."""

import meshio
import numpy as np
import pytest

from rftstatic.mesh import trimesh as mesh


@pytest.mark.parametrize("pattern", mesh.PATTERNS)
def test_rectangle_counts_area_and_topology(pattern):
    m = mesh.rectangle(2.0, 1.0, 9, 5, origin=(-1.0, -0.5), pattern=pattern)
    assert m.n_nodes == 45 and m.n_elements == 2 * 8 * 4
    assert m.area.sum() == pytest.approx(2.0) and (m.area > 0).all()
    assert m.node_area.sum() == pytest.approx(2.0)
    t = m.topology
    # every interior edge pairs two elements that point back at each other
    e, k = np.nonzero(~t.is_boundary)
    nb, nv = t.neighbour[e, k], t.neighbour_vertex[e, k]
    assert (t.neighbour[nb, nv] == e).all()
    assert len(m.boundary_nodes) == 2 * (9 + 5) - 4
    assert len(t.edges) == m.n_nodes + m.n_elements - 1  # Euler: V - E + F = 1


def test_polar_disc_annulus_and_square_polar():
    disc = mesh.polar(1.0, 6, 24)
    assert disc.n_nodes == 1 + 5 * 24 and disc.area.sum() == pytest.approx(24 / 2 * np.sin(2 * np.pi / 24), rel=1e-12)
    ring = mesh.polar(1.0, 4, 30, r_inner=0.5)
    assert ring.n_nodes == 120
    assert len(ring.topology.edges) - ring.n_nodes - ring.n_elements == 0  # V - E + F = 0 for one hole
    sq = mesh.square_polar(0.25, 6, 40)
    assert sq.area.sum() == pytest.approx(0.25, rel=1e-12)  # exactly the 50 x 50 cm sheet
    assert np.abs(sq.X).max() == pytest.approx(0.25)


def test_read_any_meshio_format_round_trip(tmp_path):
    m = mesh.rectangle(0.3, 0.2, 4, 3)
    for suffix in (".vtu", ".msh", ".obj"):
        path = tmp_path / f"sheet{suffix}"
        meshio.write(path, meshio.Mesh(np.c_[m.X * 100, np.full(m.n_nodes, 5.0)], [("triangle", m.tri)]))
        r = mesh.read(path, length_scale=0.01)  # the file is in cm
        assert np.allclose(r.X, m.X) and np.array_equal(r.tri, m.tri) and r.z0 == pytest.approx(0.05)


def test_read_rejects_a_curved_surface(tmp_path):
    m = mesh.rectangle(1.0, 1.0, 3, 3)
    path = tmp_path / "bent.vtu"
    meshio.write(path, meshio.Mesh(np.c_[m.X, m.X[:, 0] ** 2], [("triangle", m.tri)]))
    with pytest.raises(mesh.MeshError, match="not flat"):
        mesh.read(path)


def test_bad_meshes_are_reported():
    X = np.array([[0, 0], [1, 0], [0, 1], [2, 0]], float)
    with pytest.raises(mesh.MeshError, match="degenerate"):
        mesh.TriMesh(X, np.array([[0, 1, 2], [0, 1, 3]]))
    X = np.array([[0, 0], [1, 0], [0, 1], [0, -1], [1, 1]], float)
    with pytest.raises(mesh.MeshError, match="shared by 3 triangles"):
        mesh.TriMesh(X, np.array([[0, 1, 2], [0, 3, 1], [0, 1, 4]]))
    with pytest.raises(mesh.MeshError, match="belong to no triangle"):
        mesh.TriMesh(np.vstack([X[:3], [[5, 5]]]), np.array([[0, 1, 2]]))
    with pytest.raises(mesh.MeshError, match="pattern"):
        mesh.rectangle(1, 1, 3, 3, pattern="zigzag")


def test_clockwise_triangles_are_reoriented():
    m = mesh.TriMesh(np.array([[0, 0], [1, 0], [0, 1]], float), np.array([[0, 2, 1]]))
    assert m.area[0] == pytest.approx(0.5)


def test_patches_and_bending_of_a_large_mesh_build_vectorised():
    # 2 x 10^5 triangles build (timed by `python -m rftstatic bench construction`, not here: 10^6 in 17 s);
    # the bending stiffness is symmetric, positive semi-definite with the rigid motions in its null space
    from rftstatic import material
    from rftstatic.element import patch

    m = mesh.rectangle(1.0, 1.0, 318, 318)
    p = patch.build_patches(m)
    Kb = patch.bending_stiffness(m, p, material.preset("wool-kang-yu").Db)
    assert m.n_elements > 2e5 and Kb.shape == (m.n_nodes, m.n_nodes)
    assert abs(Kb - Kb.T).max() <= 1e-12 * abs(Kb).max()
    for rigid in (np.ones(m.n_nodes), m.X[:, 0], m.X[:, 1]):  # translation and rotations about x, y
        assert np.abs(Kb @ rigid).max() <= 1e-9 * abs(Kb).max()


def test_mesh_files_that_are_not_a_clean_triangle_mesh_are_refused(tmp_path):
    import meshio

    pts = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]])
    cases = {
        "quads": ([("triangle", np.array([[0, 1, 2]])), ("quad", np.array([[1, 4, 2, 3]]))], "quad cells"),
        "missing": ([("triangle", np.array([[0, 1, 7]]))], "names node 7"),
    }
    for name, (cells, fragment) in cases.items():
        path = tmp_path / f"{name}.vtu"
        meshio.write(path, meshio.Mesh(pts, cells))
        with pytest.raises(mesh.MeshError, match=fragment):
            mesh.read(path)
    dup = np.vstack([pts[:4], pts[2:3]])  # node 4 sits on node 2
    path = tmp_path / "dup.vtu"
    meshio.write(path, meshio.Mesh(dup, [("triangle", np.array([[0, 1, 2], [0, 4, 3]]))]))
    with pytest.raises(mesh.MeshError, match="repeated"):
        mesh.read(path)


def test_polar_grading_is_a_geometric_progression():
    """grading = outermost / innermost ring spacing, the spacings a geometric progression between them."""
    m = mesh.polar(15.0, 7, 16, r_inner=9.0, grading=4.0)
    r = np.unique(np.round(np.hypot(*m.X.T), 9))
    d = np.diff(r)
    assert r[0] == 9.0 and r[-1] == 15.0 and len(r) == 7
    assert d[-1] / d[0] == pytest.approx(4.0) and np.allclose(d[1:] / d[:-1], 4.0 ** 0.2)
    assert (m.area > 0).all() and m.area.sum() < np.pi * (15.0**2 - 9.0**2)
