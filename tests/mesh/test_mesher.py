"""Tests of the advancing-front mesher (rftstatic.mesh.mesher)."""

import numpy as np
import pytest

from rftstatic.errors import MeshingError
from rftstatic.mesh.mesher import BackgroundGrid, Domain, MeshQuality, generate
from rftstatic.mesh.mesher.improve import flip_edges, signed_area
from rftstatic.mesh.mesher.quality import unique_edges
from rftstatic.mesh.mesher.sizefield import limit_gradation


# ----------------------------------------------------------------------------- helpers
def assert_conforming(res, domain):
    """Valid, conforming triangulation whose boundary is exactly the discretised loops."""
    p, t = res.points, res.triangles
    assert p.dtype == np.float64 and p.shape[1] == 2
    assert t.dtype == np.int64 and t.shape[1] == 3
    assert np.all(signed_area(p, t) > 0), "every triangle counter-clockwise with positive area"
    a, b = p[res.boundary_edges[:, 0]], p[res.boundary_edges[:, 1]]
    enclosed = 0.5 * np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1])
    assert np.isclose(signed_area(p, t).sum(), enclosed, rtol=1e-12)
    assert np.isclose(enclosed, domain.area, rtol=2e-2)
    # directed half-edges: each appears once; interior edges have their reverse too
    half = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    n = len(p)
    key = half[:, 0] * n + half[:, 1]
    assert len(np.unique(key)) == len(key), "an edge is used twice in the same direction"
    rkey = half[:, 1] * n + half[:, 0]
    lone = ~np.isin(key, rkey)
    bkey = res.boundary_edges[:, 0] * n + res.boundary_edges[:, 1]
    assert set(key[lone].tolist()) == set(bkey.tolist()), "boundary edges = discretised loops exactly"
    assert np.array_equal(np.flatnonzero(res.boundary), np.unique(res.boundary_edges))
    # every node used; Euler characteristic of a disc with holes
    assert len(np.unique(t)) == n
    n_edges = len(unique_edges(t))
    assert n - n_edges + len(t) == 1 - domain.n_holes


def assert_quality(q, *, min_angle=30.0, mean_min_angle=50.0, band=0.90):
    assert q.min_angle >= min_angle, q
    assert q.mean_min_angle >= mean_min_angle, q
    assert q.band_share >= band, q


def point_field(h0, h1, slope, centre):
    """h = min(h1, h0 + slope * |x - centre|) [m]."""
    cx, cy = centre
    return lambda x, y: np.minimum(h1, h0 + slope * np.hypot(x - cx, y - cy))


# ----------------------------------------------------------------------------- cases
def _rect():
    d = Domain.rectangle(0.0, 0.0, 1.0, 0.6)
    return d, BackgroundGrid.uniform(0.025, d)


def _disc():
    d = Domain.disc(0.1, -0.2, 0.5)
    return d, BackgroundGrid.uniform(0.03, d)


def _annulus():
    d = Domain.annulus(0.0, 0.0, 0.25, 0.6)
    return d, BackgroundGrid.uniform(0.03, d)


def _graded20():
    d = Domain.rectangle(0.0, 0.0, 1.0, 1.0)
    return d, BackgroundGrid.from_function(point_field(0.005, 0.1, 0.3, (0.0, 0.0)), d)


def _graded20_disc():
    d = Domain.disc(0.0, 0.0, 1.0)
    return d, BackgroundGrid.from_function(point_field(0.005, 0.1, 0.25, (0.4, 0.1)), d)


def _graded_annulus():
    d = Domain.annulus(0.0, 0.0, 0.2, 1.0)
    return d, BackgroundGrid.from_function(lambda x, y: 0.01 + 0.15 * np.abs(np.hypot(x, y) - 0.2), d)


def _l_with_hole():
    d = Domain.polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],
                       holes=[[[0.3, 0.3], [0.3, 0.6], [0.6, 0.6], [0.6, 0.3]]])
    return d, BackgroundGrid.from_function(lambda x, y: 0.03 + 0.1 * np.abs(np.sin(3 * x) * np.cos(2 * y)), d)


