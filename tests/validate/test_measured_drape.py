"""The measured-drape report's plan and trend checks (no solve: the runs are replaced by made-up summaries)."""

import pytest

from rftstatic.validate import BENCHMARKS, measured_drape as md


def test_plan_runs_the_lab_fabric_alone_and_with_2hb_on_every_specimen_size():
    rows = md.plan(False)
    assert "measured_drape" in BENCHMARKS
    for size in (24, 30, 36):
        alone = rows[md._lab_label(size, 0.0, md.RATIOS[0])]
        with_hb = rows[md._lab_label(size, md.HB2[-1], md.RATIOS[0])]
        assert alone[0] == with_hb[0] == f"cusick-{size}"
        assert "kes_2HB" not in " ".join(alone[1]) and "kes_2HB_warp=0.05" in " ".join(with_hb[1])
        assert all(k in " ".join(alone[1]) for k in ("kes_B_warp", "kes_B_weft", "kes_W", "kes_T"))


def _summary(c, dc, folds):
    return {"material": {"bending_length_warp": c, "bending_length_weft": c}, "nodes": 100, "element": "RFT6",
            "drape": {"drape_coefficient_percent": dc, "fold_count": folds, "boundary_radius_min": 11.0,
                      "boundary_radius_max": 13.0},
            "call_wall_time_s": 1.0, "newton_iterations": 3, "resolved_scene": {"mesh": {"radius": 15.0}}}


@pytest.mark.parametrize("sign, passes", [(1.0, True), (-1.0, False)])
def test_a_dc_that_falls_with_the_bending_length_fails_the_report(monkeypatch, sign, passes):
    cs = {"wool B x 0.5": 1.2, "wool B x 2": 2.0}
    monkeypatch.setattr(md, "plan", lambda quick: {k: ("cusick-30", [k]) for k in cs})
    monkeypatch.setattr(md, "run_row", lambda scene, sets: _summary(cs[sets[0]], 50 + sign * 20 * (cs[sets[0]] - 1.6),
                                                                    9 - sign * (cs[sets[0]] > 1.6)))
    result = md.run(True)
    assert result.passed is passes
    assert ("dc_rises_with_bending_length" in result.notes[0]) is not passes
