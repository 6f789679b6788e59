"""Remeshed scene runs (rftstatic.remesh_run): outputs, records, and the relax route against the static solution."""

import json

import numpy as np
import pytest

from rftstatic.app.remeshed import run_remesh_scene
from rftstatic.errors import SceneError
from rftstatic.scenes.options import remesh_options
from rftstatic.scenes.schema import load_scene

# a 20 x 20 cm sheet on the 10 cm pedestal, coarse enough to run in a few seconds
TINY = ["mesh.h=4.0", "remesh.const=2.0", "remesh.h_lower=2.5", "remesh.h_upper=5.0", "remesh.every=200",
        "remesh.kappa_h2_max=6.0", "dynamics.t_end=0.5"]


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("remesh-square")
    scene = load_scene("remesh-pedestal-square-20", TINY)
    return out, run_remesh_scene(scene, out, progress=False, figures=True)


def test_relax_outputs_exist_and_are_well_formed(tiny_run):
    import meshio

    out, summary = tiny_run
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["nodes"] == summary["nodes"] and on_disk["route"] == "remesh_relax"
    recs = on_disk["records"]
    assert recs[0]["reason"] == "initial" and recs[0]["time"] == 0.0 and len(recs) == on_disk["remeshes"] + 1
    assert all(r["nodes"] > 0 and r["triangles"] > r["nodes"] for r in recs)
    assert np.all(np.diff([r["time"] for r in recs]) > 0)  # scene time units [s], increasing
    assert recs[-1]["nodes"] == on_disk["nodes"] and np.isfinite(recs[-1]["max_kappa_h"])
    # time in seconds: the run stops at the first 200-step chunk past t_end = 0.5 s; lengths in cm
    assert 0.5 <= on_disk["t"] < 1.5 and on_disk["remesh"]["h_lower"] == 2.5
    d = on_disk["drape"]
    assert 0 < d["drape_coefficient"] < 1 and d["boundary_radius_max"] < 15.0  # cm: the half diagonal is 14.1
    si = on_disk["self_intersections"]
    assert si["pairs"] >= 0 and 0.0 < si["smallest_distance"] < si["within"] < 10.0   # cm
    m = meshio.read(out / "deformed.vtu")
    assert len(m.points) == on_disk["nodes"] and m.cells[0].data.shape == (on_disk["elements"], 3)
    frames = on_disk["frames"]
    assert len(frames) == len(recs) + 1 and frames[-1]["mesh"] == "final"
    for f in frames:
        for view in ("top", "iso"):
            assert (out / f["files"][view]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "remesh.gif").read_bytes()[:6] == b"GIF89a"
    assert (out / "nodes.png").stat().st_size > 0


def test_the_view_has_a_slider_over_the_meshes(tiny_run):
    """meshes.pvd lists every mesh's state (the last is deformed.vtu's), and view.html steps through them."""
    from rftstatic.io.viewer import build_figure, load_summary

    out, _ = load_summary(tiny_run[0])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["view"] == "view.html" and (out / "view.html").exists()
    fig = build_figure(out, summary)
    nodes = [r["nodes"] for r in summary["records"]] + [summary["nodes"]]
    assert [len(f.data[0].x) for f in fig.frames] == nodes
    assert all(len(f.data[0].i) > 0 for f in fig.frames)                        # each mesh its own triangles
    assert fig.layout.sliders[0].steps[-1].label == f"{len(nodes) - 1} ({summary['nodes']} nodes)"


def test_remesh_options_scene_units_and_errors():
    s = load_scene("remesh-pedestal-round-50")
    o = remesh_options(s)
    assert o.h_lower == pytest.approx(0.006) and o.const == pytest.approx(0.006)  # cm -> m
    assert o.gradation == 1.3 and o.transfer == "mesh"
    with pytest.raises(SceneError, match="remesh.h_lower"):
        remesh_options(load_scene("remesh-pedestal-round-50", ["remesh.h_lower=9.0"]))
    with pytest.raises(SceneError, match="remesh.transfer"):
        remesh_options(load_scene("remesh-pedestal-round-50", ["remesh.transfer=spline"]))
    assert o.damping == "critical" and remesh_options(load_scene("strip", ["remesh.const=0.04", "remesh.h_lower=0.1",
                                                                         "remesh.h_upper=0.4"])).damping == "fixed"
    with pytest.raises(SceneError, match="remesh.damping"):
        remesh_options(load_scene("remesh-pedestal-round-50", ["remesh.damping=adaptive"]))


