"""Load-scaled Newton iteration on the total potential energy (method.md, §4).

The gravity/load factor ``lam`` rises from 0 to 1 in adaptive increments. At each increment a
Newton iteration minimises Pi(U) = E_b + E_m + E_c - lam P.U. Two iterations are offered:

- ``iteration = "mixed"`` (default): MIP Newton (:mod:`rftstatic.solvers.mixed`), the membrane stress
  of every element carried as an unknown of its own, so that a step that rotates a stiff membrane does
  not see the spurious second-order stretch; no energy line search, the step cap only;
- ``iteration = "displacement"``: Newton on the displacements alone, safeguarded for any start:

  1. tangent: the exact Hessian first; if the Cholesky factorisation finds it indefinite (membrane
     compression) or the step is not a descent direction, the compressive stress is dropped from the
     geometric stiffness (positive semi-definite membrane tangent), and if needed a
     Levenberg-Marquardt shift is added (the mixed iteration uses the same safeguards);
  2. the step is scaled so that no node moves more than ``max_step`` (the "simple scaling" of Liu &
     Sze 2009), which keeps the first steps from a flat start in range (both iterations);
  3. an Armijo backtracking line search on Pi makes every accepted step lower the energy;
  4. on large meshes (``step_solver``, :mod:`~rftstatic.solvers.krylov`) a step between two factorisations
     is solved by conjugate gradients on the exact tangent, preconditioned with the last factorisation.

Convergence (:class:`~rftstatic.solvers.iteration.Criteria`) needs both the force residual
``|r| <= rtol |lam P|`` (plus the round-off floor of the internal force) and the energy criterion
``|d . r_new| <= etol W`` (work of the residual on the last step, W the work of the applied load).
An increment that does not converge is cut back (``increment / 4``) from the last equilibrium;
below ``min_increment`` the solve stops with :class:`~rftstatic.errors.ConvergenceError`, which
carries the last equilibrium, labelled as not converged.

This module holds the iteration at one load factor (:func:`newton`) and the static result; the options
are :mod:`rftstatic.solvers.options`, the load steps :mod:`rftstatic.solvers.load_steps`, the route that
chains them with dynamic relaxation :mod:`rftstatic.solvers.static`.
"""

from __future__ import annotations

import logging
import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.model.state import State
from rftstatic.solvers.iteration import Criteria, Iteration, capped_step, direction, self_contact_limited
from rftstatic.solvers.krylov import forcing, krylov_direction, uses_krylov
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.mixed import mixed_iterations

log = logging.getLogger(__name__)


@dataclass
class StaticResult:
    """Outcome of :func:`solve_static`.

    Attributes
    ----------
    U : (N, 3) displacements of the last equilibrium [m]
    lam : load factor reached [-]
    converged : True only if lam = 1 was reached in equilibrium
    load_steps : one record per accepted increment (load factor, iterations, residual, scheme)
    iterations : Newton iterations in all, those of failed tries included
    cutbacks : increments cut back after a failure
    retries : increments whose mixed iteration failed and that the displacement iteration retried
    factorisations : numeric factorisations of the tangent (Newton steps, failed Cholesky attempts, the
        first increment's rate; not the stability check)
    state : the solve's final :class:`~rftstatic.model.state.State` (U, load factor, contact candidates)
    path : the arc-length route's record (:func:`~rftstatic.solvers.continuation.solve_arc_length`: each
        step's load factor, arc length and negative pivots, the critical points and the branches taken);
        empty for the other routes
    levels : mesh sequencing (:mod:`rftstatic.app.levels`): one record per mesh, coarsest first (nodes,
        route, iterations, residual, energy, wall time); empty for a single mesh
    """

    U: np.ndarray
    lam: float
    converged: bool
    load_steps: list = field(default_factory=list)
    iterations: int = 0
    cutbacks: int = 0
    retries: int = 0
    factorisations: int = 0
    linear_solver: str = ""
    wall_time: float = 0.0
    energies: dict = field(default_factory=dict)
    residual: float = float("nan")
    stable: bool | None = None
    message: str = ""
    tangent_modes: dict = field(default_factory=dict)
    seed: int | None = None
    route: str = "load-steps"
    relax: dict = field(default_factory=dict)
    state: State | None = None
    path: dict = field(default_factory=dict)
    levels: list = field(default_factory=list)

