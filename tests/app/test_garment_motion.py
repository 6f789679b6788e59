"""The garment-motion analysis (rftstatic.app.garment_motion): its scene checks (exit 2 naming the key) and the
moving stage's scene; the whole skirt-turn run (slow): it settles after the form stops, never crosses the form, and
settles onto the static drape turned with the form."""

import json

import numpy as np
import pytest

from rftstatic.app.garment_motion import motion_options, moving_scene
from rftstatic.cli import main
from rftstatic.scenes.schema import load_scene


def test_the_moving_stage_is_a_dynamic_scene_of_the_form_with_friction_and_keyframes(tmp_path):
    scene = load_scene("skirt-turn")
    opts, given = motion_options(scene)
    assert opts.friction == 0.4 and opts.t_end == pytest.approx(5.0) and given["alpha"] == 3.0
    stage = moving_scene(scene, tmp_path / "body-m.obj", given, opts)
    assert stage.analysis == "dynamic" and "supports" not in stage.data and "garment" not in stage.data
    ob = stage.data["obstacles"]
    assert len(ob) == 1 and ob[0]["friction"] == 0.4 and ob[0]["motion"]["angles"] == [0.0, 60.0]
    assert stage.data["dynamics"]["frames"] == [0.0, 0.2, 2.2, 5.0]


@pytest.mark.parametrize("setting, message", [
    ("motion.friction=-1.0", r"motion\.friction: -1\.0 is out of range"),
    ("motion.speed=2.0", r"motion\.speed: unknown"),
    ("body.motion.axis=[0,0,0]", r"body\.motion\.axis: .*zero vector"),
    ("motion.t_end=1.0", r"motion\.t_end: 1\.0 ends before the form stops"),
])
def test_bad_motion_keys_exit_2(tmp_path, capsys, setting, message):
    import re

    rc = main(["case", "skirt-turn", "--no-figures", "--out", str(tmp_path / "run"), "--set", setting])
    err = capsys.readouterr().err
    assert rc == 2 and "skirt-turn.toml" in err and re.search(message, err), err


@pytest.mark.slow
def test_the_skirt_turns_with_the_form_and_settles(tmp_path):
    """skirt-turn (about 2 min): 0 crossing pairs with the form at every saved state, settled after the form
    stopped, and the settled skirt within 0.5 cm of the static drape turned 60 deg with the form (0.04 cm measured),
    the same hem drape coefficient (1e-3) and folds."""
    rc = main(["case", "skirt-turn", "--no-figures", "--out", str(tmp_path / "run")])
    assert rc == 0
    s = json.loads((tmp_path / "run" / "summary.json").read_text())
    g = s["garment_motion"]
    assert g["max_body_crossing_pairs"] == 0 and g["saved_states"] >= 50
    assert g["settled"] and g["time_at_rest"] > g["form_stops_at"]
    assert g["final_angle_deg"] == pytest.approx(60.0, abs=1e-9)
    c = g["compared_with_static_turned"]
    assert c["max_node_distance"] < 0.5
    assert c["hem_drape_coefficient"] == pytest.approx(c["hem_drape_coefficient_static"], abs=1e-3)
    assert c["hem_folds"] == c["hem_folds_static"]
    assert s["self_intersections"]["pairs"] == 0
    assert np.isfinite(g["kinetic_energy"]["kinetic"]).all()
