"""The compiled (numba) twins of the self-contact loops agree with the numpy path to round-off: the PSD
projection of the law's blocks and of random symmetric matrices, the additive CCD, and the broad phase
(the pair geometry's two back ends: test_geometry.py)."""

import numpy as np
import pytest

from rftstatic.contact.self_contact import distance, law_kernels
from rftstatic.contact.self_contact.broad_phase import SheetPrimitives, find_pairs

pytest.importorskip("numba")


def _on(monkeypatch, compiled):
    monkeypatch.setattr(distance, "compiled_for", lambda n, choice=None: compiled)


def _both(monkeypatch, f, *args, **kw):
    _on(monkeypatch, False)
    a = f(*args, **kw)
    _on(monkeypatch, True)
    return a, f(*args, **kw)


def _law_blocks(random_pairs, seed=0):
    """Law-like blocks ``c1 gg^T + c2 H`` of random pairs of both kinds, ``c2`` of either sign."""
    rng = np.random.default_rng(seed)
    out = []
    for kind, f in (("pt", distance.point_triangle), ("ee", distance.edge_edge)):
        s, g, H, _ = f(random_pairs(kind, 1000, seed, parallel_every=6))
        g = g.reshape(-1, 12)
        c1, c2 = rng.uniform(0, 2, (2, len(s), 1, 1)) * [[[[1.0]]], [[[-1.0]]]]
        out.append(c1 * np.einsum("pm,pn->pmn", g, g) + c2 * rng.choice([-1.0, 1.0], (len(s), 1, 1)) * H)
    return np.concatenate(out)


def test_psd_projection_agrees(random_pairs, monkeypatch):
    rng = np.random.default_rng(1)
    full = rng.standard_normal((200, 12, 12))
    low = rng.standard_normal((200, 12, 4))
    sign = np.where(np.arange(4) % 2, -1.0, 1.0)
    blocks = [_law_blocks(random_pairs), full + full.transpose(0, 2, 1), np.einsum("pik,k,pjk->pij", low, sign, low),
              np.zeros((3, 12, 12))]
    for B in blocks:
        a, b = _both(monkeypatch, law_kernels.psd_project, B)
        scale = np.abs(B).max(axis=(1, 2), keepdims=True) + 1e-300
        np.testing.assert_allclose(b / scale, a / scale, rtol=0, atol=1e-12)
        assert np.linalg.eigvalsh(b).min() >= -1e-12 * scale.max()


@pytest.mark.parametrize("kind", [0, 1])
@pytest.mark.parametrize("size", [0.01, 0.3, 3.0])
def test_additive_ccd_agrees(random_pairs, monkeypatch, kind, size):
    rng = np.random.default_rng(2)
    x4 = random_pairs("pt" if kind == 0 else "ee", 2000, seed=3, parallel_every=6)
    dx4 = size * rng.standard_normal(x4.shape)
    a, b = _both(monkeypatch, law_kernels.additive_ccd, x4, dx4, kind, 0.2, 200)
    assert 0.0 < a < 1.0 or size == 0.01
    assert b == pytest.approx(a, rel=1e-12)
    nodes = rng.permutation(4 * len(x4)).reshape(-1, 4)  # the same pairs as nodes of a point cloud
    x, dx = np.empty((4 * len(x4), 3)), np.empty((4 * len(x4), 3))
    x[nodes], dx[nodes] = x4, dx4
    c, e = _both(monkeypatch, law_kernels.additive_ccd_nodes, x, dx, nodes, kind, 0.2, 200)
    assert c == a and e == pytest.approx(a, rel=1e-12)


@pytest.mark.parametrize("threads", [1, 2])
def test_broad_phase_agrees_on_a_folded_crumpled_sheet(monkeypatch, threads):
    # threads: the compiled join over ranges of boxes on two threads gives the same sorted pairs
    import numba

    from rftstatic.bench.self_contact import crumpled, smooth_step
    from rftstatic.contact.self_contact import broad_phase

    monkeypatch.setattr(broad_phase, "JOIN_THREADS_FROM", 1)
    monkeypatch.setattr(numba, "get_num_threads", lambda: threads)
    mesh, X = crumpled(31)
    X[X[:, 0] > 0.4, 2] += 0.004
    prims = SheetPrimitives.of_mesh(mesh)
    for r, X1 in ((3e-3, None), (5e-3, None), (5e-4, X + smooth_step(X, 0.05))):
        a, b = _both(monkeypatch, find_pairs, prims, X, r, X1)
        assert len(a.pt) and len(a.ee)
        np.testing.assert_array_equal(b.pt, a.pt)
        np.testing.assert_array_equal(b.ee, a.ee)


def test_load_compiled_loads_the_twins_and_what_is_loaded_never_decides():
    from rftstatic import compiled
    from rftstatic.contact.self_contact import distance, law_kernels

    if not compiled.numba_available():
        assert law_kernels.load_compiled() is False
        return
    assert law_kernels.load_compiled() and distance.compiled_loaded()
    # loaded or not, a call outside a run chooses by its size alone, and a run's choice decides
    n = distance.COMPILED_MIN_PAIRS
    assert not distance.compiled_for(n - 1) and distance.compiled_for(n)
    assert distance.compiled_for(1, True) and not distance.compiled_for(10 * n, False)