def test_kinematic_contact_reaction_balances_weight_on_the_pedestal():
    # a flat sheet lying on the pedestal's top: the top face carries the weight of the nodes on it,
    # so the residual with the contact reaction is zero there and only the overhang is unbalanced
    from rftstatic.contact.kinematic import contact_reaction_residual
    from rftstatic.scenes.build import build_model

    scene = load_scene("remesh-pedestal-square-20", TINY)
    plain, extras = build_model(scene)  # a relax scene: kinematic obstacles, no contact term
    assert plain.contact is None
    U = np.zeros_like(plain.X3)
    r0 = plain.residual(U).copy()
    r = contact_reaction_residual(plain, extras["obstacles"], U)
    X = plain.X3[:, :2]  # [m]: the 10 x 10 cm pedestal top is |x|, |y| <= 0.05 m
    on_top = np.all(np.abs(X) < 0.05 - 0.002, axis=1)  # clear of the 0.2 cm edge rounding
    off = np.any(np.abs(X) > 0.05, axis=1)
    assert on_top.sum() >= 3 and off.sum() >= 3
    assert np.abs(r0[on_top, 2]).max() > 0 and np.abs(r[on_top]).max() == 0.0
    assert np.array_equal(r[off], r0[off])


def _sphere_with_hold_off_the_top():
    """The tiny sphere scene shifted 0.8 cm in x: the node held in x and y (the in-plane hold
    nearest the sheet's centre) sits on the sphere where its normal is inclined."""
    from rftstatic.scenes.build import build_model

    scene = load_scene("remesh-sphere-30", ["mesh.h=3.0", "obstacles.0.centre=[0.8, 0.3, -5.0]"])
    model, extras = build_model(scene)  # a relax scene: kinematic obstacles, in-plane holds kept
    return scene, model, extras["obstacles"]


def test_contact_reaction_at_a_node_held_in_plane_on_a_sphere():
    from rftstatic.contact.kinematic import contact_reaction_residual
    from rftstatic.contact.obstacles import from_spec

    _, plain, _ = _sphere_with_hold_off_the_top()
    i = np.flatnonzero(~plain.free[:, 0] & plain.free[:, 2])[0]  # held in x, y, free in z
    # a 5 cm sphere whose surface passes through that node with the normal tilted 0.3 rad
    R, tilt = 0.05, 0.3
    xi = plain.X3[i]
    centre = xi - R * np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    sphere = from_spec({"type": "sphere", "centre": centre.tolist(), "radius": R})
    assert abs(sphere.signed_distance(xi[None])[0][0]) < 1e-15
    U = np.zeros_like(plain.X3)  # flat and unstrained: the residual is minus the weight
    r = np.where(plain.free, contact_reaction_residual(plain, [sphere], U), 0.0)
    w = -plain.load[i, 2]
    assert w > 0
    # the normal reaction w / cos(tilt) carries the weight; its in-plane part goes to the support
    # (removing only r . n = w cos(tilt) left w sin^2(tilt) unbalanced on z: never at rest)
    assert abs(r[i, 2]) < 1e-12 * w
    free_nodes = np.flatnonzero(plain.free.all(axis=1) & (sphere.signed_distance(plain.X3)[0] > 1e-6))
    assert np.allclose(r[free_nodes, 2], -plain.load[free_nodes, 2])


def test_explicit_contact_never_moves_a_held_dof():
    from rftstatic.remesh.relax_driver import explicit_advance

    scene, plain, obstacles = _sphere_with_hold_off_the_top()
    held = ~plain.free
    assert held.any()
    adv = explicit_advance(alpha=1.0, mass_scale=100.0, obstacles=tuple(obstacles), safety=0.5)
    U, V = np.zeros_like(plain.X3), np.zeros_like(plain.X3)
    for _ in range(5):
        U, V, _ = adv(plain, U, V, 100)
        # the projection onto the sphere used to give the held x, y dofs a velocity that the
        # lagged damping never removed (a steady 8.6 cm/s on the 30 cm sheet: never at rest)
        assert not V[held].any() and not U[held].any()


def test_static_route_matches_remesh_static_records(tmp_path):
    # the static route on the strip: the node count settles, as in tests/test_remesh.py, and the
    # summary carries one record per solve with the scene's length unit (cm)
    scene = load_scene("strip", ["mesh.kind=unstructured", "mesh.h=0.25", "remesh.const=0.04",
                                 "remesh.h_lower=0.1", "remesh.h_upper=0.4", "remesh.max_cycles=4"])
    s = run_remesh_scene(scene, tmp_path, progress=False, figures=False)
    assert s["route"] == "remesh_static" and s["converged"]
    assert s["records"][-1]["max_kappa_h"] <= 0.32 and s["remesh"]["const"] == pytest.approx(0.04)
    tip = np.array(s["probes"]["tip"]["deformed"]) - np.array(s["probes"]["tip"]["reference"])
    assert np.hypot(tip[0] + 3.23252, tip[2] + 4.34561) < 0.01 * 5.4  # cm; TIP_REF of tests/test_remesh.py


