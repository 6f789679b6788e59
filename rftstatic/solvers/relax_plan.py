"""The relaxation route's plan (:func:`relax_plan`): its mass scaling, damping critical for the drape's pendulum
mode, and time limits, checked against the stable explicit step before the first step (the relaxation route of
:mod:`rftstatic.solvers.static` runs it)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ConvergenceError, StepLimitError
from rftstatic.solvers import friction_lag
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE
from rftstatic.solvers.timestep import stable_time_step
from rftstatic.units import STANDARD_GRAVITY

__all__ = ["MAX_RELAX_STEPS", "RELAX_ATTEMPT_FACTOR", "RELAX_SEGMENT_STEPS", "RELAX_TIME_ALLOWANCE", "RelaxPlan",
           "relax_plan"]

MAX_RELAX_STEPS = 200_000
"""Explicit steps of the relaxation's expected need (100 damping times) that the route plans at most: a longer
need is planned at this many steps (:data:`RELAX_ATTEMPT_FACTOR`) or not attempted."""

RELAX_ATTEMPT_FACTOR = 4.0
"""A relaxation whose expected need is at most this many times :data:`MAX_RELAX_STEPS` is attempted with its time cut
to :data:`MAX_RELAX_STEPS` steps, not refused: the need is a budget of 100 damping times where the drapes hand over to
Newton after far fewer (cusick-30 after about 7). Measured: a thin lab fabric on cusick-30 refined against membrane
locking (16 x 200 nodes; need 2.34e5 steps) was refused; attempted, it hands over after a few percent of the budget
(validation/fabric_rules.md). A need beyond (a membrane thousands of times stiffer than any fabric's) is refused."""

RELAX_TIME_ALLOWANCE = 2.0
"""The relaxation may run this many times its expected need (100 damping times) before Newton takes over for good;
the step-count check uses the expected need."""

RELAX_SEGMENT_STEPS = int(RELAX_TIME_ALLOWANCE * MAX_RELAX_STEPS)
"""Most explicit steps of one relaxation segment: the longest segment (the route's whole time) at the reference
state's step. A segment from a state whose stable step is far shorter (a start lifted by many element sizes
stretches the membrane) is refused before its first step, a ConvergenceError."""


@dataclass(frozen=True)
class RelaxPlan:
    """One model's relaxation route: mass scale, damping [1/s] (a time scale under the law ``damping``), times [s]."""

    mass_scale: float
    alpha: float
    max_time: float
    chunk: float
    min_span: float
    damping: str = "viscous"


def relax_plan(model, first, damping: str = "viscous") -> RelaxPlan:
    """The relaxation's damping, critical for the drape's pendulum mode, or the law ``damping`` (viscous with friction:
    its rest test measures the impulses' leftover velocities), and time limits; ConvergenceError when the sheet has no
    mass (weightless), its stable step collapsed or it would need over :data:`RELAX_ATTEMPT_FACTOR` x
    :data:`MAX_RELAX_STEPS` explicit steps (a need above :data:`MAX_RELAX_STEPS` is cut to it)."""

    def refuse(text):
        return ConvergenceError(text, None) if first is None else ConvergenceError(f"{first}; {text}", first.result)

    if not model.material.mass_per_area > 0:  # the explicit motion needs a mass (lumped_mass refuses none)
        raise refuse(f"no dynamic relaxation: the material's areal weight is {model.material.weight:g} N/m^2, so "
                     "the sheet has no mass to move; give material.weight > 0 or load steps that converge "
                     "(e.g. a larger solver.max_iterations)")
    size = float(np.ptp(model.mesh.X, axis=0).max())
    omega1 = np.sqrt(STANDARD_GRAVITY / (0.25 * size))  # pendulum estimate of the lowest drape mode
    mass_scale = RELAX_MASS_SCALE
    alpha = 2.0 * omega1 / np.sqrt(mass_scale)  # about critical for that mode of the scaled system
    max_time = 100.0 / alpha  # the relaxation's expected need: 100 damping times (checked below)
    try:
        est = stable_time_step(model, mass_scale=mass_scale, alpha=alpha)
    except StepLimitError as exc:
        raise refuse(f"no dynamic relaxation: {exc}") from None
    limit = RELAX_ATTEMPT_FACTOR * MAX_RELAX_STEPS
    if not max_time / est.dt <= limit:  # a membrane far stiffer than the bending: too many steps
        raise refuse(f"dynamic relaxation would need up to {max_time / est.dt:.3g} explicit steps (dt {est.dt:.3g} "
                     f"s); not attempted (the static route's limit is {limit:g} steps, which "
                     "dynamics.max_steps does not change). Try solver.start = \"load-steps\" (Newton from the "
                     "flat sheet, no explicit steps) or solver.continuation = \"arc-length\"; or a coarser mesh, or "
                     "a smaller membrane stiffness, which lengthen the stable step")
    max_time = min(max_time, 0.95 * MAX_RELAX_STEPS * est.dt)  # a long need: attempted within the planned steps
    # (5 % below them: a segment's own stable step, estimated again at its start, may be a little shorter)
    # settling folds on fine meshes (31 x 240 rings) take longer
    return RelaxPlan(mass_scale=mass_scale, alpha=alpha, max_time=max_time * RELAX_TIME_ALLOWANCE, chunk=4.0 / alpha,
                      min_span=10 * est.dt, damping="viscous" if friction_lag.active(model) else damping)
