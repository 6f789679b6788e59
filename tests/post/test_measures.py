"""Drape measures: rftstatic.post.measures (shadow, boundary, sharp, summary)."""

import json

import numpy as np
import pytest

from rftstatic.element.curvature import curvature_norm
from rftstatic.post.measures.boundary import boundary_loop, fold_count
from rftstatic.post.measures.shadow import drape_coefficient, shadow_area
from rftstatic.post.measures.sharp import dihedral_angles, sharp_fold_indicator
from rftstatic.post.measures.summary import drape_measures


def square_grid(n, side=1.0):
    """(n+1)² nodes on a centred square, 2n² counter-clockwise triangles."""
    u = np.linspace(-side / 2, side / 2, n + 1)
    X, Y = np.meshgrid(u, u, indexing="xy")
    x = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)]
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c = a + 1, a + n + 1
    return x, np.r_[np.c_[a, b, c + 1], np.c_[a, c + 1, c]]


def annulus(r_in, r_out, n_r, n_t):
    """Polar grid between two radii: (n_r+1)·n_t nodes, counter-clockwise triangles."""
    r = np.linspace(r_in, r_out, n_r + 1)
    t = np.linspace(0.0, 2 * np.pi, n_t, endpoint=False)
    R, T = np.meshgrid(r, t, indexing="ij")
    x = np.c_[(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel(), np.zeros(R.size)]
    i, j = np.meshgrid(np.arange(n_r), np.arange(n_t), indexing="ij")
    a = (i * n_t + j).ravel()
    b = (i * n_t + (j + 1) % n_t).ravel()
    c, d = a + n_t, b + n_t
    return x, np.r_[np.c_[a, b, d], np.c_[a, d, c]]


def rot_z(th):
    c, s = np.cos(th), np.sin(th)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# --- shadow area ------------------------------------------------------------------------------

def test_shadow_area_flat_square_is_exact():
    x, tri = square_grid(10)
    assert shadow_area(x, tri) == pytest.approx(1.0, abs=1e-13)
    assert shadow_area(x, tri, resolution=7) == pytest.approx(1.0, abs=1e-13)


@pytest.mark.parametrize("th", [0.3, np.pi / 4, 1.0])
def test_shadow_area_rotated_square_within_stated_bound(th):
    x, tri = square_grid(8)
    x = x @ rot_z(th).T
    for n in (100, 2000):
        dy = (x[:, 1].max() - x[:, 1].min()) / n
        # L'(y) jumps by (tan + cot) at each of the four corners: bound Σ|ΔL'| Δy²/8
        c, s = abs(np.cos(th)), abs(np.sin(th))
        bound = 4 * (c / s + s / c) * dy**2 / 8
        assert abs(shadow_area(x, tri, resolution=n) - 1.0) <= bound + 1e-14


def test_shadow_area_overlapping_and_reversed_triangles():
    # A = (0,0),(2,0),(0,2) and B = (1,0),(3,0),(1,2), B clockwise: A ∩ B = (1,0),(2,0),(1,1)
    x = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [1, 0, 1], [1, 2, 1], [3, 0, 1]], float)
    tri = np.array([[0, 1, 2], [3, 4, 5]])
    assert shadow_area(x, tri) == pytest.approx(2 + 2 - 0.5, rel=1e-6)
    # a triangle inside another adds nothing
    x2 = np.r_[x[:3], [[0.2, 0.2, 0.5], [0.8, 0.2, 0.5], [0.2, 0.8, 0.5]]]
    assert shadow_area(x2, tri) == pytest.approx(2.0, rel=1e-6)


def test_shadow_area_of_a_sheet_folded_onto_itself_is_half():
    x, tri = square_grid(10)
    right = x[:, 0] > 0
    x[right, 2] = 0.01 * x[right, 0]
    x[right, 0] *= -1.0                     # fold the right half over the left
    assert shadow_area(x, tri) == pytest.approx(0.5, abs=1e-12)


