"""The explicit step planner: the step and the horizon of an explicit run, planned once.

An explicit run of central differences (Eq. 20-22) to ``t_end`` [s] takes ``n = ceil(t_end / dt)`` steps of
``t_end / n`` (a step shortened slightly so that a whole number of them ends at ``t_end``). ``dt`` is the
caller's, or ``safety`` times the critical step of the damped scheme
(:func:`~rftstatic.solvers.timestep.stable_time_step`).
A run of more than the step limit is refused before it starts (:class:`~rftstatic.errors.StepLimitError`, a
ValueError naming the option that sets the limit), or, when asked (a relaxation, which stops at rest), ends
after the limit's steps. :func:`plan_steps` returns a :class:`StepPlan`; the explicit solver and the apps
that run it call it, nothing else sizes the steps of a run.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ParameterError, StepLimitError
from rftstatic.solvers.timestep import SAFETY, StepEstimate, stable_time_step

log = logging.getLogger(__name__)

__all__ = ["StepPlan", "plan_steps", "step_count", "default_max_steps", "MAX_STEPS", "MAX_STEPS_KEY"]

MAX_STEPS = 10_000_000
"""Largest step limit of one explicit run (hours of computing on a large sheet), and the limit of a run that
names none: a run that asks for more is refused before it starts, naming t_end, dt and the limit."""

MAX_STEPS_KEY = "dynamics.max_steps"
"""The option that sets an explicit run's step limit, named in the refusal unless the caller names another."""

STEPS_PER_SIDE_NODE = 10_000
"""Default step limit of a scene's explicit run (:func:`default_max_steps`) per node along a side of the sheet."""

MIN_DEFAULT_STEPS = 50_000
"""Least default step limit of a scene's explicit run, however small its mesh."""


def default_max_steps(n_nodes: float) -> int:
    """The default step limit of a scene's explicit run on a mesh of ``n_nodes`` nodes:
    ``STEPS_PER_SIDE_NODE sqrt(n_nodes)``, at least :data:`MIN_DEFAULT_STEPS`, at most :data:`MAX_STEPS`.

    The stable step shrinks with the element size h (dt ~ h for the membrane) and the time a sheet takes to
    swing and come to rest does not, so the steps a run needs grow like the nodes along a side, sqrt(N):
    hang-20 (t_end 2 s) took 4554 steps on 7 x 7 nodes and 30370 on 41 x 41 (6.7 x for 5.9 x the side);
    the remeshed relaxations of ``validation/remesh_scenes.md`` 22,000-43,000 steps on 500-1900 nodes. The
    limit leaves a factor 10 over these: 410,000 steps on 41 x 41 nodes, 70,000 (about 2 s at 31 us a step)
    on 7 x 7, where a limit of 10^7 let a tiny relaxation that cannot come to rest run for minutes.
    """
    return int(min(MAX_STEPS, max(MIN_DEFAULT_STEPS, STEPS_PER_SIDE_NODE * float(np.sqrt(max(n_nodes, 0.0))))))


def step_count(t_end: float, dt: float, max_steps: int | None = None, *, limit_name: str = MAX_STEPS_KEY) -> int:
    """Steps of ``dt`` [s] (rounded up) that reach ``t_end`` [s]; :class:`StepLimitError` (a ValueError)
    beyond ``max_steps`` (``limit_name``: the option that sets it, for the message) or for a step that is
    not a positive finite number."""
    limit = MAX_STEPS if max_steps is None else int(max_steps)
    if not (np.isfinite(dt) and dt > 0):
        raise StepLimitError(f"the explicit step dt = {dt!r} s is not a positive finite number (a stable step that "
                             "collapsed: a stiffness without bound at this state)")
    steps = t_end / dt - 1e-9
    if not np.isfinite(steps) or steps > limit:
        raise StepLimitError(f"t_end = {t_end:.6g} s with dt = {dt:.6g} s needs {steps:.3g} explicit steps, more "
                             f"than the limit of {limit:d} ({limit_name}); shorten t_end or lengthen dt")
    return max(1, int(np.ceil(steps)))


