"""Triangle-surface obstacles (scene type ``mesh``): exact signed distance, derivatives, the PSD penalty and
sharp-feature pairs checked by finite differences, and the bad-input messages."""

import importlib.util
from pathlib import Path

import meshio
import numpy as np
import pytest

from rftstatic.contact.obstacles import Sphere, SurfaceObstacle, from_spec
from rftstatic.contact.obstacles.surface_geometry import closest_on_triangles, winding_number
from rftstatic.contact.penalty import PenaltyContact
from rftstatic.errors import MeshError
from rftstatic.mesh.trimesh import rectangle
from rftstatic.post.measures.obstacle_crossings import obstacle_crossings

# a box [-1, 1]^2 x [-2, 0] (file units) as 12 outward triangles
BOX_V = np.array([[x, y, z] for z in (-2, 0) for y in (-1, 1) for x in (-1, 1)], float)
BOX_F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])


def _tool(name):
    """A script of tools/ as a module (the icosphere the scenes' obstacle files are made with)."""
    path = Path(__file__).resolve().parents[2] / "tools" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"tools_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_icosphere = _tool("icosphere").icosphere


def _write(path, V, F, kind="triangle"):
    meshio.write(path, meshio.Mesh(V, [(kind, np.asarray(F))]))
    return path


@pytest.fixture
def ico(tmp_path):
    return SurfaceObstacle(_write(tmp_path / "ico.obj", *_icosphere(2)), scale=5.0, translate=[0, 0, -0.05],
                           scene_length=0.01)


def _brute(x, ob):
    V, T = ob.V, ob.T
    pt, tt = np.repeat(np.arange(len(x)), len(T)), np.tile(np.arange(len(T)), len(x))
    q, _, _ = closest_on_triangles(x[pt], V[T[tt, 0]], V[T[tt, 1]], V[T[tt, 2]])
    d = np.linalg.norm(x[pt] - q, axis=1).reshape(len(x), -1).min(axis=1)
    return np.where(winding_number(x, V, T) > 0.5, -d, d)


def test_signed_distance_is_exact_near_and_a_lower_bound_far(ico):
    x = np.random.default_rng(1).uniform(-0.12, 0.12, (400, 3)) - [0, 0, 0.05]
    phi, _ = ico.signed_distance(x)
    true = _brute(x, ico)
    near = np.abs(true) < ico.band
    assert near.sum() > 50 and (~near).sum() > 50
    assert np.abs(phi - true)[near].max() <= 1e-15
    assert np.all(phi[~near] <= true[~near] + 1e-15) and np.all(phi[~near] > ico.band - ico.radius - 1e-15)
    # the facets lie inside the sphere through the vertices, within the sagitta (1 - cos(half the edge angle)) R
    sph = Sphere([0, 0, -0.05], 0.05)
    assert np.all(phi[near] >= sph.signed_distance(x[near])[0] - 1e-15)
    assert np.abs(phi - sph.signed_distance(x)[0])[near].max() < 0.05 * 0.02


def _assert_normal_and_hessian_are_derivatives(ob, x, n, H, tol_normal, hessian_scale, h=1e-7):
    """The normal ``n`` and Hessian ``H`` of ``ob`` at ``x`` against central differences of its signed distance
    and normal: the normal within ``tol_normal``, the Hessian within 1e-5 of ``hessian_scale``."""
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        (pp, np_), (pm, nm) = ob.signed_distance(x + e), ob.signed_distance(x - e)
        assert np.abs((pp - pm) / (2 * h) - n[:, i]).max() < tol_normal
        assert np.abs((np_ - nm) / (2 * h) - H[:, :, i]).max() < 1e-5 * hessian_scale


