"""The drape bench's child solves a scene with ``solver.levels`` by mesh sequencing, as the CLI does."""

import json

from rftstatic.bench.drape import child


def test_the_drape_child_honours_solver_levels(tmp_path):
    rec = child("pedestal-square-20", str(tmp_path), ["mesh.nodes=[9,9]", "solver.levels=2"], figures=False)
    summary = json.loads((tmp_path / "summary.json").read_text(encoding="utf-8"))
    assert rec["converged"] and summary["route"].endswith("+levels")
    assert [lvl["mesh"] for lvl in summary["levels"]] == ["[5, 5]", "[9, 9]"]
