"""Shear hysteresis as scene input: the KES 2HG and 2HG5 keys, their conversion, the refusals (exit 2 naming the key), the summary,
the explain listing, and a short run that records what the friction did."""

import json

import numpy as np
import pytest

from rftstatic.cli import main
from rftstatic.errors import SceneError
from rftstatic.scenes.material import build_material, material_summary
from rftstatic.scenes.schema import scene_from_dict
from rftstatic.units import STANDARD_GRAVITY

LAB = {"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_W": 19.0, "kes_T": 0.5}


def _scene(table):
    return scene_from_dict({"units": "cm-gf-s", "material": table})


def test_kes_2hg_gives_the_friction_shear_force_half_the_loop_width():
    scene = _scene({**LAB, "kes_2HG": 1.2, "kes_2HG5": 2.5, "shear_hysteresis_ratio": 20.0})
    mat = build_material(scene)
    gf_per_cm = STANDARD_GRAVITY * 1e-3 / 1e-2  # N/m
    assert mat.shear_hysteresis.tau0 == pytest.approx(0.6 * gf_per_cm, rel=1e-12)
    assert mat.shear_hysteresis.ratio == 20.0
    assert mat.hysteresis is None
    summary = material_summary(scene, mat)
    assert summary["shear_hysteresis"]["tau0"] == pytest.approx(0.6, rel=1e-12)
    assert summary["shear_hysteresis"]["unit"] == "gf/cm"
    assert summary["lab"]["shear_tau0"]["from"] == "kes_2HG"
    assert summary["lab"]["shear_tau5"]["converted"] == pytest.approx(1.25, rel=1e-12)  # 2HG5 / 2
    assert "recorded only" not in summary["lab"]["shear_tau5"]["rule"]
    assert mat.shear_hysteresis.tau5 == pytest.approx(1.25 * gf_per_cm, rel=1e-12)
    assert summary["shear_hysteresis"]["tau5"] == pytest.approx(1.25, rel=1e-12)
    assert "0.5 deg" in summary["shear_hysteresis"]["growth"] and "5 deg" in summary["shear_hysteresis"]["growth"]
    assert build_material(_scene({**LAB, "kes_2HG": 1.2})).shear_hysteresis.tau5 is None  # no 2HG5: tau0 throughout
    assert "C_shear" in summary["filled"]  # the stick stiffness rests on the G its rule fills
    assert build_material(_scene(dict(LAB))).shear_hysteresis is None


@pytest.mark.parametrize("extra, key, fragment", [
    ({"kes_2HG": 0.0}, "material.kes_2HG", "must be > 0"),
    ({"kes_2HG": -1.0}, "material.kes_2HG", "must be > 0"),
    ({"kes_2HG": 80.0}, "material.kes_2HG", "outside the plausible range [0.01, 50] gf/cm"),
    ({"kes_2HG": 1.0, "kes_2HG5": 500.0}, "material.kes_2HG5", "outside the plausible range"),
    ({"kes_2HG5": 2.0}, "material.kes_2HG", "missing: kes_2HG5"),
    ({"shear_hysteresis_ratio": 5.0}, "material.kes_2HG", "missing: shear_hysteresis_ratio"),
    ({"kes_2HG": 1.0, "shear_hysteresis_ratio": 0.5}, "material.shear_hysteresis_ratio", "[1, 1e4]"),
    ({"kes_2HG": 2.0, "kes_2HG5": 1.5}, "material.kes_2HG5", "1.5 gf/cm is below kes_2HG = 2.0 gf/cm"),
])
def test_bad_shear_hysteresis_input_names_the_key(extra, key, fragment):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")) as err:
        build_material(_scene({**LAB, **extra}))
    assert fragment in str(err.value)


def test_bad_2hg_on_the_command_line_is_exit_2_naming_the_key(capsys, tmp_path):
    table = "material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5, kes_2HG=-1.0}"
    code = main(["case", "cusick-30", "--set", table, "--out", str(tmp_path / "o"), "--no-figures"])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "cusick-30.toml: material.kes_2HG: " in err and "\n" not in err, err
    code = main(["case", "cusick-30", "--set", "material.kes_2HG=1.0", "--out", str(tmp_path / "p"), "--no-figures"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "material.kes_2HG: " in err and 'next to preset = "wool-kang-yu"' in err, err
    table = "material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5, kes_2HG=2.0, kes_2HG5=1.0}"
    code = main(["case", "cusick-30", "--set", table, "--out", str(tmp_path / "q"), "--no-figures"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "material.kes_2HG5: 1.0 gf/cm is below kes_2HG = 2.0 gf/cm" in err and "\n" not in err, err


def test_explain_lists_the_key(capsys):
    assert main(["fabrics", "--explain"]) == 0
    out = capsys.readouterr().out
    assert "kes_2HG" in out and "kes_2HG5" in out
    line = next(row for row in out.splitlines() if "kes_2HG5" in row)
    assert "recorded only" not in line and "grows" in line


def test_compare_and_arc_length_are_refused_with_shear_hysteresis():
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene

    table = "material={" + ", ".join(f"{k}={v}" for k, v in {**LAB, "kes_2HG": 1.0}.items()) + "}"
    with pytest.raises(SceneError, match=r"solver\.continuation: \"arc-length\" does not commit"):
        build_model(load_scene("strip", [table, "solver.continuation=arc-length"]))


def test_a_short_cusick_run_records_the_shear_friction(capsys, tmp_path):
    """A coarse Cusick specimen (4 rings x 80) with 2HG = 1 gf/cm: the run finishes and its summary lists the
    friction, what it dissipated and the shear it reached."""
    table = "material={" + ", ".join(f"{k}={v}" for k, v in {**LAB, "kes_2HG": 1.0}.items()) + "}"
    code = main(["case", "cusick-30", "--set", table, "--set", "mesh.nodes=[4,80]", "--out", str(tmp_path / "o"),
                 "--no-figures"])
    assert code == 0, capsys.readouterr().err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    sh = s["shear_hysteresis"]
    assert s["material"]["shear_hysteresis"]["tau0"] == pytest.approx(0.5)
    assert sh["dissipated_both_frictions"] > 0 and 0 <= sh["yielded_share"] <= 1
    assert 0 < sh["max_shear_angle_deg"] < 90
    assert np.isfinite(s["drape"]["drape_coefficient_percent"])


def test_checkpoint_keeps_both_frictions_slips(tmp_path):
    """With bending and shear hysteresis the State's slip array holds three columns (warp, weft bending; shear) and a
    checkpoint gives them back."""
    from rftstatic.mesh import trimesh as mesh
    from rftstatic.model import model
    from rftstatic.model.state import State
    from rftstatic.solvers.checkpoint import read_checkpoint, restore_state, state_arrays

    mat = build_material(_scene({**LAB, "kes_2HB_warp": 0.05, "kes_2HB_weft": 0.04, "kes_2HG": 1.0}))
    mod = model.Model(mesh.rectangle(0.02, 0.01, 5, 3), mat)
    state = State.initial(mod)
    assert state.slip.shape == (mod.mesh.n_elements, 3)
    state.slip = np.random.default_rng(2).normal(size=state.slip.shape)
    state.dissipated = 2.5e-6
    path = tmp_path / "c.npz"
    np.savez(path, **state_arrays(state, {"what": "test"}))
    back = restore_state(mod, read_checkpoint(path)[1])
    np.testing.assert_array_equal(back.slip, state.slip)
    bend, shear = mod.split_slip(back.slip)
    np.testing.assert_array_equal(shear[:, 0], state.slip[:, 2])
    assert bend.shape[1] == 2 and back.dissipated == 2.5e-6
