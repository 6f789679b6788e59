"""The Kratos peer of the clamped strip (rftstatic.bench.kratos_peer): material mapping, missing Kratos, a solve."""

import importlib.util
import math

import pytest

from rftstatic.bench import kratos_peer


def test_the_shell_has_the_strips_rigidities_and_weight(wool):
    B, C, w = wool.Db[0, 0], wool.Dm[0, 0], wool.weight
    s = kratos_peer.strip_shell(B, C, w)
    assert s["nu"] == 0.0
    assert math.isclose(s["E"] * s["thickness"], C, rel_tol=1e-12)
    assert math.isclose(s["E"] * s["thickness"] ** 3 / 12, B, rel_tol=1e-12)
    assert math.isclose(s["density"] * s["thickness"] * kratos_peer.GRAVITY, w, rel_tol=1e-12)


def test_without_kratos_the_error_names_the_pip_command(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "KratosMultiphysics"
                        else real(name, *a))
    assert not kratos_peer.kratos_available()
    with pytest.raises(ImportError, match="pip install KratosMultiphysics KratosStructuralMechanicsApplication"):
        kratos_peer.solve_strip(21, 6)


def test_kratos_drops_the_tip_of_a_coarse_strip_within_2_percent_of_the_elastica():
    pytest.importorskip("KratosMultiphysics")
    r = kratos_peer.solve_strip(21, 6, increments=5)  # 21 nodes along the 5 cm, 6 across
    assert r["converged"] and r["iterations"] > 0 and len(r["step_iterations"]) == r["increments"] == 5
    assert r["tip_drop_cm"] == pytest.approx(kratos_peer.REFERENCE_TIP_DROP_CM, rel=0.02)
    assert r["error"] == pytest.approx(r["tip_drop_cm"] / 4.34468 - 1)
    assert r["nodes"] == 126 and r["dofs"] == 6 * (126 - 6) and r["solve_s"] > 0
