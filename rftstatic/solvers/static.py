"""The static route (method.md, §4 and §6): load-scaled Newton, dynamic relaxation, or both.

:func:`solve_static` runs the load-scaled Newton iteration (:mod:`rftstatic.solvers.newton`) from the
flat start; when it cannot get through (a drape whose many folds snap through one after another), or
when ``start = "relax"``, dynamic relaxation at full load (:mod:`rftstatic.solvers.relaxation`) brings
the sheet near rest and Newton polishes the equilibrium to the same tolerance. The result is checked
to be a stable minimum (one Cholesky factorisation of the exact tangent).
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

from rftstatic.errors import ConvergenceError, InstabilityError
from rftstatic.solvers.linear import LinearSolveError, NotPositiveDefinite, make_solver
from rftstatic.solvers.load_steps import solve_load_steps
from rftstatic.solvers.newton import NewtonWorkspace, StaticOptions, StaticResult
from rftstatic.solvers.perturbation import fold_pattern, start_perturbation
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE, relax
from rftstatic.solvers.timestep import stable_time_step
from rftstatic.units import STANDARD_GRAVITY

__all__ = ["ConvergenceError", "StaticOptions", "StaticResult", "solve_static", "compare_with_static"]

log = logging.getLogger(__name__)


def solve_static(model, *, U0=None, options: StaticOptions | None = None, callback=None) -> StaticResult:
    """Solve the static equilibrium of ``model`` under its full load (see module docstring).

    The load-scaled Newton iteration is the main route. When it cannot get through (a drape whose
    many folds snap through one after another) and ``relax_fallback`` is on, or when
    ``start = "relax"``, dynamic relaxation (§6: damped, mass-scaled explicit motion at full load)
    brings the sheet near rest and Newton polishes the equilibrium to the same tolerance; the
    result's ``route`` and ``relax`` record what was done.

    Parameters
    ----------
    model : :class:`rftstatic.model.Model`
    U0 : (N, 3) start [m] (default: the flat reference, optionally perturbed)
    options : :class:`StaticOptions`
    callback : called as ``callback(lam, U)`` after every converged increment (checkpoints, frames)

    Raises
    ------
    ConvergenceError
        when an increment cannot converge even at ``min_increment`` (and the relaxation fallback
        fails too); ``.result`` holds the last equilibrium (``converged=False``).
    """
    opts = options or StaticOptions()
    ws = NewtonWorkspace.for_model(model)  # shared by the Newton phases of this solve
    if opts.start == "relax":
        return _check_stability(model, _relax_then_newton(model, opts, callback, ws, first=None), opts)
    try:
        return _check_stability(model, solve_load_steps(model, U0=U0, options=opts, callback=callback,
                                                        workspace=ws), opts)
    except ConvergenceError as exc:
        if not opts.relax_fallback or model.load_terms or not np.any(model.load):
            raise
        log.warning("load steps failed (%s); trying dynamic relaxation at full load, then Newton", exc)
        return _check_stability(model, _relax_then_newton(model, opts, callback, ws, first=exc), opts)


def _check_stability(model, result, opts):
    """``result.stable``: is the converged equilibrium a strict local minimum of the energy (the exact
    tangent positive definite, one Cholesky factorisation)? None when the linear solver cannot tell."""
    solver = make_solver(opts.linear_solver, coordinates=model.X3, free_dofs=model.plan.free_dofs)
    result.stable = _positive_definite(model, result.U, solver, lam=result.lam) if solver.detects_indefinite else None
    return result


MAX_RELAX_STEPS = 200_000
"""Largest number of explicit steps the relaxation route may take before it is not attempted."""

RELAX_TIME_ALLOWANCE = 2.0
"""The relaxation may run this many times its expected need (100 damping times) before Newton takes
over for good; the step-count check uses the expected need."""

RELAX_NEWTON_ITERATIONS = 10
"""Newton's ``max_iterations`` (doubled at full load: 20 iterations) from a relaxed state before the
relaxation resumes; the final handover uses the solver's own budget."""

RELAX_BASIN_NEWTON_ITERATIONS = 40
"""Newton's ``max_iterations`` (80 at full load) from the first relaxed state whose exact tangent is
positive definite: in the basin of a stable minimum, Newton's line-searched descent gets there even on
a flat energy (the 80 cm sheet at 81 x 81 needs 38-44 iterations; relaxing on and retrying with 20
iterations took four tries and 8,700 explicit steps more). Later handovers get
:data:`RELAX_NEWTON_ITERATIONS` again."""