def test_shadow_area_of_a_disc_polygon():
    n_t = 64
    x, tri = annulus(0.2, 1.0, 4, n_t)
    polygon = 0.5 * n_t * np.sin(2 * np.pi / n_t)          # outer polygon
    hole = 0.04 * polygon
    assert shadow_area(x, tri) == pytest.approx(polygon - hole, rel=1e-6)


def test_drape_coefficient_flat_and_errors():
    x, tri = square_grid(6)
    assert drape_coefficient(x, tri, 1.0, 0.1) == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(ValueError, match="sheet_area = 0.1, disc_area = 0.2"):
        drape_coefficient(x, tri, 0.1, 0.2)
    with pytest.raises(ValueError, match=r"x.shape = \(3,\)"):
        shadow_area(np.zeros(3), tri)


# --- boundary loop ----------------------------------------------------------------------------

def test_boundary_loop_square_is_ordered_and_counter_clockwise():
    n = 12
    x, tri = square_grid(n)
    rng = np.random.default_rng(0)
    tri = tri[rng.permutation(len(tri))]
    loop = boundary_loop(tri)
    assert loop.size == 4 * n and np.unique(loop).size == loop.size
    step = np.linalg.norm(x[np.roll(loop, -1)] - x[loop], axis=1)
    assert np.allclose(step, 1.0 / n)
    q = x[loop]
    area = 0.5 * np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1])
    assert area == pytest.approx(1.0)


def test_boundary_loop_picks_the_outer_loop_of_an_annulus():
    x, tri = annulus(0.3, 1.0, 3, 40)
    loop = boundary_loop(tri, x)
    assert loop.size == 40 and np.allclose(np.hypot(x[loop, 0], x[loop, 1]), 1.0)
    with pytest.raises(ValueError, match="closed"):
        boundary_loop(np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]))


# --- folds ------------------------------------------------------------------------------------

@pytest.mark.parametrize("n_folds", [4, 8, 12])
def test_fold_count_on_noisy_wavy_outlines(n_folds):
    rng = np.random.default_rng(n_folds)
    t = np.sort(rng.uniform(0, 2 * np.pi, 600))             # irregular boundary nodes
    R, a = 0.15, 0.03
    phase = rng.uniform(0, 2 * np.pi)
    r = R + a * np.cos(n_folds * (t - phase)) + rng.normal(0, 0.03 * a, t.size)
    x = np.c_[r * np.cos(t) + 0.01, r * np.sin(t) - 0.02, np.zeros_like(t)]
    prof = fold_count(x, np.arange(t.size), centre=(0.01, -0.02))
    assert prof.count == n_folds
    crest = (phase + 2 * np.pi * np.arange(n_folds) / n_folds) % (2 * np.pi)
    d = np.angle(np.exp(1j * (prof.peak_theta[:, None] - crest[None, :])))
    assert np.abs(d).min(axis=1).max() < 0.1                # crests found where they are
    assert np.allclose(prof.r, R + a * np.cos(n_folds * (prof.theta - phase)), atol=0.15 * a)


def test_fold_count_circle_has_no_folds_and_centre_outside_is_an_error():
    t = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    x = np.c_[np.cos(t), np.sin(t), 0 * t] * (1 + 1e-4 * np.cos(37 * t))[:, None]
    assert fold_count(x, np.arange(t.size)).count == 0
    with pytest.raises(ValueError, match="misses the boundary"):
        fold_count(x, np.arange(t.size), centre=(3.0, 0.0))


# --- sharp folds ------------------------------------------------------------------------------

@pytest.mark.parametrize("phi", [0.0, 0.4, 2.5])
def test_dihedral_angle_of_a_hinge(phi):
    x = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [-np.cos(phi), 0.5, np.sin(phi)]])
    tri = np.array([[0, 2, 1], [0, 1, 3]])
    edges, ang = dihedral_angles(x, tri)
    assert edges.tolist() == [[0, 1]] and ang[0] == pytest.approx(phi, abs=1e-12)


