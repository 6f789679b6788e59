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


def test_explicit_analyses_refuse_a_mesh_obstacle_naming_the_keys(tmp_path):
    with pytest.raises(SceneError, match=r'static route only.*analysis = "static".*solver.start = "relax"'):
        build_model(_scene(tmp_path, analysis="relax"))


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