@pytest.mark.parametrize("s", [0.0, 1.0])
def test_translation_free_motion_agrees_and_ignores_translation(monkeypatch, s):
    from rftstatic.contact.self_contact.near_pairs import translation_free_motion

    rng = np.random.default_rng(5)
    x0 = rng.standard_normal((1500, 3))
    x, dx = x0 + 0.01 * rng.standard_normal(x0.shape), 0.01 * rng.standard_normal(x0.shape)
    (ma, ba), (mb, bb) = _both(monkeypatch, translation_free_motion, x, x0, b=dx, s=s)
    np.testing.assert_allclose(mb, ma, rtol=1e-13, atol=1e-16)
    assert bb == pytest.approx(ba, rel=1e-13) and ba == ma.max()
    shifted = translation_free_motion(x + np.array([3.0, -2.0, 7.0]), x0, b=dx, s=s)[0]  # a translation
    np.testing.assert_allclose(shifted, ma, atol=1e-12)
    u = x + s * dx - x0
    c = 0.5 * (u.max(axis=0) + u.min(axis=0))
    np.testing.assert_allclose(ma, np.linalg.norm(u - c, axis=1), rtol=1e-13)


@pytest.mark.parametrize("kind", [0, 1])
def test_additive_ccd_with_a_floor_agrees_and_stops_at_the_floor(random_pairs, monkeypatch, kind):
    rng = np.random.default_rng(4)
    x4 = random_pairs("pt" if kind == 0 else "ee", 500, seed=6, parallel_every=6)
    dx4 = 0.3 * rng.standard_normal(x4.shape)
    dist2 = distance.point_triangle_distance2 if kind == 0 else distance.edge_edge_distance2
    floor = float(np.median(np.sqrt(dist2(x4))))
    a, b = _both(monkeypatch, law_kernels.additive_ccd, x4, dx4, kind, 0.2, 200, floor)
    assert b == pytest.approx(a, rel=1e-12)
    assert a <= law_kernels.additive_ccd(x4, dx4, kind, 0.2, 200)  # a floor only shortens the step
    d0 = np.sqrt(dist2(x4))
    for t in np.linspace(0.0, a, 21):  # on the allowed part of the path no pair that began above the floor goes below it
        d = np.sqrt(dist2(x4 + t * dx4))
        assert np.all(d[d0 > floor] >= floor * (1 - 1e-9))
        assert np.all(d >= 0.2 * d0 * (1 - 1e-9))


def test_near_pair_distances_by_index_agree(monkeypatch):
    from rftstatic.bench.self_contact import crumpled
    from rftstatic.contact.self_contact.near_pairs import _distances

    mesh, X = crumpled(31)
    prims = SheetPrimitives.of_mesh(mesh)
    pairs = find_pairs(prims, X, 5e-3)
    (pa, ea), (pb, eb) = _both(monkeypatch, _distances, prims, X, pairs)
    assert len(pa) == len(pairs.pt) and len(eb) == len(pairs.ee) and len(pa) and len(ea)
    np.testing.assert_allclose(pb, pa, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(eb, ea, rtol=1e-12, atol=1e-15)


def test_step_motions_are_the_three_motions_of_the_filter(monkeypatch):
    """:meth:`NearPairCache.step_motions` gives, compiled in one loop, the largest of three compiled translation-free
    motions (since the build at x and at x + dx, the step's spread) bit for bit, and the numpy path's to round-off;
    a motion past half the margin rebuilds the list at x."""
    from rftstatic.bench.self_contact import crumpled
    from rftstatic.contact.self_contact.near_pairs import NearPairCache, translation_free_motion

    mesh, X = crumpled(21)
    prims = SheetPrimitives.of_mesh(mesh)
    rng = np.random.default_rng(3)
    _on(monkeypatch, True)
    for scale, builds in ((1e-4, 1), (2e-2, 2)):
        x, dx = X + scale * rng.standard_normal(X.shape), 1e-4 * rng.standard_normal(X.shape)
        caches = []
        for compiled in (False, True, True):
            cache = NearPairCache(0.02, compiled=compiled)
            cache.rebuild(prims, X, 0.002)
            caches.append(cache)
        numpy_path, fused = (c.step_motions(prims, x, dx, 0.002) for c in caches[:2])
        three = (caches[2].current(prims, x, 0.002)[1], caches[2].motion(x, dx)[1],
                 translation_free_motion(dx, np.zeros_like(dx), compiled=True)[1])
        assert fused == three
        np.testing.assert_allclose(numpy_path, three, rtol=1e-13)
        assert [c.builds for c in caches] == [builds] * 3


def test_largest_norm_agrees(monkeypatch):
    from rftstatic.contact.self_contact.step_filter import _largest

    v = np.random.default_rng(2).standard_normal((3000, 3))
    a, b = _largest(v, False), _largest(v, True)
    assert b == pytest.approx(a, rel=1e-15) and a == pytest.approx(np.linalg.norm(v, axis=1).max(), rel=1e-15)
    assert _largest(np.zeros((0, 3)), True) == 0.0