@dataclass(frozen=True)
class StepPlan:
    """The steps of one explicit run.

    Attributes
    ----------
    dt : the step [s]: ``t_end / steps``
    steps : number of steps
    t_end : the time the run goes to [s] (the asked end time, or the step limit's, :func:`plan_steps`)
    estimate : the stable-step estimate the step was checked against or taken from (None: not made)
    reason : why this step and horizon, in words
    """

    dt: float
    steps: int
    t_end: float
    estimate: StepEstimate | None
    reason: str


def plan_steps(model, *, t_end: float, alpha: float, mass_scale: float, dt: float | None = None, U=None,
               safety: float = SAFETY, max_steps: int | None = None, limit_name: str = MAX_STEPS_KEY,
               check_dt: bool = True, stop_at_limit: bool = False) -> StepPlan:
    """Plan the step and the horizon of an explicit run of ``model`` (module docstring).

    Parameters
    ----------
    model : the model (its lumped mass and stiffness give the stable step)
    t_end : end time [s], > 0
    dt : step [s]; None: ``safety`` times the critical step at ``U`` [m] (zero: the reference state)
    alpha : mass damping [1/s] (a damping shortens the critical step); mass_scale : s [-]
    safety : factor on the critical step, in (0, 1]
    max_steps : step limit (None: :data:`MAX_STEPS`); limit_name : the option that sets it, for the messages
    check_dt : estimate the stable step also when ``dt`` is given, and warn when ``dt`` exceeds it
    stop_at_limit : a run that needs more than ``max_steps`` steps to reach ``t_end`` ends after ``max_steps``
        steps (logged) instead of being refused

    Raises
    ------
    ParameterError
        ``t_end`` or ``dt`` not positive
    StepLimitError
        more steps than the limit (unless ``stop_at_limit``), or a step that is not a positive finite number
    """
    if not t_end > 0:
        raise ParameterError("t_end", f"must be > 0 [s], got {t_end!r}")
    if dt is not None and not dt > 0:
        raise ParameterError("dt", f"the time step must be > 0 [s], got {dt!r}")
    estimate = None
    if check_dt or dt is None:
        estimate = stable_time_step(model, U, mass_scale=mass_scale, alpha=alpha, safety=safety)
    if dt is None:
        dt, reason = estimate.dt, f"{safety:g} x the critical step ({estimate.method} estimate)"
    else:
        dt, reason = float(dt), "the given step"
        if estimate is not None and dt > estimate.dt * (1 + 1e-3):  # Lanczos digits vary with the platform
            log.warning("time step dt = %.4g s exceeds the stable estimate %.4g s (critical %.4g s, omega_max "
                        "%.4g rad/s); the run may become unstable", dt, estimate.dt, estimate.dt_crit,
                        estimate.omega_max)
            reason += " (above the stable estimate)"
    limit = MAX_STEPS if max_steps is None else int(max_steps)
    horizon = t_end
    try:
        steps = step_count(t_end, dt, limit, limit_name=limit_name)
    except StepLimitError:
        if not (stop_at_limit and np.isfinite(dt) and dt > 0 and np.isfinite(limit * dt)):
            raise
        log.warning("the relaxation stops after %s = %d steps of %.4g s (t = %.4g s) unless at rest before; t_end "
                    "= %.4g s is further", limit_name, limit, dt, limit * dt, t_end)
        horizon = limit * dt * (1.0 - 1e-12)  # limit steps after step_count's rounding
        steps = step_count(horizon, dt, limit, limit_name=limit_name)
        reason += f"; t_end lies beyond the step limit ({limit_name} = {limit}): the run stops there"
    return StepPlan(dt=horizon / steps, steps=steps, t_end=horizon, estimate=estimate, reason=reason)