def test_gradient_and_hessian_match_finite_differences(ico):
    rng = np.random.default_rng(2)
    d = rng.normal(size=(60, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    x = np.array([0, 0, -0.05]) + d * (0.05 + rng.uniform(-2e-3, 4e-3, (60, 1)))
    phi, n = ico.signed_distance(x)
    H = ico.normal_gradient(x)
    _assert_normal_and_hessian_are_derivatives(ico, x, n, H, 1e-7, max(1.0, np.abs(H).max()))
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)


def _bent_sheet():
    """A 9 x 9 sheet laid over the box's top edge x = 1 cm, bent down beyond it, 0.3 um above the top."""
    m = rectangle(0.04, 0.04, 9, 9, origin=(-0.02, -0.02))
    x = m.X3.copy()
    x[:, 0] += 0.003
    over = x[:, 0] > 0.01
    x[over, 2] -= (x[over, 0] - 0.01) * 0.8
    x[:, 2] += 3e-7
    return m, x + np.random.default_rng(0).normal(scale=2e-5, size=x.shape)


def test_penalty_and_feature_pairs_force_is_the_energy_gradient_and_tangent_psd(tmp_path):
    box = SurfaceObstacle(_write(tmp_path / "box.obj", BOX_V, BOX_F), scene_length=0.01)
    assert box.closed and len(box.feature_edges) == 12 and len(box.feature_corners) == 8
    f = box.sharp_features()
    mid = f.points[f.edges].mean(axis=1) - f.points.mean(axis=0)  # from the box's centre
    assert np.allclose(np.linalg.norm(f.edge_normals, axis=1), 1.0) and np.all(np.einsum("ei,ei->e", mid, f.edge_normals) > 0)
    m, x = _bent_sheet()
    pc = PenaltyContact([box], m.node_area, 1e7, smoothing=1e-4, sheet=m)
    cs = pc.evaluate(x)
    assert cs.pair_blocks is not None and cs.energy > 0
    h = 1e-8
    nodes = np.argsort(-np.linalg.norm(cs.force, axis=1))[:8]
    for n in nodes:
        for i in range(3):
            e = np.zeros_like(x)
            e[n, i] = h
            fd = (pc.evaluate(x + e, tangent=False).energy - pc.evaluate(x - e, tangent=False).energy) / (2 * h)
            assert fd == pytest.approx(cs.force[n, i], rel=1e-5, abs=1e-9 * np.abs(cs.force).max())
    rows, cols, blocks = cs.pair_blocks
    assert np.linalg.eigvalsh(0.5 * (cs.tangent_blocks + cs.tangent_blocks.transpose(0, 2, 1))).min() >= -1e-9
    # assembled feature tangent of the sheet's dofs: symmetric PSD
    N = m.n_nodes
    K = np.zeros((3 * N, 3 * N))
    for a in range(3):
        for b in range(3):
            np.add.at(K, (3 * rows + a, 3 * cols + b), blocks[:, a, b])
    assert np.abs(K - K.T).max() <= 1e-9 * np.abs(K).max()
    assert np.linalg.eigvalsh(K).min() >= -1e-8 * np.abs(K).max()


def _assert_tangent_blocks_are_force_gradients(pc, x, cs, h=1e-9):
    """Each node's (3, 3) tangent block of the penalty ``pc`` at ``x`` against central differences of its force."""
    for n in range(len(x)):
        for i in range(3):
            e = np.zeros_like(x)
            e[n, i] = h
            fd = (pc.evaluate(x + e).force[n] - pc.evaluate(x - e).force[n]) / (2 * h)
            assert np.allclose(fd, cs.tangent_blocks[n, :, i], rtol=1e-5, atol=1e-6 * np.abs(cs.tangent_blocks).max())


def test_tangent_is_the_force_gradient_on_faces(ico):
    # points pressed 0.2 mm into the middle of the icosphere's upper faces, or 0.05 mm above them (within the
    # onset): face regions, where the PSD tangent is the exact one
    up = np.flatnonzero(ico.nf[:, 2] > 0.5)[:12]
    depth = np.where(np.arange(len(up)) % 2, -2e-4, 5e-5)
    x = ico.centroid[up] + depth[:, None] * ico.nf[up]
    pc = PenaltyContact([ico], np.full(len(x), 1e-4), 1e7, smoothing=1e-4)
    cs = pc.evaluate(x)
    assert np.all(cs.energy > 0) and np.abs(cs.tangent_blocks).max() > 0
    _assert_tangent_blocks_are_force_gradients(pc, x, cs)


def test_independent_crossing_check(tmp_path):
    box = SurfaceObstacle(_write(tmp_path / "box.obj", BOX_V, BOX_F), scene_length=0.01)
    m = rectangle(0.04, 0.04, 9, 9, origin=(-0.02, -0.02))
    V, T = box.surface()
    assert obstacle_crossings(m.X3, m.tri, V, T)["pairs"] == 0  # touching the top is not crossing
    r = obstacle_crossings(m.X3 + [0.0013, 0.0007, -0.001], m.tri, V, T)  # off the side planes
    assert r["pairs"] > 0 and r["smallest_distance"] == 0.0
    r = obstacle_crossings(m.X3 + [0, 0, 0.001], m.tri, V, T)
    assert r["pairs"] == 0 and r["smallest_distance"] == pytest.approx(0.001)


def test_scene_keys_transform_units_and_relative_path(tmp_path):
    _write(tmp_path / "box.stl", BOX_V, BOX_F)
    ob = from_spec({"type": "mesh", "path": "box.stl", "units": "mm", "scale": 2.0, "rotate": [0, 0, 90],
                    "translate": [1.0, 0.0, 0.0]}, 0.01, base_dir=tmp_path)
    lo, hi = ob.bounding_box()
    assert np.allclose(lo, [0.01 - 0.002, -0.002, -0.004]) and np.allclose(hi, [0.01 + 0.002, 0.002, 0.0])
    again = from_spec(ob.as_dict(), 1.0)
    assert np.allclose(again.V, ob.V)


def _refused(tmp_path, name, V, cells, fragment, **keys):
    path = tmp_path / name
    if cells is not None:
        meshio.write(path, meshio.Mesh(np.asarray(V, float), cells))
    with pytest.raises(MeshError, match=fragment):
        SurfaceObstacle(path, **keys)


def test_bad_mesh_files_are_refused_with_the_file_and_the_problem(tmp_path):
    (tmp_path / "empty.obj").write_text("")
    with pytest.raises(MeshError, match="empty.obj"):
        SurfaceObstacle(tmp_path / "empty.obj")
    (tmp_path / "junk.stl").write_text("not a mesh")
    with pytest.raises(MeshError, match="junk.stl: meshio could not read it"):
        SurfaceObstacle(tmp_path / "junk.stl")
    with pytest.raises(MeshError, match="no such file"):
        SurfaceObstacle(tmp_path / "missing.obj")
    P = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1]]
    _refused(tmp_path, "lines.vtu", P, [("line", np.array([[0, 1]]))], "no triangle cells")
    _refused(tmp_path, "degenerate.vtu", P + [[2, 0, 0]], [("triangle", np.array([[0, 1, 2], [0, 1, 5]]))],
             "degenerate", side="front")
    _refused(tmp_path, "dup.vtu", P, [("triangle", np.array([[0, 1, 2], [2, 1, 0]]))], "duplicate", thickness=0.1)
    _refused(tmp_path, "fan.vtu", P + [[0, -1, 0]], [("triangle", np.array([[0, 1, 2], [0, 1, 4], [1, 0, 5]]))],
             "shared by 3 triangles", thickness=0.1)
    _refused(tmp_path, "flip.vtu", P, [("triangle", np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4]]))],
             "inconsistent orientation", side="front")
    _refused(tmp_path, "open.vtu", P, [("triangle", np.array([[0, 1, 2], [0, 2, 3]]))], "open")
    # quads are split (and said), not refused
    ob = SurfaceObstacle(_write(tmp_path / "quad.vtu", P[:4], [[0, 1, 2, 3]], "quad"), side="front")
    assert len(ob.T) == 2 and "quad" in ob.notes[0]


