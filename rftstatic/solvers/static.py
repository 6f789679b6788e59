"""The static route (§4 and §6): load-scaled Newton, dynamic relaxation, or both.

:func:`solve_static` runs the load-scaled Newton iteration (:mod:`rftstatic.solvers.newton`) from the
flat start; when it cannot get through (a drape whose many folds snap through one after another), or
when ``start = "relax"``, dynamic relaxation at full load (:mod:`rftstatic.solvers.relaxation`) brings
the sheet near rest and Newton polishes the equilibrium to the same tolerance. The result is checked
to be a stable minimum (one Cholesky factorisation of the exact tangent).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import numpy as np

from rftstatic.errors import ConvergenceError, FallError, InstabilityError, ParameterError, StepLimitError
from rftstatic.model.state import State
from rftstatic.solvers import friction_lag
from rftstatic.solvers.checkpoint import as_state
from rftstatic.solvers.continuation import solve_arc_length
from rftstatic.solvers.drive import Pause, finish
from rftstatic.solvers.explicit import EXPLICIT
from rftstatic.solvers.linear import LinearSolveError, NotPositiveDefinite
from rftstatic.solvers.load_steps import load_steps, solve_load_steps
from rftstatic.solvers.newton import StaticResult, start_state
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.perturbation import fold_pattern, start_perturbation
from rftstatic.solvers.relaxation import RelaxOptions, newton_descent, relax_steps
from rftstatic.solvers.relax_plan import RELAX_SEGMENT_STEPS, relax_plan
from rftstatic.solvers.release import RELEASE, release
from rftstatic.solvers.rest import RestCriterion

__all__ = ["ConvergenceError", "RelaxRoute", "StaticOptions", "StaticResult", "compare_with_static", "solve_static"]

log = logging.getLogger(__name__)

STATIC = "static"
"""The static route's key in ``State.route``: ``{"result": StaticResult}`` once the solve is done (a checkpoint
written then lets an interrupted output step lose nothing)."""

TESTED = "stable-at"
"""Key in ``State.route`` of the U [m] where the route has just found the exact tangent positive definite."""

RELAX_ROUTE = "relax-route"
"""The relaxation route's key in ``State.route``: its :class:`RelaxRoute`."""

SEGMENT = "relax-segment"
"""The key in ``State.route`` of the explicit State of a relaxation segment under way (its own contact caches)."""


def solve_static(model, *, U0=None, options: StaticOptions | None = None, callback=None) -> StaticResult:
    """Solve the static equilibrium of ``model`` under its full load: :func:`static_route` from a fresh
    :func:`~rftstatic.solvers.newton.start_state`, run to its end without checkpoints.

    Parameters
    ----------
    model : :class:`rftstatic.model.model.Model`
    U0 : (N, 3) start [m] (default: the flat reference, optionally perturbed)
    options : :class:`StaticOptions`
    callback : called as ``callback(lam, U)`` after every converged increment (frames, probes)

    Raises
    ------
    ConvergenceError
        when an increment cannot converge even at ``min_increment`` (and the relaxation fallback
        fails too); ``.result`` holds the last equilibrium (``converged=False``).
    """
    opts = options or StaticOptions()
    state = start_state(model, opts.newton.linear_solver)
    return finish(static_route(model, state, opts, U0=U0, callback=callback))


def static_route(model, state, opts: StaticOptions, *, U0=None, callback=None):
    """The static solve as a route (:mod:`rftstatic.solvers.drive`): returns its :class:`StaticResult`.

    The load-scaled Newton iteration is the main route. When it cannot get through (a drape whose
    many folds snap through one after another) and ``relax_fallback`` is on, or when
    ``start = "relax"``, dynamic relaxation (§6: damped, mass-scaled explicit motion at full load)
    brings the sheet near rest and Newton polishes the equilibrium to the same tolerance; the
    result's ``route`` and ``relax`` record what was done. Then the self-contact continuation and the
    stability check; the result is kept in ``state.route`` at a final pause.

    It pauses after converged increments (the load steps), at the ends of relaxation segments, after failed
    handovers and after every explicit step of a segment; ``state`` (from
    :func:`~rftstatic.solvers.newton.start_state`) with a saved ``route`` goes on from where that was saved.
    """
    done = state.route.get(STATIC)
    if done is not None:
        return done["result"]
    if RELAX_ROUTE in state.route or opts.route.start == "relax":
        result = yield from _relax_then_newton(model, opts, callback, state)
    elif RELEASE in state.route or opts.route.start == "release":  # the support lowered: rftstatic.solvers.release
        result = yield from release(model, state, opts, U0=U0, callback=callback)
    else:
        try:
            if opts.increments.continuation == "arc-length":
                if model.has_friction:  # the path's points are not committed steps
                    raise ParameterError("solver.continuation", '"arc-length" cannot carry bending or shear '
                                         'hysteresis')
                result = solve_arc_length(model, U0=U0, options=opts, callback=callback, state=state)
            else:
                result = yield from load_steps(model, state, opts, U0=U0, callback=callback)
        except ConvergenceError as exc:
            if not opts.route.relax_fallback or model.load_terms or not np.any(model.load):
                raise
            log.warning("load steps failed (%s); trying dynamic relaxation at full load, then Newton", exc)
            result = yield from _relax_then_newton(model, opts, callback, state, first=exc)
    result = _check_stability(model, _stiffen_self_contact(model, result, opts, state), state)
    state.route[STATIC] = {"result": result}
    yield Pause("the result", final=True)
    del state.route[STATIC]
    return result