CASES = {
    "rectangle": _rect,
    "disc": _disc,
    "annulus": _annulus,
    "graded_1_20_square": _graded20,
    "graded_1_20_disc": _graded20_disc,
    "graded_annulus": _graded_annulus,
    "L_with_hole": _l_with_hole,
}


@pytest.fixture(scope="module", params=list(CASES))
def meshed(request):
    domain, field = CASES[request.param]()
    return request.param, domain, field, generate(domain, field)


def test_conforming_triangulation(meshed):
    _, domain, field, res = meshed
    assert_conforming(res, domain)
    # smoothing never moved a boundary node off its discretised position
    bp, be, _ = domain.discretise(field)
    assert np.array_equal(res.points[res.boundary], bp) and np.array_equal(res.boundary_edges, be)


def test_quality_targets(meshed):
    name, _, field, res = meshed
    q = res.quality
    assert isinstance(q, MeshQuality)
    assert_quality(q)
    assert q.n_nodes == len(res.points) and q.n_triangles == len(res.triangles)
    assert q.wall_time > 0 and q.triangles_per_second > 0


def test_strong_grading_really_spans_1_to_20():
    _, field = _graded20()
    assert field.h_max / field.h_min == pytest.approx(20.0)


def test_edge_lengths_follow_size_field(meshed):
    _, domain, field, res = meshed
    p, t = res.points, res.triangles
    e = unique_edges(t)
    a, b = p[e[:, 0]], p[e[:, 1]]
    h = field.size_at(0.5 * (a + b))
    ratio = np.hypot(*(b - a).T) / h
    # unbiased in fine and coarse parts alike
    for part in (h <= np.median(h), h >= np.median(h)):
        assert 0.85 < np.median(ratio[part]) < 1.2
    # number of triangles ~ integral of the equilateral density 4 / (sqrt(3) h^2)
    area = signed_area(p, t)
    c = p[t].mean(axis=1)
    expected = np.sum(area * 4.0 / (np.sqrt(3.0) * field.size_at(c) ** 2))
    assert 0.8 < len(t) / expected < 1.25


def test_boundary_nodes_lie_on_loops():
    d, field = _annulus()
    res = generate(d, field)
    r = np.hypot(*res.points[res.boundary].T)
    assert np.all(np.isclose(r, 0.25, atol=1e-12) | np.isclose(r, 0.6, atol=1e-12))
    assert np.all(np.hypot(*res.points[~res.boundary].T) > 0.25)
    d, field = _l_with_hole()
    res = generate(d, field, smooth_iterations=0)
    corners = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2], [0.3, 0.3], [0.6, 0.6]], float)
    bp = res.points[res.boundary]
    for c in corners:
        assert np.min(np.hypot(*(bp - c).T)) == 0.0, f"corner {c} kept exactly"


def test_boundary_segments_follow_size_field():
    d = Domain.rectangle(0, 0, 2, 1)
    g = BackgroundGrid.from_function(lambda x, y: 0.02 + 0.03 * x, d)
    bp, be, _ = d.discretise(g)
    a, b = bp[be[:, 0]], bp[be[:, 1]]
    ratio = np.hypot(*(b - a).T) / g.size_at(0.5 * (a + b))
    assert np.all((ratio > 0.85) & (ratio < 1.15))


def test_deterministic():
    d, field = _graded20()
    r1, r2 = generate(d, field), generate(d, field)
    assert np.array_equal(r1.points, r2.points) and np.array_equal(r1.triangles, r2.triangles)


def test_uniform_number_and_quality_as_dict():
    d = Domain.rectangle(0, 0, 1, 1)
    res = generate(d, 0.05)
    q = res.quality.as_dict()
    assert set(q) >= {"min_angle", "mean_min_angle", "band_share", "n_nodes", "n_triangles",
                      "wall_time", "triangles_per_second"}
    assert q["n_triangles"] == len(res.triangles)


