"""The Newton loop of the static solver: one loop, its parts plugged in (after felupe's ``newtonraphson``).

Every Newton iteration of the package runs :func:`newton_loop`: the displacement iteration
(:mod:`rftstatic.solvers.newton`: safeguarded direct or Krylov-preconditioned direction, line search and
Levenberg-Marquardt trust region), the MIP iteration (:mod:`rftstatic.solvers.mixed`: the direction with the
carried membrane stress, the capped step as it is) and the arc-length corrector
(:mod:`rftstatic.solvers.continuation`: the bordered direction, the step capped in load and displacement).
Each iteration is

1. the convergence ``test(x)`` of the iterate ``x`` (from iteration ``first_test`` on);
2. a ``direction(x)``: a :class:`Direction` on the free dofs (and the load factor, for arc length);
3. the ``globalise(x, direction)`` step to the next iterate, whose residual it evaluates: a line search, a
   trust region, or the capped step as it stands; it returns the new iterate and a record of the step.

A part that cannot go on raises :class:`StepFailure` with its reason (a linear solve that failed, no
decrease of the energy, a residual that is not finite); the loop then stops there. The residual work of
the steps and the history of the iteration are the loop's; the strategies' own state (damping, reused
factorisations, the carried stress) lives in the part objects, made per call of the iteration.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Direction", "Iterate", "LoopOutcome", "StepFailure", "newton_loop"]


@dataclass
class Iterate:
    """A Newton iterate.

    Attributes
    ----------
    U : (N, 3) displacements [m]
    lam : load factor [-]
    r : (n,) residual on the free dofs [N] (None before it is evaluated)
    rnorm : its norm [N]
    work : ``|d . r|`` of the step that led here, the residual's work on it [J] (inf at the start)
    stress : (E, 3) membrane stress carried by the mixed iteration [N/m] (None otherwise)
    energy : total potential energy at ``U`` [J] and ``energy_scale`` its round-off scale (line search)
    tangent, factor : the tangent at ``U`` and its factorisation (arc-length corrector)
    reusable : the step that led here was a full step that cut the residual fast, so the next may reuse
        the last factorisation (modified Newton)
    """

    U: np.ndarray
    lam: float
    r: np.ndarray | None = None
    rnorm: float = float("nan")
    work: float = float("inf")
    stress: np.ndarray | None = None
    energy: float | None = None
    energy_scale: float | None = None
    tangent: object = None
    factor: object = None
    reusable: bool = False


@dataclass
class Direction:
    """A Newton direction at an iterate.

    Attributes
    ----------
    d : (n,) step on the free dofs [m]
    mode : which tangent gave it (``"exact"``, ``"modified"``, ``"psd"``, ``"shift"``, ``"reused"``, ``"krylov"``)
    fresh : computed from a new tangent at this iterate (not a reused factorisation)
    curvature : ``d . K d`` of the quadratic model along ``d`` [J] (for the trust region)
    dlam : the load-factor part of an arc-length direction [-]
    """

    d: np.ndarray
    mode: str
    fresh: bool = True
    curvature: float = 0.0
    dlam: float = 0.0


class StepFailure(Exception):
    """A part of the loop cannot go on: ``reason``; ``iterate`` the iterate reached (None: the current one)."""

    def __init__(self, reason: str, iterate: Iterate | None = None):
        super().__init__(reason)
        self.reason, self.iterate = reason, iterate


@dataclass
class LoopOutcome:
    """What :func:`newton_loop` returns: ``converged``, the last iterate ``x``, the ``iterations`` taken, the
    ``reason`` it stopped short (None: the iterations ran out) and the ``history`` (one record per step:
    the residual before it [N] and what the globalisation reports)."""

    converged: bool
    x: Iterate
    iterations: int
    reason: str | None = ""
    history: list = field(default_factory=list)


def newton_loop(x: Iterate, *, test, direction, globalise, max_iterations: int, first_test: int = 2,
                final_test: bool = True) -> LoopOutcome:
    """Newton iterations from the iterate ``x`` (module docstring).

    Parameters
    ----------
    x : the start, its residual evaluated (the arc-length corrector's is evaluated by its test)
    test : ``test(x) -> bool``, the convergence test
    direction : ``direction(x) -> Direction``
    globalise : ``globalise(x, direction) -> (Iterate, dict)``, the next iterate and the step's record
    max_iterations : most steps
    first_test : the first iteration whose start is tested (2: the start itself is not; 1: it is)
    final_test : test the last iterate after the last step
    """
    history = []
    for k in range(1, max_iterations + 1):
        try:
            if k >= first_test and test(x):
                return LoopOutcome(True, x, k - 1, "", history)
            new, record = globalise(x, direction(x))
        except StepFailure as exc:
            return LoopOutcome(False, exc.iterate if exc.iterate is not None else x, k, exc.reason, history)
        history.append({"residual": x.rnorm, **record})
        x = new
    if final_test and test(x):
        return LoopOutcome(True, x, max_iterations, "", history)
    return LoopOutcome(False, x, max_iterations, None, history)