SELF_CONTACT_STIFFENINGS = 3
"""Most times the self-contact stiffness is raised (x :data:`SELF_CONTACT_STIFFENING`) after a converged solve whose
smallest pair distance is below half the thickness, each followed by Newton from that state."""

SELF_CONTACT_MIN_GAP = 0.5
"""Smallest pair distance of a converged self-contact equilibrium, as a share of the thickness d, below
which the stiffness is raised (issue "Self-contact": >= 0.5 d)."""

SELF_CONTACT_STIFFENING = 8.0
"""Factor on the self-contact stiffness per raise: the cubic penalty's push at a given gap grows with it,
so a gap of 0.05 d under the automatic stiffness opens to about d/2 after two raises."""


def _stiffen_self_contact(model, result, opts, state):
    """Continuation on the self-contact stiffness (as IPC adapts its barrier stiffness): while the converged state
    has a pair closer than :data:`SELF_CONTACT_MIN_GAP` times the thickness d (folds pinched harder than the
    automatic stiffness's design load, ten times the sheet's weight), raise the stiffness and converge again from
    that state (its steps bounded by the collision test, so no pair crosses on the way). The raised stiffness is the
    solve's State's (``state.self_contact_scale``; the model's law stays as built):
    ``result.self_contact_stiffenings`` counts the raises, ``result.self_contact_scale`` is the factor the
    equilibrium holds with (its summary reports the stiffness)."""
    sc = model.self_contact
    if sc is None or not result.converged:
        return result
    polish = opts.from_state(relax_fallback=False).replace(max_continuations=0)
    for _ in range(SELF_CONTACT_STIFFENINGS):
        gap = sc.min_distance(model.positions(result.U))
        if not gap < SELF_CONTACT_MIN_GAP * sc.thickness:
            break
        state.self_contact_scale *= SELF_CONTACT_STIFFENING
        log.info("self-contact: a pair %.3g d apart; stiffness x %g, Newton again", gap / sc.thickness,
                 SELF_CONTACT_STIFFENING)
        try:
            res = solve_load_steps(model, U0=result.U, options=polish, state=state)
        except ConvergenceError as exc:
            state.self_contact_scale /= SELF_CONTACT_STIFFENING
            log.warning("self-contact: Newton with the raised stiffness did not converge (%s); the equilibrium "
                        "of the last stiffness stands", exc)
            break
        result = replace(result, self_contact_stiffenings=result.self_contact_stiffenings + 1,
                         self_contact_scale=state.self_contact_scale, U=res.U, residual=res.residual,
                         energies=res.energies, iterations=result.iterations + res.iterations,
                         factorisations=result.factorisations + res.factorisations,
                         load_steps=list(result.load_steps) + list(res.load_steps))
    return result


def _check_stability(model, result, state):
    """``result.stable``: is the converged equilibrium a strict local minimum of the energy (the exact tangent
    positive definite, one Cholesky factorisation by the solve's solver)? None when the linear solver cannot tell.
    The tangent takes the solve's self-contact pairs, with the stiffness scale it converged with. Not factorised
    again at the ``U`` the relaxation route's first handover found positive definite (``state.route[TESTED]``)."""
    tested = state.route.pop(TESTED, None)
    if tested is not None and np.array_equal(tested, result.U):
        return replace(result, stable=True)
    stable = (_positive_definite(model, result.U, state.solver, lam=result.lam, pairs=state.self_pairs,
                                  slip=state.slip, candidates=state.candidates)
              if state.solver.detects_indefinite else None)
    return replace(result, stable=stable)


