"""table-cloth: a square cloth over a square table top given as a mesh file (cases/table-top.obj, written by
tools/table.py), with friction (the scene) and frictionless: a stable equilibrium with no crossing of the table or of
itself."""

import importlib.util
from pathlib import Path

import pytest

from rftstatic import api

ROOT = Path(__file__).resolve().parents[2]


def _tool():
    spec = importlib.util.spec_from_file_location("tools_table", ROOT / "tools" / "table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_table_file_is_the_one_the_tool_writes(tmp_path):
    tool = _tool()
    V, F = tool.table_top(24.0, 2.0)
    tool.write_obj(tmp_path / "t.obj", V, F, 24.0, 2.0)
    assert (tmp_path / "t.obj").read_text() == (ROOT / "cases" / "table-top.obj").read_text()


def _check(summary, folds=4):
    assert summary["converged"] and summary["stable_minimum"]
    (crossing,) = summary["obstacle_crossings"]
    assert crossing["pairs"] == 0 and crossing["smallest_node_distance"] > 0.0
    assert summary["self_intersections"]["pairs"] == 0
    drape = summary["drape"]
    assert drape["fold_count"] == folds  # one fold down from each corner of the table (the square's symmetry)
    # the cloth hangs: its shadow lies between the table's (24 cm square) and the flat cloth's (40 cm square)
    assert 24.0**2 < drape["shadow_area"] < 40.0**2


def test_coarse_table_cloth_rests_on_the_table_without_crossing(tmp_path):
    """13 x 13 nodes, frictionless by relaxation: the corner folds' layers touch (24 self-crossing pairs without
    self-contact)."""
    _check(api.run("table-cloth", tmp_path, overrides=["mesh.nodes=[13, 13]", "contact.friction=0",
                                                       "solver.start=relax"], figures=False).summary)


@pytest.mark.slow
def test_table_cloth_scene(tmp_path):
    """The scene as given (25 x 25 nodes, RFT3, self-contact on, friction 0.3 by load steps): 98 s on the loaded
    2-core machine, 1879 Newton iterations; frictionless by relaxation its DC is 19.40 %."""
    summary = api.run("table-cloth", tmp_path, figures=False).summary
    _check(summary)
    assert summary["drape"]["drape_coefficient_percent"] == pytest.approx(17.50, abs=0.05)
