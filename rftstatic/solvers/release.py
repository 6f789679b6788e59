"""The release route: the sheet at full weight on a support that is lowered step by step (a drape test as done).

BS 5058 / ISO 9073-9 lower the specimen onto the disc, or release it from a support around the disc, under its
full weight, and let it settle. The quasi-static model of that is a **support moved at full load**: the sheet
starts flat, resting on a support plane (the model's last obstacle, which the scene adds for
``solver.start = "release"``: :func:`rftstatic.scenes.release.release_support`); the support is lowered in steps,
each a Newton solve at load factor 1 from the last equilibrium (the total potential Pi = E_b + E_m + E_c - P.U of
§4 with the support's penalty energy E_c at its new height), until it is at its rest pose, below anything the
sheet can reach, and touches nothing. The bending length is the fabric's at every step (a gravity ramp, the
load steps, is a ramp of the bending length from infinity down: validation/cusick_route.md), and no step is
dynamic, so no fall overshoots into high modes.

The support's height is the route's parameter and lives in the State (:attr:`rftstatic.model.state.State.obstacle_offsets`,
a translation of the obstacle that every contact evaluation reads; the Model stays frozen). A step that Newton
cannot converge is cut (x 1/4) and tried again from the last equilibrium; one that converges lets the next grow
(x :data:`STEP_GROWTH`, at most :data:`MAX_STEP_GROWTH` x the first). Where a fold snaps through, Newton's
energy descent follows it to the next minimum (continued while the energy falls, ``solver.max_continuations``).
The seeded start imperfection is the load steps' (``solver.perturbation``, ``solver.seed``:
:func:`rftstatic.solvers.perturbation.start_perturbation`).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.progress import Progress
from rftstatic.solvers.drive import Pause
from rftstatic.solvers.newton import StaticResult, close_record, newton
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.perturbation import start_perturbation

__all__ = ["RELEASE", "ReleasePath", "release", "support_lift"]

log = logging.getLogger(__name__)

RELEASE = "release"
"""The release route's key in ``State.route``: its :class:`ReleasePath` after the last converged step."""

MAX_STEP_GROWTH = 4.0
"""Largest lowering step, in first steps (``solver.release_step``): a long step drops the freed part of the sheet
onto a minimum far from the last one, as a fall would."""

STEP_GROWTH = 1.5
"""Factor on the lowering step after a converged step."""

MIN_STEP_SHARE = 1e-4
"""Smallest lowering step, as a share of the first: below it the route stops with a ConvergenceError."""


@dataclass
class ReleasePath:
    """Where the release route stands after a converged step (``State.route["release"]``).

    Attributes
    ----------
    height : the support's height above its rest pose [m] at the equilibrium ``U``
    U : (N, 3) displacements of that equilibrium [m]
    step : the next lowering [m]
    first : the first lowering step [m]
    result : the :class:`~rftstatic.solvers.newton.StaticResult` so far (one record per step)
    """

    height: float
    U: np.ndarray
    step: float
    first: float
    result: StaticResult


def support_lift(model) -> float:
    """Height [m] by which the model's support (its contact's last obstacle) rises from its rest pose until it
    touches the flat sheet's lowest free node: the route's start. ValueError without a contact."""
    contact = model.contact
    if contact is None or not getattr(contact, "obstacles", None):
        raise ValueError('solver.start = "release" needs a support to lower: the model has no contact obstacle')
    free = model.free.any(axis=1)
    phi, _ = contact.obstacles[-1].signed_distance(model.X3[free])
    return float(phi.min())


def _offsets(model, height: float) -> np.ndarray:
    """The obstacles' translations ``(M, 3)`` [m] with the support (the last) raised by ``height`` [m]."""
    offsets = np.zeros((len(model.contact.obstacles), 3))
    offsets[-1, 2] = height
    return offsets


def release(model, state, opts: StaticOptions, *, U0=None, callback=None):
    """The release route (module docstring) as a route (:mod:`rftstatic.solvers.drive`): from ``U0`` (default the
    flat sheet, perturbed if asked) or from the :class:`ReleasePath` saved in ``state.route``, pausing after every
    converged step (the last one final); returns the :class:`~rftstatic.solvers.newton.StaticResult` (``route``
    ``"release"``, one ``load_steps`` record per step with the support's height [m]).

    ``callback``: ``callback(1.0, U)`` after every converged step.
    """
    try:
        return (yield from _release(model, state, opts, U0, callback))
    finally:
        state.route.pop(RELEASE, None)