RELAX_NEWTON_ITERATIONS = 10
"""Newton's ``max_iterations`` (doubled at full load: 20 iterations) from a relaxed state before the
relaxation resumes; the final handover uses the solver's own budget."""

FIRST_HANDOVER_CONTINUATIONS = 20
"""Continuations of Newton from the first relaxed state (each ``2 x`` :data:`RELAX_NEWTON_ITERATIONS` more
displacement iterations while the energy falls, :data:`~rftstatic.solvers.load_steps.FROM_STATE_PROGRESS`),
after the mixed iteration's short try; the result counts only if it is a stable minimum. Hanging garments walk
their soft fold modes for a few hundred iterations: at 8 the first handover of skirt-circle, dress and
pedestal-square-80 ran out and relaxed on; at 20 it converges there (317, 281 and 182 iterations) to the same
equilibrium (total energy to 1e-10) with 6,360, 4,908 and 1,101 fewer explicit steps (solve 114 -> 100 s,
118 -> 92 s, 48 -> 44 s; validation/bench_profile.md); the other paper scenes' first handover converged before."""

RELAX_BASIN_NEWTON_ITERATIONS = 40
"""Newton's ``max_iterations`` (80 at full load) from the first relaxed state whose exact tangent is positive
definite: in the basin of a stable minimum, Newton's line-searched descent gets there even on a flat energy (the
80 cm sheet at 81 x 81 needs 38-44 iterations; relaxing on and retrying with 20 iterations took four tries and
8,700 explicit steps more). Later handovers get :data:`RELAX_NEWTON_ITERATIONS` again."""


@dataclass
class RelaxRoute:
    """Where the relaxation route of :func:`solve_static` stands between two of its steps: what its
    checkpoints save and what a resumed solve continues from (SI units).

    Attributes
    ----------
    phase : ``"start"`` (nothing relaxed yet), ``"guide"`` (the guided first stage, under way), ``"relax"``
        (a relaxation segment to run, or under way), ``"handover"`` (a segment has ended: tangent check,
        then Newton)
    U, V : (N, 3) displacements [m] and half-step velocities [m/s] at the start of the next step (None
        before the first segment; ``U`` then holds the start perturbation, if any)
    t_used : relaxation time so far [s]
    peak : peak kinetic energy of the relaxation so far [J]
    tol_force : the out-of-balance force at which the next segment stops, relative to ``|P|`` [-]
    span : the longest next segment [s]
    at_rest : whether the last segment ended at rest
    seed : seed of the start perturbation or fold guide (None: none)
    info : the route's record (:attr:`StaticResult.relax`: mass scale, damping, time, steps, handovers)
    first : the failure of the load steps that led here (None: ``start = "relax"``)
    """

    phase: str
    U: np.ndarray | None
    V: np.ndarray | None
    t_used: float
    peak: float
    tol_force: float
    span: float
    at_rest: bool
    seed: int | None
    info: dict
    first: ConvergenceError | None = None


def _relax_then_newton(model, opts, callback, state, *, first=None):
    """Dynamic relaxation at full load to near rest, then Newton to the full tolerance.

    The relaxation first stops when the motion has died down (kinetic energy 1e-4 of its peak) while the
    out-of-balance force is still of the order of the weight (``|r| < |P|``): Newton usually converges from there in
    a few iterations, and the slow tail of the relaxation (half of its steps on a 33 x 33 drape) is skipped. Newton
    gets a short budget (:data:`RELAX_NEWTON_ITERATIONS`), here continued while the energy falls
    (:data:`FIRST_HANDOVER_CONTINUATIONS`; taken if a stable minimum). When it fails, the relaxation resumes (same
    displacements and velocities) in chunks of a few damping times; after each chunk the tangent is factorised, and
    Newton tries again (:data:`RELAX_BASIN_NEWTON_ITERATIONS`) only when it is positive definite (in the basin of a
    stable minimum: from an indefinite tangent a short-budget Newton may walk to a point that is no minimum). The
    relaxation ends at rest at half the solver's ``rtol`` or at its time limit; Newton then finishes with the
    solver's own budget. Coulomb friction: :func:`rftstatic.solvers.friction_lag.anchor`.

    A route (:mod:`rftstatic.solvers.drive`): its :class:`RelaxRoute` is ``state.route[RELAX_ROUTE]``, the explicit
    State of a segment under way ``state.route[SEGMENT]``. It pauses (final) after the failed load steps, at the end
    of every segment and after every failed handover, and after every explicit step of a segment; given a State with
    a saved route, it goes on from there.
    """
    try:
        return (yield from _relax_route(model, opts, callback, state, first))
    finally:
        state.route.pop(RELAX_ROUTE, None)
        state.route.pop(SEGMENT, None)