def test_a_sheet_edge_pushed_under_a_rim_is_pushed_back_out(tmp_path):
    """A sheet edge bent 45 deg over the box's top rim x = 1 cm, its ends on either side: 0.1 d outside the rim,
    the feature pair pushes it outward; moved 0.2 d through the rim it is pushed outward again, harder (the signed
    distance: an unsigned one would push it on through)."""
    from rftstatic.contact.features import FeatureContact

    box = SurfaceObstacle(_write(tmp_path / "box.obj", BOX_V, BOX_F), scene_length=0.01)
    X = np.array([[0.009, 0.0, 0.001], [0.011, 0.0, -0.001], [0.009, 0.001, 0.001]])  # through the rim
    tri, edges = np.array([[0, 1, 2]]), np.array([[0, 1], [1, 2], [0, 2]])
    fc = FeatureContact([box], tri, edges, X, gap=1e-4, stiffness=10.0, margin=1e-3)
    pushes = []
    out = np.array([1.0, 0.0, 1.0]) / np.sqrt(2.0)  # the rim's outward normal
    for shift in (1e-5, -2e-5):
        fs = fc.evaluate(X + shift * out)
        pushes.append(-fs.force[:2].sum(axis=0) @ out)  # what the pair does to the edge's two nodes, outward
    assert 0 < pushes[0] < pushes[1]