def _release(model, state, opts, U0, callback):
    t0 = time.perf_counter()
    h = float(model.mesh.element_size.mean())
    path = state.route.get(RELEASE)
    if path is None:
        U = np.zeros((model.mesh.n_nodes, 3)) if U0 is None else np.array(U0, dtype=float)
        seed = None
        if opts.route.perturbation and U0 is None:
            seed = opts.route.seed
            U[:, 2] += start_perturbation(model.mesh, opts.route) * model.free[:, 2]
        first = opts.route.release_step * h
        height, step = support_lift(model), first
        result = StaticResult(U=U, lam=1.0, converged=False, linear_solver=state.solver.name, seed=seed,
                              route="release")
        state.modes = {"exact": 0, "psd": 0, "shift": 0}
    else:
        height, U, step, first, result = path.height, path.U, path.step, path.first, path.result
    if not np.isfinite(U).all():
        raise ConvergenceError("release: the start displacements are not finite (NaN or inf)", None)
    state.obstacle_offsets = _offsets(model, height)
    max_step = opts.newton.max_step if opts.newton.max_step is not None else 0.1 * float(
        np.linalg.norm(np.ptp(model.mesh.X, axis=0)))
    bar = Progress(1.0, f"release {model.element}", enabled=opts.progress)
    top = support_lift(model)
    try:
        while height > 0.0 or not result.load_steps:
            target = max(0.0, height - step) if result.load_steps else height  # first: settle on the support
            if result.load_steps and _clear(model, U, height):
                target = 0.0  # the support carries nothing: it goes to its rest pose at once
            state.obstacle_offsets = _offsets(model, target)
            nt = _settle(model, U, opts, state, max_step, result)
            if not nt.converged:
                result.cutbacks += 1
                state.obstacle_offsets = _offsets(model, height)
                step /= 4.0
                log.info("release: support at %.4g m: %s after %d iterations (|r| = %.3e); step cut to %.3g m",
                         target, nt.reason, nt.iterations, nt.residual, step)
                if not step >= MIN_STEP_SHARE * first:
                    raise ConvergenceError(
                        f"release: support at {target:.6g} m (step {len(result.load_steps) + 1}): {nt.reason}, "
                        f"|r| = {nt.residual:.3e} N; the lowering step fell below {MIN_STEP_SHARE:g} of the first. "
                        f"Last equilibrium with the support at {height:.6g} m. Try a smaller solver.release_step "
                        "or a larger solver.max_iterations")
                continue
            height, U = target, nt.U
            result.load_steps.append({"lam": 1.0, "support_height": height, "iterations": nt.iterations,
                                      "residual": nt.residual, "scheme": nt.scheme})
            result.U, result.residual = U, nt.residual
            state.load_branches = model.load_branches(U, state.load_branches)
            state.commit_slip(model, U)
            # Newton takes about as many iterations for a short step as for a long one (12 on the coarse
            # cusick-30 at 1/2 to 1/256 of an element size: the contact set's settling), so only failures cut
            step = min(step * STEP_GROWTH, MAX_STEP_GROWTH * first)
            bar.update(1.0 - height / max(top, 1e-300), f"it {nt.iterations}")
            if callback is not None:
                callback(1.0, U)
            state.route[RELEASE] = ReleasePath(height, U, step, first, result)
            state.U, state.lam = U, 1.0
            yield Pause(f"release: support {height:.4g} m above its rest, {len(result.load_steps)} steps",
                        final=height <= 0.0)
    except ConvergenceError as exc:
        close_record(model, result, state, t0, exc)
        raise
    finally:
        bar.close()
    return close_record(model, result, state, t0)


def _settle(model, U, opts, state, max_step, result):
    """Newton at full load from ``U`` with the support where ``state`` has it: the scene's iteration, then the
    displacement iteration (energy line search) if that fails, continued while the energy falls (a snap-through);
    the iterations are counted in ``result``."""
    nt = newton(model, U, 1.0, opts.newton, state, max_step)
    result.iterations += nt.iterations
    if not nt.converged and nt.scheme == "mixed":
        result.retries += 1
        nt = newton(model, U, 1.0, opts.newton, state, max_step, scheme="displacement")
        result.iterations += nt.iterations
    for _ in range(opts.increments.max_continuations):
        if nt.converged or not nt.descending:
            break
        nt = newton(model, nt.U, 1.0, opts.newton, state, max_step, scheme="displacement")
        result.iterations += nt.iterations
    return nt


def _clear(model, U, height: float) -> bool:
    """Whether no node of the sheet at ``U (N, 3)`` [m] is within the support's reach (its contact onset, or the
    candidate margin) with the support at ``height`` [m]: lowering it further changes nothing."""
    phi, _ = model.contact.obstacles[-1].signed_distance(model.positions(U) - _offsets(model, height)[-1])
    return bool(phi.min() > model.contact.margin)
