"""Cheap cells of the stability matrix (rftstatic.validate.stability): converge correctly or stop clearly."""

import numpy as np
import pytest

from rftstatic.errors import InstabilityError, PatchError
from rftstatic.solvers import static
from rftstatic.solvers.explicit import run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.timestep import stable_time_step
from rftstatic.validate import stability as st
from rftstatic.validate.stability.cell_functions import _hang, _strip


def test_soft_membrane_strip_matches_heavy_elastica():
    # C/B = 100 /cm^2 (wool: 1.35e4): the strip stretches by w L / C ~ 1 %, the extensible elastica follows
    r = st.strip_cell(11, 3, element="RFT3", ratio=1e2)
    assert r["converged"] and r["error"] < st.strip_tolerance(11)


def test_stiff_membrane_strip_converges_correctly_or_stops_clearly():
    # C/B = 1e9 /cm^2: near the limit of double precision; a wrong converged tip would be a defect
    try:
        r = st.strip_cell(11, 3, element="RFT3", ratio=1e9)
    except static.ConvergenceError as exc:
        assert "load factor" in str(exc) and exc.result is not None and not exc.result.converged
    else:
        assert r["error"] < st.strip_tolerance(11)


def test_one_increment_to_full_load_finds_its_own_way():
    r = st.strip_cell(11, 3, element="RFT3", one_step=True)
    assert r["converged"] and r["error"] < st.strip_tolerance(11)


def test_degenerate_patch_is_reported_with_the_element():
    with pytest.raises(PatchError, match=r"element \d+ at"):
        st.strip_cell(21, 5, degenerate=1e-9)


def test_explicit_step_above_critical_raises_with_a_working_suggestion():
    mod, _ = _hang(7)
    est = stable_time_step(mod, alpha=5.0)
    t_end = 300 * est.dt
    with pytest.raises(InstabilityError) as info:
        run_explicit(mod, ExplicitOptions(t_end=t_end, dt=1.2 * est.dt, alpha=5.0, progress=False))
    exc = info.value
    assert exc.suggested_dt <= est.dt * (1 + 1e-9) and f"{exc.suggested_dt:.4g}" in str(exc)
    res = run_explicit(mod, ExplicitOptions(t_end=t_end, dt=exc.suggested_dt, alpha=5.0, progress=False))
    assert np.isfinite(res.U).all()


def test_a_cell_over_its_budget_is_a_fail_not_a_hang():
    cell = st.Cell("test", "budget", "strip_cell", {"nx": 41, "ny": 9}, budget=0.05, tolerance=0.01)
    rec = st.run_cell(cell)
    assert rec["verdict"] == "FAIL" and rec["reason"].startswith("hang") and rec["wall_time_s"] < 10


def test_rft6_warns_of_membrane_locking_where_the_strip_stiffens(caplog):
    """Above LOCKING_WARN an RFT6 model warns (log and ``model.warnings``) and names the fix: the strip
    of the stability matrix at C/B = 1e6 /cm^2 on 21 x 5 nodes (locking number 8e4, measured 3.3 %
    too stiff) warns; RFT3 and the paper's wool on the same mesh do not. The matrix then reports an
    out-of-tolerance answer on a warned model as a limitation, not as a silent wrong answer."""
    import logging

    from rftstatic.model.model import LOCKING_WARN, locking_number

    with caplog.at_level(logging.WARNING, logger="rftstatic.model.model"):
        coarse = _strip(21, 5, element="RFT6", ratio=1e6)
    assert locking_number(coarse.mesh, coarse.material) > LOCKING_WARN
    assert coarse.warnings and "RFT3" in coarse.warnings[0] and "Refine" in coarse.warnings[0]
    assert any("membrane locking" in r.message for r in caplog.records)
    assert not _strip(21, 5, element="RFT3", ratio=1e6).warnings  # the CST does not lock
    wool = _strip(21, 5, element="RFT6")
    assert locking_number(wool.mesh, wool.material) < LOCKING_WARN and not wool.warnings
    cell = st.Cell("g", "c", "strip_cell", {}, 10, 0.01)
    rec = {"converged": True, "error": 0.03}
    assert st.verdict(cell, rec)[0] == "FAIL"
    assert st.verdict(cell, dict(rec, warnings=coarse.warnings))[0] == "limitation"
