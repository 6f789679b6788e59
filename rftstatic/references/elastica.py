"""The heavy cantilever elastica: a strip clamped at one end, bending under its own weight.

This is the reference solution of the paper's §4.1 (Kang & Yu's 1×5 cm wool strip,
Sze & Zhou 2016, Fig. 5), where the strip is narrow enough for a beam model.

Equations (inextensible, Euler-Bernoulli): with s the arc length from the clamp,
θ the slope below the horizontal, w the weight per unit length [N/m] and EI the
bending stiffness [N·m²],

    EI θ'' = −w (L − s) cos θ,    θ(0) = 0,  θ'(L) = 0,
    x' = cos θ,   z' = −sin θ,    x(0) = z(0) = 0   (z upward, so the tip has z < 0).

With s̄ = s/L and lengths scaled by L the only parameter is α = w L³ / EI:

    θ'' = −α (1 − s̄) cos θ.

For small α the linear cantilever gives a tip deflection δ/L = α/8 (δ = wL⁴/8EI).
For the paper's strip (weight 0.019 gf/cm², warp bending rigidity 0.083 gf·cm/cm,
L = 5 cm) α = 0.019·5³/0.083 ≈ 28.61.

Extensible variant (optional): the axial tension at s is N = w (L − s) sin θ (the
weight of the part beyond s, resolved on the tangent) and the axial strain is
ε = N / C, C the membrane rigidity of the strip [N]. With s the reference arc
length and w the weight per reference length,

    θ'' = −α (1 − s̄)(1 + ε) cos θ,   ε = β (1 − s̄) sin θ,   β = w L / C,
    x' = (1 + ε) cos θ,   z' = −(1 + ε) sin θ.

The moment is taken as M = EI dθ/ds with s the reference arc length; measuring the
curvature per current length instead changes the solution by O(ε κ), far below
what matters for fabric (β ≈ 1e-4 for the wool).

Solution: ``scipy.integrate.solve_bvp`` on y = (θ, θ', x, z) with an analytic
Jacobian, tolerance 1e-10 by default. Large α is reached by continuation in
log α from the linear-beam solution θ = α/6 (1 − (1 − s̄)³); every solution is
cached and the nearest cached one below the requested α starts the next.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.integrate import solve_bvp

__all__ = ["ElasticaSolution", "ElasticaError", "heavy_elastica", "alpha_of", "chord_angle", "alpha_at_chord_angle"]

_ALPHA_START = 1.0   # the linear-beam guess converges directly up to here
_STEP = 2.0          # continuation factor on α
_CONTINUATION_TOL = 1e-6


class ElasticaError(RuntimeError):
    """The elastica boundary-value problem did not converge."""


@dataclass(frozen=True, eq=False)   # arrays inside: compare by identity
class ElasticaSolution:
    """A solved heavy elastica, nondimensional (lengths / L, s̄ = s / L).

    Attributes
    ----------
    alpha : float
        Gravity parameter α = w L³ / EI [-].
    beta : float
        Extensibility β = w L / C [-] (0 for the inextensible elastica).
    s : (n,) ndarray
        Reference arc length of the collocation mesh, from 0 (clamp) to 1 (tip) [-].
    x, z : (n,) ndarray
        Position / L at ``s``; x along the strip, z upward (z ≤ 0) [-].
    theta : (n,) ndarray
        Slope below the horizontal at ``s`` [rad].
    kappa : (n,) ndarray
        dθ/ds̄, curvature × L [-] (M L / EI).
    tip_x, tip_z : float
        Tip position / L [-]; ``-tip_z`` is the tip deflection / L.
    tol : float
        Tolerance the BVP was solved to.
    n_nodes : int
        Size of the final collocation mesh.
    """

    alpha: float
    beta: float
    s: np.ndarray
    x: np.ndarray
    z: np.ndarray
    theta: np.ndarray
    kappa: np.ndarray
    tip_x: float
    tip_z: float
    tol: float
    n_nodes: int
    _interp: Callable[[np.ndarray], np.ndarray] = field(repr=False, compare=False)

    @property
    def tip_theta(self) -> float:
        """Slope at the tip [rad]."""
        return float(self.theta[-1])

    def __call__(self, s: np.ndarray | float) -> np.ndarray:
        """Evaluate the shape at reference arc length ``s``.

        Parameters
        ----------
        s : float or (m,) array_like
            Arc length / L in [0, 1] [-].

        Returns
        -------
        (m, 3) ndarray (or (3,) for scalar ``s``)
            Columns x / L, z / L and θ [rad] (cubic collocation interpolant).
        """
        s_arr = np.asarray(s, dtype=float)
        if np.any((s_arr < 0.0) | (s_arr > 1.0)):
            raise ValueError(f"ElasticaSolution: s must lie in [0, 1]; got range "
                             f"[{s_arr.min():g}, {s_arr.max():g}]")
        y = self._interp(np.atleast_1d(s_arr))
        out = np.stack([y[2], y[3], y[0]], axis=-1)
        return out[0] if s_arr.ndim == 0 else out

    def dimensional(self, L: float) -> dict[str, np.ndarray]:
        """Mesh-point shape in physical units for a strip of length ``L`` [m].

        Returns
        -------
        dict
            ``s``, ``x``, ``z`` (n,) [m] and ``theta`` (n,) [rad].
        """
        return {"s": self.s * L, "x": self.x * L, "z": self.z * L, "theta": self.theta.copy()}


def alpha_of(w: float, L: float, EI: float) -> float:
    """Gravity parameter α = w L³ / EI [-].

    Parameters
    ----------
    w : float
        Weight per unit length [N/m] (weight per area × width).
    L : float
        Free length [m].
    EI : float
        Bending stiffness [N·m²] (bending rigidity per width × width).
    """
    return w * L**3 / EI


def _rhs(alpha: float, beta: float):
    def fun(s, y):
        th, k = y[0], y[1]
        c, sn = np.cos(th), np.sin(th)
        stretch = 1.0 + beta * (1.0 - s) * sn
        return np.vstack([k, -alpha * (1.0 - s) * stretch * c, stretch * c, -stretch * sn])

    def jac(s, y):
        th = y[0]
        c, sn = np.cos(th), np.sin(th)
        a = 1.0 - s
        stretch = 1.0 + beta * a * sn
        dstretch = beta * a * c                           # d(1+ε)/dθ
        J = np.zeros((4, 4, s.size))
        J[0, 1] = 1.0
        J[1, 0] = -alpha * a * (dstretch * c - stretch * sn)
        J[2, 0] = dstretch * c - stretch * sn
        J[3, 0] = -(dstretch * sn + stretch * c)
        return J

    return fun, jac


def _bc(ya, yb):
    return np.array([ya[0], ya[2], ya[3], yb[1]])


def _bc_jac(ya, yb):
    dya = np.zeros((4, 4))
    dyb = np.zeros((4, 4))
    dya[0, 0] = dya[1, 2] = dya[2, 3] = 1.0
    dyb[3, 1] = 1.0
    return dya, dyb


def _linear_guess(alpha: float, s: np.ndarray) -> np.ndarray:
    a = 1.0 - s
    th = alpha / 6.0 * (1.0 - a**3)
    x = s.copy()
    z = -alpha / 24.0 * (6.0 * s**2 - 4.0 * s**3 + s**4)
    return np.vstack([th, alpha / 2.0 * a**2, x, z])


def _initial_mesh(alpha: float, n: int) -> np.ndarray:
    # the clamp boundary layer has width ~ α^(-1/2): cluster nodes there
    u = np.linspace(0.0, 1.0, n)
    p = 1.0 + min(2.0, 0.25 * math.log10(max(alpha, 1.0)))
    return u**p


_CACHE: dict[tuple[float, float, float], ElasticaSolution] = {}


def _solve(alpha: float, beta: float, tol: float, guess: ElasticaSolution | None,
           max_nodes: int) -> ElasticaSolution:
    fun, jac = _rhs(alpha, beta)
    if guess is None:
        s0 = _initial_mesh(alpha, 201)
        y0 = _linear_guess(alpha, s0)
    else:
        s0 = guess.s
        y0 = np.vstack([guess.theta, guess.kappa, guess.x, guess.z])
    res = solve_bvp(fun, _bc, s0, y0, fun_jac=jac, bc_jac=_bc_jac, tol=tol,
                    bc_tol=tol, max_nodes=max_nodes)
    if res.status != 0:
        raise ElasticaError(
            f"heavy_elastica(alpha={alpha:g}, beta={beta:g}, tol={tol:g}): solve_bvp status "
            f"{res.status} ({res.message}) with {res.x.size} nodes; raise max_nodes or loosen tol"
        )
    th, k, x, z = res.y
    return ElasticaSolution(
        alpha=alpha, beta=beta, s=res.x, x=x, z=z, theta=th, kappa=k,
        tip_x=float(x[-1]), tip_z=float(z[-1]), tol=tol, n_nodes=int(res.x.size),
        _interp=res.sol,
    )


def heavy_elastica(alpha: float, *, beta: float = 0.0, tol: float = 1e-10,
                   max_nodes: int = 200_000) -> ElasticaSolution:
    """Solve the heavy cantilever elastica for one α.

    Parameters
    ----------
    alpha : float
        α = w L³ / EI [-], from about 1e-6 to 1e4 (w weight per length [N/m],
        L length [m], EI bending stiffness [N·m²]); see :func:`alpha_of`.
    beta : float, optional
        β = w L / C [-] for the extensible variant (C axial rigidity [N]);
        0 (default) is the inextensible elastica.
    tol : float, optional
        ``solve_bvp`` tolerance on the collocation residual and boundary
        conditions [-].
    max_nodes : int, optional
        Largest collocation mesh ``solve_bvp`` may build.

    Returns
    -------
    ElasticaSolution
        Nondimensional shape (lengths / L); ``tip_z`` < 0 is the tip height
        below the clamp / L. Solutions are cached per (α, β, tol).

    Raises
    ------
    ValueError
        If ``alpha`` is not positive and finite, or ``beta`` is negative.
    ElasticaError
        If ``solve_bvp`` fails at some continuation step.
    """
    if not (np.isfinite(alpha) and alpha > 0.0):
        raise ValueError(f"heavy_elastica: alpha = {alpha!r}; it must be positive and finite")
    if not (np.isfinite(beta) and beta >= 0.0):
        raise ValueError(f"heavy_elastica: beta = {beta!r}; it must be >= 0 (0 = inextensible)")
    alpha, beta, tol = float(alpha), float(beta), float(tol)
    key = (alpha, beta, tol)
    if key in _CACHE:
        return _CACHE[key]
    # continuation at a loose tolerance (its only job is a good start), from the
    # nearest cached step below α with the same β
    ctol = max(tol, _CONTINUATION_TOL)
    below = [a for (a, b, t) in _CACHE if b == beta and t == ctol and a <= alpha]
    guess = _CACHE[(max(below), beta, ctol)] if below else None
    if guess is None:
        a = min(alpha, _ALPHA_START)
        guess = _solve(a, beta, ctol, None, max_nodes)
        _CACHE[(a, beta, ctol)] = guess
    while guess.alpha < alpha:
        a = min(alpha, guess.alpha * _STEP)
        guess = _solve(a, beta, ctol, guess, max_nodes)
        _CACHE[(a, beta, ctol)] = guess
    if ctol != tol:
        guess = _solve(alpha, beta, tol, guess, max_nodes)
        _CACHE[key] = guess
    return guess


def chord_angle(alpha: float) -> float:
    """Angle below the horizontal of the chord from the clamp to the tip of the heavy elastica [rad]: the
    cantilever tester's reading (the tip on the plane through the platform edge at that angle)."""
    s = heavy_elastica(alpha)
    return float(math.atan2(-s.tip_z, s.tip_x))


def alpha_at_chord_angle(angle: float, *, xtol: float = 1e-12) -> float:
    """The gravity parameter alpha = w l^3 / EI at which the heavy elastica's chord meets the plane at
    ``angle`` [rad] below the horizontal (Peirce's cantilever tester: 41.5 deg gives alpha = 8.0042, so that
    the bending length c = (EI/w)^(1/3) = l alpha^(-1/3) is l/2 to 0.03 %: G = W (l/2)^3 reads the rigidity
    0.052 % high; Peirce's closed form c = l (cos(theta/2) / (8 tan theta))^(1/3), an approximation, gives
    c = 0.5093 l there, 5.7 % high in G)."""
    from scipy.optimize import brentq

    if not 0.0 < angle < 0.5 * math.pi:
        raise ValueError(f"alpha_at_chord_angle: angle = {angle!r} rad; it must lie in (0, pi/2)")
    lo, hi = 1e-3, 8.0
    while chord_angle(hi) < angle:
        lo, hi = hi, 2.0 * hi
    return float(brentq(lambda a: chord_angle(a) - angle, lo, hi, xtol=xtol))
