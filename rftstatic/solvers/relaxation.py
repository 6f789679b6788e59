"""Dynamic relaxation (§6): damped, mass-scaled explicit motion until the sheet is at rest.

Mass scaling (s = 100 as in §6) lengthens the stable step by sqrt(s); the load is not scaled, so the
resting state is the static equilibrium.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from rftstatic.solvers.explicit import ExplicitResult, run_explicit
from rftstatic.solvers.rest import AtRest, RestCriterion

log = logging.getLogger(__name__)

RELAX_MASS_SCALE = 100.0
"""Mass-scaling factor s of dynamic relaxation (§6 uses 100): the stable step grows by sqrt(s)."""


@dataclass
class RelaxResult:
    """Outcome of :func:`relax`: resting displacements ``U (N, 3)`` [m], whether the criteria were
    met, the time [s] and steps used, the explicit run (histories), the final half-step velocity
    ``V (N, 3)`` [m/s] and the peak kinetic energy [J] (to resume)."""

    U: np.ndarray
    converged: bool
    t: float
    steps: int
    run: ExplicitResult
    V: np.ndarray | None = None
    peak_kinetic: float = 0.0


def relax(model, *, mass_scale: float = RELAX_MASS_SCALE, alpha: float, tol_kinetic: float = 1e-8, tol_force: float = 1e-4,
          max_time: float, dt: float | None = None, U0=None, V0=None, obstacles=(), sample_every: int = 20,
          peak_kinetic: float = 0.0, progress: bool = True, backend: str = "auto", load=None, checkpoint=None,
          restart: dict | None = None, max_steps: int | None = None,
          max_steps_name: str = "dynamics.max_steps") -> RelaxResult:
    """Dynamic relaxation (§6): damped explicit motion until the sheet is at rest.

    At rest means, at a sample, kinetic energy / peak kinetic energy < ``tol_kinetic`` *and* the
    out-of-balance force on the free dofs ``|P - F(U)|`` < ``tol_force |P|``. Mass scaling (default
    s = 100 as in §6) lengthens the stable step by sqrt(s); the load is not scaled, so the resting
    state is the static equilibrium.

    Parameters
    ----------
    alpha : mass damping [1/s]; near ``2 omega_1 / sqrt(s)`` (critical for the lowest mode of the
        scaled system) relaxes fastest
    max_time : give up after this simulated time [s] (``converged=False``, logged)
    U0, V0 : start [m] and half-step velocity v_(-1/2) [m/s] (default zero), e.g. to resume a
        relaxation from its :class:`RelaxResult` (``U``, ``V``)
    peak_kinetic : peak kinetic energy [J] of the motion so far, when resuming (``RelaxResult.peak_kinetic``)
    load : (N, 3) external nodal load [N] instead of ``model.load`` (the resting state then balances it)
    checkpoint : saves the explicit state during the run, as in :func:`~rftstatic.solvers.explicit.run_explicit`
        (and a Ctrl-C then stops at a whole step, saved)
    restart : the explicit state saved during an earlier call with the same arguments
        (:func:`~rftstatic.solvers.checkpoint.load_checkpoint`): the run continues from it, step for step as
        the uninterrupted one (``peak_kinetic`` is the peak before that call; ``U0``, ``V0``, ``dt`` are unused)
    max_steps, max_steps_name : refuse a relaxation of more explicit steps than this, or whose stable step
        collapsed (:class:`~rftstatic.errors.StepLimitError`, before the first step), naming that option
    """
    P = model.load if load is None else load
    P_norm = float(np.linalg.norm(np.where(model.free, P, 0.0)))
    at_rest = AtRest(RestCriterion(tol_kinetic, tol_force), load_norm=P_norm, peak_kinetic=peak_kinetic)
    if restart is not None:  # the peaks of the samples before the interruption, as the rest test saw them
        at_rest.resume_from(restart["history"])
    run = run_explicit(model, t_end=max_time, dt=dt, alpha=alpha, mass_scale=mass_scale, obstacles=obstacles,
                       U0=U0, V0=V0, start="consistent" if V0 is None else "given", sample_every=sample_every,
                       callback=at_rest, progress=progress, backend=backend, load=load, checkpoint=checkpoint,
                       max_steps=max_steps, max_steps_name=max_steps_name, _restart=restart)
    if not run.stopped:
        log.warning("dynamic relaxation not at rest after %.4g s (%d steps): kinetic %.3e J, |r| %.3e N",
                    run.t, run.steps, run.history["kinetic"][-1], run.history["residual"][-1])
    return RelaxResult(U=run.U, converged=run.stopped, t=run.t, steps=run.steps, run=run, V=run.V,
                       peak_kinetic=at_rest.peak_kinetic)
