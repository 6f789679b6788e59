"""The load-scaled route of the static solver (§4): the load factor rises from 0 to 1 in
adaptive increments, each solved by Newton's method (:func:`rftstatic.solvers.newton.newton`).

Increments are sized from the secant displacement rate d|U|/d lam (the first from the tangent rate)
and grown with fast convergence; the mixed iteration starts each one from the last equilibrium (its
first step is the tangent predictor), the displacement iteration from a secant predictor; an increment
that does not converge is cut back (``increment / 4``) from the last equilibrium, after two mixed
failures the displacement iteration takes it, and one still sliding downhill when its iterations run
out continues (snap-through into a fold). Below ``min_increment`` the solve stops with
:class:`~rftstatic.errors.ConvergenceError`, which carries the last equilibrium. The whole load from a
given state (a relaxed drape, a coarser level's, a remeshed one) is never cut back, which would unload
it: its Newton continues while the energy falls at all, up to ``max_continuations`` times, and else
stops with its last iterate at full load.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.progress import Progress
from rftstatic.solvers.linear import LinearSolveError, NotPositiveDefinite
from rftstatic.model.state import State
from rftstatic.solvers.newton import StaticResult, close_record, mixed_scheme, newton, start_state
from rftstatic.solvers import friction_lag
from rftstatic.solvers.drive import Pause, finish
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.perturbation import start_perturbation

log = logging.getLogger(__name__)


@dataclass
class LoadPath:
    """Where the load steps stand after a converged increment (``State.route["load-steps"]``): what a resumed
    :func:`load_steps` continues from.

    Attributes
    ----------
    lam : load factor of the equilibrium ``U`` [-]
    U : (N, 3) displacements of that equilibrium [m]
    dlam : the next load increment [-]
    target : target largest nodal displacement of the next increment [m]
    lam_prev, U_prev : the equilibrium before (load factor [-], (N, 3) [m]) for the secant predictor; None
        before the first increment
    result : the :class:`StaticResult` so far (load-step records, iteration counts, seed, tangent modes)
    """

    lam: float
    U: np.ndarray
    dlam: float
    target: float
    lam_prev: float | None
    U_prev: np.ndarray | None
    result: StaticResult


LOAD_STEPS = "load-steps"
"""The load steps' key in ``State.route``: their :class:`LoadPath` after the last converged increment."""


def solve_load_steps(model, *, U0=None, options: StaticOptions | None = None, callback=None,
                     state: State | None = None, iteration_fallback: bool = True,
                     relaxed: bool = False) -> StaticResult:
    """The load-scaled Newton iteration of :func:`solve_static` (module docstring): :func:`load_steps` run to its
    end. ``state``: the solve's :class:`~rftstatic.model.state.State`, shared with its other phases (default
    :func:`~rftstatic.solvers.newton.start_state`)."""
    opts = options or StaticOptions()
    state = state if state is not None else start_state(model, opts.newton.linear_solver)
    return finish(load_steps(model, state, opts, U0=U0, callback=callback, iteration_fallback=iteration_fallback,
                             relaxed=relaxed))


def load_steps(model, state: State, opts: StaticOptions, *, U0=None, callback=None, iteration_fallback: bool = True,
               relaxed: bool = False):
    """The load steps as a route (:mod:`rftstatic.solvers.drive`): from ``U0`` (default the flat sheet, perturbed
    if asked) or from the :class:`LoadPath` saved in ``state.route`` (then as the uninterrupted solve went on),
    pausing after every converged increment (the last one final); returns the :class:`StaticResult`.

    ``callback``: ``callback(lam, U)`` after every converged increment. ``iteration_fallback``: an increment the
    mixed iteration cannot converge and that cannot be cut back (or has failed twice) is tried with the
    displacement iteration; off for the relaxation route's intermediate handovers, where the relaxation goes on
    instead. ``relaxed``: ``U0`` is a relaxed drape (the relaxation route's handovers,
    :mod:`rftstatic.solvers.static`): on its whole load the short mixed try has a reach (:data:`FROM_STATE_REACH`)
    and the displacement iteration refines its line search (``refine`` of
    :func:`~rftstatic.solvers.displacement.displacement_iterations`), both measured there only.
    """
    try:
        return (yield from _load_steps(model, state, opts, U0, callback, iteration_fallback, relaxed))
    finally:
        state.route.pop(LOAD_STEPS, None)