def _relax_route(model, opts, callback, state, first):
    t0 = time.perf_counter()
    route = state.route.get(RELAX_ROUTE)
    first = route.first if route is not None else first
    plan = relax_plan(model, first, opts.route.relax_damping)
    if route is None:
        route = state.route[RELAX_ROUTE] = _start_route(model, opts, plan, first)
        if first is not None:
            yield _route_pause(route)  # the end of the failed load steps' phase
    polish = opts.from_state(relax_fallback=False)
    # a handover that fails gives way to more relaxation (no fallback to the slower displacement iteration)
    short = polish.replace(max_continuations=0, min_increment=1.0, max_iterations=RELAX_NEWTON_ITERATIONS)
    # in a stable minimum's basin the line-searched displacement iteration gets there where the mixed one wanders
    basin = short.replace(max_iterations=RELAX_BASIN_NEWTON_ITERATIONS)
    info = route.info

    def fail(text, result=None):
        if result is not None:
            result = replace(result, route="relax+newton", relax=info, seed=route.seed)
        text = text if first is None else f"{first}; {text}"
        return ConvergenceError(text, result if result is not None else (first.result if first else None))

    if route.phase in ("start", "guide"):
        if opts.route.guide_folds and opts.route.guide_weight:
            yield from _guided_relaxation(model, opts, plan, route, fail, state)
        route.phase = "relax"
    while True:
        if route.phase == "relax":
            yield from _relax_segment(model, opts, plan, route, fail, state, t0)
        final = (route.at_rest and route.tol_force < 1.0) or route.t_used >= plan.max_time * (1 - 1e-9)
        friction_lag.anchor(model, state, route.U)  # Coulomb friction: stick anchors at the relaxed state
        if not final and route.tol_force < 1.0 and not _positive_definite(
                model, route.U, state.solver, slip=state.slip, candidates=state.candidates):
            route.phase = "relax"
            continue  # still outside the basin of a stable minimum: relax on
        handover = {"time_s": route.t_used, "steps": info["steps"], "at_rest": route.at_rest,
                    "rest_test": info.get("rest_test")}
        info["handovers"].append(handover)
        try:
            # the first handover inside a basin gets the long budget; if that fails, the landscape is
            # rougher than a slow valley and later ones get the short one (a 21 x 160 round-pedestal
            # start needed 19 of them: 80 iterations each cost it 20 minutes)
            long_try = route.tol_force < 1.0 and not any(h.get("basin") for h in info["handovers"][:-1])
            first_try = not final and len(info["handovers"]) == 1
            handover["basin"] = route.tol_force < 1.0
            options = (polish if final else short.replace(max_continuations=FIRST_HANDOVER_CONTINUATIONS)
                       if first_try else basin if long_try else short)
            history = state.slip, state.dissipated  # committed by a converged Newton
            res = solve_load_steps(model, U0=route.U, options=options, callback=callback, state=state,
                                   iteration_fallback=final or long_try or first_try, relaxed=True)
            if first_try:  # kept only if a stable minimum (which the final stability check then knows)
                if not _positive_definite(model, res.U, state.solver, pairs=state.self_pairs,
                                          slip=state.slip, candidates=state.candidates):
                    state.slip, state.dissipated = history  # the relaxation goes on from before that Newton
                    raise ConvergenceError(f"converged in {res.iterations} iterations to an equilibrium that is not "
                                           "a stable minimum", res)
                state.route[TESTED] = res.U
        except ConvergenceError as exc:
            handover["newton"] = str(exc)
            if final:
                result = exc.result
                if result is not None:  # write the relaxed shape at full load, labelled not converged
                    r = model.residual(route.U, 1.0, slip=state.slip).ravel()[model.free.ravel()]
                    result = replace(result, U=route.U, lam=1.0, residual=float(np.linalg.norm(r)))
                raise fail(f"{exc} (after dynamic relaxation to t = {route.t_used:.3g} s, {info['steps']} steps; "
                           "the result is the relaxed shape at full load, not an equilibrium)", result) from None
            handover["descent"] = descent = newton_descent(model, state, route, exc.result)
            log.info("Newton failed from the relaxed state at t = %.3g s (%s); relaxing on%s", route.t_used, exc,
                     " from its last iterate (lower energy)" * descent)
            route.tol_force, route.span, route.phase = 0.5 * opts.newton.rtol, plan.chunk, "relax"
            yield _route_pause(route)
            continue
        handover["newton"] = f"converged in {res.iterations} iterations"
        break
    before = first.result if first is not None else None  # the failed load steps' record, if any
    return replace(res, route="relax+newton", relax=info, seed=route.seed,
                   wall_time=time.perf_counter() - t0 + (0.0 if before is None else before.wall_time),
                   cutbacks=res.cutbacks + (0 if before is None else before.cutbacks),
                   iterations=res.iterations + (0 if before is None else before.iterations))


