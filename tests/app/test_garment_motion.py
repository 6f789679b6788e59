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
    assert opts.friction == 0.4 and opts.t_end == pytest.approx(4.0) and given["alpha"] == 2.0
    stage = moving_scene(scene, tmp_path / "body-m.obj", given, opts)
    assert stage.analysis == "dynamic" and "supports" not in stage.data and "garment" not in stage.data
    ob = stage.data["obstacles"]
    assert len(ob) == 1 and ob[0]["friction"] == 0.4 and ob[0]["motion"]["angles"] == [0.0, 60.0]
    assert stage.data["dynamics"]["frames"] == [0.0, 0.2, 1.2, 4.0]


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
    """skirt-turn (about 3 min): 0 crossing pairs with the form and 0 self-intersections at every saved state, a
    swing after the form stopped (kinetic energy 7 % of the turn's peak), settled after it; the settled skirt is
    another equilibrium than the static drape turned with the form (friction holds it; 5.4 cm apart at most
    measured), with its hem drape coefficient within 0.01 (0.1266 against 0.1296) and the same folds (8)."""
    rc = main(["case", "skirt-turn", "--no-figures", "--out", str(tmp_path / "run")])
    assert rc == 0
    s = json.loads((tmp_path / "run" / "summary.json").read_text())
    g = s["garment_motion"]
    assert g["max_body_crossing_pairs"] == 0 and g["saved_states"] >= 51
    assert g["settled"] and g["time_at_rest"] > g["form_stops_at"]
    assert g["final_angle_deg"] == pytest.approx(60.0, abs=1e-9)
    c = g["compared_with_static_turned"]
    assert 0.02 < g["peak_kinetic_after_stop"] / g["peak_kinetic"] < 0.2
    assert c["max_node_distance"] < 10.0
    assert c["hem_drape_coefficient"] == pytest.approx(c["hem_drape_coefficient_static"], abs=0.01)
    assert c["hem_folds"] == c["hem_folds_static"]
    assert s["self_intersections"]["pairs"] == 0 and s["self_intersections"]["max_pairs_saved"] == 0
    assert np.isfinite(g["kinetic_energy"]["kinetic"]).all()