def _load_steps(model, state, opts, U0, callback, iteration_fallback, relaxed):
    t0 = time.perf_counter()
    n = model.mesh.n_nodes
    resume = state.route.get(LOAD_STEPS)
    if resume is not None:
        U0 = resume.U
    from_state = U0 is not None and resume is None and opts.increments.initial_increment >= 1.0
    U = np.zeros((n, 3)) if U0 is None else np.array(U0, dtype=float)
    seed = None if resume is None else resume.result.seed
    if opts.route.perturbation and U0 is None:
        seed = opts.route.seed
        U[:, 2] += start_perturbation(model.mesh, opts.route) * model.free[:, 2]
    if not (np.isfinite(U).all() and np.isfinite(model.load).all()):
        what = "the load (nodal forces)" if not np.isfinite(model.load).all() else "the start displacements"
        raise ConvergenceError(f"load factor 0: {what} are not finite (NaN or inf); check the scene's loads, "
                               "weight and mesh coordinates", None)
    if resume is None:
        state.modes = {"exact": 0, "psd": 0, "shift": 0}
    solver = state.solver
    diagonal = float(np.linalg.norm(np.ptp(model.mesh.X, axis=0)))
    max_step = opts.newton.max_step if opts.newton.max_step is not None else 0.1 * diagonal
    inc = opts.increments
    target = inc.increment_displacement if inc.increment_displacement is not None else TARGET_SHARE * diagonal
    result = StaticResult(U=U, lam=0.0, converged=False, linear_solver=solver.name, seed=seed)
    lam = 0.0
    mixed = mixed_scheme(model, opts.newton.iteration)
    friction_lag.link(model, state, U)
    if resume is None:
        dlam = _first_increment(model, U, opts, state, target)
        U_prev, lam_prev = None, None  # previous equilibrium, for the secant predictor
    else:
        lam, dlam, target, U_prev, lam_prev = resume.lam, resume.dlam, resume.target, resume.U_prev, resume.lam_prev
        _continue_result(model, result, resume, state)
    continuing = None  # Newton state of an increment that is still snapping through
    continuations = 0
    failures = 0  # mixed iterations failed in a row at this load level
    bar = Progress(1.0, f"static {model.element}", enabled=opts.progress)
    try:
        while lam < 1.0:
            if len(result.load_steps) >= opts.increments.max_load_steps:
                raise ConvergenceError(
                    f"load factor {lam:.6g}: {opts.increments.max_load_steps} load increments used without reaching "
                    "full load; raise solver.max_load_steps or solver.initial_increment")
            lam_next = min(1.0, lam + dlam)
            # the displacement iteration takes over while snapping through, and after repeated failures
            # of the mixed one at this load level or where the increment cannot be cut back
            fallback = continuing is not None or (iteration_fallback and failures >= MIXED_FAILURES)
            start = U
            if continuing is not None:
                start = continuing.U
            elif U_prev is not None and (fallback or not mixed):  # secant predictor along the path
                start = U + (lam_next - lam) / (lam - lam_prev) * (U - U_prev)
            # the mixed iteration starts from the last equilibrium itself: its first step there is the
            # tangent predictor (a secant start stretches a stiff membrane: the 21 x 5 RFT6 strip at
            # C/B = 1e9 /cm^2 took 177 iterations from it, 38 from the equilibrium)
            friction_lag.predict(model, state, lam_next)
            # the whole load from a given state (a relaxed or transferred drape) retries with the
            # displacement iteration before cutting back, which would unload the drape; its mixed try is short
            whole_from_state = from_state and not result.load_steps and lam_next >= 1.0
            short = whole_from_state and iteration_fallback and mixed and not fallback and continuing is None
            valley = whole_from_state and relaxed  # a relaxed drape: the handover's walk along its flat valley
            reach = FROM_STATE_REACH * float(model.mesh.element_size.mean()) if short and relaxed else None
            nt = newton(model, start, lam_next, _short_mixed(opts.newton) if short else opts.newton, state, max_step,
                        scheme="displacement" if fallback else None, reach=reach, refine=valley)
            continuing = None
            result.iterations += nt.iterations
            if (not nt.converged and nt.scheme == "mixed" and iteration_fallback
                    and (whole_from_state or not dlam / 4.0 >= opts.increments.min_increment)):
                result.retries += 1
                log.info("load factor %.6g: %s (|r| = %.3e); retrying with displacement iterations",
                         lam_next, nt.reason, nt.residual)
                nt = newton(model, start, lam_next, opts.newton, state, max_step, scheme="displacement",
                            refine=valley)
                result.iterations += nt.iterations
            if nt.converged and friction_lag.active(model):  # the lagged friction settles here
                nt, its = friction_lag.settle(model, state, nt, lam_next, lambda V: newton(
                    model, V, lam_next, opts.newton, state, max_step, scheme="displacement"))
                result.iterations += its
            if nt.converged:
                continuations = 0
                U_prev, lam_prev = U, lam
                lam, U = lam_next, nt.U
                state.load_branches = model.load_branches(U, state.load_branches)  # angle-type potentials
                state.commit_slip(model, U)  # bending hysteresis: the return mapping of the converged step
                result.load_steps.append({"lam": lam, "iterations": nt.iterations, "residual": nt.residual,
                                          "increment": dlam, "scheme": nt.scheme})
                result.U, result.lam, result.residual, result.stable = U, lam, nt.residual, nt.stable
                bar.update(lam, f"it {nt.iterations}")
                if callback is not None:
                    callback(lam, U)
                failures = 0
                target *= _target_factor(nt.iterations)
                rate = np.linalg.norm(U - U_prev, axis=1).max() / (lam - lam_prev)
                grow = GROWTH * (lam - lam_prev)
                dlam = float(np.clip(target / max(rate, 1e-300), inc.min_increment, min(inc.max_increment, grow)))
                state.route[LOAD_STEPS] = LoadPath(lam, U, dlam, target, lam_prev, U_prev, result)
                state.U, state.lam = U, lam
                yield Pause(f"load factor {lam:.6g}, {len(result.load_steps)} increments", final=lam >= 1.0)
                continue
            # from a given state at full load the energy's slow creep along a flat valley counts too: the
            # 31 x 240 round pedestal's finest level needed 468 iterations, 20 of them at |r| ~ 1e-3 |P|
            # with a drop below DESCENDING before converging quadratically
            creeping = whole_from_state and nt.progress > FROM_STATE_PROGRESS
            if (nt.descending or creeping) and continuations < opts.increments.max_continuations:
                continuations += 1
                continuing = nt
                log.info("load factor %.6g: still descending after %d iterations (snap-through); continuing "
                         "(%d/%d)", lam_next, nt.iterations, continuations, opts.increments.max_continuations)
                continue
            if whole_from_state:
                # a cut back would unload the given drape (measured on that level: eight cut backs down to
                # a load factor of 1.5e-5, none converged): stop with the last iterate at full load
                result.U, result.lam, result.residual = nt.U, lam_next, nt.residual
                drop = (f" (energy drop over the last third {nt.progress:.2g} of the load's work)"
                        if nt.scheme == "displacement" else "")
                raise ConvergenceError(
                    f"load factor {lam_next:.6g} from the given state, iteration {result.iterations}: {nt.reason}, "
                    f"|r| = {nt.residual:.3e} N after {continuations} continuations{drop}; the result is the last "
                    "iterate at full load, not an equilibrium. Raise solver.max_continuations or start from a "
                    "closer state.")
            failures += nt.scheme == "mixed"
            result.cutbacks += 1
            log.info("load factor %.6g: %s after %d iterations (|r| = %.3e); cutting back the increment",
                     lam_next, nt.reason, nt.iterations, nt.residual)
            dlam /= 4.0
            target /= 4.0
            if not dlam >= opts.increments.min_increment:  # also stops on a NaN increment
                raise ConvergenceError(
                    f"load factor {lam_next:.6g} (increment {len(result.load_steps) + 1}), iteration "
                    f"{nt.iterations}: {nt.reason}, |r| = {nt.residual:.3e} N; the increment fell below "
                    f"min_increment = {opts.increments.min_increment:g}. Last equilibrium at load factor {lam:.6g}. "
                    "Try solver.start = \"relax\" (dynamic relaxation at full load, then Newton) or "
                    "solver.continuation = \"arc-length\" (path following through the snap-throughs), or a larger "
                    "solver.max_iterations")
    except ConvergenceError as exc:
        close_record(model, result, state, t0, exc)
        friction_lag.explain(model, state, exc)
        raise
    finally:
        bar.close()
    return close_record(model, result, state, t0)