def _route_pause(route) -> Pause:
    """The final pause of the relaxation route where it stands (the end of a phase)."""
    return Pause(f"relaxation to t = {route.t_used:.4g} s, {route.phase}", final=True)


def _segment_state(model, state, route) -> State:
    """The explicit State of the segment that starts from ``route`` (its own contact caches), or the one saved
    in ``state.route``; kept there while the segment runs."""
    seg = as_state(model, state.route.get(SEGMENT))
    if seg is None:
        seg = State.initial(model, route.U, route.V)
        seg.slip, seg.dissipated = state.slip, state.dissipated  # the friction's history goes on
    state.route[SEGMENT] = seg
    return seg


def _start_route(model, opts, plan, first) -> RelaxRoute:
    """The relaxation route before its first segment: from the flat sheet, lifted by the same seeded
    perturbation as the load steps' start (it picks the fold branch)."""
    U, seed = None, None
    if opts.route.perturbation:
        seed = opts.route.seed
        U = np.zeros((model.mesh.n_nodes, 3))
        U[:, 2] = start_perturbation(model.mesh, opts.route) * model.free[:, 2]
    info = {"mass_scale": plan.mass_scale, "alpha_per_s": plan.alpha, "damping": plan.damping, "time_s": 0.0,
            "steps": 0, "handovers": [], "after_failure": None if first is None else str(first)}
    return RelaxRoute(phase="start", U=U, V=None, t_used=0.0, peak=0.0, tol_force=1.0, span=plan.max_time,
                      at_rest=False, seed=seed, info=info, first=first)


def _relax_segment(model, opts, plan, route, fail, state, t0):
    """One relaxation segment from ``route`` (or the one saved in ``state``); then a final pause at ``"handover"``.
    A segment that goes unstable runs again from its start with the step the explicit run names (kept for the
    route's later segments in ``route.info["dt_s"]``), at most :data:`STEP_CUTS` times in the route."""
    while True:
        seg = _segment_state(model, state, route)
        saved = seg.route.get(EXPLICIT)
        span = max(min(route.span, plan.max_time - route.t_used), plan.min_span)
        first = friction_lag.handover_kinetic(model, opts.route.handover_kinetic) if route.tol_force >= 1.0 else 1e-4
        rest = RestCriterion(tol_kinetic=first, tol_force=route.tol_force)
        try:
            rel = yield from relax_steps(model, seg, RelaxOptions(
                mass_scale=plan.mass_scale, alpha=plan.alpha, rest=rest, damping=plan.damping,
                max_time=span if saved is None else float(saved["options"]["t_end"]), progress=opts.progress,
                max_steps=RELAX_SEGMENT_STEPS, max_steps_name="the relaxation route's segment limit",
                dt=route.info.get("dt_s")), given_velocity=route.V is not None, peak_kinetic=route.peak)
            break
        except InstabilityError as exc:
            cuts = route.info.setdefault("step_cuts", [])
            if len(cuts) >= STEP_CUTS or not 0.0 < exc.suggested_dt < exc.dt:
                raise fail(f"dynamic relaxation became unstable ({exc})") from None
            log.warning("dynamic relaxation unstable at t = %.4g s with dt = %.3g s; the segment runs again from "
                        "t = %.4g s with dt = %.3g s", route.t_used + exc.t, exc.dt, route.t_used, exc.suggested_dt)
            cuts.append({"time_s": route.t_used + exc.t, "dt_s": exc.dt, "new_dt_s": exc.suggested_dt})
            route.info["dt_s"] = exc.suggested_dt
            del state.route[SEGMENT]
        except FallError as exc:
            raise fail(str(exc)) from None
        except StepLimitError as exc:  # the stable step at this state collapsed (a stretched start)
            raise fail(f"dynamic relaxation cannot go on from t = {route.t_used:.3g} s: {exc}") from None
    del state.route[SEGMENT]
    state.slip, state.dissipated = seg.slip, seg.dissipated
    route.U, route.V, route.peak, route.at_rest = rel.U, rel.V, rel.peak_kinetic, rel.converged
    route.t_used += rel.t
    route.info.update(time_s=route.t_used, steps=route.info["steps"] + rel.steps, at_rest=rel.converged,
                      rest_test=rest.record(), wall_time_s=time.perf_counter() - t0)
    route.phase = "handover"
    yield _route_pause(route)


