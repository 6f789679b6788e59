"""The fabric library's presets from Feng et al.'s (2022) data set (``ctd-*``): built from the published row,
their bending lengths against values computed by hand from that row, the rule for what the data set does
not give, and the cantilever tester recovering a preset's rigidity."""

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rftstatic.fabrics.library import CTD_COLUMNS, FABRICS, bending_lengths
from rftstatic.material import PRESETS
from rftstatic.scenes.material import build_material, list_fabrics
from rftstatic.scenes.schema import load_scene, scene_from_dict

GF_CM = 9.80665e-3 / 1e-2   # 1 gf/cm in N/m
GF_CM_MOMENT = 9.80665e-5   # 1 gf cm in N m

# Bending lengths c = (B / W)^(1/3) by hand from each data row (dataset/dataset.csv, commit 24a980c):
# B = "linear warp/weft[SI*1e9]" x 1e-9 N m, W = "density[kg.m-2]" x 9.80665 m/s^2.
HAND_C_CM = {
    # row 291: W = 0.0490 x 9.80665 = 0.480526 N/m^2; 1078.5e-9 / 0.480526 = 2.24442e-6 m^3 -> 1.30929 cm;
    #          815.2e-9 / 0.480526 = 1.69647e-6 m^3 -> 1.19266 cm
    "ctd-291-light-soft": (1.30929, 1.19266),
    # row 12: W = 0.0604 x 9.80665 = 0.592322; 33479.0e-9 / W = 5.65217e-5 -> 3.83771;
    #         4057.1e-9 / W = 6.84949e-6 -> 1.89912
    "ctd-12-light-stiff": (3.83771, 1.89912),
    # row 213: W = 0.2023 x 9.80665 = 1.98389; 14501.9e-9 / W = 7.30985e-6 -> 1.94075;
    #          10176.5e-9 / W = 5.12958e-6 -> 1.72462
    "ctd-213-medium": (1.94075, 1.72462),
    # row 350: W = 0.3873 x 9.80665 = 3.79812; 7830.1e-9 / W = 2.06157e-6 -> 1.27272;
    #          4695.5e-9 / W = 1.23627e-6 -> 1.07326
    "ctd-350-heavy-soft": (1.27272, 1.07326),
    # row 367: W = 0.3989 x 9.80665 = 3.91187; 135107.1e-9 / W = 3.45377e-5 -> 3.25660;
    #          35003.8e-9 / W = 8.94809e-6 -> 2.07608
    "ctd-367-heavy-stiff": (3.25660, 2.07608),
}


def _material(name, **extra):
    return build_material(scene_from_dict({"units": "cm-gf-s", "material": {"preset": name, **extra}}))


@pytest.mark.parametrize("name", sorted(HAND_C_CM))
def test_ctd_preset_bending_lengths_are_the_published_rows(name):
    m = _material(name)
    c = bending_lengths(m)
    assert c["warp"]["c"] * 100 == pytest.approx(HAND_C_CM[name][0], rel=2e-5)
    assert c["weft"]["c"] * 100 == pytest.approx(HAND_C_CM[name][1], rel=2e-5)
    fab = FABRICS[name]
    row = int(name.split("-")[1])
    assert f"data row {row}" in fab.source and "24a980c" in fab.source and "dataset/dataset.csv" in fab.source
    # the published row is kept whole: used values plus the ones the linear model does not take
    assert set(fab.values) == {"ctd_density", "ctd_B_warp", "ctd_B_weft"}
    assert len(fab.values) + len(fab.not_used) == len(CTD_COLUMNS)
    assert m.weight == pytest.approx(fab.values["ctd_density"] * 9.80665, rel=1e-12)
    assert m.Db[0, 0] == pytest.approx(fab.values["ctd_B_warp"] * 1e-9, rel=1e-12)


def test_ctd_presets_span_the_data_set():
    """Light-soft to heavy-stiff: the weights and bending lengths are ordered as the names say."""
    lengths = {n: math.sqrt(a * b) for n, (a, b) in HAND_C_CM.items()}
    weight = {n: FABRICS[n].values["ctd_density"] for n in HAND_C_CM}
    assert lengths["ctd-350-heavy-soft"] < lengths["ctd-213-medium"] < lengths["ctd-367-heavy-stiff"]
    assert lengths["ctd-291-light-soft"] < lengths["ctd-213-medium"] < lengths["ctd-12-light-stiff"]
    assert max(weight["ctd-291-light-soft"], weight["ctd-12-light-stiff"]) < weight["ctd-213-medium"] \
        < min(weight["ctd-350-heavy-soft"], weight["ctd-367-heavy-stiff"])