FROM_STATE_PROGRESS = 1e-9
"""Least relative energy drop (:attr:`~rftstatic.solvers.iteration.Iteration.progress`) over the last third
of an unconverged Newton call at full load from a given state at which the call continues: any decrease
well above the energy's round-off (1e-16 of its terms, each about the load's work)."""


def _continue_result(model, result, path: LoadPath, state) -> None:
    """``result`` carries on from ``path.result`` (records, counts) at the equilibrium ``path.U``; the branches
    of the potential loads in ``state`` (as restored from a checkpoint) are committed there."""
    old = path.result
    result.load_steps = list(old.load_steps)
    result.iterations, result.cutbacks, result.retries = old.iterations, old.cutbacks, old.retries
    result.U, result.lam, result.residual = path.U, path.lam, old.residual
    state.load_branches = model.load_branches(path.U, state.load_branches)


TARGET_SHARE = 0.1
"""Default target displacement per increment, as a share of the sheet's diagonal. Measured (total
Newton iterations, mixed iteration from the last equilibrium; strip 51 x 11, then the 21 x 5 cells RFT6
C/B = 1e2, 1e8, 1e9 and RFT3 1e9, 1e7 /cm^2): 0.05: 35, 29, 38, 54, 45, 42; 0.1: 32, 25, 38, 38, 42, 36;
0.2: 32, 23, 34, 36, 39, 37; 0.4: 32, 21, 36, 49, 42, 35. 0.1 keeps the path closer to the paper's
load-scaled one at no cost."""