@dataclass
class NewtonWorkspace:
    """What the Newton phases of one static solve share and update (never the Model).

    Attributes
    ----------
    state : the solve's :class:`~rftstatic.model.state.State` (its contact candidate list is used by
        every energy, residual and tangent evaluation)
    solver : the linear solver (symbolic analysis reused between factorisations)
    modes : counts of the tangents used: exact, psd, shift, reused, krylov (steps by preconditioned CG, and
        their "CG iterations")
    factorisations : numeric factorisations of a tangent (failed Cholesky attempts included)
    lm_scale : mean tangent diagonal [N/m], the scale of the Levenberg-Marquardt damping, computed once
        per solve at the state where damping is first needed
    modified_shift : the last diagonal shift [N/m] that made the indefinite exact tangent positive definite
        (:func:`~rftstatic.solvers.iteration.direction`, mode ``"modified"``): the next try starts below it
    """

    state: State
    solver: object = None
    modes: dict = field(default_factory=lambda: {"exact": 0, "psd": 0, "shift": 0})
    lm_scale: float | None = None
    factorisations: int = 0
    modified_shift: float = 0.0

    @classmethod
    def for_model(cls, model) -> NewtonWorkspace:
        """A fresh workspace: the flat state at load factor 0 (the solver is made by each phase)."""
        return cls(State.initial(model, lam=0.0))

    @property
    def candidates(self):
        return self.state.candidates

    @property
    def pairs(self):
        """The solve's self-contact pair cache (None without self-contact)."""
        return self.state.self_pairs


def newton(model, U, lam, opts, ws, max_step, *, stress=None, scheme=None) -> Iteration:
    """Newton iterations at fixed load factor ``lam`` from ``U`` (not modified), with the options ``opts``
    (:class:`~rftstatic.solvers.options.NewtonOptions`).

    ``scheme``: ``"mixed"`` (MIP Newton, :func:`~rftstatic.solvers.mixed.mixed_iterations`) or ``"displacement"``
    (:func:`displacement_iterations`); default ``opts.iteration``. ``stress (E, 3)`` [N/m]: the
    mixed membrane stress at ``U`` (default ``D^m eps(U)``).
    """
    scheme = scheme or opts.iteration
    if scheme == "mixed" and model.with_membrane:
        return mixed_iterations(model, U, lam, opts, ws, max_step, stress)
    return displacement_iterations(model, U, lam, opts, ws, max_step)

