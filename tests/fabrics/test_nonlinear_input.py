"""Nonlinear bending as scene input: bending_k2_* (scene units), the data set's ctd_k2_* and a ctd-* preset's opt-in,
the summary, refusals naming the key, and a run that reports it in summary.json."""

import json

import pytest

from rftstatic.errors import SceneError
from rftstatic.scenes.material import build_material, material_summary
from rftstatic.scenes.schema import scene_from_dict
from rftstatic.units import STANDARD_GRAVITY

GF = STANDARD_GRAVITY * 1e-3
CTD = {"ctd_B_warp": 14501.9, "ctd_B_weft": 10176.5, "ctd_density": 0.2023, "thickness": 0.05}


def _scene(table, units="cm-gf-s"):
    return scene_from_dict({"units": units, "material": table})


def test_scene_keys_give_k2_in_scene_units_and_the_summary_reports_them():
    scene = _scene({"preset": "wool-kang-yu", "bending_k2_warp": -0.0176, "bending_k2_weft": -0.0122,
                    "bending_floor": 0.3})
    mat = build_material(scene)
    nb = mat.nonlinear_bending
    assert nb.k2_warp == pytest.approx(-0.0176 * GF * 1e-4, rel=1e-12)  # gf cm^2 -> N m^2
    assert nb.floor == 0.3
    s = material_summary(scene, mat)["nonlinear_bending"]
    assert s["k2_warp"] == pytest.approx(-0.0176, rel=1e-12)
    # k2 / (B c) at the bending length: the wool's c = (0.083 / 0.019)^(1/3) cm
    assert s["ratio_at_bending_length_warp"] == pytest.approx(-0.0176 / (0.083 * (0.083 / 0.019) ** (1 / 3)), rel=1e-9)
    assert s["floor_curvature_warp"] == pytest.approx(0.7 * 0.083 / (2 * 0.0176), rel=1e-9)  # [1/cm]
    assert material_summary(scene, mat)["changed"] == ["bending_floor", "bending_k2_warp", "bending_k2_weft"]
    assert build_material(_scene({"preset": "wool-kang-yu"})).nonlinear_bending is None


def test_ctd_keys_and_the_preset_opt_in_give_the_data_set_k2():
    mat = build_material(_scene({**CTD, "ctd_k2_warp": -26843.8, "ctd_k2_weft": -35285.0}))
    assert mat.nonlinear_bending.k2_warp == pytest.approx(-26843.8e-12, rel=1e-12)
    assert mat.nonlinear_bending.floor == 0.2
    scene = _scene({"preset": "ctd-213-medium", "nonlinear_bending": True})
    opted = build_material(scene)
    assert opted.nonlinear_bending.k2_weft == pytest.approx(-35285.0e-12, rel=1e-12)
    s = material_summary(scene, opted)
    assert s["lab"]["bending_k2_warp"]["from"] == "ctd_k2_warp"
    assert s["nonlinear_bending"]["ratio_at_bending_length_warp"] == pytest.approx(-0.0954, abs=5e-4)
    # without the opt-in the preset is linear, as before
    assert build_material(_scene({"preset": "ctd-213-medium"})).nonlinear_bending is None


@pytest.mark.parametrize("table, key", [
    ({"preset": "wool-kang-yu", "bending_k2_warp": 0.01, "bending_k2_weft": -0.01}, "material.bending_k2_warp"),
    ({"preset": "wool-kang-yu", "bending_k2_warp": float("nan"), "bending_k2_weft": -0.01}, "material.bending_k2_warp"),
    ({"preset": "wool-kang-yu", "bending_k2_warp": -0.01}, "material.bending_k2_weft"),
    ({"preset": "wool-kang-yu", "bending_k2_warp": -0.01, "bending_k2_weft": -0.01, "bending_floor": 1.0},
     "material.bending_floor"),
    ({"preset": "wool-kang-yu", "bending_floor": 0.3}, "material.bending_floor"),
    ({"preset": "wool-kang-yu", "nonlinear_bending": True}, "material.nonlinear_bending"),
    ({**CTD, "nonlinear_bending": True}, "material.nonlinear_bending"),
    ({**CTD, "ctd_k2_warp": 50701.9, "ctd_k2_weft": -1.0}, "material.ctd_k2_warp"),
    ({**CTD, "ctd_k2_warp": -1.0, "ctd_k2_weft": float("inf")}, "material.ctd_k2_weft"),
    ({**CTD, "ctd_k2_warp": -2e7, "ctd_k2_weft": -1.0}, "material.ctd_k2_warp"),
    ({**CTD, "ctd_k2_weft": -1.0}, "material.ctd_k2_warp"),
    ({**CTD, "ctd_k2_warp": -1.0, "ctd_k2_weft": -1.0, "bending_k2_warp": -0.01}, "material.ctd_k2_warp"),
])
def test_bad_nonlinear_input_names_the_key(table, key):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        build_material(_scene(table))


def test_a_run_reports_nonlinear_bending_in_summary_json_and_the_strip_droops_more(tmp_path):
    from rftstatic.cli import main

    tips = {}
    for name, sets in (("linear", []), ("soft", ["material.bending_k2_warp=-0.03", "material.bending_k2_weft=-0.02"])):
        out = tmp_path / name
        args = ["case", "strip", "--set", "mesh.nodes=[21,5]", "--no-figures", "--out", str(out)]
        assert main(args + [a for k in sets for a in ("--set", k)]) == 0
        s = json.loads((out / "summary.json").read_text())
        tips[name] = s["probes"]["tip"]["deformed"][2]
    assert s["material"]["nonlinear_bending"]["k2_warp"] == pytest.approx(-0.03)
    assert s["material"]["nonlinear_bending"]["floor"] == 0.2
    run = s["nonlinear_bending"]
    assert 0.0 < run["floor_share_warp"] < 1.0 and run["max_over_floor_curvature_warp"] > 1.0
    assert s["converged"]
    assert tips["soft"] < tips["linear"]  # the softened strip hangs lower
