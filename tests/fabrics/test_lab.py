"""Lab units (KES-F, FAST) -> model rigidities, checked against hand-computed values; the scene rules
(one source per quantity, ranges, preset overrides) as scene errors that name the key and value."""

import math

import numpy as np
import pytest

from rftstatic.errors import ParameterError, SceneError
from rftstatic.fabrics.lab import RANGE_EVIDENCE, RANGES, lab_to_si
from rftstatic.fabrics.library import FABRICS, bending_lengths
from rftstatic.scenes.material import build_material
from rftstatic.scenes.schema import load_scene, scene_from_dict

GF_CM = 9.80665e-3 / 1e-2   # 1 gf/cm in N/m
GF_CM_MOMENT = 9.80665e-5   # 1 gf cm in N m


def test_kes_conversions_by_hand():
    si, rec = lab_to_si({"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_G": 0.73, "kes_EMT_warp": 4.0,
                         "kes_LT_weft": 0.6, "kes_WT_weft": 6.0, "kes_W": 19.0, "kes_T": 0.8})
    assert si["B_warp"] == pytest.approx(0.083 * 9.80665e-5, rel=1e-12)          # gf cm^2/cm = gf cm
    assert si["B_weft"] == pytest.approx(6.1781895e-6, rel=1e-7)
    # 0.73 gf/(cm deg) * 57.29578 deg/rad = 41.8259 gf/cm = 41.0172 N/m
    assert si["C_shear"] == pytest.approx(0.73 * 180 / math.pi * GF_CM, rel=1e-12)
    assert si["C_shear"] == pytest.approx(41.01721, rel=1e-6)
    # secant at 500 gf/cm: 500 / 0.04 = 12500 gf/cm = 12258.3 N/m; LT/WT: eps = 2*6/(0.6*500) = 0.04
    assert si["C_warp"] == pytest.approx(12500 * GF_CM, rel=1e-12)
    assert si["C_weft"] == pytest.approx(si["C_warp"], rel=1e-12)
    assert si["weight"] == pytest.approx(0.019 * 9.80665e-3 / 1e-4, rel=1e-12)   # 19 mg/cm^2 = 1.8633 N/m^2
    assert si["thickness"] == pytest.approx(0.8e-3)
    assert rec["C_shear"]["from"] == "kes_G" and "180/pi" in rec["C_shear"]["rule"]


def test_fast_conversions_by_hand():
    si, _ = lab_to_si({"fast_B_warp": 8.14, "fast_B_weft": 6.18, "fast_E100_warp": 2.0, "fast_E100_weft": 4.0,
                       "fast_G": 41.0, "fast_W": 190.0})
    assert si["B_warp"] == pytest.approx(8.14e-6) and si["B_weft"] == pytest.approx(6.18e-6)
    assert si["C_warp"] == pytest.approx(98.0665 / 0.02) and si["C_weft"] == pytest.approx(98.0665 / 0.04)
    assert si["C_shear"] == 41.0
    assert si["weight"] == pytest.approx(0.190 * 9.80665)


def test_kes_fm_changes_the_secant():
    si, _ = lab_to_si({"kes_EMT_warp": 10.0, "kes_Fm": 50.0})   # knits are tested to 50 gf/cm
    assert si["C_warp"] == pytest.approx(500 * GF_CM)


@pytest.mark.parametrize("key, value", [("kes_B_warp", 83.0), ("kes_G", -1.0), ("fast_W", 1.9), ("kes_W", 1e4)])
def test_out_of_range_lab_values_are_refused(key, value):
    with pytest.raises(ParameterError) as err:
        lab_to_si({key: value})
    assert err.value.key == key and repr(value) in err.value.detail


def test_bounds_of_b_and_w_hold_the_measured_data_set_with_margin():
    """The B and W bounds against the span of Feng et al.'s (2022) 618 fabrics
    (RANGE_EVIDENCE): each extreme is inside, and the bound lies a factor >= 4 beyond it."""
    b_lo, b_hi = RANGE_EVIDENCE["B_uNm"]
    w_lo, w_hi = RANGE_EVIDENCE["W_g_per_m2"]
    to_kes_b = 1e-6 / GF_CM_MOMENT                  # uN m -> gf cm^2/cm (1 gf cm = 98.0665 uN m)
    spans = {"fast_B_warp": (b_lo, b_hi), "kes_B_weft": (b_lo * to_kes_b, b_hi * to_kes_b),
             "fast_W": (w_lo, w_hi), "kes_W": (w_lo / 10.0, w_hi / 10.0)}   # 1 mg/cm^2 = 10 g/m^2
    for key, (lo, hi) in spans.items():
        lab_to_si({key: lo})
        lab_to_si({key: hi})
        assert RANGES[key][0] * 4 <= lo and RANGES[key][1] >= 4 * hi, key
    assert b_lo * to_kes_b == pytest.approx(0.002274, rel=1e-3)


def _material(table, units="cm-gf-s"):
    return build_material(scene_from_dict({"units": units, "material": table}))


