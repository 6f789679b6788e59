"""The stability matrix runs each cell in a fresh child interpreter (rftstatic.validate.stability.runner).

A forked child hung in "clamped plate 41x41" once the parent had run a supernodal CHOLMOD factorisation
(libgomp's thread team: the fork copies its lock, not its threads). The default suite runs that cell
after such a factorisation in this process, and a subset of the quick matrix with one cell of every
outcome through the report, and the whole quick matrix (26 cells, each a fresh interpreter of ~1 s
start-up: 45 s on the 2-core machine at load average 2.5, 97 s at 4).
"""

import dataclasses
import importlib.util
import time

import pytest

from rftstatic.validate import stability as st
from rftstatic.validate.stability import report

SUBSET = {  # cell name -> expected outcome: one of each ("clamped plate 41x41", a pass, in the test above)
    "C/B = 1e+09 /cm^2, RFT6 11x3": "limitation",
    "C/B = 1e+02 /cm^2, pedestal-square-20 9x9": "converged",
    "21x5, opposite node at 1e-12 of its distance to the edge": "expected stop",
    "hang-20 11x11, dt = 1.2 x estimate": "expected stop",
    "scene preset + override material.C_warp": "pass",
}


def _quick(name):
    return next(c for c in st.cells(quick=True) if c.name == name)


@pytest.mark.skipif(importlib.util.find_spec("sksparse") is None, reason="needs CHOLMOD (scikit-sparse)")
def test_a_cell_runs_after_this_process_started_openmp_threads():
    from rftstatic.validate.plates import plate_coefficient

    assert plate_coefficient(41, "clamped", "uniform")["converged"]  # supernodal CHOLMOD here: libgomp threads
    cell = dataclasses.replace(_quick("clamped plate 41x41 (bending only)"), budget=60.0)
    t0 = time.perf_counter()
    rec = st.run_cell(cell)
    assert rec["verdict"] == "pass", rec["reason"]
    assert time.perf_counter() - t0 < 30 and rec["process_s"] >= rec["wall_time_s"] > 0 and rec["peak_rss_mb"] > 50


def test_a_hung_cell_is_killed_and_named_in_its_verdict():
    cell = st.Cell("test", "slow strip", "strip_cell", {"nx": 401, "ny": 41}, budget=1.0, tolerance=0.01)
    t0 = time.perf_counter()
    rec = st.run_cell(cell)
    assert time.perf_counter() - t0 < 10 and rec["verdict"] == "FAIL"
    assert rec["reason"] == ('hang: stability cell "test: slow strip": no result within the budget of 1 s; the child '
                             "process was killed")


def test_a_subset_of_the_quick_matrix_one_cell_of_each_outcome(monkeypatch, capsys):
    cells = [_quick(name) for name in SUBSET]
    monkeypatch.setattr(report, "cells", lambda quick: cells)
    result = st.run(quick=True)
    rows = {r["case"]: r for r in result.rows}
    assert {name: rows[name]["verdict"] for name in SUBSET} == SUBSET
    assert result.passed and "FAIL" not in capsys.readouterr().out
    assert rows["21x5, opposite node at 1e-12 of its distance to the edge"]["exception"] == "MeshError"
    assert rows["hang-20 11x11, dt = 1.2 x estimate"]["stopped"] == "InstabilityError"


def test_the_quick_stability_matrix_has_no_fail():
    result = st.run(quick=True)
    fails = [f"{r['case']}: {r['reason']}" for r in result.rows if r["verdict"] == "FAIL"]
    assert len(result.rows) == len(st.cells(quick=True)) == 26 and not fails and result.passed
