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


def test_the_hand_written_node_count_section_is_carried_over_a_regeneration(monkeypatch, tmp_path):
    """The section of tools/node_count_study.py's runs survives ``validate measured_drape``: taken from the report on
    disk up to the next heading, placed before the route's scope; absent file or section: no section."""
    report = tmp_path / "measured_drape.md"
    assert md.carried_section(report) is None
    report.write_text("# T\n\n## Trends\n\nold rows\n\n## " + md.NODES_HEADING
                      + "\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\nConclusion.\n\n## Route and scope\n\nold scope\n",
                      encoding="utf-8")
    assert md.carried_section(report) == "| a | b |\n|---|---|\n| 1 | 2 |\n\nConclusion."
    assert md.carried_section(report, "Missing") is None
    monkeypatch.setattr(md, "plan", lambda quick: {"wool B x 0.5": ("cusick-30", ["wool B x 0.5"])})
    monkeypatch.setattr(md, "run_row", lambda scene, sets: _summary(1.2, 40.0, 10))
    headings = [h for h, _ in md.run(True, out=tmp_path).sections]
    assert headings.index(md.NODES_HEADING) == headings.index("Route and scope") - 1
    headings = [h for h, _ in md.run(True, out=tmp_path / "elsewhere").sections]
    assert md.NODES_HEADING not in headings
