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
    assert mesh.z0 == pytest.approx(form.waist_height)
    r = np.linalg.norm(mesh.X, axis=1)
    assert r.min() == pytest.approx(0.1114, abs=1e-9) and r.max() == pytest.approx(0.6114, abs=1e-9)
    # placing turns the flat pattern rigidly: every element keeps its pattern area
    assert mesh.area.sum() == pytest.approx(math.pi * (0.6114**2 - 0.1114**2), rel=5e-3)
    a = np.linalg.norm(mesh.X[mesh.tri[:, 1]] - mesh.X[mesh.tri[:, 0]], axis=1)
    b = np.linalg.norm(uv[mesh.tri[:, 1]] - uv[mesh.tri[:, 0]], axis=1)
    assert np.abs(a - b).max() < 1e-12
    # the ring clears the form's waist at the start: its opening lies outside the waist ellipse
    aw, bw = form.section(np.array([form.waist_height]))
    inner = r < 0.1115
    assert np.all((mesh.X[inner, 0] / aw) ** 2 + (mesh.X[inner, 1] / bw) ** 2 > 1.0)
    hem = _hem(mesh)
    assert np.allclose(np.linalg.norm(mesh.X[hem], axis=1), 0.6114, atol=1e-9)


def test_garment_obj_uvs_round_trip(tmp_path):
    scene = load_scene("skirt-circle", ["garment.h=8.0"])
    _, mesh, uv = dressed_mesh(scene)
    rng = np.random.default_rng(1)
    x = mesh.X3 + rng.normal(scale=0.01, size=mesh.X3.shape)
    write_obj(tmp_path / "g.obj", x * 100, mesh.tri, uv * 100)
    y, vt, tri = read_obj_uv(tmp_path / "g.obj")
    assert np.array_equal(tri, mesh.tri)
    # 9 significant digits: within 1e-8 of the largest coordinate [cm]
    assert np.abs(y - x * 100).max() < 1e-8 * 100 * np.abs(x).max()
    assert np.abs(vt - uv * 100).max() < 1e-8 * 100 * np.abs(uv).max()


def test_a_pattern_with_seams_is_refused_until_sewing_is_built(tmp_path):
    text = (load_scene("skirt-circle").path.read_text()
            .replace("patterns/skirt-circle-ring.toml", "patterns/skirt-a-line.toml"))
    (tmp_path / "patterns").symlink_to(load_scene("skirt-circle").path.parent / "patterns")
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(SceneError, match="garment.pattern.*seams"):
        dressed_mesh(load_scene(str(tmp_path / "s.toml")))


def test_bad_body_measurements_name_the_key():
    scene = load_scene("skirt-circle", ["body.waist_height=50.0"])
    with pytest.raises(SceneError, match="body.*height"):
        dress_form(scene)
