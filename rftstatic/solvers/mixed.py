"""MIP Newton: the Newton iteration at one load factor with the membrane stress carried as an unknown."""

from __future__ import annotations

import numpy as np

from rftstatic.solvers.iteration import Criteria, Iteration, capped_step, direction, self_contact_limited
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.loop import Direction, Iterate, StepFailure, newton_loop

MIXED_ITERATIONS = 12
"""Most mixed iterations per increment (twice at full load, at most ``max_iterations``): where it
converges, the mixed iteration needs 3-8 (the §4.1 strip from C/B = 1e2 to 1e9 /cm^2); one that has
not converged by 12 wanders (RFT6 at C/B = 1e8 from a secant start went on for 30 without settling) and
a smaller increment is the better remedy."""


def mixed_iterations(model, U, lam, opts, state, max_step, stress, reach=None) -> Iteration:
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

    ``reach`` [m] (None: none): give up at the first iteration when its tangent is not the exact one (indefinite)
    or its step would move a node farther than ``reach`` (:class:`MixedDirection`), before taking that step: a
    start so far from the equilibrium that the quadratic model does not hold over the step, where the
    step without a line search only wanders (the short try from a relaxed drape,
    :data:`~rftstatic.solvers.load_steps.FROM_STATE_REACH`).
    """
    test = Criteria(model, lam, opts, U)
    budget = min(opts.max_iterations, MIXED_ITERATIONS)
    max_iterations = 2 * budget if lam >= 1.0 else budget
    U = U.copy()
    S = model.membrane_stress(U) if stress is None else np.array(stress, float)
    r = model.residual(U, lam, candidates=state.candidates, pairs=state.self_pairs,
                       slip=state.slip).ravel()[model.free.ravel()]
    x = Iterate(U, lam, r, float(np.linalg.norm(r)), stress=S)
    if not np.isfinite(x.rnorm):
        return Iteration(False, U, 0, x.rnorm, "non-finite residual", scheme="mixed")
    find = MixedDirection(model, opts, state, reach)
    out = newton_loop(x, test=lambda it: test.met(it.U, it.r, it.work, state.solver), direction=find,
                      globalise=CappedStep(model, state, test, max_step), max_iterations=max_iterations)
    x = out.x
    if out.converged:
        return Iteration(True, x.U, out.iterations, x.rnorm, stable=find.stable, history=out.history, stress=x.stress,
                         scheme="mixed")
    if out.reason is None:
        state.modes["mixed failed"] = state.modes.get("mixed failed", 0) + 1
    reason = out.reason or f"no convergence in {max_iterations} mixed iterations"
    return Iteration(False, x.U, out.iterations, x.rnorm, reason, history=out.history, stress=x.stress, scheme="mixed")


class MixedDirection:
    """The MIP direction: the safeguarded Newton direction whose geometric stiffness takes the carried stress
    (:func:`~rftstatic.solvers.iteration.direction` with ``stress``); ``stable``: the last tangent was the
    exact one and positive definite (None when the solver cannot tell). ``reach`` [m]: the first direction
    fails (:class:`~rftstatic.solvers.loop.StepFailure`) unless it comes from the exact tangent and moves no
    node farther than that (None: no test)."""

    def __init__(self, model, opts, state, reach=None):
        self.model, self.opts, self.state, self.reach = model, opts, state, reach
        self.stable = None

    def __call__(self, x: Iterate) -> Direction:
        try:
            d, mode, _ = direction(self.model, x.U, x.lam, x.r, self.opts, self.state, stress=x.stress)
        except LinearSolveError as exc:
            raise StepFailure(f"linear solve failed ({exc})") from None
        self.stable = mode == "exact" if self.state.solver.detects_indefinite else None
        if self.reach is not None:
            reach, self.reach = self.reach, None  # the first direction only
            move = float(np.linalg.norm(capped_step(self.model, d, np.inf)[0], axis=1).max())
            if mode != "exact" or not move <= reach:
                why = f"its tangent is not positive definite ({mode})" if mode != "exact" else (
                    f"its step moves a node {move:.3g} m, beyond the reach {reach:.3g} m")
                raise StepFailure(f"the first mixed step was not taken: {why}")
        return Direction(d, mode)


class CappedStep:
    """The MIP globalisation: the step as it is, capped (``max_step`` [m]) and bounded by the self-contact
    collision test; the carried stress updated to that of the linearised strain; the first step sets the
    energy scale of the convergence test (the work of the load on it)."""

    def __init__(self, model, state, test: Criteria, max_step: float):
        self.model, self.state, self.test, self.max_step = model, state, test, max_step
        self.free = model.free.ravel()
        self.first = True

    def __call__(self, x: Iterate, dn: Direction):
        model, state = self.model, self.state
        step, cap = capped_step(model, dn.d, self.max_step)
        step, frac = self_contact_limited(model, x.U, step, state)
        cap *= frac
        if self.first:
            self.test.load_work(x.U, step)
            self.first = False
        S = model.mixed_stress(x.U, step)
        U = x.U + step
        r = model.residual(U, x.lam, candidates=state.candidates, pairs=state.self_pairs,
                           slip=state.slip).ravel()[self.free]
        new = Iterate(U, x.lam, r, float(np.linalg.norm(r)), work=abs(float(step.ravel()[self.free] @ r)), stress=S)
        if not np.isfinite(new.rnorm):
            raise StepFailure("non-finite residual", new)
        return new, {"alpha": 1.0, "cap": cap, "mu": 0.0, "fresh": True, "mode": dn.mode}
