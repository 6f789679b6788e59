"""MIP Newton: the Newton iteration at one load factor with the membrane stress carried as an unknown."""

from __future__ import annotations

import numpy as np

from rftstatic.solvers.iteration import Criteria, Iteration, capped_step, direction, self_contact_limited
from rftstatic.solvers.linear import LinearSolveError

MIXED_ITERATIONS = 12
"""Most mixed iterations per increment (twice at full load, at most ``max_iterations``): where it
converges, the mixed iteration needs 3-8 (the §4.1 strip from C/B = 1e2 to 1e9 /cm^2); one that has
not converged by 12 wanders (RFT6 at C/B = 1e8 from a secant start went on for 30 without settling) and
a smaller increment is the better remedy."""


def mixed_iterations(model, U, lam, opts, ws, max_step, stress) -> Iteration:
    """MIP Newton (Magisano, Leonetti & Garcea, CMAME 313, 2017): Newton on the Hellinger-Reissner form
    of Eq. 15 with the membrane stress of every element an unknown of its own, condensed element by
    element. The step solves ``K(U, S) d = -r(U)`` with the ordinary residual r and the ordinary tangent
    except that the geometric stiffness takes the carried stress S; then ``S <- D^m (eps(U) + Bbar(U) d)``
    (:meth:`~rftstatic.model.model.Model.mixed_stress`), the stress of the *linearised* strain.

    A displacement-based Newton step that rotates a stiff membrane stretches it to second order in the
    rotation and sees, at the next iterate, a membrane stress of order C theta^2 that is not there at
    the solution; its energy line search then cuts the step, and the iterations grow with C/B (strip
    cells, validation/stability.md: 1600 iterations at C/B = 1e7 /cm^2, none converging at 1e8). The
    mixed stress does not carry that spurious stretch (the 21 x 5 strip: 25 iterations at C/B = 1e2,
    42 (RFT3) and 38 (RFT6) at 1e9), and at the solution S = D^m eps(U), so the converged state and
    the quadratic rate are those of the exact tangent. The steps do not lower Pi
    monotonically, so there is no energy line search; only the step cap ``max_step`` applies. An
    iteration that fails returns to the load steps (:mod:`rftstatic.solvers.load_steps`), which cut the
    increment back and, after repeated failures, try the displacement iteration.
    """
    free = model.free.ravel()
    test = Criteria(model, lam, opts, U)
    budget = min(opts.max_iterations, MIXED_ITERATIONS)
    max_iterations = 2 * budget if lam >= 1.0 else budget
    cand, modes = ws.candidates, ws.modes
    U = U.copy()
    S = model.membrane_stress(U) if stress is None else np.array(stress, float)
    r = model.residual(U, lam, candidates=cand, pairs=ws.pairs).ravel()[free]
    rnorm = float(np.linalg.norm(r))
    if not np.isfinite(rnorm):
        return Iteration(False, U, 0, rnorm, "non-finite residual", scheme="mixed")
    work, stable, hist = np.inf, None, []
    for it in range(1, max_iterations + 1):
        if it > 1 and test.met(U, r, work, ws.solver):
            return Iteration(True, U, it - 1, rnorm, stable=stable, history=hist, stress=S, scheme="mixed")
        try:
            d, mode, _ = direction(model, U, lam, r, opts, ws, stress=S)
        except LinearSolveError as exc:
            return Iteration(False, U, it, rnorm, f"linear solve failed ({exc})", history=hist, stress=S,
                             scheme="mixed")
        stable = mode == "exact" if ws.solver.detects_indefinite else None
        step, cap = capped_step(model, d, max_step)
        step, frac = self_contact_limited(model, U, step, ws)
        cap *= frac
        if it == 1:
            test.load_work(U, step)
        S = model.mixed_stress(U, step)
        U = U + step
        hist.append({"residual": rnorm, "alpha": 1.0, "cap": cap, "mu": 0.0, "fresh": True, "mode": mode})
        r = model.residual(U, lam, candidates=cand, pairs=ws.pairs).ravel()[free]
        work = abs(float(step.ravel()[free] @ r))
        rnorm = float(np.linalg.norm(r))
        if not np.isfinite(rnorm):
            return Iteration(False, U, it, rnorm, "non-finite residual", history=hist, stress=S, scheme="mixed")
    if test.met(U, r, work, ws.solver):
        return Iteration(True, U, max_iterations, rnorm, stable=stable, history=hist, stress=S, scheme="mixed")
    modes["mixed failed"] = modes.get("mixed failed", 0) + 1
    return Iteration(False, U, max_iterations, rnorm, f"no convergence in {max_iterations} mixed iterations",
                   history=hist, stress=S, scheme="mixed")
