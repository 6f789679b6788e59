"""Self-contact broad phase: the grid finds exactly the box-overlapping pairs that brute force finds,
on a crumpled sheet and for swept boxes; the cache rebuilds only after a motion of margin / 2."""

import numpy as np
import pytest

from rftstatic.contact.self_contact.broad_phase import (PairCache, SheetPrimitives, brute_force_pairs,
                                                        find_pairs)
from rftstatic.mesh.trimesh import rectangle

pytestmark = pytest.mark.usefixtures("backend")


def crumpled(n, seed=0, amp=0.4):
    """An n x n sheet of side 1 [m] crumpled by random waves (amplitude ~amp) and folded over once."""
    mesh = rectangle(1.0, 1.0, n, n, pattern="alternate")
    rng = np.random.default_rng(seed)
    X = mesh.X3.copy()
    z = np.zeros(len(X))
    for _ in range(6):
        k = rng.normal(0, 8, 2)
        z += amp / 6 * np.sin(X[:, :2] @ k + rng.uniform(0, 6.3))
    X[:, 2] = z
    # fold the right half over the left one, 0.02 above it: pairs between the layers
    right = X[:, 0] > 0.5
    X[right, 0] = 1.0 - X[right, 0]
    X[right, 2] = 0.02 + 0.5 * z[right]
    return mesh, X


def _same(p, q):
    for a, b in ((p.pt, q.pt), (p.ee, q.ee)):
        sa = {tuple(r) for r in a.tolist()}
        sb = {tuple(r) for r in b.tolist()}
        assert sa == sb
        assert len(sa) == len(a)  # no duplicates


def test_grid_equals_brute_force_on_a_crumpled_sheet():
    mesh, X = crumpled(15)
    prims = SheetPrimitives.of_mesh(mesh)
    for r in (0.01, 0.05, 0.2):
        got = find_pairs(prims, X, r)
        _same(got, brute_force_pairs(prims, X, r))
    assert len(got.pt) > 0 and len(got.ee) > 0
    # no pair with a node of its triangle, no edge pair sharing a node
    assert not np.any(mesh.tri[got.pt[:, 1]] == got.pt[:, :1])
    e = prims.edges
    assert not np.any(e[got.ee[:, 0]][:, :, None] == e[got.ee[:, 1]][:, None, :])


def test_swept_boxes_equal_brute_force():
    mesh, X = crumpled(12, seed=1)
    prims = SheetPrimitives.of_mesh(mesh)
    rng = np.random.default_rng(5)
    X1 = X + 0.1 * rng.standard_normal(X.shape)
    _same(find_pairs(prims, X, 0.02, X1), brute_force_pairs(prims, X, 0.02, X1))


def test_pairs_closer_than_radius_are_found():
    """Every pair whose exact distance is below r (by the narrow phase) is in the list."""
    from rftstatic.contact.self_contact.distance import edge_edge_distance2, point_triangle_distance2

    mesh, X = crumpled(10, seed=2)
    prims = SheetPrimitives.of_mesh(mesh)
    r = 0.05
    got = find_pairs(prims, X, r)
    allp = brute_force_pairs(prims, X, 10.0)  # every admissible pair
    x4 = np.concatenate([X[allp.pt[:, :1]], X[mesh.tri[allp.pt[:, 1]]]], axis=1)
    near = allp.pt[np.sqrt(point_triangle_distance2(x4)) < r]
    assert {tuple(p) for p in near.tolist()} <= {tuple(p) for p in got.pt.tolist()}
    x4 = X[prims.edges[allp.ee].reshape(-1, 4)]
    near = allp.ee[np.sqrt(edge_edge_distance2(x4)) < r]
    assert len(near) > 0
    assert {tuple(p) for p in near.tolist()} <= {tuple(p) for p in got.ee.tolist()}


def test_cache_rebuilds_after_half_margin():
    mesh, X = crumpled(8)
    prims = SheetPrimitives.of_mesh(mesh)
    cache = PairCache(0.1)
    p1 = cache.pairs(prims, X, 0.01)
    Y = X.copy()
    Y[3, 2] += 0.049
    assert cache.pairs(prims, Y, 0.01) is p1 and cache.builds == 1
    Y[3, 2] += 0.002
    cache.pairs(prims, Y, 0.01)
    assert cache.builds == 2


def test_bad_input():
    mesh, X = crumpled(4)
    prims = SheetPrimitives.of_mesh(mesh)
    with pytest.raises(ValueError, match="radius"):
        find_pairs(prims, X, 0.0)
    with pytest.raises(ValueError, match="shape"):
        find_pairs(prims, X[:-1], 0.1)


@pytest.mark.parametrize("dense", [True, False])
def test_grid_equals_brute_force_on_random_folded_sheets(monkeypatch, dense):
    """The same pairs in the same (sorted) order as brute force on folded sheets of several seeds and radii,
    with the dense cell array and with the sorted occupied cells."""
    from rftstatic.contact.self_contact import broad_phase

    if not dense:
        monkeypatch.setattr(broad_phase, "DENSE_CELLS", 0)
        monkeypatch.setattr(broad_phase, "DENSE_MIN_CELLS", 0)
    for seed in range(4):
        mesh, X = crumpled(11 + 2 * seed, seed=seed, amp=0.2 + 0.2 * seed)
        prims = SheetPrimitives.of_mesh(mesh)
        for r in (0.005, 0.03, 0.12):
            got, ref = find_pairs(prims, X, r), brute_force_pairs(prims, X, r)
            np.testing.assert_array_equal(got.pt, ref.pt)
            np.testing.assert_array_equal(got.ee, ref.ee)


def test_near_list_holds_every_pair_within_the_radius():
    """The near list of a build (:class:`NearPairCache`) is every admissible pair whose exact distance is below
    ``thickness + margin``, by an all-pairs search on folded sheets, with its build distances."""
    from rftstatic.contact.self_contact.distance import edge_edge_distance2, point_triangle_distance2
    from rftstatic.contact.self_contact.near_pairs import NearPairCache, pair_nodes

    for seed in range(3):
        mesh, X = crumpled(9 + 3 * seed, seed=seed + 10)
        prims = SheetPrimitives.of_mesh(mesh)
        d, margin = 0.01, 0.03
        cache = NearPairCache(margin)
        cache.rebuild(prims, X, d)
        allp = brute_force_pairs(prims, X, 10.0)  # every admissible pair
        npt, nee = pair_nodes(prims, allp)
        dpt, dee = np.sqrt(point_triangle_distance2(X[npt])), np.sqrt(edge_edge_distance2(X[nee]))
        want = np.concatenate([npt[dpt < d + margin], nee[dee < d + margin]])
        assert len(want) > 0
        np.testing.assert_array_equal(cache.nodes, want)
        np.testing.assert_allclose(cache.dist, np.concatenate([dpt[dpt < d + margin], dee[dee < d + margin]]),
                                   rtol=1e-12)
