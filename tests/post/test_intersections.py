"""Self-intersection check: rftstatic.post.measures.intersections (crossing pairs, smallest distance)."""

import itertools
import math

import numpy as np
import pytest

from rftstatic.post.measures.intersections import (
    intersecting_pairs,
    self_intersections,
    smallest_distance,
    triangle_distances,
)

T1 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def two(t2, t1=T1):
    """Two separate triangles (6 nodes): x (6, 3), tri (2, 3)."""
    return np.r_[t1, np.asarray(t2, float)], np.array([[0, 1, 2], [3, 4, 5]])


def grid(nx, ny, lx=1.0, ly=1.0, u=None):
    """(nx+1)(ny+1) nodes in the z = 0 plane, 2 nx ny counter-clockwise triangles."""
    u = np.linspace(0.0, lx, nx + 1) if u is None else u
    v = np.linspace(0.0, ly, ny + 1)
    X, Y = np.meshgrid(u, v, indexing="xy")
    x = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    a = (j * (nx + 1) + i).ravel()
    b, c = a + 1, a + nx + 1
    return x, np.r_[np.c_[a, b, c + 1], np.c_[a, c + 1, c]]


def rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q


# --- hand-built pairs -------------------------------------------------------------------------

def test_edge_piercing_the_face_is_one_pair_at_distance_zero():
    x, tri = two([[0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5]])
    assert intersecting_pairs(x, tri).tolist() == [[0, 1]]
    assert smallest_distance(x, tri, within=10.0) == (0.0, (0, 1))
    R = rotation(1)                                           # a rigid motion changes nothing
    assert intersecting_pairs(x @ R.T + 3.0, tri).tolist() == [[0, 1]]


def test_crossing_found_from_either_triangle():
    # T2 (plane x = 0.5) meets T1's edge y = 0 only at its boundary, but T1's hypotenuse pierces T2
    x, tri = two([[0.5, 0.0, -1.0], [0.5, 0.0, 1.0], [0.5, 1.0, 0.0]])
    assert len(intersecting_pairs(x, tri)) == 1
    x, tri = two([[0.5, 0.0, -1.0], [0.5, 0.0, 1.0], [0.5, -1.0, 0.0]])    # the same, turned away
    assert len(intersecting_pairs(x, tri)) == 0
    assert triangle_distances(x, tri, [[0, 1]])[0] == pytest.approx(0.0, abs=1e-15)


def test_touching_is_not_intersecting_within_tol():
    # a vertex on the face: touching
    x, tri = two([[0.2, 0.2, 0.0], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]])
    assert len(intersecting_pairs(x, tri)) == 0
    assert smallest_distance(x, tri, within=10.0)[0] == 0.0
    # 1e-12 through the face: within the default tol (1e-9 mean edges), unless tol = 0
    x[3, 2] = -1e-12
    assert len(intersecting_pairs(x, tri)) == 0
    assert len(intersecting_pairs(x, tri, tol=0.0)) == 1
    assert smallest_distance(x, tri, within=10.0)[0] == pytest.approx(1e-12, rel=1e-3)
    x[3, 2] = -1e-6                                           # a real penetration
    assert len(intersecting_pairs(x, tri)) == 1


