"""The factorisation benchmark runs on a tiny problem and leaves sksparse as it found it."""

import pytest

from rftstatic.solvers import linear

pytestmark = pytest.mark.skipif(not linear.cholmod_available(), reason="scikit-sparse is not installed")


def test_factor_bench_runs(capsys):
    from rftstatic.bench import factor

    factor.run(problems=("strip 21x5",), reps=2)
    out = capsys.readouterr().out
    assert "strip 21x5: 300 unknowns" in out and "supernodal" in out


def test_solve_factor_times_counts_and_restores():
    import sksparse.cholmod as skc

    from rftstatic.bench import factor

    analyze = skc.analyze
    r = factor.solve_factor_times(11, 3)
    assert r["factorisations"] > 0 and r["factor_s"] > 0
    assert skc.analyze is analyze
