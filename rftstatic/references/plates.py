"""Centre deflection of a square Kirchhoff plate (small deflection).

Source: S. Timoshenko and S. Woinowsky-Krieger, *Theory of Plates and Shells*,
2nd ed., McGraw-Hill (1959): chapter 5 (simply supported rectangular plates:
Navier solution for uniform load and for a concentrated load) and chapter 6
(rectangular plates with clamped edges). The coefficients are as transcribed in
the project's shared reference table.

For a square plate of side ``a`` and flexural rigidity
``D = E h³ / (12 (1 − ν²))`` the centre deflection is

    w_c = β_q · q a⁴ / D      (uniform pressure q [N/m²])
    w_c = β_P · P a² / D      (central point force P [N])

and β does not depend on ν for these edge conditions (only D does).

The simply supported coefficients are computed here from the Navier double
series (sin(mπ/2) sin(nπ/2) = ±1 at the centre), with m, n odd:

    β_q = 16/π⁶ · Σ (−1)^((m+n)/2 − 1) / (m n (m² + n²)²)
    β_P =  4/π⁴ · Σ 1 / (m² + n²)²

The uniform-load series alternates and converges quickly. The point-load
series is positive with a truncation error that decays like 1/M² for the box
m, n ≤ M, so it is summed on two boxes M and 2M and Richardson-extrapolated;
M is doubled until two extrapolations agree to the requested tolerance.
Clamped plates have no closed series; their coefficients are the tabulated
values (0.0012653, and 0.0056 given to two figures only).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["TABLE", "navier_coefficient", "centre_deflection"]

TABLE = {
    ("simply_supported", "uniform"): 0.0040624,
    ("clamped", "uniform"): 0.0012653,
    ("simply_supported", "point"): 0.011601,
    ("clamped", "point"): 0.0056,
}
"""Tabulated centre-deflection coefficients β [-], keyed by (edges, load)."""

_EDGES = ("simply_supported", "clamped")
_LOADS = ("uniform", "point")


def _navier_partial_sum(load: str, m_max: int) -> float:
    """Navier coefficient summed over odd m, n ≤ m_max (one vectorised block)."""
    k = np.arange(1, m_max + 1, 2, dtype=float)
    m, n = k[:, None], k[None, :]
    r2 = m * m + n * n
    if load == "uniform":
        # (−1)^((m+n)/2 − 1) for odd m, n: +1 when m + n ≡ 2 (mod 4)
        sign = np.where(((m + n) % 4) == 2, 1.0, -1.0)
        return 16.0 / np.pi**6 * float(np.sum(sign / (m * n * r2 * r2)))
    return 4.0 / np.pi**4 * float(np.sum(1.0 / (r2 * r2)))


@lru_cache(maxsize=None)
def navier_coefficient(load: str, *, rtol: float = 1e-9, m_max: int = 6401) -> float:
    """Centre-deflection coefficient of a simply supported square plate.

    Parameters
    ----------
    load : {"uniform", "point"}
        Uniform pressure (β_q, w_c = β_q q a⁴/D) or central point force
        (β_P, w_c = β_P P a²/D).
    rtol : float, optional
        Relative change between successive (extrapolated) sums at which the
        series is taken as converged.
    m_max : int, optional
        Largest odd index allowed before giving up.

    Returns
    -------
    float
        β [-]: 0.00406235266 (uniform) and 0.0116008398 (point).

    Raises
    ------
    ValueError
        If ``load`` is unknown.
    RuntimeError
        If the series has not converged to ``rtol`` by ``m_max``.
    """
    if load not in _LOADS:
        raise ValueError(f"navier_coefficient: load = {load!r}; use 'uniform' or 'point'")
    m, prev_sum, prev_est = 51, _navier_partial_sum(load, 25), None
    while m <= m_max:
        s = _navier_partial_sum(load, m)
        # box truncation error of the point-load series ∝ 1/M²: Richardson on (M/2, M)
        est = s if load == "uniform" else s + (s - prev_sum) / 3.0
        if prev_est is not None and abs(est - prev_est) <= rtol * abs(est):
            return est
        prev_sum, prev_est, m = s, est, 2 * m - 1
    raise RuntimeError(
        f"navier_coefficient({load!r}): no convergence to rtol = {rtol:g} with m, n ≤ {m_max}; "
        "raise m_max or loosen rtol"
    )


def centre_deflection(edges: str, load: str, a: float, D: float, q_or_P: float) -> float:
    """Small-deflection centre deflection of a square Kirchhoff plate.

    Parameters
    ----------
    edges : {"simply_supported", "clamped"}
        Edge condition on all four edges (``"ss"`` is accepted for simply supported).
    load : {"uniform", "point"}
        Uniform pressure or a force at the centre.
    a : float
        Side length [m].
    D : float
        Flexural rigidity E h³ / (12 (1 − ν²)) [N·m].
    q_or_P : float
        Pressure q [N/m²] (uniform) or force P [N] (point).

    Returns
    -------
    float
        Centre deflection in the direction of the load [m]. Simply supported
        plates use the Navier series computed by :func:`navier_coefficient`;
        clamped plates use :data:`TABLE`.

    Raises
    ------
    ValueError
        If ``edges`` or ``load`` is unknown, or ``a`` or ``D`` is not positive.
    """
    edges = "simply_supported" if edges == "ss" else edges
    if edges not in _EDGES:
        raise ValueError(
            f"centre_deflection: edges = {edges!r}; use 'simply_supported' (or 'ss') or 'clamped'"
        )
    if load not in _LOADS:
        raise ValueError(f"centre_deflection: load = {load!r}; use 'uniform' or 'point'")
    if not (a > 0 and D > 0):
        raise ValueError(f"centre_deflection: a = {a!r}, D = {D!r}; both must be positive")
    beta = navier_coefficient(load) if edges == "simply_supported" else TABLE[(edges, load)]
    return beta * q_or_P * (a**4 if load == "uniform" else a**2) / D
