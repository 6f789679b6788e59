"""Reference data and reference solutions: rftstatic.references."""

import math

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.special import zeta

from rftstatic.references import END_MOMENT, END_SHEAR, SLIT_ANNULAR, SZE2004_NAMES, load_sze2004
from rftstatic.references.elastica import alpha_of, heavy_elastica
from rftstatic.references.plates import TABLE, centre_deflection, navier_coefficient

ALPHA_PAPER = 0.019 * 5.0**3 / 0.083   # §4.1 strip: weight gf/cm², L = 5 cm, B_warp gf·cm


# --- Sze, Liu & Lo (2004) data -------------------------------------------------------------

@pytest.mark.parametrize("name", SZE2004_NAMES)
def test_load_sze2004_columns_and_monotone_load(name):
    d = load_sze2004(name)
    lf = d["load_fraction"]
    assert lf[-1] == 1.0 and np.all(np.diff(lf) > 0)
    assert all(v.shape == lf.shape and np.all(np.isfinite(v)) for v in d.values())


def test_load_sze2004_accepts_file_name_and_rejects_unknown():
    assert np.array_equal(load_sze2004("sze2004_end_shear.csv")["w_tip"],
                          load_sze2004("end_shear")["w_tip"])
    with pytest.raises(ValueError, match="unknown benchmark name = 'end_torsion'"):
        load_sze2004("end_torsion")


def test_end_moment_exact_column_is_the_circle_formula():
    d = load_sze2004("end_moment")
    th = 2.0 * np.pi * d["load_fraction"]
    L = END_MOMENT.L
    assert np.allclose(d["minus_u_tip_exact"], L * (1.0 - np.sin(th) / th), atol=1.5e-3)
    assert np.allclose(d["w_tip_exact"], L * (1.0 - np.cos(th)) / th, atol=1.5e-3)


def test_problem_parameters():
    assert END_SHEAR.EI == pytest.approx(100.0) and END_MOMENT.EI == pytest.approx(100.0)
    assert END_MOMENT.load_max == pytest.approx(2.0 * np.pi * END_MOMENT.EI / END_MOMENT.L)
    assert SLIT_ANNULAR.total_force_max == pytest.approx(3.2)
    assert SLIT_ANNULAR.D == pytest.approx(21e6 * 0.03**3 / 12.0)
    with pytest.raises(AttributeError):
        END_SHEAR.L = 1.0   # frozen


# --- Kirchhoff plates -----------------------------------------------------------------------

def test_navier_reproduces_timoshenko_coefficients():
    assert round(navier_coefficient("uniform"), 7) == 0.0040624
    assert round(navier_coefficient("point"), 6) == 0.011601


def test_navier_point_load_against_closed_form_inner_sum():
    # Σ_{n odd} 1/(n² + c²)² = −f'(c)/(2c), f(c) = Σ_{n odd} 1/(n² + c²) = π tanh(πc/2)/(4c);
    # for large c it tends to π/(8c³) (exponentially fast), whose tail is a Hurwitz zeta.
    m = np.arange(1, 2001, 2, dtype=float)
    t = np.tanh(np.pi * m / 2.0)
    fprime = np.pi / 4.0 * ((np.pi / 2.0) * (1.0 - t**2) / m - t / m**2)
    inner = -fprime / (2.0 * m)
    tail = np.pi / 8.0 * zeta(3.0, (m[-1] + 2.0) / 2.0) / 8.0
    beta = 4.0 / np.pi**4 * (inner.sum() + tail)
    assert navier_coefficient("point") == pytest.approx(beta, rel=1e-9)


def test_centre_deflection_scaling_and_errors():
    a, D = 2.0, 3.0
    assert centre_deflection("ss", "uniform", a, D, 5.0) == pytest.approx(
        navier_coefficient("uniform") * 5.0 * a**4 / D)
    assert centre_deflection("clamped", "point", a, D, 7.0) == pytest.approx(
        TABLE[("clamped", "point")] * 7.0 * a**2 / D)
    assert centre_deflection("clamped", "uniform", a, D, 1.0) < centre_deflection(
        "simply_supported", "uniform", a, D, 1.0)
    with pytest.raises(ValueError, match="edges = 'free'"):
        centre_deflection("free", "uniform", a, D, 1.0)
    with pytest.raises(ValueError, match="load = 'line'"):
        centre_deflection("ss", "line", a, D, 1.0)


