"""Scenes with a triangle-surface obstacle: exit-2 messages for bad input (issue 36, item 5)."""

import meshio
import numpy as np
import pytest

from rftstatic.cli import main
from rftstatic.errors import SceneError
from rftstatic.scenes.build import build_mesh, build_model
from rftstatic.scenes.schema import scene_from_dict

BOX_V = np.array([[x, y, z] for z in (-2, 0) for y in (-1, 1) for x in (-1, 1)], float)
BOX_F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])


def _scene(tmp_path, analysis="static", **obstacle):
    meshio.write(tmp_path / "box.obj", meshio.Mesh(BOX_V * 5.0, [("triangle", BOX_F)]))
    return scene_from_dict({
        "units": "cm-gf-s", "analysis": analysis,
        "mesh": {"kind": "rectangle", "size": [20.0, 20.0], "nodes": [9, 9], "origin": [-10.0, -10.0]},
        "material": {"preset": "wool-kang-yu"}, "loads": {"gravity": True},
        "obstacles": [{"type": "mesh", "path": str(tmp_path / "box.obj"), **obstacle}]})


def test_a_box_under_the_sheet_builds_with_its_sharp_edges(tmp_path):
    model, extras = build_model(_scene(tmp_path))
    assert model.contact.features is not None and len(model.contact.features.fedges) == 12
    assert extras["obstacles"][0].closed


def test_an_obstacle_through_the_sheet_is_refused_saying_where(tmp_path):
    with pytest.raises(SceneError, match=r"obstacles\.0.*cuts through the flat sheet.*translate"):
        build_model(_scene(tmp_path, translate=[0.0, 0.0, 3.0]))


def _table_top(tmp_path, analysis):
    """The 20 x 20 cm sheet over a 10 x 10 cm table top given as an open plate, a 2 mm two-sided shell whose top
    lies 0.5 mm below the sheet."""
    plate = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0], [0, 0, 0]]
    meshio.write(tmp_path / "top.obj", meshio.Mesh(np.array(plate, float), [("triangle", np.array(
        [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]))]))
    return scene_from_dict({
        "units": "cm-gf-s", "analysis": analysis,
        "mesh": {"kind": "rectangle", "size": [20.0, 20.0], "nodes": [9, 9], "origin": [-10.0, -10.0]},
        "material": {"preset": "wool-kang-yu"}, "loads": {"gravity": True},
        "dynamics": {"t_end": 0.004},
        "obstacles": [{"type": "mesh", "path": str(tmp_path / "top.obj"), "thickness": 0.2,
                       "translate": [0.0, 0.0, -0.15]}]})


def test_a_sheet_thrown_at_a_thin_table_top_stays_on_it_in_explicit_steps(tmp_path):
    """A sheet moving down at 100 m/s steps 5 times the 2 mm shell's thickness each explicit step: the kinematic
    contact's continuous collision detection stops every node on top (none ends below or inside the shell)."""
    from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    model, extras = build_model(_table_top(tmp_path, "dynamic"))
    ob = extras["obstacles"][0]
    dt = 1e-4
    V0 = np.zeros((model.mesh.n_nodes, 3))
    V0[:, 2] = -100.0
    assert 100.0 * dt >= 5 * ob.thickness
    res = run_explicit(model, ExplicitOptions(t_end=5 * dt, dt=dt, energy_check=False), V0=V0, obstacles=[ob])
    x = model.X3 + res.U
    over = np.all(np.abs(model.X3[:, :2]) < 0.05 - 1e-9, axis=1)  # the 3 x 3 nodes inside the table's outline
    # on the table's top face (z = -0.5 mm), not through it; the sheet's edges over its rim (under a row of nodes
    # here) lifted some up to 0.15 mm (rftstatic.contact.feature_sweep)
    assert over.sum() == 9 and np.all((x[over, 2] >= -0.0005 - 1e-12) & (x[over, 2] < -0.0003))
    beside = np.any(np.abs(model.X3[:, :2]) > 0.05 + 1e-9, axis=1)
    assert beside.sum() == 81 - 25 and np.all(x[beside, 2] < -0.03)  # those beside it fell past its rim
    assert np.all(ob.signed_distance(x)[0] > -1e-9)
    # the sheet's triangles on the table cross nothing (here the rim lies exactly under a row of nodes, whose edges
    # pivot about it as node contacts: 8 pairs there; rims between nodes: tests/contact/test_feature_sweep.py)
    on = np.all(over[model.mesh.tri], axis=1)
    assert on.sum() == 8 and obstacle_crossings(x, model.mesh.tri[on], *ob.surface())["pairs"] == 0