def _relax_then_newton(model, opts, callback, ws, *, first):
    """Dynamic relaxation at full load to near rest, then Newton to the full tolerance.

    The relaxation first stops when the motion has died down (kinetic energy 1e-4 of its peak) while
    the out-of-balance force is still of the order of the weight (``|r| < |P|``): Newton usually
    converges from there in a few iterations, and the slow tail of the relaxation (half of its steps
    on a 33 x 33 drape) is skipped. Newton gets a short budget (:data:`RELAX_NEWTON_ITERATIONS`). When
    it fails, the relaxation resumes (same displacements and velocities) in chunks of a few damping
    times; after each chunk the tangent is factorised, and Newton tries again, with a longer budget
    (:data:`RELAX_BASIN_NEWTON_ITERATIONS`), only when it is positive definite (the state is in the basin of a stable minimum: from an indefinite tangent, Newton walks
    downhill for hundreds of iterations on the PSD tangent, to a point that need not be a minimum —
    the 80 cm sheet did). The relaxation ends at rest at half the solver's ``rtol`` or at its time
    limit; Newton then finishes with the solver's own budget.
    """
    t0 = time.perf_counter()
    size = float(np.ptp(model.mesh.X, axis=0).max())
    omega1 = np.sqrt(STANDARD_GRAVITY / (0.25 * size))  # pendulum estimate of the lowest drape mode
    mass_scale = RELAX_MASS_SCALE
    alpha = 2.0 * omega1 / np.sqrt(mass_scale)  # about critical for that mode of the scaled system
    max_time = 100.0 / alpha  # the relaxation's expected need: 100 damping times (checked below)
    chunk = 4.0 / alpha  # relaxation between two tangent checks [s]
    est = stable_time_step(model, mass_scale=mass_scale, alpha=alpha)
    if max_time / est.dt > MAX_RELAX_STEPS:  # a membrane far stiffer than the bending: too many steps
        message = (f"dynamic relaxation would need up to {max_time / est.dt:.3g} explicit steps (dt {est.dt:.3g} s); "
                   f"not attempted (limit {MAX_RELAX_STEPS:g})")
        if first is not None:
            raise ConvergenceError(f"{first}; {message}", first.result) from None
        raise ConvergenceError(message, None)
    max_time *= RELAX_TIME_ALLOWANCE  # settling folds on fine meshes (31 x 240 rings) take longer
    U, V, seed = None, None, None
    if opts.perturbation:  # the same seeded lift as the load steps' start picks the fold branch
        seed = opts.seed
        U = np.zeros((model.mesh.n_nodes, 3))
        U[:, 2] = start_perturbation(model.mesh, opts) * model.free[:, 2]
    polish = opts.from_state(relax_fallback=False)
    # a handover that fails gives way to more relaxation, not to the slower displacement iteration
    short = replace(polish, max_continuations=0, min_increment=1.0, max_iterations=RELAX_NEWTON_ITERATIONS,
                    iteration_fallback=False)
    basin = replace(short, max_iterations=RELAX_BASIN_NEWTON_ITERATIONS)
    info = {"mass_scale": mass_scale, "alpha_per_s": alpha, "time_s": 0.0, "steps": 0, "handovers": [],
            "after_failure": None if first is None else str(first)}
    t_used, peak = 0.0, 0.0
    tol_force, span = 1.0, max_time  # the first stop: motion died down, |r| < |P|
    checker = make_solver(opts.linear_solver, coordinates=model.X3, free_dofs=model.plan.free_dofs)

    def fail(text, result=None):
        if result is not None:
            result.route, result.relax, result.seed = "relax+newton", info, seed
        if first is not None:
            text = f"{first}; {text}"
        return ConvergenceError(text, result if result is not None else (first.result if first else None))

    if opts.guide_folds and opts.guide_weight:
        rel = _guided_relaxation(model, opts, mass_scale=mass_scale, alpha=alpha, U0=U, fail=fail)
        U, V, peak, t_used = rel.U, rel.V, rel.peak_kinetic, rel.t
        seed = opts.seed
        info.update(time_s=t_used, steps=rel.steps, guide={"folds": opts.guide_folds, "weight": opts.guide_weight,
                                                          "time_s": rel.t, "steps": rel.steps})
    while True:
        try:
            rel = relax(model, mass_scale=mass_scale, alpha=alpha, tol_kinetic=1e-4, tol_force=tol_force,
                        max_time=max(min(span, max_time - t_used), 10 * est.dt), U0=U, V0=V, peak_kinetic=peak,
                        progress=opts.progress)
        except InstabilityError as exc:
            raise fail(f"dynamic relaxation became unstable ({exc})") from None
        U, V, peak = rel.U, rel.V, rel.peak_kinetic
        t_used += rel.t
        info.update(time_s=t_used, steps=info["steps"] + rel.steps, at_rest=rel.converged,
                    wall_time_s=time.perf_counter() - t0)
        final = (rel.converged and tol_force < 1.0) or t_used >= max_time * (1 - 1e-9)
        if not final and tol_force < 1.0 and not _positive_definite(model, U, checker):
            continue  # still outside the basin of a stable minimum: relax on
        handover = {"time_s": t_used, "steps": info["steps"], "at_rest": rel.converged}
        info["handovers"].append(handover)
        try:
            # the first handover inside a basin gets the long budget; if that fails, the landscape is
            # rougher than a slow valley and later ones get the short one (a 21 x 160 round-pedestal
            # start needed 19 of them: 80 iterations each cost it 20 minutes)
            long_try = tol_force < 1.0 and not any(h.get("basin") for h in info["handovers"][:-1])
            handover["basin"] = tol_force < 1.0
            res = solve_load_steps(model, U0=U, options=polish if final else basin if long_try else short,
                                   callback=callback, workspace=ws)
        except ConvergenceError as exc:
            handover["newton"] = str(exc)
            if final:
                result = exc.result
                if result is not None:  # write the relaxed shape at full load, labelled not converged
                    result.U, result.lam = U, 1.0
                    result.residual = float(np.linalg.norm(model.residual(U, 1.0).ravel()[model.free.ravel()]))
                raise fail(f"{exc} (after dynamic relaxation to t = {t_used:.3g} s, {info['steps']} steps; "
                           "the result is the relaxed shape at full load, not an equilibrium)", result) from None
            log.info("Newton did not converge from the relaxed state at t = %.3g s (%s); relaxing further",
                     t_used, exc)
            tol_force, span = 0.5 * opts.rtol, chunk
            continue
        handover["newton"] = f"converged in {res.iterations} iterations"
        break
    res.route, res.relax, res.seed = "relax+newton", info, seed
    res.wall_time = time.perf_counter() - t0 + (0.0 if first is None or first.result is None else first.result.wall_time)
    if first is not None and first.result is not None:
        res.cutbacks += first.result.cutbacks
        res.iterations += first.result.iterations
    return res


