"""The drape bench's child solves a scene with ``solver.levels`` by mesh sequencing, as the CLI does."""

import json

import pytest

from rftstatic.app import levels
from rftstatic.bench.drape import child
from rftstatic.errors import ConvergenceError


def test_the_drape_child_honours_solver_levels(tmp_path):
    rec = child("pedestal-square-20", str(tmp_path), ["mesh.nodes=[9,9]", "solver.levels=2"], figures=False)
    summary = json.loads((tmp_path / "summary.json").read_text(encoding="utf-8"))
    assert rec["converged"] and summary["route"].endswith("+levels")
    assert [lvl["mesh"] for lvl in summary["levels"]] == ["[5, 5]", "[9, 9]"]


def test_a_coarser_level_that_fails_raises_the_solvers_error(tmp_path, monkeypatch):
    """No state to write (a coarser level failed): the child raises the ConvergenceError, as the CLI does."""

    def fails(scene, model, opts, **kw):
        raise ConvergenceError("mesh sequencing: level 1 of 2 ([5, 5], 25 nodes) did not converge", result=None)

    monkeypatch.setattr(levels, "solve_levels", fails)
    with pytest.raises(ConvergenceError, match="level 1 of 2"):
        child("pedestal-square-20", str(tmp_path), ["mesh.nodes=[9,9]", "solver.levels=2"], figures=False)