def test_open_surfaces_with_a_side_or_a_thickness(tmp_path):
    """A 2 x 2 cm plate (two counter-clockwise triangles, normals +z) at z = 0: two-sided with a thickness, or
    solid behind its front (the side its normals face) or its back; beyond the rim every point is outside."""
    path = _write(tmp_path / "plate.obj", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    x = np.array([[0.0, 0.0, 0.001], [0.0, 0.0, -0.001], [0.02, 0.0, -0.005]])
    beside = np.hypot(0.01, 0.005)
    shell = SurfaceObstacle(path, thickness=0.0004, scene_length=0.01)
    assert np.allclose(shell.signed_distance(x)[0], [0.0008, 0.0008, beside - 0.0002])
    front = SurfaceObstacle(path, side="front", scene_length=0.01)
    phi, n = front.signed_distance(x)
    assert np.allclose(phi, [0.001, -0.001, beside]) and np.allclose(n[:2], [[0, 0, 1], [0, 0, 1]])
    back = SurfaceObstacle(path, side="back", scene_length=0.01)
    assert np.allclose(back.signed_distance(x)[0], [-0.001, 0.001, beside])
    assert len(shell.feature_edges) == 4 and len(front.feature_edges) == 4  # the rim is a sharp feature


def test_compiled_and_numpy_queries_and_held_candidate_sets_agree_with_brute_force(tmp_path):
    """The closest-triangle query (compiled and numpy twins) is exact near the surface however the points moved
    since the last call (the candidate sets held from it, re-sought when they no longer prove the nearest)."""
    path = _write(tmp_path / "ico.obj", *_icosphere(3))
    rng = np.random.default_rng(3)
    d = rng.normal(size=(200, 3))
    x = np.array([0, 0, -0.05]) + d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(0.048, 0.056, (200, 1))
    twins = []
    for compiled in (False, True):
        ob = SurfaceObstacle(path, scale=5.0, translate=[0, 0, -0.05], scene_length=0.01)
        ob.compiled = compiled and ob.compiled
        twins.append(ob)
    for step in (0.0, 1e-5, 2e-3, 2e-2):  # the same points again, a little and far moved
        xs = x + rng.normal(scale=step, size=x.shape)
        exact = _brute(xs, twins[0])
        near = np.abs(exact) < twins[0].band
        for ob in twins:
            phi = ob.signed_distance(xs)[0]
            assert np.abs(phi - exact)[near].max() < 1e-15 and np.all(phi <= exact + 1e-15)
        assert len(twins[0]._sets) == 1
    for ob in twins:  # no point asked about (a contact candidate list may be empty)
        phi, normal = ob.signed_distance(np.zeros((0, 3)))
        assert phi.shape == (0,) and normal.shape == (0, 3) and ob.normal_gradient(np.zeros((0, 3))).shape == (0, 3, 3)


def _grid_plate(n):
    """An open n x n square plate of 2 (n - 1)^2 counter-clockwise triangles on [-1, 1]^2 at z = 0 (normals +z),
    its middle row raised into a ridge (convex and reflex edges)."""
    t = np.linspace(-1.0, 1.0, n)
    X, Y = np.meshgrid(t, t, indexing="ij")
    Z = np.where(np.abs(X) < 1e-12, 0.3, 0.0)
    V = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    a = (i * n + j).ravel()
    return V, np.vstack([np.column_stack([a, a + n, a + n + 1]), np.column_stack([a, a + n + 1, a + 1])])


@pytest.mark.parametrize("kind", ["closed", "front", "back", "thickness"])
def test_compiled_signed_distance_equals_the_numpy_twin(tmp_path, kind):
    """The compiled whole-query kernel (:func:`rftstatic.contact.obstacles.surface_kernels.signed_in_sets`) gives
    the numpy path's signed distance, normal and Hessian everywhere: near faces, edges and vertices, inside, far
    beyond the band (inside a closed surface's box: its winding number), for closed and open surfaces, after
    the points moved (held candidate sets)."""
    if kind == "closed":
        path, keys = _write(tmp_path / "ico.obj", *_icosphere(3)), {}
        centre, size = np.array([0.0, 0.0, -0.05]), 0.05
    else:
        path = _write(tmp_path / "plate.obj", *_grid_plate(11))
        keys = {"thickness": 0.0004} if kind == "thickness" else {"side": kind}
        centre, size = np.zeros(3), 0.01
    twins = []
    for compiled in (False, True):
        ob = SurfaceObstacle(path, scale=5.0 if kind == "closed" else 1.0, scene_length=0.01,
                             translate=[0, 0, -0.05] if kind == "closed" else [0, 0, 0], **keys)
        ob.compiled = compiled
        twins.append(ob)
    assert len(twins[0].T) > 64
    rng = np.random.default_rng(4)
    x = centre + rng.uniform(-3 * size, 3 * size, (600, 3))
    x[:300] = centre + rng.uniform(-1.05 * size, 1.05 * size, (300, 3))
    x[:20] = centre + rng.uniform(-0.05 * size, 0.05 * size, (20, 3))  # deep inside: beyond the band
    for step in (0.0, 1e-4, 3e-3):
        xs = x + rng.normal(scale=step, size=x.shape)
        (p0, n0), (p1, n1) = (ob.signed_distance(xs) for ob in twins)
        H0, H1 = (ob.normal_gradient(xs) for ob in twins)
        assert np.abs(p1 - p0).max() < 1e-15 and np.abs(n1 - n0).max() < 1e-12
        assert np.abs(H1 - H0).max() <= 1e-9 * np.abs(H0).max()
    assert (p0 < 0).sum() > (0 if kind == "thickness" else 20) and (np.abs(H0).sum(axis=(1, 2)) > 0).sum() > 20


def test_a_step_through_a_thin_shell_stops_on_its_side(tmp_path):
    """Continuous collision detection of the kinematic contact: nodes stepped 3 mm down through a 0.4 mm
    plate would end below it (projected onto its far face) without it; with it they stop on top, their
    downward velocity gone. Steps beside the plate, above it, or sliding on a solid's face are left alone."""
    from rftstatic.contact.kinematic import kinematic_contact

    plate = _write(tmp_path / "plate.obj", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    shell = SurfaceObstacle(plate, thickness=0.0004, scene_length=0.01)
    x0 = np.array([[0.0, 0.0, 0.0003], [0.005, -0.003, 0.001], [0.02, 0.0, 0.001], [0.0, 0.005, 0.004]])
    x1 = x0 + [[0.0, 0.0, -0.003], [0.001, 0.0, -0.003], [0.0, 0.0, -0.003], [0.0, 0.0, -0.001]]
    v = (x1 - x0) / 1e-3
    blind, _, _ = kinematic_contact(shell, x1, v)
    assert np.all(blind[:2, 2] < 0)  # tunnelled: projected onto the far face
    x, vn, active = kinematic_contact(shell, x1, v, x_old=x0)
    assert active == 2 and np.allclose(x[:2, 2], 0.0002) and np.allclose(vn[:2, 2], 0.0)
    assert np.allclose(x[2:], x1[2:]) and np.allclose(vn[2:], v[2:])  # beside the plate; above it
    # the node stops above the point where its path crossed the mid-surface, a third of the way
    assert np.isclose(x[1, 0], 0.005 + 0.001 / 3)
    box = SurfaceObstacle(_write(tmp_path / "box.obj", BOX_V, BOX_F), scene_length=0.01)
    on = np.array([[0.0, 0.0, 0.0]])
    hit, _, _ = box.segment_crossings(on, on + [0.002, 0.0, 0.0])  # sliding on the top face
    assert not hit.any()
    through = box.segment_crossings([[0.0, 0.0, 0.001]], [[0.0, 0.0, -0.03]])  # right through the 2 cm box
    assert through[0][0] and np.allclose(through[1][0], 0.0) and np.allclose(through[2][0], [0, 0, 1])


def test_a_rounded_surface_is_the_box_grown_by_a_ball_with_an_exact_penalty_tangent(tmp_path):
    # the 2 x 2 x 2 cm box rounded by 3 mm: phi = the distance to the box less 3 mm (a Minkowski sum), its
    # curvature at most 1 / 3 mm, so the penalty's tangent is the exact gradient of its force everywhere,
    # at the rounded edges and corners too (no PSD clamp), compiled and numpy paths alike
    r = 3e-3
    path = _write(tmp_path / "box.obj", BOX_V, BOX_F)
    box = SurfaceObstacle(path, scene_length=0.01, rounding=r)
    plain = SurfaceObstacle(path, scene_length=0.01)
    assert not box.psd_tangent and plain.psd_tangent
    rng = np.random.default_rng(4)
    x = rng.uniform([-0.015, -0.015, -0.025], [0.015, 0.015, 0.005], (300, 3))
    x = x[np.abs(plain.signed_distance(x)[0] - r) < 2e-3]  # within 2 mm of the rounded surface
    assert len(x) > 60
    phi, n = box.signed_distance(x)
    assert np.abs(phi - (plain.signed_distance(x)[0] - r)).max() <= 1e-15
    H = box.normal_gradient(x)
    assert np.abs(H).max() <= 1.0 / (0.5 * r) + 1e-9  # bounded curvature
    lo, hi = box.bounding_box()
    assert np.allclose(lo, [-0.01 - r, -0.01 - r, -0.02 - r]) and np.allclose(hi, [0.01 + r, 0.01 + r, r])
    # points just off the rounded surface near the top edges and corners: the onset and the penetrated range
    q = np.array([[0.01, y, 0.0] for y in np.linspace(-0.012, 0.012, 7)] + [[0.01, 0.01, 0.0]], float)
    d = np.array([1.0, 0.3, 1.0]) / np.linalg.norm([1.0, 0.3, 1.0])
    x = q + (r + np.linspace(-2e-4, 8e-5, len(q)))[:, None] * d
    pc = PenaltyContact([box], np.full(len(x), 1e-4), 1e7, smoothing=1e-4)
    cs = pc.evaluate(x)
    assert np.linalg.eigvalsh(cs.tangent_blocks).min() < 0  # the exact tangent softens along the rounded edges
    _assert_tangent_blocks_are_force_gradients(pc, x, cs)
    # the compiled query (an icosphere of 320 triangles) rounds alike
    ipath = _write(tmp_path / "ico.obj", *_icosphere(2))
    ico, iplain = (SurfaceObstacle(ipath, scale=5.0, scene_length=0.01, rounding=rr) for rr in (r, 0.0))
    x = rng.normal(size=(200, 3))
    x = x / np.linalg.norm(x, axis=1, keepdims=True) * (0.05 + r + rng.uniform(-1e-3, 1e-3, (200, 1)))
    assert ico.compiled == iplain.compiled
    assert np.abs(ico.signed_distance(x)[0] - (iplain.signed_distance(x)[0] - r)).max() <= 1e-15
    assert np.allclose(ico.normal_gradient(x), iplain.normal_gradient(x), rtol=1e-12, atol=0.0)
    with pytest.raises(ValueError, match="rounding"):
        SurfaceObstacle(path, scene_length=0.01, rounding=-1.0)
    assert from_spec({"type": "mesh", "path": str(path), "rounding": 0.3}, 0.01).rounding == pytest.approx(r)


def test_the_smooth_surface_is_c2_near_the_sphere_and_its_derivatives_are_exact(tmp_path):
    # the IMLS surface of a level-4 icosphere (5 cm): within 0.05 mm of the analytic sphere, |grad| ~ 1, its
    # gradient and Hessian the derivatives of phi (central differences), the penalty's tangent exact (no clamp)
    path = _write(tmp_path / "ico4.obj", *_icosphere(4))
    ico = SurfaceObstacle(path, scale=5.0, scene_length=0.01, smooth=0.0075)  # [m]: 3.1 facet radii
    assert not ico.psd_tangent and ico.params()["smooth"] == pytest.approx(0.0075)
    assert from_spec({"type": "mesh", "path": str(path), "scale": 5.0, "smooth": 0.75}, 0.01).smooth == pytest.approx(0.0075)
    rng = np.random.default_rng(5)
    d = rng.normal(size=(300, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    x = d * (0.05 + rng.uniform(-2e-3, 3e-3, (300, 1)))
    phi, n = ico.signed_distance(x)
    assert np.abs(phi - (np.linalg.norm(x, axis=1) - 0.05)).max() < 5e-5
    assert np.abs(np.linalg.norm(n, axis=1) - 1.0).max() < 0.02
    H = ico.normal_gradient(x)
    _assert_normal_and_hessian_are_derivatives(ico, x, n, H, 1e-6, np.abs(H).max())
    # far points keep the triangles' distance; a support under 2.5 facet radii or an open surface is refused
    far = np.array([[0.0, 0.0, 0.2]])
    assert 0.15 - ico.radius - 1e-9 <= ico.signed_distance(far)[0][0] <= 0.15 + 1e-9  # its lower bound far out
    # far points (outside, deep inside) keep their held nearest centroid while they move under FAR_SLACK of its
    # distance: within twice their motion m of a fresh query, on the right side; one moved onto the surface is exact
    far = np.concatenate([d[:40] * 0.1, d[40:80] * 0.02])
    held = ico.signed_distance(far)[0]
    m = np.r_[np.full(40, 0.004), np.full(40, 0.002)]  # under FAR_SLACK of their distance to the centroids
    moved = far + m[:, None] * d[80:160]
    fresh = SurfaceObstacle(path, scale=5.0, scene_length=0.01, smooth=0.0075).signed_distance(moved)[0]
    now = ico.signed_distance(moved)[0]
    assert np.all(np.sign(now) == np.sign(held)) and np.all(now[:40] > 0) and np.all(now[40:] < 0)
    assert np.all((now - fresh) * np.sign(now) >= -1e-12) and np.all(np.abs(now - fresh) <= 2 * m)
    moved[0] = d[0] * 0.0501
    assert ico.signed_distance(moved)[0][0] == pytest.approx(
        SurfaceObstacle(path, scale=5.0, scene_length=0.01, smooth=0.0075).signed_distance(moved[:1])[0][0], abs=1e-12)
    with pytest.raises(ValueError, match="facet radii"):
        SurfaceObstacle(path, scale=5.0, scene_length=0.01, smooth=0.001)
    with pytest.raises(MeshError, match="closed"):
        SurfaceObstacle(_write(tmp_path / "plate.obj", *_grid_plate(4)), scene_length=0.01, side="front", smooth=0.1)


def test_a_sheet_node_in_a_concave_valley_of_the_facets_feels_a_continuous_force(tmp_path):
    # two facets meeting at a concave 20 deg crease (a V-shaped trough): the triangles' distance jumps its normal at
    # the bisecting plane, the smooth surface's does not
    V = np.array([[-0.02, -0.02, 0.0], [-0.02, 0.02, 0.0], [0.0, -0.02, -0.0035], [0.0, 0.02, -0.0035],
                  [0.02, -0.02, 0.0], [0.02, 0.02, 0.0], [0.0, 0.0, -0.05]])
    F = np.array([[0, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5], [0, 6, 2], [2, 6, 4], [1, 3, 6], [3, 5, 6],
                  [0, 1, 6], [4, 6, 5]])
    path = _write(tmp_path / "trough.obj", V, F)
    sharp, smooth = (SurfaceObstacle(path, units="m", **k) for k in ({}, {"smooth": 0.09}))
    x = np.stack([np.linspace(-1e-4, 1e-4, 201), np.zeros(201), np.full(201, -0.0030)], axis=1)
    jump = lambda ob: np.abs(np.diff(ob.signed_distance(x)[1][:, 0])).max()  # noqa: E731
    assert jump(sharp) > 0.3 and jump(smooth) < 1e-3


@pytest.mark.parametrize("cells", [128, 3])
def test_the_smooth_surface_grid_finds_every_facet_in_the_support(tmp_path, monkeypatch, cells):
    # (S1) from the cell grid against the sum over all facets (numpy), cells of h and cells far larger than h
    from rftstatic.contact.obstacles import surface_smooth

    monkeypatch.setattr(surface_smooth, "GRID_CELLS", cells)
    V, T = _icosphere(3)
    surface = surface_smooth.SmoothSurface(0.05 * V, T, 0.012)
    rng = np.random.default_rng(2)
    x = rng.uniform(-0.07, 0.07, (400, 3))
    phi, _, _, W = surface.evaluate(x)
    r = np.linalg.norm(x[:, None] - surface.p[None], axis=2)
    q = np.minimum(r / surface.h, 1.0)
    w = surface.area * (1.0 - q) ** 4 * (4.0 * q + 1.0)
    d = np.einsum("pfi,fi->pf", x[:, None] - surface.p[None], surface.n)
    assert np.allclose(W, w.sum(axis=1), rtol=1e-12, atol=1e-300)
    near = W > 0
    assert 50 < near.sum() < 400
    assert np.allclose(phi[near], (w * d).sum(axis=1)[near] / W[near], rtol=1e-10, atol=1e-15)


def test_the_smooth_surface_gives_the_same_bits_on_any_number_of_threads(monkeypatch):
    # the threaded kernel splits the points into blocks; each point's sums are the serial kernel's
    numba = pytest.importorskip("numba")
    from rftstatic.contact.obstacles import surface_smooth

    if surface_smooth._kernels()["parallel"] is None or numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs numba and two threads")
    monkeypatch.setattr(surface_smooth, "PARALLEL_MIN_POINTS", 1)
    V, T = _icosphere(3)
    surface = surface_smooth.SmoothSurface(0.05 * V, T, 0.012)
    x = np.random.default_rng(3).uniform(-0.07, 0.07, (301, 3))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        serial = surface.evaluate(x, hessian=True)
        numba.set_num_threads(2)
        threaded = surface.evaluate(x, hessian=True)
    finally:
        numba.set_num_threads(before)
    assert (serial[3] > 0).sum() > 50
    for a, b in zip(serial, threaded):
        assert np.array_equal(a, b)
