"""A fabric given by KES-F B, W and T alone (issue 35 item 2): every missing quantity filled by its stated
rule (hand-computed here), listed with unit, rule and source; given values always beat the rules."""

import math

import numpy as np
import pytest

from rftstatic.errors import SceneError
from rftstatic.fabrics.rules import FILL_RULES, SHEAR_PER_BENDING, fill
from rftstatic.scenes.material import build_material, material_summary
from rftstatic.scenes.schema import load_scene, scene_from_dict

GF_CM = 9.80665e-3 / 1e-2   # 1 gf/cm in N/m
GF_CM_MOMENT = 9.80665e-5   # 1 gf cm in N m

KES_ONLY = {"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_W": 19.0, "kes_T": 0.5}
"""Kang & Yu's wool as a lab reports it (B, W) with a suiting's thickness."""


def _scene(table, units="cm-gf-s"):
    return scene_from_dict({"units": units, "material": table})


def test_the_wool_shear_ratio_is_its_own():
    # 41.8 gf/cm / sqrt(0.083 * 0.063) gf cm = 578.1 cm^-2
    assert SHEAR_PER_BENDING == pytest.approx(41.8 / math.sqrt(0.083 * 0.063) * 1e4, rel=1e-12)
    assert SHEAR_PER_BENDING * 1e-4 == pytest.approx(578.1, abs=0.05)


def test_a_kes_only_fabric_is_filled_by_the_stated_rules():
    scene = _scene(KES_ONLY)
    m = build_material(scene)
    # tensile: C = 12 B / T^2 = 12 * 0.083 gf cm / (0.05 cm)^2 = 398.4 gf/cm; weft 302.4 gf/cm
    assert m.Dm[0, 0] == pytest.approx(398.4 * GF_CM, rel=1e-12)
    assert m.Dm[1, 1] == pytest.approx(302.4 * GF_CM, rel=1e-12)
    # shear: the wool's own ratio gives back the wool's 41.8 gf/cm for the wool's B
    assert m.Dm[2, 2] == pytest.approx(41.8 * GF_CM, rel=1e-12)
    assert m.Db[2, 2] == pytest.approx(0.5 * math.sqrt(0.083 * 0.063) * GF_CM_MOMENT, rel=1e-12)
    assert m.Dm[0, 1] == 0.0 and m.Db[0, 1] == 0.0
    filled = material_summary(scene, m)["filled"]
    assert set(filled) == set(FILL_RULES)
    assert filled["C_warp"]["value"] == pytest.approx(398.4) and filled["C_warp"]["unit"] == "gf/cm"
    assert filled["B_twist"]["unit"] == "gf cm" and "Poisson" in filled["C12"]["rule"]
    assert all(rec["rule"] and rec["source"] for rec in filled.values())
    assert "Timoshenko" in filled["C_weft"]["source"] and "Kang & Yu" in filled["C_shear"]["source"]
    assert m.name.startswith("lab fabric (kes_B_warp 0.083")


def test_the_rules_are_the_same_in_any_unit_system():
    """The SI scene's filled values are the cm-gf-s scene's, converted (the rules work in SI)."""
    a, b = build_material(_scene(KES_ONLY)), build_material(_scene(KES_ONLY, units="SI"))
    np.testing.assert_allclose(a.Dm, b.Dm, rtol=1e-12)
    np.testing.assert_allclose(a.Db, b.Db, rtol=1e-12)
    assert material_summary(_scene(KES_ONLY, units="SI"), b)["filled"]["C_warp"]["unit"] == "N/m"


@pytest.mark.parametrize("given, key, expected", [
    ({"kes_G": 1.0}, "C_shear", 1.0 * 180 / math.pi * GF_CM),              # a measured shear beats its rule
    ({"kes_EMT_warp": 5.0, "kes_EMT_weft": 5.0}, "C_warp", 500 / 0.05 * GF_CM),
    ({"B_twist": 0.02}, "B_twist", 0.02 * GF_CM_MOMENT),
    ({"C12": 30.0}, "C12", 30.0 * GF_CM),
])
def test_a_given_value_is_used_instead_of_its_rule(given, key, expected):
    scene = _scene({**KES_ONLY, **given})
    m = build_material(scene)
    index = {"C_shear": ("Dm", 2, 2), "C_warp": ("Dm", 0, 0), "B_twist": ("Db", 2, 2), "C12": ("Dm", 0, 1)}[key]
    assert getattr(m, index[0])[index[1], index[2]] == pytest.approx(expected, rel=1e-12)
    assert key not in material_summary(scene, m)["filled"]


def test_tensile_data_make_the_thickness_unnecessary():
    m = build_material(_scene({**{k: v for k, v in KES_ONLY.items() if k != "kes_T"}, "kes_EMT_warp": 5.0,
                               "kes_EMT_weft": 6.0}))
    assert m.Dm[1, 1] == pytest.approx(500 / 0.06 * GF_CM, rel=1e-12)


def test_fill_reports_what_a_rule_needs():
    si = {"B_warp": 1e-5, "B_weft": 1e-5}
    with pytest.raises(KeyError, match="thickness"):
        fill(si)
    assert set(fill(si, only=("B_twist",))) == {"B_twist"} and si["B_twist"] == pytest.approx(0.5e-5)


@pytest.mark.parametrize("table, key, words", [
    ({k: v for k, v in KES_ONLY.items() if k != "kes_T"}, "kes_T", "needs the fabric's thickness"),
    ({k: v for k, v in KES_ONLY.items() if k != "kes_W"}, "kes_W", "is given without kes_W"),
    ({k: v for k, v in KES_ONLY.items() if k != "kes_B_weft"}, "kes_B_weft", "is given without kes_B_weft"),
    ({**KES_ONLY, "kes_B_warp": 0.0}, "kes_B_warp", "must be > 0"),
    ({**KES_ONLY, "kes_T": -0.5}, "kes_T", "must be > 0"),
    ({**KES_ONLY, "kes_W": 1900.0}, "kes_W", "Feng et al. (2022)"),
    ({**KES_ONLY, "kes_G": 50.0}, "kes_G", "unverified"),
    ({**KES_ONLY, "preset": "wool-kang-yu"}, "kes_B_warp", "next to preset"),
])
def test_bad_lab_input_names_the_key(table, key, words):
    with pytest.raises(SceneError) as err:
        build_material(_scene(table))
    assert f"material.{key}:" in str(err.value) and words in str(err.value)


def test_an_out_of_range_message_gives_the_range():
    with pytest.raises(SceneError, match=r"\[0\.0005, 20\] gf cm\^2/cm"):
        build_material(_scene({**KES_ONLY, "kes_B_weft": 83.0}))


def test_the_cusick_scene_takes_a_kes_only_table_from_the_command_line():
    scene = load_scene("cusick-30", ["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5}"])
    assert build_material(scene).Dm[0, 0] == pytest.approx(398.4 * GF_CM, rel=1e-12)


def test_fabrics_explain_lists_the_rules_and_a_scenes_sources(capsys):
    from rftstatic.cli import main

    assert main(["fabrics", "--explain"]) == 0
    out = capsys.readouterr().out
    assert "kes_T" in out and "C_warp = 12 B_warp / T^2" in out and "Timoshenko" in out and "[0.0005, 20]" in out
    assert main(["fabrics", "--explain", "cusick-30", "--set",
                 "material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5}"]) == 0
    out = capsys.readouterr().out
    assert "398.4 gf/cm      filled" in out and "given: kes_W = 19 mg/cm^2" in out
    assert main(["fabrics", "--explain", "cusick-30"]) == 0
    assert "preset wool-kang-yu" in capsys.readouterr().out
