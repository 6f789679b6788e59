"""Self-contact in the explicit solver: a fast layer thrown onto the clamped half of a folded strip
does not pass through it (0 crossings by the independent test at every saved state) where the same
run without self-contact does; the explicit force is the static law's gradient; the velocity filter
conserves momentum, only removes approach and meets its bound; the near-pair cache keeps every pair
within the radius."""

import numpy as np
import pytest

from rftstatic.contact.self_contact.broad_phase import find_pairs
from rftstatic.contact.self_contact.law import SelfContact
from rftstatic.contact.self_contact.near_pairs import NearPairCache, pair_nodes
from rftstatic.contact.self_contact.distance import edge_edge_distance2, point_triangle_distance2
from rftstatic.contact.self_contact.step_filter import StepFilter
from rftstatic.element.explicit_force import ForceKernel
from rftstatic.mesh.trimesh import TriMesh, rectangle
from rftstatic.model.state import State
from rftstatic.post.measures.intersections import intersecting_pairs, smallest_distance
from rftstatic.solvers.explicit import run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions

from tests.contact.self_contact.test_static_fold import D, folded_strip


def _thrown(self_contact, speed=3.0, mass_scale=1.0):
    """The folded strip of the static test, its upper layer thrown down at ``speed`` [m/s] onto the
    clamped lower half 2 cm below it (it reaches it within ~7 ms)."""
    model, U0, _ = folded_strip(self_contact)
    V0 = np.zeros_like(U0)
    upper = model.positions(U0)[:, 2] > 0.015
    V0[upper, 2] = -speed
    times = np.linspace(0.0, 0.02, 41)
    run = run_explicit(model, ExplicitOptions(t_end=0.02, alpha=5.0, mass_scale=mass_scale, progress=False,
                                              start="given"), U0=U0, V0=V0, frame_times=times)
    return model, run


@pytest.mark.parametrize("mass_scale", [1.0, 100.0])
def test_a_fast_layer_does_not_pass_through_the_folded_strip(mass_scale):
    model, run = _thrown(False, mass_scale=mass_scale)
    tri = model.mesh.tri
    crossed = [len(intersecting_pairs(model.positions(U), tri)) for _, U in run.frames]
    assert max(crossed) > 0  # without self-contact the layer goes through
    model, run = _thrown(True, mass_scale=mass_scale)
    assert len(run.frames) >= 40
    closest = np.inf
    for t, U in run.frames:
        x = model.positions(U)
        assert len(intersecting_pairs(x, tri)) == 0, f"crossing at t = {t:.4f} s"
        closest = min(closest, smallest_distance(x, tri)[0])
    assert 0.5 * D <= closest < D  # the layer came down onto the strip, and stayed apart by half the thickness
    stats = model.self_contact.stats
    assert stats.impulses > 0 and stats.filter_work_steps > 0
    assert np.isfinite(run.history["total"]).all()


def test_explicit_force_is_the_static_gradient():
    model, U0, _ = folded_strip(True)
    U = U0.copy()
    U[model.positions(U0)[:, 2] > 0.015, 2] -= 0.02 - 0.6 * D  # the upper layer 0.6 d above the lower one
    x = model.positions(U)
    assert model.self_contact.evaluate(x, tangent=False).n_active > 0
    state = State.initial(model)
    kernel = ForceKernel(model, backend="numpy")
    f = kernel(U, pairs=state.self_pairs)
    np.testing.assert_allclose(f, model.internal_force(U), rtol=1e-10, atol=1e-12 * np.abs(f).max())
    _, W = kernel(U, energy=True, pairs=state.self_pairs)
    e = model.energies(U)
    assert W == pytest.approx(e["bending"] + e["membrane"] + e["self_contact"], rel=1e-10)


def _two_sheets():
    """Two separate 4 x 4 cm sheets of 5 x 5 nodes side by side in the reference (one mesh of two
    pieces), their reference positions and a mesh."""
    a = rectangle(0.04, 0.04, 5, 5)
    X = np.concatenate([a.X, a.X + [0.06, 0.0]])
    tri = np.concatenate([a.tri, a.tri + a.n_nodes])
    return TriMesh(X, tri), a.n_nodes


