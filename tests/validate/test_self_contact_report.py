"""The self-contact report on one tiny scene: both runs, the verdict fields and the cost table."""

from rftstatic.validate import self_contact


def test_one_scene_with_and_without_self_contact(monkeypatch, tmp_path):
    monkeypatch.setattr(self_contact, "SCENES", {
        "sphere-30 9x9 RFT3": ("sphere-30", ["element=RFT3", "mesh.nodes=[9,9]"], True, [])})
    res = self_contact.run(quick=False)
    (row,) = res.rows
    assert "failed" not in row["on"] and "failed" not in row["off"], res.notes
    assert row["on"]["pairs"] == 0 and row["on"]["thickness"] == 0.05 and row["on"]["costs"]["broad_phase_build_s"] > 0
    assert row["on"]["converged"] and row["verdict"] in ("pass", "FAIL")
    assert (row["verdict"] == "pass") == (not row["reasons"])
    tables = dict(res.sections)
    assert "sphere-30 9x9 RFT3" in tables["Runs"] and "sphere-30 9x9 RFT3" in tables["Cost of the self-contact"]