@pytest.mark.slow
def test_relax_route_ends_near_the_static_solution(tmp_path):
    # the remeshed dynamic relaxation of the strip comes to rest within 1 % of the tip displacement
    # of the structured static solution (TIP_REF of tests/test_remesh.py, in cm)
    scene = load_scene("strip", ["analysis=relax", "mesh.kind=unstructured", "mesh.h=0.25",
                                 "remesh.const=0.04", "remesh.h_lower=0.1", "remesh.h_upper=0.4",
                                 "remesh.every=5000", "dynamics.t_end=30.0", "dynamics.alpha=3.0",
                                 "dynamics.force_tolerance=1e-3"])
    s = run_remesh_scene(scene, tmp_path, progress=False, figures=False)
    assert s["converged"] and s["records"][-1]["reason"] != "initial"
    tip = np.array(s["probes"]["tip"]["deformed"]) - np.array(s["probes"]["tip"]["reference"])
    assert np.hypot(tip[0] + 3.23252, tip[2] + 4.34561) < 0.01 * 5.4


@pytest.mark.slow
def test_remeshed_square_pedestal_comes_to_rest(tmp_path):
    # §6.1 with its scene defaults (critical damping): at rest on a settled mesh well before t_end,
    # on the static solution's branch (33 x 33: DC 0.502, 4 folds); measured 470-510 nodes, at rest
    # after 8.5-13 s of simulated time, DC 0.490-0.526, 10-25 s wall
    s = run_remesh_scene(load_scene("remesh-pedestal-square-20"), tmp_path, progress=False, figures=False)
    assert s["converged"] and s["t"] < 0.8 * s["t_end"] and s["residual_relative"] <= 5e-3
    assert s["drape"]["fold_count"] == 4 and abs(s["drape"]["drape_coefficient"] - 0.502) < 0.04
    assert 1.0 < s["alpha_final"] < 5.0


def test_bench_scene_in_a_fresh_process_and_its_report(tmp_path):
    # the remesh bench runs each scene in its own interpreter (wall time, CPU, peak memory)
    from rftstatic.bench.remesh import bench_scene, write_report

    r = bench_scene("remesh-pedestal-square-20", TINY)
    assert r["nodes"] > 0 and r["remeshes"] >= 1 and r["peak_rss_mb"] > 50
    assert r["process_s"] >= r["wall_time_s"] > 0 and r["cpu_time_s"] > 0 and "within_target" in r
    mesher = [{"case": "square uniform", "nodes": 2000, "triangles": 3800, "wall_s": 0.3, "triangles_per_s": 12000,
               "peak_rss_mb": 80.0, "min_angle": 31.0, "mean_min_angle": 52.0, "band_share": 0.98}]
    write_report({"mesher": mesher, "scenes": [r], "machine": {"cpus": 2, "python": "3", "rftstatic": "0",
                                                               "date": "today", "load_before": [1.0, 1.0, 1.0]}},
                 tmp_path)
    text = (tmp_path / "bench_remesh.md").read_text()
    assert "| square uniform | 2000 | 3800 |" in text and "remesh-pedestal-square-20" in text
    assert json.loads((tmp_path / "bench_remesh.json").read_text())["scenes"][0]["nodes"] == r["nodes"]


def test_a_remeshed_relaxation_with_self_contact_rebuilds_its_pairs_on_every_mesh(tmp_path):
    # each remesh builds a model with its own self-contact (pairs rebuilt on the new mesh); the summary
    # keeps the last mesh's counters and the independent crossing check
    scene = load_scene("remesh-pedestal-square-20", ["contact.self=true", "remesh.h_lower=1.0", "remesh.h_upper=3.0",
                                                     "dynamics.t_end=2.0"])
    s = run_remesh_scene(scene, tmp_path, progress=False, figures=False)
    assert s["remeshes"] >= 1 and s["self_intersections"]["pairs"] == 0
    sc = s["self_contact"]
    assert sc["thickness"] == pytest.approx(0.05) and {"rebuilds", "filter_steps", "force_s"} <= set(sc)


def test_a_remeshed_run_writes_its_summary_once_and_last(tmp_path, monkeypatch):
    """summary.json is written once, after the frames, the node plot and the final state's files, and holds
    their names (it used to be written, then rewritten after the figures)."""
    from rftstatic.io import results

    written = []
    real = results.write_json
    monkeypatch.setattr(results, "write_json", lambda path, data: (written.append(path.name), real(path, data)))
    scene = load_scene("strip", ["mesh.kind=unstructured", "mesh.h=0.5", "remesh.const=0.08", "remesh.h_lower=0.2",
                                 "remesh.h_upper=0.8", "remesh.max_cycles=2"])
    s = run_remesh_scene(scene, tmp_path, progress=False, figures=True)
    assert written == ["summary.json"]
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk["node_plot"] == "nodes.png" and on_disk["frames"] == s["frames"] and len(s["frames"]) >= 2
    newest = max(p.stat().st_mtime_ns for p in tmp_path.iterdir() if p.name != "summary.json")
    assert (tmp_path / "summary.json").stat().st_mtime_ns >= newest