def displacement_iterations(model, U, lam, opts, ws, max_step) -> Iteration:
    """Newton on the displacements alone (module docstring): exact or safeguarded tangent, step cap,
    Armijo line search on Pi, Levenberg-Marquardt damping as a trust region, optional reuse of a
    factorisation (modified Newton)."""
    solver, modes, cand = ws.solver, ws.modes, ws.candidates
    test = Criteria(model, lam, opts, U)
    P = test.P
    # the final increment converges to the tight tolerance and may need longer
    max_iterations = 2 * opts.max_iterations if lam >= 1.0 else opts.max_iterations
    free = model.free.ravel()
    U = U.copy()
    parts = model.energies(U, lam, candidates=cand, pairs=ws.pairs)
    Pi, scale = parts["total"], _energy_scale(parts)
    r = (model.residual(U, lam, candidates=cand, pairs=ws.pairs)).ravel()[free]
    rnorm = float(np.linalg.norm(r))
    if not np.isfinite(rnorm):
        return Iteration(False, U, 0, rnorm, "non-finite residual")
    work0 = None
    last_work = np.inf
    stable = None
    mu = 0.0  # Levenberg-Marquardt damping, relative to the mean tangent diagonal
    Pi_history = [Pi]
    reuse = False  # the last factorisation may serve the next step (modified Newton)
    age = 0
    hist = []
    krylov = uses_krylov(opts, len(r), solver)
    refresh = True  # krylov steps: the next step factorises the tangent anew
    first_rnorm = rnorm
    for it in range(1, max_iterations + 1):
        if it > 1 and test.met(U, r, last_work, solver):
            return Iteration(True, U, it - 1, rnorm, stable=stable, history=hist)
        d = None
        fresh = False
        mode = "reused"
        if krylov and not refresh:
            d, dKd, refresh = krylov_direction(model, U, lam, r, ws, mu, forcing(rnorm, first_rnorm))
            fresh, mode = d is not None, "krylov"
        elif reuse and age < opts.reuse_factorisation and not krylov:
            try:
                d = solver.resolve(-r)
            except LinearSolveError:
                d = None
            if d is not None and not (np.all(np.isfinite(d)) and float(r @ d) < 0.0):
                d = None
            if d is not None:
                modes["reused"] = modes.get("reused", 0) + 1
                age += 1
        if d is None:
            try:
                d, mode, shift = direction(model, U, lam, r, opts, ws, damping=mu)
            except LinearSolveError as exc:
                return Iteration(False, U, it, rnorm, f"linear solve failed ({exc})")
            stable = (mode == "exact" and mu == 0.0) if solver.detects_indefinite else None
            age = 0
            fresh = True
            refresh = False
            # curvature of the quadratic model along d: (K + s I) d = -r  =>  d.K.d = -d.r - s d.d
            dKd = -float(r @ d) - shift * float(d @ d)
        step, cap = capped_step(model, d, max_step)
        slope = float(r @ step.ravel()[free])
        step, frac = self_contact_limited(model, U, step, ws)
        cap *= frac
        slope = float(r @ step.ravel()[free])
        alpha, parts = _line_search(model, U, step, lam, Pi, slope, opts, cand, ws.pairs, scale)
        if alpha is None:
            return Iteration(False, U, it, rnorm, "line search found no decrease of the energy")
        Pi_new, scale = parts["total"], _energy_scale(parts)
        U = U + alpha * step
        Pi = Pi_new
        hist.append({"residual": rnorm, "alpha": alpha, "cap": cap, "mu": mu, "fresh": fresh,
                     "mode": mode if fresh else "reused"})
        Pi_history.append(Pi)
        # Levenberg-Marquardt damping as a trust region (More's update): the ratio of the actual to
        # the predicted energy decrease of a fresh Newton step decides; a step the line search had to
        # shorten (a near-singular or indefinite direction: a sheet balanced on a sphere, a fold
        # forming) damps the next one, good steps undo it, so the final iterations are pure Newton
        if fresh:
            predicted = -(slope + 0.5 * cap * cap * dKd)
            actual = Pi_history[-2] - Pi_new if len(Pi_history) > 1 else 0.0
            tiny = 1e-10 * max(abs(Pi), abs(work0 or 0.0))
            if alpha == 1.0 and abs(predicted) <= tiny:
                rho = 1.0  # below what the energy resolves: the residual decides convergence
            else:
                rho = actual / predicted if (alpha == 1.0 and predicted > 0) else 0.0
            if alpha < 1.0 or rho < 0.25:
                mu = max(4.0 * mu, 1e-6)
            elif rho > 0.75:
                mu = mu / 3.0 if mu > 1e-9 else 0.0
        r_new = model.residual(U, lam, candidates=cand, pairs=ws.pairs).ravel()[free]
        work = abs(float(alpha * step.ravel()[free] @ r_new))
        if work0 is None:
            # energy scale: the first step's work or the work of the load so far, whichever is larger
            # (a good predictor makes the first step tiny; round-off must not stall the criterion);
            # ``parts``: the energies at the new U, from the line search
            work0 = max(abs(alpha * slope), abs(lam * float(np.einsum("ni,ni->", P, U))),
                        parts["bending"] + parts["membrane"], 1e-300)
            test.work_ref = work0
        last_work = work
        # modified Newton: keep the factorisation while it still cuts the residual fast
        rnorm_new = float(np.linalg.norm(r_new))
        reuse = alpha == 1.0 and rnorm_new < 0.3 * rnorm
        r = r_new
        rnorm = rnorm_new
        if not np.isfinite(rnorm):
            return Iteration(False, U, it, rnorm, "non-finite residual")
    if test.met(U, r, last_work, solver):
        return Iteration(True, U, max_iterations, rnorm, stable=stable)
    # still sliding downhill? compare the energy drop of the last third with the scale of the work
    k = max(2, len(Pi_history) // 3)
    drop = Pi_history[-k] - Pi_history[-1]
    progress = drop / max(work0 or 0.0, abs(lam * float(np.einsum("ni,ni->", P, U))), 1e-300)
    return Iteration(False, U, max_iterations, rnorm, f"no convergence in {max_iterations} iterations",
                     progress=progress, history=hist)


def _line_search(model, U, step, lam, Pi0, slope, opts, candidates=None, pairs=None, scale=None, max_trials=12):
    """Armijo backtracking on Pi along ``step``: ``(alpha, parts)``, ``parts`` the energies
    (:meth:`~rftstatic.model.model.Model.energies`) at ``U + alpha step``; ``(None, None)`` when no trial
    lowers the energy. ``scale`` [J]: :func:`_energy_scale` of the energies at ``U`` (computed when None;
    the caller passes the last accepted step's, which saves an evaluation per iteration)."""
    def parts_at(alpha):
        return model.energies(U + alpha * step, lam, candidates=candidates, pairs=pairs)

    if not opts.line_search:
        return 1.0, parts_at(1.0)
    if scale is None:
        scale = _energy_scale(model.energies(U, lam, candidates=candidates, pairs=pairs))
    if abs(slope) <= 1e-10 * scale:
        # the predicted decrease is below what the energy can resolve: near the solution the Newton
        # step is reliable, and the force residual (not the energy) decides convergence
        return 1.0, parts_at(1.0)
    roundoff = 1e-13 * scale
    alpha = 1.0
    for _ in range(max_trials):
        parts = parts_at(alpha)
        Pi = parts["total"]
        if np.isfinite(Pi) and Pi <= Pi0 + 1e-4 * alpha * slope + roundoff:
            return alpha, parts
        # minimiser of the quadratic through Pi0, slope and Pi(alpha), safeguarded
        if np.isfinite(Pi):
            denom = 2.0 * (Pi - Pi0 - slope * alpha)
            a_q = -slope * alpha * alpha / denom if denom > 0 else 0.5 * alpha
            alpha = float(np.clip(a_q, 0.1 * alpha, 0.5 * alpha))
        else:
            alpha *= 0.1
    return None, None


def _energy_scale(parts: dict) -> float:
    """Magnitude of the energy [J] against which the line search judges round-off: the summed magnitudes
    of bending, membrane, contact energies and the load's work."""
    return abs(parts["bending"]) + abs(parts["membrane"]) + abs(parts["contact"]) + abs(parts["external_work"])


@contextmanager
def route_outcome(model, result: StaticResult, ws: NewtonWorkspace, t0: float, bar, *, extra=None):
    """The ending every static route shares, around its body: ``converged`` and ``message`` on success; a
    :class:`~rftstatic.errors.ConvergenceError` labelled with its message and carrying the last
    equilibrium (``exc.result``); in any case the bar closed, tangent modes, factorisations, wall time
    [s] (from ``t0``), energies and the workspace's State of the final ``result``. ``extra(result)``
    adds a route's own counters before the energies."""
    try:
        yield
        result.converged = True
        result.message = "converged"
    except ConvergenceError as exc:
        result.message = str(exc)
        exc.result = result
        raise
    finally:
        bar.close()
        result.tangent_modes = dict(ws.modes)
        result.factorisations = ws.factorisations
        if extra is not None:
            extra(result)
        result.wall_time = time.perf_counter() - t0
        result.energies = model.energies(result.U, result.lam, candidates=ws.candidates, pairs=ws.pairs)
        ws.state.U, ws.state.lam = result.U, result.lam
        result.state = ws.state
