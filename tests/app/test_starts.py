"""solver.compare: the drape solved from a second start, the lower stable minimum kept (rftstatic.app.starts)."""

import json

import pytest

from rftstatic.cli import main

STIFF = ["--set", "material.B_warp=0.332", "--set", "material.B_weft=0.252", "--set", "material.B_twist=0.108"]
"""The wool of cusick-30 with its bending rigidities x 4: the relaxation keeps 8 nodes, the load steps find 4."""


def test_the_lower_of_two_stable_drapes_is_kept(tmp_path):
    out = tmp_path / "out"
    assert main(["case", "cusick-30", "--no-figures", "--out", str(out), *STIFF,
                 "--set", "solver.compare=load-steps"]) == 0
    s = json.loads((out / "summary.json").read_text())
    rows = {r["start"]: r for r in s["starts"]["compared"]}
    assert set(rows) == {"relax", "load-steps"}
    assert all(r["converged"] and r["stable_minimum"] for r in rows.values())
    kept = min(rows, key=lambda k: rows[k]["energy"])
    assert s["starts"]["kept"] == kept
    # the outputs are the kept drape's: its energy, fold count and DC
    assert s["energies"]["total"] == pytest.approx(rows[kept]["energy"], rel=1e-12)
    assert s["drape"]["fold_count"] == rows[kept]["fold_count"]
    assert s["drape"]["drape_coefficient_percent"] == pytest.approx(rows[kept]["drape_coefficient_percent"])
    assert rows["relax"]["fold_count"] != rows["load-steps"]["fold_count"]  # two different drapes were compared
    assert s["wall_time_s"] >= rows["relax"]["wall_time_s"] + rows["load-steps"]["wall_time_s"] - 1e-6


def test_every_seeded_specimen_is_compared(tmp_path):
    out = tmp_path / "out"
    assert main(["case", "cusick-30", "--no-figures", "--out", str(out), *STIFF, "--set", "mesh.nodes=[9,96]",
                 "--set", "solver.compare=load-steps", "--set", "solver.seeds=2"]) == 0
    s = json.loads((out / "summary.json").read_text())
    specimens = s["seeds"]["specimens"]
    assert [r["start"] for r in specimens][0] == s["starts"]["kept"]
    assert all(r["start"] in ("relax", "load-steps") for r in specimens)


def test_comparing_with_the_scenes_own_start_is_a_single_solve(tmp_path, caplog):
    out = tmp_path / "out"
    assert main(["case", "strip", "--no-figures", "--out", str(out), "--set", "solver.compare=load-steps"]) == 0
    assert "starts" not in json.loads((out / "summary.json").read_text())
    assert "nothing to compare" in caplog.text


@pytest.mark.parametrize("sets, text", [
    (["solver.compare=sideways"], "solver.compare"),
    (["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=25.0, kes_T=0.5, kes_2HB_warp=0.05, kes_2HB_weft=0.04}",
      "solver.compare=load-steps"], "bending or shear hysteresis depends on its route"),
    (["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=25.0, kes_T=0.5, kes_2HG=1.0}",
      "solver.compare=load-steps"], "bending or shear hysteresis depends on its route"),
])
def test_bad_compare_exits_2_naming_the_key(tmp_path, capsys, sets, text):
    args = ["case", "cusick-30", "--no-figures", "--out", str(tmp_path / "o")]
    assert main(args + [a for k in sets for a in ("--set", k)]) == 2
    assert text in capsys.readouterr().err