def test_explicit_analyses_run_a_mesh_obstacle_and_report_its_crossings(tmp_path):
    """The dynamic app runs a scene with a triangle-surface obstacle and writes the crossing check."""
    import json

    from rftstatic.app.dynamic import run

    run(_table_top(tmp_path, "dynamic"), tmp_path / "out", progress=False, figures=False)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    (crossing,) = summary["obstacle_crossings"]
    assert crossing["pairs"] == 0 and crossing["smallest_node_distance"] > -1e-6


def test_a_sheet_mesh_file_with_a_non_manifold_edge_exits_2(tmp_path, capsys):
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [1, 1, 0]], float)
    meshio.write(tmp_path / "fan.vtu", meshio.Mesh(pts, [("triangle", np.array([[0, 1, 2], [0, 3, 1], [0, 1, 4]]))]))
    scene = tmp_path / "fan.toml"
    scene.write_text('units = "SI"\nanalysis = "static"\n[mesh]\nkind = "file"\npath = "fan.vtu"\n'
                     '[material]\npreset = "wool-kang-yu"\n[loads]\ngravity = true\n[[supports]]\nkind = "clamped"\n'
                     'at = [0.0, 0.0]\n')
    assert main(["case", str(scene), "--no-figures", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "fan.vtu" in err and "shared by 3 triangles" in err
    with pytest.raises(SceneError):
        build_mesh(scene_from_dict({"units": "SI", "mesh": {"kind": "file", "path": str(tmp_path / "fan.vtu")},
                                    "material": {"preset": "wool-kang-yu"}}))


def test_a_remeshed_relaxation_on_a_mesh_box_reports_its_crossings(tmp_path):
    """remesh-pedestal-square-20 (coarse, 3 s of relaxation with 4 remeshes) with its pedestal replaced by a
    10 x 10 x 10 cm box file: the remesh app writes the crossing check of the last mesh's state. (That state is
    the transfer of the last remesh, at t_end, with no step after it: 5 nodes lay inside the box, up to 3.2 mm,
    before the final projection onto the surface, :func:`rftstatic.app.remeshed._settle`.)"""
    from rftstatic.app import remeshed
    from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
    from rftstatic.scenes.schema import load_scene

    meshio.write(tmp_path / "box.obj", meshio.Mesh(BOX_V * 5.0, [("triangle", BOX_F)]))
    data = load_scene("remesh-pedestal-square-20", ["mesh.h=4.0", "remesh.const=2.0", "remesh.h_lower=2.5",
                                                    "remesh.h_upper=5.0", "remesh.every=200",
                                                    "remesh.kappa_h2_max=6.0", "dynamics.t_end=3.0"]).data
    data["obstacles"] = [{"type": "mesh", "path": str(tmp_path / "box.obj")}]
    res = remeshed.run(scene_from_dict(data), tmp_path / "out", progress=False, figures=False)
    (crossing,) = res.summary["obstacle_crossings"]
    ob = res.extras["obstacles"][0]
    x = res.model.positions(res.U)
    assert res.summary["remeshes"] == 4
    assert crossing["smallest_node_distance"] == pytest.approx(ob.signed_distance(x)[0].min() / 0.01)
    assert crossing["pairs"] == obstacle_crossings(x, res.model.mesh.tri, *ob.surface())["pairs"]
    # the last remesh's transfer (at t_end, no step after it) left nodes inside: moved back onto the surface
    assert crossing["smallest_node_distance"] > -1e-9