def test_edge_through_a_vertex_and_coplanar_overlap_are_touching():
    # T2's edge passes through T1's vertex (1, 0, 0); T1 lies on one side of T2's plane
    x, tri = two([[1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [2.0, 0.5, 0.0]])
    assert len(intersecting_pairs(x, tri)) == 0
    assert smallest_distance(x, tri, within=10.0)[0] == pytest.approx(0.0, abs=1e-15)
    # two layers lying on each other, overlapping in area: zero thickness, not a crossing
    x, tri = two(T1 + [0.2, 0.2, 0.0])
    assert len(intersecting_pairs(x, tri)) == 0
    assert smallest_distance(x, tri, within=10.0)[0] == 0.0


def test_parallel_triangles_at_height_h():
    for h in (1e-4, 0.03, 0.7):
        x, tri = two(T1 + [0.1, 0.1, h])
        assert len(intersecting_pairs(x, tri)) == 0
        d, pair = smallest_distance(x, tri, within=10.0)
        assert d == pytest.approx(h, rel=1e-12) and pair == (0, 1)
    x, tri = two(T1 + [0.1, 0.1, 0.7])
    assert smallest_distance(x, tri, within=0.5) == (math.inf, (-1, -1))   # nothing within 0.5


def test_skew_edges_distance_against_the_line_formula():
    rng = np.random.default_rng(3)
    for _ in range(5):
        d = rng.uniform(0.05, 1.0)
        th = rng.uniform(0.3, np.pi - 0.3)                    # angle between the two edges
        e2 = np.array([np.cos(th), np.sin(th), 0.0])
        ta = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]          # edge on the x-axis, below
        tb = [-e2 + [0, 0, d], e2 + [0, 0, d], [0.0, 0.0, d + 1.0]]        # edge at height d, above
        x, tri = two(tb, ta)
        R = rotation(int(rng.integers(1000)))
        x = x @ R.T
        p1, u1, p2, u2 = x[0], x[1] - x[0], x[3], x[4] - x[3]
        n = np.cross(u1, u2)
        exact = abs(np.dot(p2 - p1, n)) / np.linalg.norm(n)
        assert exact == pytest.approx(d, rel=1e-12)
        assert smallest_distance(x, tri, within=10.0)[0] == pytest.approx(exact, rel=1e-10)


def test_vertex_above_the_face():
    x, tri = two([[0.25, 0.25, 0.3], [0.3, 0.3, 2.0], [0.2, 0.3, 2.0]])
    assert triangle_distances(x, tri, [[0, 1]])[0] == pytest.approx(0.3, rel=1e-12)


def test_pairs_sharing_a_node_are_excluded():
    # T2 shares node 0 with T1 and cuts right through it
    x = np.r_[T1, [[0.3, 0.3, 0.5], [0.3, 0.3, -0.5]]]
    tri = np.array([[0, 1, 2], [0, 3, 4]])
    assert len(intersecting_pairs(x, tri)) == 0
    assert smallest_distance(x, tri, within=10.0) == (math.inf, (-1, -1))
    x = np.r_[x, [[0.3, 0.3, 0.5]]]                           # the same triangle on its own node
    tri = np.array([[0, 1, 2], [5, 3, 4]])
    assert intersecting_pairs(x, tri).tolist() == [[0, 1]]


# --- sheets ------------------------------------------------------------------------------------

def test_flat_sheet_no_pairs_and_the_in_layer_floor():
    x, tri = grid(12, 10, 1.2, 1.0)
    h = 0.1
    assert len(intersecting_pairs(x, tri)) == 0
    d, (i, j) = smallest_distance(x, tri)
    assert d == pytest.approx(h / math.sqrt(2), rel=1e-12)   # a vertex to the next-but-one diagonal
    assert not set(tri[i]) & set(tri[j])
    s = self_intersections(x, tri)
    assert (s["pairs"], s["triangles"], s["area_fraction"]) == (0, 0, 0.0)


def folded_strip(push: float, n=(60, 10), length=6.0, width=1.0, r=0.15):
    """A strip folded back over itself round a half cylinder of radius r; the returning layer
    descends by ``push`` over its length (push > 2 r: its end goes through the bottom layer)."""
    x, tri = grid(*n, length, width)
    s = x[:, 0].copy()
    s1 = 0.5 * (length - np.pi * r)                            # flat bottom, fold, returning leg
    th = np.clip((s - s1) / r, 0.0, np.pi)
    back = np.maximum(s - s1 - np.pi * r, 0.0)
    x[:, 0] = np.where(s < s1, s, s1 + r * np.sin(th) - back)
    x[:, 2] = np.where(s < s1, 0.0, r * (1 - np.cos(th)) - push * back / s1)
    return x, tri, s1