def test_remesh_from_old_mesh_boundary_and_samples():
    """Remeshing cycle of section 5.2: old mesh -> h_target samples -> grid -> new mesh."""
    d, field = _rect()
    old = generate(d, field)
    half = np.concatenate([old.triangles[:, [0, 1]], old.triangles[:, [1, 2]], old.triangles[:, [2, 0]]])
    n = len(old.points)
    lone = ~np.isin(half[:, 0] * n + half[:, 1], half[:, 1] * n + half[:, 0])
    new_domain = Domain.from_segments(old.points, half[lone])
    assert len(new_domain.loops[0].vertices) == 4          # collinear boundary nodes merged
    c = old.points[old.triangles].mean(axis=1)
    h_target = np.where(c[:, 0] < 0.5, 0.01, 0.05)
    grid = BackgroundGrid.from_samples(c, h_target, new_domain, spacing=0.01, h_lower=0.01, h_upper=0.05)
    res = generate(new_domain, grid)
    assert_conforming(res, new_domain)
    assert_quality(res.quality)


# ----------------------------------------------------------------------------- size field
def test_bilinear_is_exact_for_linear_fields():
    g = BackgroundGrid.from_function(lambda x, y: 1.0 + 2.0 * x + 3.0 * y, (0, 0, 1, 2), spacing=0.1,
                                     gradation=None)
    pts = np.random.default_rng(0).uniform([0, 0], [1, 2], (200, 2))
    assert np.allclose(g.size_at(pts), 1.0 + 2.0 * pts[:, 0] + 3.0 * pts[:, 1])
    # outside points are clamped to the grid
    assert g.size_at([[-5.0, 0.0]])[0] == pytest.approx(1.0)


def test_gradation_limit_is_satisfied_and_maximal():
    rng = np.random.default_rng(1)
    s, gr = 0.05, 1.3
    v = rng.uniform(0.01, 1.0, (40, 30))
    h = limit_gradation(v, s, gr)
    assert np.all(h <= v)
    for dx, dy in ((1, 0), (0, 1), (1, 1), (1, -1)):
        a = h[max(dx, 0):h.shape[0] + min(dx, 0), max(dy, 0):h.shape[1] + min(dy, 0)]
        b = h[max(-dx, 0):h.shape[0] + min(-dx, 0), max(-dy, 0):h.shape[1] + min(-dy, 0)]
        lim = (gr - 1) * s * np.hypot(dx, dy) * (1 + 1e-12)
        assert np.all(np.abs(a - b) <= lim)
    # maximal: equal to brute-force Bellman-Ford relaxation over the 8 neighbours
    ref = v.copy()
    while True:
        old = ref.copy()
        for dx, dy in ((1, 0), (0, 1), (1, 1), (1, -1), (-1, 0), (0, -1), (-1, -1), (-1, 1)):
            sh = np.full_like(ref, np.inf)
            src = ref[max(-dx, 0):ref.shape[0] - max(dx, 0), max(-dy, 0):ref.shape[1] - max(dy, 0)]
            sh[max(dx, 0):ref.shape[0] - max(-dx, 0), max(dy, 0):ref.shape[1] - max(-dy, 0)] = src
            ref = np.minimum(ref, sh + (gr - 1) * s * np.hypot(dx, dy))
        if np.array_equal(old, ref):
            break
    assert np.allclose(h, ref, rtol=0, atol=1e-14)
    assert np.allclose(limit_gradation(h, s, gr), h, rtol=0, atol=1e-14)
    # a single small value spreads as a cone of slope gradation - 1
    v = np.ones((21, 21))
    v[10, 10] = 0.1
    h = limit_gradation(v, s, gr)
    assert h[10, 15] == pytest.approx(0.1 + 0.3 * 5 * s)
    assert h[15, 15] == pytest.approx(0.1 + 0.3 * 5 * np.sqrt(2) * s)


def test_from_samples_minimum_per_cell_and_fill():
    pts = np.array([[0.0, 0.0], [0.01, 0.0], [1.0, 1.0]])
    g = BackgroundGrid.from_samples(pts, [0.5, 0.2, 0.8], (0, 0, 1, 1), spacing=0.25, gradation=None)
    assert g.values[0, 0] == 0.2            # minimum of the two samples in that cell
    assert g.values[4, 4] == 0.8
    assert g.values[3, 4] == 0.8            # filled from the nearest sample
    assert g.values[1, 0] == 0.2