STEP_CUTS = 2
"""Most times the relaxation route runs a segment again with a shorter explicit step after it went unstable (the
step estimate leaves out the penalty contact's node springs, which can take up its safety factor: a limp skirt on the
form at h = 4 cm, validation/bench_profile.md)."""

GUIDE_DAMPING_TIMES = 30.0  # length of the guided stage of the relaxation [damping times 1/alpha]


def _guided_relaxation(model, opts: StaticOptions, plan, route, fail, state):
    """The guided first stage of :func:`_relax_then_newton`: relax under an n-fold modulated weight.

    The weight of every node is scaled by ``1 + guide_weight * fold_pattern(...)`` (so the total
    stays about the same and the load stays downward) for :data:`GUIDE_DAMPING_TIMES` damping
    times; the model itself keeps its true load. A route: it goes on with the stage saved in ``state``.
    """
    guide = opts.route
    guided = model.load * (1.0 + guide.guide_weight * fold_pattern(model.mesh, guide.guide_folds, guide.seed))[:, None]
    route.phase = "guide"
    seg = _segment_state(model, state, route)
    try:
        rel = yield from relax_steps(model, seg, RelaxOptions(
            mass_scale=plan.mass_scale, alpha=plan.alpha, rest=RestCriterion(1e-4, tol_force=1.0), damping=plan.damping,
            max_time=GUIDE_DAMPING_TIMES / plan.alpha, progress=opts.progress, max_steps=RELAX_SEGMENT_STEPS,
            max_steps_name="the relaxation route's segment limit"), given_velocity=route.V is not None, load=guided)
    except InstabilityError as exc:
        raise fail(f"the guided dynamic relaxation became unstable ({exc})") from None
    except StepLimitError as exc:
        raise fail(f"the guided dynamic relaxation cannot run: {exc}") from None
    del state.route[SEGMENT]
    state.slip, state.dissipated = seg.slip, seg.dissipated
    route.U, route.V, route.peak, route.t_used = rel.U, rel.V, rel.peak_kinetic, rel.t
    route.seed = guide.seed
    route.info.update(time_s=rel.t, steps=rel.steps, guide={"folds": guide.guide_folds, "weight": guide.guide_weight,
                                                            "time_s": rel.t, "steps": rel.steps})
    route.phase = "relax"
    yield _route_pause(route)


def _positive_definite(model, U, solver, lam=1.0, pairs=None, slip=None, candidates=None) -> bool:
    """Whether the exact tangent at load factor ``lam`` is positive definite at ``U`` (one factorisation); ``pairs``,
    ``slip``, ``candidates``: the solve's caches (:meth:`~rftstatic.model.model.Model.tangent`)."""
    if not solver.detects_indefinite:
        return True
    _, K = model.tangent(U, lam=lam, pairs=pairs, slip=slip, candidates=candidates)
    try:
        solver.solve(K, np.zeros(K.shape[0]))
    except (NotPositiveDefinite, LinearSolveError):
        return False
    return True


def compare_with_static(model, U_relaxed, U_static=None) -> dict:
    """Difference between a relaxed state and the static Newton solution (``solve_static`` if not given):
    ``{"max_difference": [m], "max_displacement": [m], "relative": [-]}``."""
    U_static = solve_static(model, options=StaticOptions(progress=False)).U if U_static is None else U_static
    d, s = (float(np.linalg.norm(v, axis=1).max()) for v in (U_relaxed - U_static, U_static))
    return {"max_difference": d, "max_displacement": s, "relative": d / max(s, 1e-300)}
