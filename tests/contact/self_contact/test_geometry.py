"""The one source of the pair geometry (:mod:`rftstatic.contact.self_contact.geometry`) on both back ends:
compiled and numpy agree to round-off on random and degenerate pairs (parallel edges, a point over a
triangle's edge or vertex, coincident points, zero-length edges, flat triangles); the degenerate pairs
have their exact distances; the gradient is the finite difference of the squared distance and of a
distance-based energy (the law's), the Hessian the finite difference of the gradient; the Hessian is
symmetric."""

import numpy as np
import pytest

from rftstatic.contact.self_contact import distance, geometry
from rftstatic.contact.self_contact.law import BARRIER_GAP, pair_law

FUNCS = {"pt": (distance.point_triangle, distance.point_triangle_distance2, 0),
         "ee": (distance.edge_edge, distance.edge_edge_distance2, 1)}


def _rotated(x4, seed):
    """The pairs moved by one random rotation and translation: the exact ties of axis-aligned pairs
    become near ties decided by round-off."""
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    return x4 @ Q.T + rng.standard_normal(3)


def degenerate_pt():
    """Point-triangle pairs on feature boundaries and with coincident points, their exact squared
    distances and whether the distance is differentiable there (on the triangle (0, 0, 0), (1, 0, 0),
    (0, 1, 0); not so for a flat triangle: opening it towards the point or away from it differs)."""
    t = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    h = 0.25
    rows = [
        ([0.5, 0.0, h], h * h),  # over the middle of edge t0 t1: face and edge tie
        ([0.5, 0.5, h], h * h),  # over the middle of the hypotenuse
        ([0.0, 0.0, h], h * h),  # over vertex t0: face, two edges and the vertex tie
        ([1.0, 0.0, -h], h * h),  # under vertex t1
        ([0.0, 0.0, 0.0], 0.0),  # coincident with vertex t0
        ([0.0, 1.0, 0.0], 0.0),  # coincident with vertex t2
        ([0.5, 0.0, 0.0], 0.0),  # on edge t0 t1
        ([0.25, 0.25, 0.0], 0.0),  # in the face
        ([0.5, -h, 0.0], h * h),  # in the plane, beside edge t0 t1
        ([-h, -h, 0.0], 2 * h * h),  # in the plane, beyond vertex t0
    ]
    x4 = [np.vstack([p, t]) for p, _ in rows]
    s = [s for _, s in rows]
    # flat triangles: collinear vertices, and two coincident vertices
    x4.append(np.array([[0.5, h, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]))
    s.append(h * h)
    x4.append(np.array([[0.5, 0.0, h], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    s.append(h * h)
    smooth = np.arange(len(s)) < len(rows)
    return np.array(x4), np.array(s), smooth


def degenerate_ee():
    """Edge-edge pairs with parallel edges, touching or coincident end points and zero-length edges, their
    exact squared distances and whether the distance is differentiable there (not so for parallel edges:
    a kink in their tilt; nor for one zero-length edge: lengthening it towards the other or away from
    it differs)."""
    h = 0.25
    rows = [
        ([[0, 0, 0], [1, 0, 0], [0.5, h, 0], [1.5, h, 0]], h * h),  # parallel, overlapping
        ([[0, 0, 0], [1, 0, 0], [1.5, h, 0], [0.5, h, 0]], h * h),  # anti-parallel, overlapping
        ([[0, 0, 0], [1, 0, 0], [2.0, h, 0], [3.0, h, 0]], 1.0 + h * h),  # parallel, apart along them
        ([[0, 0, 0], [1, 0, 0], [0.25, 0, 0], [0.75, 0, 0]], 0.0),  # collinear, one inside the other
        ([[0, 0, 0], [1, 0, 0], [1.0, 0, 0], [2.0, 0, 0]], 0.0),  # collinear, touching end to end
        ([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0]], 0.0),  # a coincident end point
        ([[0, 0, 0], [1, 0, 0], [0.5, 0, 0], [0.5, 1, 0]], 0.0),  # an end point on the other edge
        ([[0, 0, 0], [1, 0, 0], [0.5, -1, 0], [0.5, 1, 0]], 0.0),  # crossing
        ([[0, 0, 0], [1, 0, 0], [0.5, -1, h], [0.5, 1, h]], h * h),  # crossing over each other
        ([[0, 0, 0], [1, 0, 0], [1.0, 0, h], [1.0, 1, h]], h * h),  # over an end point: ties
        ([[0, 0, 0], [0, 0, 0], [0.5, h, 0], [0.5, 1, 0]], 0.25 + h * h),  # a zero-length edge
        ([[0, 0, 0], [0, 0, 0], [0.0, 0, 0], [0.0, 0, 0]], 0.0),  # both of zero length, coincident
    ]
    smooth = np.ones(len(rows), dtype=bool)
    smooth[[0, 1, 2, 3, 4, 10]] = False
    return np.array([r for r, _ in rows], float), np.array([s for _, s in rows]), smooth


DEGENERATE = {"pt": degenerate_pt, "ee": degenerate_ee}


@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_both_back_ends_agree_to_round_off_including_degenerate_pairs(random_pairs, kind):
    pytest.importorskip("numba")
    full, dist2, _ = FUNCS[kind]
    deg = DEGENERATE[kind]()[0]
    x4 = np.concatenate([random_pairs(kind, 3000, 0), deg, _rotated(deg, 1), _rotated(deg, 2)])
    for hessian in (True, False):
        s, g, H, code = full(x4, hessian=hessian, compiled=False)
        s_c, g_c, H_c, code_c = full(x4, hessian=hessian, compiled=True)
        np.testing.assert_array_equal(code_c, code)  # the same closest feature, ties included
        assert np.bincount(code, minlength=3).min() > 50  # every feature, many times
        np.testing.assert_allclose(s_c, s, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(g_c, g, rtol=1e-13, atol=1e-14)
        if hessian:
            scale = np.abs(H).max(axis=(1, 2), keepdims=True)
            np.testing.assert_allclose(H_c / scale, H / scale, rtol=0, atol=1e-13)
        else:
            assert H is None and H_c is None
    d_numpy = dist2(x4, compiled=False)
    d_compiled = dist2(x4, compiled=True)
    np.testing.assert_allclose(d_compiled, d_numpy, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(d_numpy, s, rtol=1e-13, atol=1e-15)  # the distance-only path: its own sums


@pytest.mark.usefixtures("backend")
@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_degenerate_pairs_have_their_exact_distance_and_finite_symmetric_derivatives(kind):
    full, dist2, _ = FUNCS[kind]
    x4, exact, _ = DEGENERATE[kind]()
    for y in (x4, _rotated(x4, 3)):
        s, g, H, _ = full(y)
        np.testing.assert_allclose(s, exact, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(dist2(y), s, rtol=1e-12, atol=1e-14)
        assert np.all(np.isfinite(g)) and np.all(np.isfinite(H))
        np.testing.assert_array_equal(H, H.transpose(0, 2, 1))  # each entry computed once
        np.testing.assert_allclose(g.sum(axis=1), 0.0, atol=1e-12)  # no net force from a distance
    touching = exact == 0
    np.testing.assert_allclose(full(x4)[1][touching], 0.0, atol=1e-15)  # the minimum of s >= 0


def _feature(x4, kind):
    """A label of each pair's closest feature finer than its code: which edge (point-triangle), which
    end points and active parameters (edge-edge)."""
    x = np.ascontiguousarray(np.moveaxis(x4, 0, -1))
    if kind == "pt":
        _, code, e, _, _, _ = geometry.pt_closest(x)
        return 10 * code + e
    _, code, S, T, a0, a1 = geometry.ee_closest(x)
    return 100 * code + 10 * np.where(a0, 2, S) + np.where(a1, 2, T)


def _same_feature_around(x4, kind, h):
    """Pairs whose closest feature stays the same at every point of the finite-difference stencil (the
    Hessian jumps where it changes)."""
    same = np.ones(len(x4), dtype=bool)
    for m in range(12):
        for sign in (1.0, -1.0):
            y = x4.copy()
            y[:, m // 3, m % 3] += sign * h
            same &= _feature(y, kind) == _feature(x4, kind)
    return same


@pytest.mark.usefixtures("backend")
@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_gradient_and_hessian_are_finite_differences_on_random_pairs(central_differences, random_pairs, kind):
    full, _, _ = FUNCS[kind]
    x4 = random_pairs(kind, 400, 4)[50:]  # not the parallel edges: there the distance has a kink in the tilt
    h = 1e-6
    same = _same_feature_around(x4, kind, h)
    assert same.sum() > 250
    s, g, H, code = full(x4)
    assert set(code[same].tolist()) == {0, 1, 2}
    g_fd = central_differences(lambda y: full(y, hessian=False)[0], x4, h)
    np.testing.assert_allclose(g.reshape(-1, 12), g_fd, rtol=1e-6, atol=1e-7)  # s is C1 everywhere
    H_fd = central_differences(lambda y: full(y, hessian=False)[1].reshape(-1, 12), x4, h)
    scale = np.abs(H).max(axis=(1, 2), keepdims=True)
    np.testing.assert_allclose(H[same] / scale[same], H_fd[same] / scale[same], rtol=0, atol=1e-6)


@pytest.mark.usefixtures("backend")
@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_gradient_is_the_finite_difference_on_degenerate_pairs(central_differences, kind):
    full, _, _ = FUNCS[kind]
    x4, _, smooth = DEGENERATE[kind]()
    x4 = x4[smooth]
    for y in (x4, _rotated(x4, 5)):
        g = full(y)[1].reshape(-1, 12)
        g_fd = central_differences(lambda z: full(z, hessian=False)[0], y, 1e-7)
        np.testing.assert_allclose(g, g_fd, rtol=0, atol=2e-6)  # central differences across a switch: O(h)


@pytest.mark.usefixtures("backend")
@pytest.mark.parametrize("kind", ["pt", "ee"])
def test_the_law_energy_of_a_pair_has_the_chain_rule_gradient_and_hessian(central_differences, random_pairs, kind):
    """``E = e(delta)``, ``delta = sqrt(s)`` (the law's energy, its barrier included): gradient
    ``e' grad s / (2 delta)`` and Hessian ``e'' gd gd^T + e' (H / (2 delta) - g g^T / (4 delta^3))``
    against finite differences, as :meth:`.law.SelfContact.evaluate_pairs` assembles them."""
    full, _, _ = FUNCS[kind]
    x4 = random_pairs(kind, 300, 6)[40:]  # not the parallel edges
    d, stiff = 3.0, 2.0
    s, g, H, _ = full(x4)
    x4 = x4[(s > 0.01) & (s < 0.8 * d * d)]

    def energy(y):
        return pair_law(np.sqrt(full(y, hessian=False)[0]), d, stiff)[0]

    def gradient(y):
        s, g, _, _ = full(y, hessian=False)
        delta = np.sqrt(s)
        return (pair_law(delta, d, stiff)[1] / (2 * delta))[:, None] * g.reshape(-1, 12)

    s, g, H, _ = full(x4)
    g = g.reshape(-1, 12)
    delta = np.sqrt(s)
    assert np.any(delta < BARRIER_GAP * d) and np.any(delta > BARRIER_GAP * d)  # the cubic and the barrier
    _, e1, e2 = pair_law(delta, d, stiff)
    gd = g / (2 * delta[:, None])
    hess = (e2[:, None, None] * np.einsum("pm,pn->pmn", gd, gd)
            + e1[:, None, None] * (H / (2 * delta[:, None, None])
                                   - np.einsum("pm,pn->pmn", g, g) / (4 * delta[:, None, None] ** 3)))
    np.testing.assert_allclose(gradient(x4), central_differences(energy, x4, 1e-6), rtol=1e-6, atol=1e-7)
    same = _same_feature_around(x4, kind, 1e-6)
    assert same.sum() > 0.8 * len(x4)
    h_fd = central_differences(gradient, x4, 1e-6)
    scale = np.abs(hess).max(axis=(1, 2), keepdims=True)
    np.testing.assert_allclose(hess[same] / scale[same], h_fd[same] / scale[same], rtol=0, atol=1e-6)