def test_velocity_filter_conserves_momentum_and_meets_its_bound():
    rng = np.random.default_rng(3)
    mesh, n = _two_sheets()
    sc = SelfContact(mesh, D, 1.0)
    X = mesh.X3
    # the second sheet 0.8 d over the first, shifted by a third of an element and a little rough
    x = X.copy()
    right = np.arange(mesh.n_nodes) >= n
    x[right, 0] -= 0.06 - 0.0033
    x[right, 1] += 0.0021
    x[right, 2] = 0.8 * D + 2e-5 * rng.uniform(-1, 1, n)
    assert len(intersecting_pairs(x, mesh.tri)) == 0
    mass = rng.uniform(0.5, 2.0, mesh.n_nodes)
    minv = np.repeat(1.0 / mass[:, None], 3, axis=1)
    v = 0.01 * rng.standard_normal((mesh.n_nodes, 3))
    v[right, 2] -= 1.0  # the right half comes down fast
    dt = 1e-3
    cache = sc.new_pairs()
    cache.pairs(sc.prims, x, D)
    filt = StepFilter(sc, minv)
    p0 = np.einsum("n,ni->i", mass, v)
    k0 = 0.5 * np.einsum("n,ni,ni->", mass, v, v)
    w = v.copy()
    removed = filt(cache, x, w, dt)
    np.testing.assert_allclose(np.einsum("n,ni->i", mass, w), p0, atol=1e-12 * np.abs(mass[:, None] * v).sum())
    k1 = 0.5 * np.einsum("n,ni,ni->", mass, w, w)
    assert removed == pytest.approx(k0 - k1) and 0 < removed < k0
    # every near pair keeps at least min_fraction of its gap along the filtered step
    for t in np.linspace(0, 1, 11):
        y = x + t * dt * w
        s_pt = point_triangle_distance2(y[cache.npt])
        s_ee = edge_edge_distance2(y[cache.nee])
        assert np.all(np.sqrt(s_pt) >= sc.min_fraction * cache.dist_pt * (1 - 1e-9))
        assert np.all(np.sqrt(s_ee) >= sc.min_fraction * cache.dist_ee * (1 - 1e-9))
    assert cache.stats.impulses > 0 and cache.stats.ccd_limited == 0  # the impulses did it, not the fail-safe
    # and the gap floor: pairs that started above it end the step above half the thickness
    y = x + dt * w
    for rows, d0, dist2 in ((cache.npt, cache.dist_pt, point_triangle_distance2),
                            (cache.nee, cache.dist_ee, edge_edge_distance2)):
        above = d0 > filt.gap_floor
        assert above.any() and np.all(np.sqrt(dist2(y[rows[above]])) >= 0.5 * D)
    # the unfiltered step does bring pairs through each other: some pair's distance passes through ~0
    closest = min(float(np.sqrt(point_triangle_distance2((x + t * dt * v)[cache.npt])).min())
                  for t in np.linspace(0, 1, 101))
    assert closest < 0.05 * D


def test_near_pair_cache_keeps_every_pair_within_the_radius():
    rng = np.random.default_rng(5)
    mesh = rectangle(0.1, 0.1, 11, 11, pattern="alternate")
    sc = SelfContact(mesh, D, 1.0)
    X = mesh.X3
    x = X.copy()
    x[:, 2] = 0.02 * np.sin(40 * X[:, 0]) * np.cos(30 * X[:, 1])
    x[X[:, 0] > 0.05, 2] *= -1  # a crease, layers close near it
    x += 1e-3 * rng.standard_normal(x.shape)
    cache = NearPairCache(sc.margin)
    cache.rebuild(sc.prims, x, D)
    r = D + sc.margin
    raw = find_pairs(sc.prims, x, r)
    npt, nee = pair_nodes(sc.prims, raw)
    dpt, dee = np.sqrt(point_triangle_distance2(x[npt])), np.sqrt(edge_edge_distance2(x[nee]))
    assert len(cache.npt) == int((dpt < r).sum()) and len(cache.nee) == int((dee < r).sum())
    assert len(cache.npt) + len(cache.nee) < len(raw)
    # the translation-free motion: a whole-sheet translation does not rebuild, and the bounds hold
    y = x + np.array([0.3, -0.2, 0.5]) + 0.2 * sc.margin * rng.uniform(-1, 1, x.shape) / np.sqrt(3)
    before = cache.builds
    cache.pairs(sc.prims, y, D)
    assert cache.builds == before
    lb = cache.lower_bounds(cache.motion(y)[0])
    q = len(cache.npt)
    assert np.all(np.sqrt(point_triangle_distance2(y[cache.npt])) >= lb[:q] - 1e-15)
    assert np.all(np.sqrt(edge_edge_distance2(y[cache.nee])) >= lb[q:] - 1e-15)


def test_dynamic_scene_with_self_contact_reports_its_counters(tmp_path):
    """contact.self = true runs in a dynamic scene (it was a SceneError) and summary.json states the
    pair counts and costs next to the crossing check of every saved state."""
    from rftstatic.app.registry import run_scene
    from rftstatic.scenes.schema import load_scene

    scene = load_scene("hang-20", ["mesh.nodes=[9, 9]", "dynamics.t_end=0.05", "dynamics.samples=4",
                                   "dynamics.frames=[0.0, 0.05]", "contact.self=true"])
    s = run_scene(scene, tmp_path / "out", progress=False, figures=False)
    sc = s["self_contact"]
    assert sc["rebuilds"] >= 1 and sc["filter_steps"] == s["steps"]
    assert sc["thickness"] == pytest.approx(0.05)  # cm
    for key in ("pairs", "max_pairs", "broad_phase_s", "force_s", "filter_s", "impulses", "ccd_limited"):
        assert key in sc
    assert s["self_intersections"]["pairs"] == 0 and max(s["self_intersections"]["pairs_saved"]) == 0


@pytest.mark.parametrize("floor", [-0.1, 1.0, float("nan")])
def test_step_filter_refuses_a_gap_floor_outside_its_range(floor):
    mesh, _ = _two_sheets()
    sc = SelfContact(mesh, D, 1.0)
    with pytest.raises(ValueError, match="floor must be in"):
        StepFilter(sc, np.ones((mesh.n_nodes, 3)), floor=floor)