FROM_STATE_MIXED_ITERATIONS = 12
"""Most mixed iterations of the first try at the whole load from a given state (a relaxed drape), when the
displacement iteration follows if it fails (instead of ``2 x`` :data:`~rftstatic.solvers.mixed.MIXED_ITERATIONS`
at full load). Measured from the relaxation route's first relaxed state: cusick-30 converges in 9 mixed
iterations (49 displacement iterations); sphere-30, pedestal-round-50 and pedestal-square-80 wander (|r| 0.3 N
after 20 on sphere-30) and then converge by the displacement iteration, so the 8 more cost 8 factorisations."""


FROM_STATE_REACH = 0.5
"""Reach of the short mixed try from a relaxed drape (``relaxed`` of :func:`load_steps`), in mean element sizes
[-]: the try gives up before its first step when that step would move a node farther, or when the exact tangent
there is indefinite
(:func:`~rftstatic.solvers.mixed.mixed_iterations`), and the displacement iteration (line search) starts at
once. Measured at the relaxation route's first handover (issue 34, validation/bench_profile.md, h-speed5): the
first Newton step moves a node 0.19 h on cusick-30 (the mixed iteration converges in 9), 1.09 h on
pedestal-round-50 and 8.0 h on pedestal-square-80 (indefinite there, and on sphere-30), where the 12 mixed
iterations wander (|r| 2e-4 -> 1.3 N at the first step on pedestal-round-50, about 22 factorisations) and the
displacement iteration restarts from the relaxed state. Along a Newton step from that state Pi follows the
quadratic model to about 1.5 times a step of 0.07 h and departs from it beyond (the membrane's strain is quadratic
in the step)."""


def _short_mixed(newton_opts):
    """``newton_opts`` whose mixed iteration stops after :data:`FROM_STATE_MIXED_ITERATIONS` at full load."""
    return replace(newton_opts, max_iterations=min(newton_opts.max_iterations, FROM_STATE_MIXED_ITERATIONS // 2))


MIXED_FAILURES = 2
"""Mixed (MIP) iterations that may fail in a row, each followed by a cut back, before the displacement
iteration (energy line search) tries the increment."""

GROWTH = 3.0
"""Largest ratio of one load increment to the last."""


def _target_factor(iterations: int) -> float:
    """Factor on the target displacement per increment after an increment converged in ``iterations``
    Newton iterations: 1.5 up to 5, 0.5 from 8, else 1. The mixed iteration takes 5-7 per increment on
    the §4.1 strip from C/B = 1e2 to 1e9 /cm^2; measured (21 x 5 strip, total iterations at C/B = 1e2,
    RFT3 1e9, RFT6 1e8, RFT6 1e9): these thresholds 29, 80, 96, 177; (6, 10): 29, 57, 136, 215."""
    if iterations <= 5:
        return 1.5
    return 0.5 if iterations >= 8 else 1.0


def _first_increment(model, U, opts, state, target) -> float:
    """First load increment: the tangent displacement rate d|U|/d lam at the start, scaled to ``target``."""
    free = model.free.ravel()
    P = model.load.ravel()[free]
    if not np.any(P) or model.load_terms:
        return opts.increments.initial_increment
    try:
        _, K = model.tangent(U, psd=True, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)
        du = np.zeros(3 * model.mesh.n_nodes)
        state.factorisations += 1
        du[free] = state.solver.solve(K, P)
    except (NotPositiveDefinite, LinearSolveError):
        return opts.increments.initial_increment
    rate = float(np.linalg.norm(du.reshape(-1, 3), axis=1).max())
    inc = opts.increments
    return float(np.clip(target / max(rate, 1e-300), inc.min_increment, inc.initial_increment))