def test_smoothly_folded_sheet_does_not_intersect():
    x, tri, s1 = folded_strip(0.0)
    arc = grid(60, 10, 6.0, 1.0)[0][tri][:, :, 0].mean(axis=1)
    assert len(intersecting_pairs(x, tri)) == 0
    d, (i, j) = smallest_distance(x, tri, within=1.0)
    # the in-layer floor (0.1 / sqrt 2 flat, a little less round the fold), not the 0.3 gap
    assert 0.06 < d <= 0.1 / math.sqrt(2) + 1e-12 and abs(arc[i] - arc[j]) < 0.3
    x, tri, _ = folded_strip(0.25)                             # its end comes down to 0.05 above the bottom
    assert len(intersecting_pairs(x, tri)) == 0
    d, (i, j) = smallest_distance(x, tri, within=1.0)
    assert d == pytest.approx(0.05, rel=1e-9) and abs(arc[i] - arc[j]) > 5.0


def test_strip_pushed_through_itself():
    x, tri, s1 = folded_strip(0.6)                             # crosses z = 0 at s1 / 3 before its end
    pairs = intersecting_pairs(x, tri)
    assert len(pairs) > 0
    cz = x[tri].mean(axis=1)
    s_tri = grid(60, 10, 6.0, 1.0)[0][tri][:, :, 0].mean(axis=1)     # arc length along the strip
    bottom = s_tri[pairs] < s1
    assert (bottom.sum(axis=1) == 1).all()                     # always one of each layer
    # the returning leg crosses z = 0 at x = s1 - 2r s1 / push ... its triangles lie there
    x_cross = s1 - (2 * 0.15 / 0.6) * s1
    assert np.abs(cz[pairs][:, :, 0] - x_cross).max() < 0.25
    # every one of the 10 triangle rows across the width has crossings
    y_rows = np.unique(np.floor(cz[pairs.ravel(), 1] / 0.1))
    assert len(y_rows) == 10
    assert smallest_distance(x, tri)[0] == 0.0
    s = self_intersections(x, tri)
    assert s["pairs"] == len(pairs) and s["triangles"] == len(np.unique(pairs))
    quick = self_intersections(x, tri, distance=False)              # crossings only
    assert quick["pairs"] == s["pairs"] and quick["area_fraction"] == s["area_fraction"]
    assert quick["smallest_distance"] is None and quick["smallest_distance_pair"] is None
    area = 0.5 * np.linalg.norm(np.cross(*(x[tri][:, 1:] - x[tri][:, :1]).transpose(1, 0, 2)), axis=1)
    assert s["area_fraction"] == pytest.approx(area[np.unique(pairs)].sum() / area.sum())


# --- against a brute-force reference -----------------------------------------------------------

def _seg_tri(p, q, a, b, c):
    """Möller-Trumbore: segment pq strictly through the interior of triangle abc."""
    e1, e2, d = b - a, c - a, q - p
    h = np.cross(d, e2)
    det = e1 @ h
    if det == 0.0:
        return False
    s = p - a
    u = (s @ h) / det
    qv = np.cross(s, e1)
    v = (d @ qv) / det
    t = (e2 @ qv) / det
    return 0 < u and 0 < v and u + v < 1 and 0 < t < 1


def _point_segment(p, a, b):
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return np.linalg.norm(p - a - t * (b - a))


def _point_triangle(p, a, b, c):
    n = np.cross(b - a, c - a)
    lam = np.linalg.solve(np.c_[b - a, c - a, n], p - a)     # p = a + l1 (b - a) + l2 (c - a) + l3 n
    if lam[0] >= 0 and lam[1] >= 0 and lam[0] + lam[1] <= 1:
        return abs(lam[2]) * np.linalg.norm(n)
    return min(_point_segment(p, a, b), _point_segment(p, b, c), _point_segment(p, c, a))


