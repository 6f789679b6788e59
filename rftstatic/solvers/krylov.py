"""The Newton step by conjugate gradients on the exact tangent, preconditioned with an earlier
factorisation of it (inexact Newton: Dembo, Eisenstat & Steihaug, SIAM J. Numer. Anal. 19, 1982;
truncated at negative curvature: Steihaug, SIAM J. Numer. Anal. 20, 1983; Nocedal & Wright, Numerical
Optimization, 2nd ed., Algorithm 7.2 without the trust radius, which the step cap and line search of
:func:`~rftstatic.solvers.displacement.displacement_iterations` replace).

Why: on the finest mesh of a drape a Newton step costs one supernodal factorisation (2.1 s at 201 x 201
nodes, 121,200 unknowns, 42e6 entries of L) against 0.12 s for a back-substitution with it, and the
finest level creeps along a flat valley for ~350 steps (~200 from locking-matched coarse levels,
docs/howto/solver-routes.md), in which the tangent changes little from one step to the next. Solving ``K d = -r`` by preconditioned CG with the last
factorisation takes 3-12 back-substitutions while that factorisation is fresh; the solver factorises
anew when CG needs more than :data:`REFRESH_ITERATIONS` or meets negative curvature. Measured
(``python -m rftstatic case pedestal-square-80 --set mesh.nodes=[201,201]``, default settings, the finest
level from the 101 x 101 drape, machine otherwise idle): 448 Newton steps, 114 factorisations and 2,946 CG
iterations, 875 s, against 355 steps and 443 factorisations, 1,474 s, with the direct steps; the same
equilibrium (-1038.11 gf cm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.solvers.iteration import diagonal_scale
from rftstatic.solvers.linear import LinearSolveError

KRYLOV_FROM = 60_000
"""Free unknowns from which ``step_solver = "auto"`` takes the preconditioned CG step (the 201 x 201 sheet
has 121,200; at 101 x 101, 30,600, a factorisation costs 0.4 s and the direct step is as fast or faster:
docs/howto/solver-routes.md; the factorisation there is ordered by nested dissection,
:data:`rftstatic.solvers.linear.CholmodSolver.NESTED_DISSECTION_FROM`)."""

REFRESH_ITERATIONS = 12
"""CG iterations above which the next step factorises the tangent anew (a factorisation at 201 x 201
costs about 20 back-substitutions with it)."""

MAX_ITERATIONS = 30
"""Most CG iterations per step; a step that needs them is taken as it stands and the next one factorises."""

LEAST_FORCING = 1e-3
"""Least relative CG tolerance (the forcing term's floor)."""


@dataclass
class KrylovStep:
    """A truncated-CG Newton step.

    Attributes
    ----------
    d : (n,) step on the free dofs [m]
    iterations : CG iterations (back-substitutions with the preconditioner)
    outcome : ``"converged"`` (to the forcing tolerance), ``"negative curvature"`` or ``"iterations"``
    curvature : ``d . K d`` [J] (without the damping shift)
    """

    d: np.ndarray
    iterations: int
    outcome: str
    curvature: float

    @property
    def stale(self) -> bool:
        """Whether the preconditioner no longer serves: the next step should factorise anew."""
        return self.outcome != "converged" or self.iterations > REFRESH_ITERATIONS


def forcing(rnorm: float, first: float) -> float:
    """Relative CG tolerance ``eta = min(0.5, max(LEAST_FORCING, sqrt(|r| / |r_1|)))`` for a residual
    ``rnorm`` [N] against the first one of the iteration ``first`` [N] (Eisenstat & Walker, SIAM J. Sci.
    Comput. 17, 1996: loose far from the solution, tightening as the residual falls)."""
    ratio = rnorm / first if first > 0 else 1.0
    return float(min(0.5, max(LEAST_FORCING, np.sqrt(ratio))))


def truncated_cg(K, r: np.ndarray, precondition, *, shift: float = 0.0, rtol: float = 0.1,
                 max_iterations: int = MAX_ITERATIONS) -> KrylovStep:
    """Preconditioned CG from ``d = 0`` on ``(K + shift I) d = -r``, stopped at ``|(K + shift I) d + r| <= rtol |r|``,
    at negative curvature (the last iterate is kept; on the first iteration the preconditioned steepest
    descent ``-M^-1 r`` is returned) or after ``max_iterations``.

    ``K`` (n, n) sparse [N/m]; ``r`` (n,) residual [N]; ``precondition(b)`` applies ``M^-1`` (a
    factorisation of an earlier, positive definite tangent); ``shift`` [N/m]: Levenberg-Marquardt damping.
    Every CG iterate ``d`` satisfies ``d . (K + shift I) d = -r . d`` (the Galerkin condition), so it is a
    descent direction of the energy while the curvature stays positive.
    """
    rnorm = float(np.linalg.norm(r))
    d = np.zeros_like(r)
    g = -r.copy()  # residual of the linear system, b - A d with b = -r
    z = precondition(g)
    p = z.copy()
    gz = float(g @ z)
    outcome = "iterations"
    iterations = 0
    for _ in range(max_iterations):
        q = K @ p + shift * p
        curvature = float(p @ q)
        iterations += 1
        if not curvature > 0.0:
            outcome = "negative curvature"
            if iterations == 1:
                d = p
            break
        a = gz / curvature
        d += a * p
        g -= a * q
        if float(np.linalg.norm(g)) <= rtol * rnorm:
            outcome = "converged"
            break
        z = precondition(g)
        gz_next = float(g @ z)
        p = z + (gz_next / gz) * p
        gz = gz_next
    return KrylovStep(d, iterations, outcome, float(d @ (K @ d)))


def uses_krylov(opts, unknowns: int, solver) -> bool:
    """Whether the displacement iteration solves its steps by CG preconditioned with the last factorisation
    (``opts.step_solver``; ``"auto"``: from :data:`KRYLOV_FROM` unknowns). Needs
    a solver whose re-solve with its factorisation is a back-substitution."""
    if opts.step_solver == "direct" or not getattr(solver, "cheap_resolve", False):
        return False
    return opts.step_solver == "krylov" or unknowns >= KRYLOV_FROM


def krylov_direction(model, U, lam, r, state, mu, rtol):
    """A Newton step by CG on the exact tangent, preconditioned with the solver's last factorisation
    (:func:`truncated_cg`): ``(d, d.K.d, refresh)``, ``d`` None when no descent
    step came out (then the caller factorises); ``refresh``: factorise at the next step. ``state``: the
    :class:`~rftstatic.model.state.State` (its solver holds the factorisation; the steps and CG
    iterations are counted in its modes); ``mu``: the Levenberg-Marquardt damping relative to the mean
    tangent diagonal; ``rtol``: the forcing term (:func:`forcing`)."""
    try:
        K = model.tangent(U, lam=lam, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)[1]
        shift = mu * diagonal_scale(model, U, state) if mu else 0.0
        step = truncated_cg(K, r, state.solver.resolve, shift=shift, rtol=rtol)
    except LinearSolveError:
        return None, 0.0, True
    state.modes["CG iterations"] = state.modes.get("CG iterations", 0) + step.iterations
    if not (np.all(np.isfinite(step.d)) and float(r @ step.d) < 0.0):
        return None, 0.0, True
    state.modes["krylov"] = state.modes.get("krylov", 0) + 1
    return step.d, step.curvature, step.stale
