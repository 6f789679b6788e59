"""Continuous collision detection of the sheet's edges against an obstacle's sharp edges in the explicit
analyses (:mod:`rftstatic.contact.feature_sweep`): exact crossing times and a thrown sheet that no rim cuts."""

import meshio
import numpy as np

from rftstatic.contact.feature_sweep import SHY, corner_crossing_times, edge_crossing_times, unit_roots
from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
from rftstatic.scenes.build import build_model
from rftstatic.scenes.schema import scene_from_dict

RIM_P, RIM_Q = np.array([[0.0, -1.0, 0.0]]), np.array([[0.0, 1.0, 0.0]])
RIM_N = np.array([[1.0, 0.0, 1.0]]) / np.sqrt(2.0)  # a box edge along y: top face +z, side face +x


def _t(a0, b0, da, db):
    return edge_crossing_times(*(np.atleast_2d(np.asarray(v, float)) for v in (a0, b0, da, db)), RIM_P, RIM_Q, RIM_N)[0]


def test_crossing_times_of_an_edge_swept_over_a_rim():
    # an edge across the rim 1 mm above it, stepped 3 mm down: it meets the rim a third of the way
    assert np.isclose(_t([-0.5, 0.0, 0.001], [0.5, 0.2, 0.001], [0, 0, -0.003], [0, 0, -0.003]), 1.0 / 3.0)
    # tilted while it falls (a quadratic f): the time where its interior passes the rim line
    t = _t([-0.5, 0.0, 0.001], [0.5, 0.0, 0.002], [0, 0, -0.004], [0, 0, -0.002])
    z = lambda s, t: (1 - s) * (0.001 - 0.004 * t) + s * (0.002 - 0.002 * t)  # noqa: E731 (height at x = 0)
    assert 0 < t < 1 and abs(z(0.5, t)) < 1e-12
    # stepped short of it, moving away, beside its end, parallel to it: no crossing
    assert np.isinf(_t([-0.5, 0.0, 0.004], [0.5, 0.0, 0.004], [0, 0, -0.003], [0, 0, -0.003]))
    assert np.isinf(_t([-0.5, 0.0, 0.001], [0.5, 0.0, 0.001], [0, 0, 0.003], [0, 0, 0.003]))
    assert np.isinf(_t([-0.5, 1.5, 0.001], [0.5, 1.6, 0.001], [0, 0, -0.003], [0, 0, -0.003]))
    assert np.isinf(_t([0.1, -0.5, 0.001], [0.1, 0.5, 0.001], [-0.2, 0, -0.003], [-0.2, 0, -0.003]))
    # lying on the rim: pushed into the box it crosses at once, lifted off or slid along it does not
    on = ([-0.5, 0.0, 0.0], [0.5, 0.0, 0.0])
    assert _t(*on, [0, 0, -0.001], [0, 0, -0.001]) == 0.0
    assert np.isinf(_t(*on, [0, 0, 0.001], [0, 0, 0.001])) and np.isinf(_t(*on, [0, 0.1, 0], [0, 0.1, 0]))
    # a node on the rim, the edge pivoting about it down the side face: the node's contact, not a crossing
    assert np.isinf(_t([0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0, 0, 0], [0, 0, -0.4]))