GUIDE_DAMPING_TIMES = 30.0  # length of the guided stage of the relaxation [damping times 1/alpha]


def _guided_relaxation(model, opts: StaticOptions, *, mass_scale, alpha, U0, fail):
    """The guided first stage of :func:`_relax_then_newton`: relax under an n-fold modulated weight.

    The weight of every node is scaled by ``1 + guide_weight * fold_pattern(...)`` (so the total
    stays about the same and the load stays downward) for :data:`GUIDE_DAMPING_TIMES` damping
    times; the model itself keeps its true load.
    """
    guided = model.load * (1.0 + opts.guide_weight * fold_pattern(model.mesh, opts.guide_folds, opts.seed))[:, None]
    try:
        return relax(model, mass_scale=mass_scale, alpha=alpha, tol_kinetic=1e-4, tol_force=1.0,
                     max_time=GUIDE_DAMPING_TIMES / alpha, U0=U0, progress=opts.progress, load=guided)
    except InstabilityError as exc:
        raise fail(f"the guided dynamic relaxation became unstable ({exc})") from None


def _positive_definite(model, U, solver, lam=1.0) -> bool:
    """Whether the exact tangent at load factor ``lam`` is positive definite at ``U`` (one factorisation)."""
    if not solver.detects_indefinite:
        return True
    _, K = model.tangent(U, lam=lam)
    try:
        solver.solve(K, np.zeros(K.shape[0]))
    except (NotPositiveDefinite, LinearSolveError):
        return False
    return True


def compare_with_static(model, U_relaxed, U_static=None) -> dict:
    """Difference between a relaxed state and the static Newton solution (``solve_static`` if not given).

    Returns ``{"max_difference": [m], "max_displacement": [m], "relative": [-]}``.
    """
    if U_static is None:
        U_static = solve_static(model, options=StaticOptions(progress=False)).U
    d = float(np.linalg.norm(U_relaxed - U_static, axis=1).max())
    s = float(np.linalg.norm(U_static, axis=1).max())
    return {"max_difference": d, "max_displacement": s, "relative": d / max(s, 1e-300)}
