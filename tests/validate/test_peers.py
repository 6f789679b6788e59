"""The peers benchmark: scikit-fem's Kirchhoff plate triangles against Timoshenko, next to RF triangles.

scikit-fem is the optional extra ``peers``; the tests that solve with it are skipped without it.
"""

import math

import pytest

from rftstatic.validate import peers
from rftstatic.validate.report import observed_rate


def test_peer_plates_converge_to_timoshenko():
    pytest.importorskip("skfem")
    # Argyris (C1 quintic) on 9 x 9 nodes: within 0.5 % of the reference in every case
    for edges, load in peers.CASES:
        row = peers.peer_plate(9, "Argyris", edges, load)
        assert row["error"] < 5e-3, (edges, load, row["error"])
        assert row["unknowns"] > 0 and row["wall_time_s"] > 0
    # the clamped uniform-load coefficient to the reference's five figures (0.0012653 +- 4e-5 relative)
    assert peers.peer_plate(9, "Argyris", "clamped", "uniform")["error"] < 4e-5
    # Morley (non-conforming quadratic): second order under uniform load, from above
    for edges in ("simply_supported", "clamped"):
        rows = [peers.peer_plate(n, "Morley", edges, "uniform") for n in (9, 17, 33)]
        assert all(r["signed_error"] > 0 for r in rows)
        p = observed_rate([r["h"] for r in rows], [r["error"] for r in rows])
        assert 1.8 < p < 2.2, (edges, p)


def test_quick_peers_run_passes_with_peer_rows():
    pytest.importorskip("skfem")
    res = peers.run(quick=True)  # measured ~4 s (no figures)
    assert res.passed
    elements = {s.element for s in res.studies}
    assert elements == {"RFT3=RFT6", "Morley (scikit-fem)", "Argyris (scikit-fem)"}
    for s in res.studies:
        assert len(s.error) == 3 and all(t > 0 for t in s.wall_time)
        if s.element.startswith("Argyris"):
            assert s.finest_error < 5e-3
        if s.element == "RFT3=RFT6":
            assert s.tolerance == pytest.approx(0.03) and s.finest_error < 0.03
    assert not any("not installed" in n for n in res.notes)
    text = dict(res.sections)["Cost of accuracy (plates)"]
    rows = [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| case")]
    assert len(rows) == 12  # 4 cases x 3 elements


def test_without_scikit_fem_the_peer_rows_are_skipped(monkeypatch):
    monkeypatch.setattr(peers, "peer_version", lambda: None)
    monkeypatch.setattr(peers, "CASES", [("clamped", "uniform")])
    res = peers.run(quick=True)
    assert res.passed
    assert [s.element for s in res.studies] == ["RFT3=RFT6"]
    assert "scikit-fem not installed: peer rows skipped" in " ".join(res.notes)
    assert math.isfinite(res.finest_error) and res.finest_error < 0.01  # clamped, 41 x 41: 0.74 %