WOOL_KES = {"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_G": 41.8 * math.pi / 180, "kes_W": 19.0,
            "C_warp": 1118.2, "C_weft": 759.5, "B_twist": 0.027}


def test_kes_wool_is_the_paper_wool():
    """Kang & Yu's wool given as KES values (B, G in degrees, W in mg/cm^2) is the preset to round-off."""
    a, b = _material(WOOL_KES), _material({"preset": "wool-kang-yu"})
    np.testing.assert_allclose(a.Dm, b.Dm, rtol=1e-12)
    np.testing.assert_allclose(a.Db, b.Db, rtol=1e-12)
    assert a.weight == pytest.approx(b.weight, rel=1e-12)
    assert set(a.info["lab"]) == {"B_warp", "B_weft", "C_shear", "weight"}


def test_mixing_kes_and_model_rigidity_of_one_quantity_is_a_scene_error():
    with pytest.raises(SceneError) as err:
        _material({**WOOL_KES, "B_warp": 0.083})
    text = str(err.value)
    assert "material.kes_B_warp" in text and "B_warp = 0.083" in text and "kes_B_warp = 0.083" in text


def test_out_of_range_kes_value_names_the_scene_key():
    with pytest.raises(SceneError, match=r"material\.kes_W: 1900\.0 mg/cm\^2 is outside"):
        _material({**WOOL_KES, "kes_W": 1900.0})


def test_a_model_key_changes_one_value_of_a_preset_and_the_summary_says_which():
    from rftstatic.scenes.material import material_summary

    base = load_scene("strip")
    wool = build_material(base)
    scene = load_scene("strip", ["material.C_warp=900.0"])
    c = build_material(scene)
    assert c.Dm[0, 0] == pytest.approx(900 * GF_CM) and c.Dm[1, 1] == pytest.approx(wool.Dm[1, 1])
    summary = material_summary(scene, c)
    assert summary["preset"] == "wool-kang-yu" and summary["changed"] == ["C_warp"]
    assert c.name == "wool-kang-yu (modified)"


def test_lab_data_next_to_a_preset_are_refused():
    """A preset never lends its other values to lab data (issue 35): the message says how to give the lab
    fabric alone. (Before, kes_B_warp on the wool silently kept the wool's membrane and twist.)"""
    with pytest.raises(SceneError) as err:
        build_material(load_scene("strip", ["material.kes_B_warp=0.1"]))
    text = str(err.value)
    assert "material.kes_B_warp" in text and 'preset = "wool-kang-yu"' in text and "material={kes_B_warp" in text


def test_twist_default_without_measurement():
    m = _material({k: v for k, v in WOOL_KES.items() if k != "B_twist"})
    assert m.Db[2, 2] == pytest.approx(0.5 * math.sqrt(0.083 * 0.063) * GF_CM_MOMENT, rel=1e-12)


def test_missing_quantity_names_its_lab_keys():
    model_keys = {"C_warp": 1118.2, "C_weft": 759.5, "C_shear": 41.8, "B_warp": 0.083, "B_weft": 0.063}
    with pytest.raises(SceneError, match="weight \\(or kes_W / fast_W / ctd_density\\)"):
        _material(model_keys)
    # a lab bending rigidity without its weight names the lab key (issue 35 item 6)
    with pytest.raises(SceneError, match=r"material\.kes_W: missing: kes_B_warp = 0\.083 is given without kes_W"):
        _material({k: v for k, v in WOOL_KES.items() if k != "kes_W"})


def test_library_bending_lengths():
    """c = (B/W)^(1/3): the wool's 1.635 cm (warp), 1.491 cm (weft); a bias cut reads its material axes."""
    for angle in (0.0, 30.0):
        m = build_material(scene_from_dict({"material": {"preset": "wool-kang-yu", "warp_angle": angle}}))
        c = bending_lengths(m)
        assert c["warp"]["c"] == pytest.approx(0.01 * (0.083 / 0.019) ** (1 / 3), rel=1e-12)
        assert c["weft"]["c"] == pytest.approx(0.01 * (0.063 / 0.019) ** (1 / 3), rel=1e-12)
    assert all(f.source for f in FABRICS.values())


def test_fabrics_command_lists_the_library(capsys):
    from rftstatic.cli import main

    assert main(["fabrics"]) == 0
    out = capsys.readouterr().out
    assert "wool-kang-yu" in out and "1.635 / 1.491" in out and "Kang" in out


def test_summary_records_the_converted_values():
    from rftstatic.scenes.material import material_summary

    scene = scene_from_dict({"units": "cm-gf-s", "material": WOOL_KES})
    rec = material_summary(scene, build_material(scene))["lab"]
    assert rec["C_shear"]["converted"] == pytest.approx(41.8, rel=1e-12) and rec["C_shear"]["from"] == "kes_G"
    assert rec["weight"]["converted"] == pytest.approx(0.019, rel=1e-12) and rec["weight"]["unit"] == "mg/cm^2"