# --- heavy cantilever elastica --------------------------------------------------------------

def test_elastica_small_alpha_is_the_linear_cantilever():
    alpha = 1e-3
    sol = heavy_elastica(alpha)
    assert -sol.tip_z == pytest.approx(alpha / 8.0, rel=1e-3)      # δ = wL⁴ / 8EI
    assert sol.tip_theta == pytest.approx(alpha / 6.0, rel=1e-3)   # θ_tip = wL³ / 6EI
    assert sol.tip_x == pytest.approx(1.0, abs=1e-6)


def test_elastica_self_convergence_in_tolerance():
    a = heavy_elastica(ALPHA_PAPER, tol=1e-9)
    b = heavy_elastica(ALPHA_PAPER, tol=1e-10)
    assert abs(a.tip_x - b.tip_x) < 1e-9 and abs(a.tip_z - b.tip_z) < 1e-9


def test_elastica_paper_strip():
    sol = heavy_elastica(ALPHA_PAPER)
    assert alpha_of(0.019, 5.0, 0.083) == pytest.approx(28.614, abs=1e-3)
    assert sol.tip_x == pytest.approx(0.3535824530, abs=1e-9)
    assert sol.tip_z == pytest.approx(-0.8689366124, abs=1e-9)
    assert 0.0 < sol.tip_theta < np.pi / 2.0
    # moment equilibrium at the clamp (not imposed): EI θ'(0) = ∫ w x ds, i.e. θ'(0) = α ∫ x ds̄
    s = np.linspace(0.0, 1.0, 4001)
    xs = sol(s)[:, 0]
    assert sol.kappa[0] == pytest.approx(ALPHA_PAPER * simpson(xs, x=s), rel=1e-8)
    # inextensible: the curve keeps its length
    xz = sol(s)[:, :2]
    assert np.sum(np.hypot(*np.diff(xz, axis=0).T)) == pytest.approx(1.0, rel=1e-6)


def test_elastica_large_alpha_hangs_with_a_clamp_boundary_layer():
    # boundary layer of width √(EI/wL): x_tip/L → √2 α^(-1/2), 1 + z_tip/L → (2 − √2) α^(-1/2)
    alpha = 1e3
    sol = heavy_elastica(alpha, tol=1e-8)
    assert sol.tip_x * math.sqrt(alpha) == pytest.approx(math.sqrt(2.0), rel=0.04)
    assert (1.0 + sol.tip_z) * math.sqrt(alpha) == pytest.approx(2.0 - math.sqrt(2.0), rel=0.04)
    assert sol.tip_theta == pytest.approx(np.pi / 2.0, abs=1e-6)


@pytest.mark.slow
def test_elastica_alpha_1e4_approaches_the_asymptote():
    errs = []
    for alpha in (1e3, 1e4):
        sol = heavy_elastica(alpha)
        errs.append(abs(sol.tip_x * math.sqrt(alpha) - math.sqrt(2.0)))
    assert errs[1] < 0.5 * errs[0]
    assert heavy_elastica(1e4).tip_z == pytest.approx(-1.0, abs=0.01)


def test_extensible_elastica():
    base = heavy_elastica(1e3, tol=1e-8)
    beta = 1e-3
    ext = heavy_elastica(1e3, beta=beta, tol=1e-8)
    # nearly hanging: the extra sag is the stretch of a hanging chain, ∫ β (1 − s̄) ds̄ = β/2
    assert (base.tip_z - ext.tip_z) / beta == pytest.approx(0.5, rel=0.05)
    assert heavy_elastica(ALPHA_PAPER, beta=0.0) is heavy_elastica(ALPHA_PAPER)


def test_elastica_rejects_bad_parameters():
    with pytest.raises(ValueError, match="alpha = -1.0"):
        heavy_elastica(-1.0)
    with pytest.raises(ValueError, match="beta = -0.1"):
        heavy_elastica(1.0, beta=-0.1)