def test_what_the_data_set_does_not_give_comes_from_the_stated_rule():
    wool = PRESETS["wool-kang-yu"][1]
    m = _material("ctd-213-medium")
    assert m.Dm[0, 0] == pytest.approx(wool["C_warp"] * GF_CM, rel=1e-12)
    assert m.Dm[1, 1] == pytest.approx(wool["C_weft"] * GF_CM, rel=1e-12)
    assert m.Dm[2, 2] == pytest.approx(wool["C_shear"] * GF_CM, rel=1e-12)
    assert m.Dm[0, 1] == 0.0 and m.Db[0, 1] == 0.0
    assert m.Db[2, 2] == pytest.approx(0.5 * math.sqrt(m.Db[0, 0] * m.Db[1, 1]), rel=1e-12)
    lab, filled = m.info["lab"], m.info["filled"]
    assert lab["B_warp"]["from"] == "ctd_B_warp" and lab["weight"]["from"] == "ctd_density"
    # the values not from the data set are listed as filled (with rule and source), not as lab conversions
    assert "wool-kang-yu" in filled["C_warp"]["rule"] and "C_shear" not in lab
    assert set(filled) == {"C_warp", "C_weft", "C_shear", "B_twist", "C12", "B12"}
    row = next(r for r in list_fabrics() if r["name"] == "ctd-213-medium")
    assert row["derived"] == ["B_twist", "C_shear", "C_warp", "C_weft"] and "wool" in row["derived_rule"]
    assert next(r for r in list_fabrics() if r["name"] == "wool-kang-yu")["derived"] == []


def test_a_scene_key_overrides_one_key_of_a_ctd_preset():
    base = build_material(load_scene("cantilever-warp", ["material.preset=ctd-213-medium"]))
    m = build_material(load_scene("cantilever-warp", ["material.preset=ctd-213-medium", "material.C_warp=900.0"]))
    assert m.Dm[0, 0] == pytest.approx(900 * GF_CM)
    assert m.Dm[1, 1] == base.Dm[1, 1] and m.Dm[2, 2] == base.Dm[2, 2]
    assert (m.Db == base.Db).all() and m.weight == base.weight
    b = build_material(load_scene("cantilever-warp", ["material.preset=ctd-213-medium", "material.B_warp=0.2"]))
    assert b.Db[0, 0] == pytest.approx(0.2 * GF_CM_MOMENT) and b.Db[1, 1] == base.Db[1, 1]


def test_fabrics_command_lists_the_ctd_presets(capsys):
    from rftstatic.cli import main

    assert main(["fabrics"]) == 0
    out = capsys.readouterr().out
    assert "ctd-213-medium" in out and "1.941 / 1.725" in out and "Feng et al. (2022) data set, row 213" in out
    assert "not from the source: membrane rigidities" in out


def test_cantilever_recovers_a_ctd_preset_rigidity(tmp_path):
    """The cantilever scene (default mesh) on the medium preset reads its B_warp within 0.5 % (measured
    2026-12-02: -0.09 %, 4 s)."""
    from rftstatic import api

    scene = api.load_scene("cantilever-warp", ["material.preset=ctd-213-medium"])
    summary = api.run(scene, tmp_path / "run", figures=False).summary
    cant = summary["cantilever"]
    assert summary["converged"]
    given = FABRICS["ctd-213-medium"].values["ctd_B_warp"] * 1e-9 / GF_CM_MOMENT   # gf cm
    assert cant["given_bending_rigidity"] == pytest.approx(given, rel=1e-12)
    assert cant["flexural_rigidity"] == pytest.approx(given, rel=5e-3)
    assert cant["bending_length"] == pytest.approx(HAND_C_CM["ctd-213-medium"][0], rel=5e-3 / 3)


CTD_CSV = os.environ.get("RFTSTATIC_CTD_CSV")


@pytest.mark.skipif(not CTD_CSV, reason="set RFTSTATIC_CTD_CSV to a copy of the data set's dataset/dataset.csv")
def test_ctd_presets_are_the_rows_of_the_file_and_the_rule_picks_them():
    """Against the file itself (not in this repository): each preset's seven values are its row, and the
    selection rule of tools/select_ctd_fabrics.py picks exactly these rows."""
    lines = open(CTD_CSV).read().splitlines()
    assert tuple(c.strip() for c in lines[0].split(",")) == CTD_COLUMNS and len(lines) - 1 == 618
    for name in HAND_C_CM:
        fab, row = FABRICS[name], int(name.split("-")[1])
        cells = [float(c) for c in lines[row + 1].split(",")]
        published = {**{k: fab.values[v] for k, v in zip(CTD_COLUMNS[:3], ("ctd_density", "ctd_B_warp",
                                                                               "ctd_B_weft"))}, **fab.not_used}
        assert [published[k] for k in CTD_COLUMNS] == cells, name
    out = subprocess.run([sys.executable, str(Path(__file__).parents[2] / "tools" / "select_ctd_fabrics.py"),
                          CTD_CSV], capture_output=True, text=True, check=True).stdout
    assert sorted(n.split(":")[0] for n in out.splitlines()[1:]) == sorted(HAND_C_CM)