def _segment_segment(p1, q1, p2, q2):
    best = min(_point_segment(p1, p2, q2), _point_segment(q1, p2, q2),
               _point_segment(p2, p1, q1), _point_segment(q2, p1, q1))
    d1, d2 = q1 - p1, q2 - p2
    A = np.array([[d1 @ d1, -d1 @ d2], [d1 @ d2, -d2 @ d2]])
    if abs(np.linalg.det(A)) > 1e-12:
        s, t = np.linalg.solve(A, [(p2 - p1) @ d1, (p2 - p1) @ d2])
        if 0 < s < 1 and 0 < t < 1:
            best = min(best, np.linalg.norm(p1 + s * d1 - p2 - t * d2))
    return best


def brute_force(x, tri):
    """All non-adjacent pairs: crossing flags and distances, one pair at a time."""
    out = {}
    for i, j in itertools.combinations(range(len(tri)), 2):
        if set(tri[i]) & set(tri[j]):
            continue
        P, Q = x[tri[i]], x[tri[j]]
        cross = any(_seg_tri(A[k], A[(k + 1) % 3], *B) for A, B in ((P, Q), (Q, P)) for k in range(3))
        d = 0.0 if cross else min(
            [_point_triangle(v, *Q) for v in P] + [_point_triangle(v, *P) for v in Q]
            + [_segment_segment(P[k], P[(k + 1) % 3], Q[m], Q[(m + 1) % 3]) for k in range(3) for m in range(3)])
        out[i, j] = (cross, d)
    return out


@pytest.mark.parametrize("seed, amplitude, graded", [(0, 0.8, False), (1, 0.3, False), (2, 0.8, True)])
def test_agrees_with_brute_force_on_a_crumpled_mesh(seed, amplitude, graded):
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, 5) ** 2 if graded else None  # graded: several size classes
    x, tri = grid(4, 4, u=u)
    x = x + amplitude * 0.25 * rng.normal(size=x.shape)
    ref = brute_force(x, tri)
    want = sorted(k for k, (c, _) in ref.items() if c)
    got = intersecting_pairs(x, tri)
    assert [tuple(p) for p in got] == want
    assert len(want) > 0 or amplitude < 0.5                    # the crumpled ones do cross
    d, pair = smallest_distance(x, tri, within=10.0)
    dmin = min(d for _, d in ref.values())
    assert d == pytest.approx(dmin, rel=1e-9, abs=1e-14)
    assert ref[pair][1] == pytest.approx(dmin, rel=1e-9, abs=1e-14)
    keys = np.array(list(ref))
    dist = triangle_distances(x, tri, keys)
    np.testing.assert_allclose(dist, [ref[tuple(k)][1] for k in keys], rtol=1e-9, atol=1e-14)
    # a small search radius finds the same smallest distance among the pairs it covers
    w = 0.05
    near = [d for _, d in ref.values() if d < w]
    assert smallest_distance(x, tri, within=w)[0] == (pytest.approx(min(near)) if near else math.inf)


# --- input checks ------------------------------------------------------------------------------

def test_bad_input_names_the_function():
    x, tri = two(T1 + [0, 0, 1.0])
    with pytest.raises(ValueError, match="intersecting_pairs: x.shape"):
        intersecting_pairs(x[:, :2], tri)
    with pytest.raises(ValueError, match="smallest_distance: tri"):
        smallest_distance(x, tri + 10)
    with pytest.raises(ValueError, match="smallest_distance: within"):
        smallest_distance(x, tri, within=0.0)
    with pytest.raises(ValueError, match="self_intersections: tol"):
        self_intersections(x, tri, tol=-1.0)
    x[0, 0] = np.nan
    with pytest.raises(ValueError, match="self_intersections: x holds 1 non-finite"):
        self_intersections(x, tri)
    with pytest.raises(ValueError, match="triangle_distances: pairs"):
        triangle_distances(np.ones_like(x), tri, [[0, 2]])