def test_dihedral_angles_flat_mesh_and_edge_count():
    n = 5
    x, tri = square_grid(n)
    edges, ang = dihedral_angles(x, tri)
    assert len(edges) == (3 * len(tri) - 4 * n) // 2 and np.allclose(ang, 0.0)


def test_curvature_norm_is_rotation_invariant():
    rng = np.random.default_rng(1)
    K = rng.normal(size=(5, 2, 2))
    K = K + K.transpose(0, 2, 1)
    Q = np.array([[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]])
    Kr = Q @ K @ Q.T
    vec = lambda k: np.c_[k[:, 0, 0], k[:, 1, 1], 2 * k[:, 0, 1]]
    assert np.allclose(curvature_norm(vec(K)), np.linalg.norm(K, axis=(1, 2)))
    assert np.allclose(curvature_norm(vec(Kr)), curvature_norm(vec(K)))


def test_sharp_fold_indicator_locates_the_crease():
    n = 6
    x, tri = square_grid(n)
    x[:, 2] = 0.3 * np.abs(x[:, 0])                        # crease along x = 0
    curv = np.zeros((len(tri), 3))
    curv[7] = [2.0, 0.0, 2.0]
    out = sharp_fold_indicator(x, tri, curv, np.full(len(tri), 0.5))
    assert out["max_dihedral_deg"] == pytest.approx(2 * np.degrees(np.arctan(0.3)))
    assert abs(out["max_dihedral_at"][0]) < 1e-12
    assert out["max_relative_curvature"] == pytest.approx(0.5 * np.sqrt(4 + 2))
    assert out["max_relative_curvature_element"] == 7
    with pytest.raises(ValueError, match="without h"):
        sharp_fold_indicator(x, tri, curv)


def test_drape_measures_is_json_ready():
    x, tri = annulus(0.05, 0.15, 4, 96)
    t = np.arctan2(x[:, 1], x[:, 0])
    r = np.hypot(x[:, 0], x[:, 1])
    hang = np.clip(r - 0.09, 0, None)                        # outside a 9 cm disc: 6 folds
    rr = r - hang * (0.6 + 0.3 * np.cos(6 * t))
    x = np.c_[rr * np.cos(t), rr * np.sin(t), -hang]
    out = drape_measures(x, tri, sheet_area=np.pi * (0.15**2 - 0.05**2),
                         disc_area=np.pi * (0.09**2 - 0.05**2), centre=(0, 0),
                         curvature=np.zeros((len(tri), 3)), h=np.full(len(tri), 0.01))
    json.dumps(out)
    assert out["fold_count"] == 6
    assert 0.0 < out["drape_coefficient"] < 1.0
    assert out["boundary_radius_max"] == pytest.approx(0.09 + 0.06 * 0.7, rel=0.01)


def test_one_curvature_norm_for_model_size_field_and_measures():
    """Model.relative_curvature, the Eq. 29 size field and the sharp-fold indicator share one |kappa|."""
    from rftstatic.bench.problems import strip_model
    from rftstatic.element.curvature import curvature_norm as norm
    from rftstatic.remesh.sizefield import target_sizes

    model = strip_model(11, 3, element="RFT3")
    rng = np.random.default_rng(3)
    U = 1e-3 * rng.standard_normal((model.mesh.n_nodes, 3))
    k = model.curvature(U)
    h = model.mesh.element_size
    # the size field of Eq. 29 uses the same |kappa|: h = sqrt(const / |kappa|) where not clipped
    hs = target_sizes(k, const=1e-4, h_lower=1e-12, h_upper=1e12)
    np.testing.assert_allclose(hs, np.sqrt(1e-4 / norm(k)), rtol=1e-14)
    np.testing.assert_array_equal(model.relative_curvature(U), norm(k) * h)
    out = sharp_fold_indicator(model.positions(U), model.mesh.tri, k, h)
    assert out["max_relative_curvature"] == float(np.max(norm(k) * h))
    with pytest.raises(ValueError, match=r"\(E, 3\)"):
        norm(np.ones((4, 2)))