def test_cubic_roots_and_a_triangle_falling_on_a_corner():
    rng = np.random.default_rng(5)
    r = np.sort(rng.uniform(-0.5, 1.5, (200, 3)), axis=1)  # (t - r1)(t - r2)(t - r3) times a scale
    k = rng.uniform(-2, 2, 200)
    c = k[:, None] * np.column_stack([-r.prod(axis=1), r[:, 0] * r[:, 1] + r[:, 1] * r[:, 2] + r[:, 0] * r[:, 2],
                                      -r.sum(axis=1), np.ones(200)])
    found = unit_roots(c)
    want = np.where((r >= 0) & (r <= 1), r, np.inf)
    assert np.allclose(np.sort(want, axis=1), found, atol=1e-12, equal_nan=False)
    quad = c.copy()
    quad[:, 0], quad[:, 1], quad[:, 2], quad[:, 3] = k * r[:, 0] * r[:, 1], -k * (r[:, 0] + r[:, 1]), k, 0.0
    want = np.where((r[:, :2] >= 0) & (r[:, :2] <= 1), r[:, :2], np.inf)  # (t - r1)(t - r2) in closed form
    found = unit_roots(quad)
    assert np.allclose(np.sort(want, axis=1), found[:, :2], atol=1e-12) and np.isinf(found[:, 2]).all()
    # a box corner at the origin (outward normal (1, 1, 1) / sqrt 3) under a falling, tilting triangle
    corner, n_c = np.zeros((1, 3)), np.ones((1, 3)) / np.sqrt(3.0)
    tri = [np.array([[-1.0, -1.0, 0.002]]), np.array([[1.0, -1.0, 0.002]]), np.array([[0.0, 1.0, 0.002]])]
    steps = [np.array([[0, 0, -0.004]]), np.array([[0, 0, -0.004]]), np.array([[0, 0, -0.004]])]
    assert np.isclose(corner_crossing_times(*tri, *steps, corner, n_c)[0], 0.5)
    steps[2] = np.array([[0, 0, -0.008]])  # the far corner faster: the plane at the origin is (z_a + z_b) / 4 + z_c / 2
    assert np.isclose(corner_crossing_times(*tri, *steps, corner, n_c)[0], 0.002 / (0.002 + 0.004))
    assert np.isinf(corner_crossing_times(*tri, *[-s for s in steps], corner, n_c)[0])  # lifted off
    far = [t + [[5.0, 0.0, 0.0]] for t in tri]  # beside the corner
    assert np.isinf(corner_crossing_times(*far, *steps, corner, n_c)[0])


def _thrown(tmp_path, sweep):
    """A 9 x 9, 20 x 20 cm sheet thrown down at 100 m/s (1 cm a step) at a 9.5 x 10 x 2 cm box whose rims (x = -3.4
    and 6.1 cm, y = -6.3 and 3.7 cm) lie between the rows and columns of nodes and whose corners on none of the
    sheet's edges; the state after 5 steps."""
    from rftstatic.contact import feature_sweep
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    V = np.array([[x, y, z] for z in (-2, 0) for y in (-6.3, 3.7) for x in (-3.4, 6.1)], float)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    meshio.write(tmp_path / "box.obj", meshio.Mesh(V, [("triangle", F)]))
    model, extras = build_model(scene_from_dict({
        "units": "cm-gf-s", "analysis": "dynamic", "mesh": {"kind": "rectangle", "size": [20.0, 20.0],
                                                              "nodes": [9, 9], "origin": [-10.0, -10.0]},
        "material": {"preset": "wool-kang-yu"}, "loads": {"gravity": True}, "dynamics": {"t_end": 0.004},
        "obstacles": [{"type": "mesh", "path": str(tmp_path / "box.obj"), "translate": [0.0, 0.0, -0.05]}]}))
    ob = extras["obstacles"][0]
    V0 = np.zeros((model.mesh.n_nodes, 3))
    V0[:, 2] = -100.0
    real = feature_sweep.FeatureSweep.for_sheet
    try:
        if not sweep:
            feature_sweep.FeatureSweep.for_sheet = classmethod(lambda cls, *a: None)
        res = run_explicit(model, ExplicitOptions(t_end=5e-4, dt=1e-4, energy_check=False), V0=V0, obstacles=[ob])
    finally:
        feature_sweep.FeatureSweep.for_sheet = real
    return model, ob, model.X3 + res.U


def test_a_thrown_sheet_is_not_cut_by_a_rim_between_its_nodes(tmp_path):
    """Without the sweep the edges from the nodes landing on the box (x = 5 cm) to those falling past it (7.5 cm)
    pass under its rim (6.1 cm): the independent check counts crossing pairs. With it they are lifted onto the
    rim (pivoting about it), and no sheet triangle crosses the box."""
    model, ob, x = _thrown(tmp_path, sweep=False)
    assert obstacle_crossings(x, model.mesh.tri, *ob.surface())["pairs"] > 0
    model, ob, x = _thrown(tmp_path, sweep=True)
    r = obstacle_crossings(x, model.mesh.tri, *ob.surface())
    assert r["pairs"] == 0 and np.all(ob.signed_distance(x)[0] > -1e-9)
    rim = np.isclose(model.X3[:, 0], 0.075) & (model.X3[:, 1] > -0.063) & (model.X3[:, 1] < 0.037)
    assert rim.sum() == 4 and np.all(x[rim, 2] > -0.01)  # beyond the rim, held up by it (5 free-fall steps: 3 cm)
    assert 0 < SHY < 0.01
