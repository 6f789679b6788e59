"""The garment scene kind (rftstatic.app.garment): scene parsing, the placed reference mesh, outputs."""

import math

import numpy as np
import pytest

from rftstatic.app.garment import dress_form, dressed_mesh, read_obj_uv, write_obj, _hem
from rftstatic.errors import SceneError
from rftstatic.scenes.schema import load_scene


def test_the_circle_skirt_scene_places_the_ring_flat_at_the_waist():
    scene = load_scene("skirt-circle", ["garment.h=6.0"])
    form = dress_form(scene)
    pmesh, mesh, uv = dressed_mesh(scene)
    assert np.allclose(mesh.X3[:, 2], form.waist_height)
    r = np.linalg.norm(mesh.X, axis=1)
    assert r.min() == pytest.approx(0.1114, abs=1e-9) and r.max() == pytest.approx(0.6114, abs=1e-9)
    # placing turns the flat pattern rigidly: every element keeps its pattern shape (and area)
    assert mesh.area.sum() == pytest.approx(math.pi * (0.6114**2 - 0.1114**2), rel=5e-3)
    for k in range(3):
        a = np.linalg.norm(mesh.X3[mesh.tri[:, (k + 1) % 3]] - mesh.X3[mesh.tri[:, k]], axis=1)
        b = np.linalg.norm(uv[mesh.tri[:, (k + 1) % 3]] - uv[mesh.tri[:, k]], axis=1)
        c = np.linalg.norm(mesh.element_X[:, (k + 1) % 3] - mesh.element_X[:, k], axis=1)
        assert np.abs(a - b).max() < 1e-12 and np.abs(c - b).max() < 1e-12
    # the elements' x axis is the grain line (the pattern's y axis: grain = 90 deg)
    d_uv = uv[mesh.tri[:, 1]] - uv[mesh.tri[:, 0]]
    d_el = mesh.element_X[:, 1] - mesh.element_X[:, 0]
    assert np.allclose(d_el[:, 0], d_uv[:, 1]) and np.allclose(d_el[:, 1], -d_uv[:, 0])
    # the ring clears the form's waist at the start: its opening lies outside the waist ellipse
    aw, bw = form.section(np.array([form.waist_height]))
    inner = r < 0.1115
    assert np.all((mesh.X[inner, 0] / aw) ** 2 + (mesh.X[inner, 1] / bw) ** 2 > 1.0)
    x = mesh.X3.copy()
    x[r > 0.6, 2] -= 0.1  # the hem is the lowest boundary loop
    hem = _hem(mesh.tri, x)
    assert np.allclose(np.linalg.norm(mesh.X[hem], axis=1), 0.6114, atol=1e-9)


def test_garment_obj_uvs_round_trip(tmp_path):
    scene = load_scene("skirt-circle", ["garment.h=8.0"])
    _, mesh, uv = dressed_mesh(scene)
    rng = np.random.default_rng(1)
    x = mesh.X3 + rng.normal(scale=0.01, size=mesh.X3.shape)
    write_obj(tmp_path / "g.obj", x * 100, mesh.tri, uv * 100)
    y, vt, tri, vt_tri = read_obj_uv(tmp_path / "g.obj")
    assert np.array_equal(tri, mesh.tri) and np.array_equal(vt_tri, mesh.tri)
    # 9 significant digits: within 1e-8 of the largest coordinate [cm]
    assert np.abs(y - x * 100).max() < 1e-8 * 100 * np.abs(x).max()
    assert np.abs(vt - uv * 100).max() < 1e-8 * 100 * np.abs(uv).max()
    # a sewn node has one texture coordinate per panel: faces name their corners' own
    corners = np.arange(mesh.tri.size).reshape(-1, 3)
    write_obj(tmp_path / "h.obj", x, mesh.tri, uv[mesh.tri].reshape(-1, 2), uv_tri=corners)
    _, vt, tri, vt_tri = read_obj_uv(tmp_path / "h.obj")
    assert np.array_equal(tri, mesh.tri) and np.array_equal(vt_tri, corners)


def test_bad_body_measurements_name_the_key():
    scene = load_scene("skirt-circle", ["body.waist_height=50.0"])
    with pytest.raises(SceneError, match="body.*height"):
        dress_form(scene)


@pytest.mark.parametrize("key, value", [("garment.h", "-1.0"), ("garment.h", "0.0"), ("garment.closing_h", "-2.0")])
def test_bad_element_sizes_exit_2_naming_the_key(tmp_path, capsys, key, value):
    from rftstatic.cli import main

    assert main(["case", "skirt-a-line", "--set", f"{key}={value}", "--out", str(tmp_path / "o"), "--no-figures"]) == 2
    assert key in capsys.readouterr().err


def test_a_missing_pattern_file_names_the_key(tmp_path):
    from rftstatic.app.garment import run

    scene = load_scene("skirt-a-line", ["garment.pattern=patterns/none.toml"])
    with pytest.raises(SceneError, match="garment.pattern.*none.toml"):
        run(scene, tmp_path)