# ----------------------------------------------------------------------------- flips
def test_flips_choose_the_delaunay_diagonal():
    p = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.1], [0.5, -0.1]])
    t = np.array([[0, 3, 2], [3, 1, 2]])   # short diagonal (2, 3): already Delaunay
    assert flip_edges(p, t) == 0
    t = np.array([[0, 1, 2], [1, 0, 3]])   # long diagonal (0, 1): flipped to (2, 3)
    assert flip_edges(p, t) == 1
    assert np.all(signed_area(p, t) > 0)
    assert set(map(frozenset, unique_edges(t).tolist())) >= {frozenset((2, 3))}


# ----------------------------------------------------------------------------- bad input
def test_errors_are_value_errors_with_fixes():
    assert issubclass(MeshingError, ValueError)
    with pytest.raises(MeshingError, match="self-intersecting"):
        Domain.polygon([[0, 0], [1, 1], [1, 0], [0, 1]])
    with pytest.raises(MeshingError, match="self-intersecting"):
        Domain.polygon([[0, 0], [1, 0], [1, 1], [0, 1]], holes=[[[0.5, 0.5], [1.5, 0.5], [1.5, 0.6]]])
    with pytest.raises(MeshingError, match="outside the outer loop"):
        Domain.polygon([[0, 0], [1, 0], [1, 1], [0, 1]], holes=[[[2, 2], [3, 2], [3, 3]]])
    with pytest.raises(MeshingError, match="at least 3"):
        Domain.polygon([[0, 0], [1, 0]])
    with pytest.raises(MeshingError, match="r_in < r_out"):
        Domain.annulus(0, 0, 1.0, 0.5)
    with pytest.raises(MeshingError, match="non-closed"):
        Domain.from_segments([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1], [1, 2], [2, 3]])
    d = Domain.rectangle(0, 0, 1, 1)
    with pytest.raises(MeshingError, match="h_lower .* larger than h_upper"):
        BackgroundGrid.from_function(lambda x, y: 0.1 + 0 * x, d, h_lower=0.2, h_upper=0.1)
    with pytest.raises(MeshingError, match="positive"):
        BackgroundGrid.from_function(lambda x, y: x - 0.5, d)
    with pytest.raises(MeshingError, match="larger than the outer loop|exceeds the domain"):
        generate(d, 5.0)
    with pytest.raises(MeshingError, match="larger than the hole"):
        generate(Domain.annulus(0, 0, 0.01, 1.0), 0.1)
    with pytest.raises(MeshingError, match="background grid covers"):
        generate(Domain.rectangle(0, 0, 2, 2), BackgroundGrid.uniform(0.1, (0, 0, 1, 1)))
    with pytest.raises(MeshingError, match="len\\(points\\) = 2, but len\\(sizes\\) = 1"):
        BackgroundGrid.from_samples([[0, 0], [1, 1]], [0.1], d)


def test_bench_main_runs_small(capsys):
    from rftstatic.bench import mesher as bench

    bench.main(["--nodes", "300"])
    out = capsys.readouterr().out
    assert "tri/s" in out


@pytest.mark.slow
def test_speed_20k_nodes():
    """Requirement: >= 5000 triangles/s; a 20k-node mesh in seconds (timed, hence slow)."""
    d = Domain.rectangle(0.0, 0.0, 1.0, 1.0)
    res = generate(d, np.sqrt(2.0 / (np.sqrt(3.0) * 20_000)))
    assert 18_000 < res.quality.n_nodes < 22_000
    assert res.quality.triangles_per_second >= 5_000
    assert res.quality.wall_time < 20.0


def test_loop_orientation_is_normalised():
    outer_cw = [[0, 0], [0, 1], [1, 1], [1, 0]]
    hole_ccw = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]
    d = Domain.polygon(outer_cw, holes=[hole_ccw])
    assert d.loops[0].signed_area > 0 > d.loops[1].signed_area
    assert d.area == pytest.approx(1.0 - 0.04)
    res = generate(d, 0.1)
    assert_conforming(res, d)
