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

This module holds the iteration at one load factor (:func:`newton`), its options and result; the load
steps are :mod:`rftstatic.solvers.load_steps`, the route that chains them with dynamic relaxation
:mod:`rftstatic.solvers.static`.
"""

from __future__ import annotations

import logging
import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.model.state import State
from rftstatic.solvers.iteration import Criteria, Iteration, capped_step, direction, self_contact_limited
from rftstatic.solvers.krylov import forcing, krylov_direction, uses_krylov
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.mixed import mixed_iterations

log = logging.getLogger(__name__)


_COUNTS = {"max_iterations": 1, "max_load_steps": 1, "max_continuations": 0, "reuse_factorisation": 0, "seed": 0,
           "perturbation_folds": 0, "guide_folds": 0, "levels": 1}
"""The integer options of :class:`StaticOptions` and their least values (a seed: numpy's generators take
none below 0)."""


@dataclass(frozen=True, kw_only=True)
class StaticOptions:
    """Options of :func:`solve_static` (scene table ``[solver]``).

    Attributes
    ----------
    initial_increment, min_increment, max_increment : load-factor increments [-]
    max_iterations : Newton iterations per increment
    rtol : force tolerance, relative to the applied load |lam P| [-], at full load
    intermediate_rtol : looser force tolerance for the increments on the way to full load [-]
    etol : energy tolerance on the work of the residual over the last step, relative to the larger
        of the first step's work and the work of the applied load [-]
    max_step : cap on the largest nodal increment per Newton iteration [m]; ``None``: 10 % of the
        sheet's diagonal
    increment_displacement : target largest nodal displacement per load increment [m], from which
        the next increment is sized by the secant (first: tangent) rate d|U|/d lam; ``None``: 10 %
        of the sheet's diagonal. Halved or grown with the Newton iteration count.
    line_search : Armijo backtracking on Pi (displacement iteration)
    iteration : ``"mixed"`` (MIP Newton, the membrane stress carried as an unknown; an increment it
        cannot converge is retried with the displacement iteration) or ``"displacement"`` (Newton on
        the displacements alone, energy line search)
    iteration_fallback : an increment the mixed iteration cannot converge and that cannot be cut back
        (or has failed twice) is tried with the displacement iteration; off for the relaxation
        route's intermediate handovers, where the relaxation goes on instead
    tangent : ``"auto"`` (exact, safeguarded when indefinite), ``"exact"`` or ``"psd"``
    linear_solver : ``"auto"``, ``"cholmod"``, ``"scipy"`` or ``"amg"``
    step_solver : how the displacement iteration solves its Newton step: ``"direct"`` (a factorisation
        of the tangent per step, reused by ``reuse_factorisation``), ``"krylov"`` (conjugate gradients on
        the exact tangent preconditioned with the last factorisation, factorised anew when CG slows,
        :mod:`~rftstatic.solvers.krylov`) or ``"auto"``: krylov from
        :data:`~rftstatic.solvers.krylov.KRYLOV_FROM` free unknowns when the linear solver re-solves
        cheaply, else direct
    max_load_steps : give up after this many increments
    start : ``"load-steps"`` (load-scaled Newton from the flat start) or ``"relax"`` (dynamic
        relaxation at full load, then Newton to polish: for drapes with many folds)
    continuation : how ``start = "load-steps"`` follows the load from 0 to 1: ``"load"`` (load
        increments, :mod:`~rftstatic.solvers.load_steps`) or ``"arc-length"`` (pseudo-arclength path
        following with the tangent's inertia tracked and branch switching at critical points,
        :mod:`~rftstatic.solvers.continuation`)
    relax_fallback : when the load steps fail, try dynamic relaxation + Newton before giving up
    reuse_factorisation : how many further steps may reuse a factorisation while the residual keeps
        falling by more than 70 % per step (modified Newton; 0 = full Newton)
    max_continuations : an increment whose Newton iteration runs out of iterations while the energy
        is still falling markedly (snap-through into a fold) continues from where it stopped, up to
        this many times, instead of cutting back
    perturbation : amplitude of a seeded random out-of-plane start, in element sizes [-]
    seed : seed of that perturbation
    perturbation_folds : 0 for random low Fourier modes; n > 0 for an n-fold lift around the sheet's
        centre (:func:`fold_perturbation`), to look for the drape branch with n folds
    guide_folds, guide_weight : ``start = "relax"`` only: during the first stage of the relaxation
        (:data:`GUIDE_DAMPING_TIMES` damping times) the weight is modulated by
        ``1 + guide_weight (r/R)^2 cos(n theta + phi)`` with n = ``guide_folds`` (:func:`fold_pattern`),
        then restored, so that the sheet falls into n folds and the rest of the relaxation tells
        whether that drape is a stable equilibrium; 0 = no guide
    levels : meshes of a mesh sequence (1: the scene's mesh alone). A scene run with ``levels = L``
        (:mod:`rftstatic.app.levels`) solves the coarsest of L meshes by this route and each finer one
        by Newton at full load from the solution below; :func:`solve_static` solves the one model it
        is given and does not read it
    level_membrane : the coarse levels' membrane: ``"same"`` (the scene's fabric) or ``"matched"`` (every level
        below the finest solved with its membrane rigidity scaled by ``(h_finest / h)^2``, the finest mesh's
        locking number ``(C/B) h^2``, the coarsest after its route has found the branch; see
        :mod:`rftstatic.app.levels`)
    """

    initial_increment: float = 0.1
    min_increment: float = 1e-5
    max_increment: float = 1.0
    max_iterations: int = 30
    rtol: float = 1e-6
    intermediate_rtol: float = 0.1
    etol: float = 1e-12
    max_step: float | None = None
    increment_displacement: float | None = None
    line_search: bool = True
    iteration: str = "mixed"
    iteration_fallback: bool = True
    tangent: str = "auto"
    linear_solver: str = "auto"
    step_solver: str = "auto"
    max_load_steps: int = 2000
    max_continuations: int = 10
    reuse_factorisation: int = 2
    start: str = "load-steps"
    continuation: str = "load"
    relax_fallback: bool = True
    perturbation: float = 0.0
    seed: int = 0
    perturbation_folds: int = 0
    guide_folds: int = 0
    guide_weight: float = 0.0
    levels: int = 1
    level_membrane: str = "same"
    progress: bool = True

    def __post_init__(self):
        for name, least in _COUNTS.items():
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ValueError(f"solver.{name} must be an integer >= {least}, got {v!r}")
        if self.continuation not in ("load", "arc-length"):
            raise ValueError(f'solver.continuation must be "load" or "arc-length", got "{self.continuation}"')
        if self.start not in ("load-steps", "relax"):
            raise ValueError(f'solver.start must be "load-steps" or "relax", got "{self.start}"')
        if self.linear_solver not in ("auto", "cholmod", "scipy", "amg"):
            raise ValueError(f'solver.linear_solver must be "auto", "cholmod", "scipy" or "amg", got '
                             f'"{self.linear_solver}"')
        if self.step_solver not in ("auto", "direct", "krylov"):
            raise ValueError(f'solver.step_solver must be "auto", "direct" or "krylov", got "{self.step_solver}"')
        if self.level_membrane not in ("same", "matched"):
            raise ValueError(f'solver.level_membrane must be "same" or "matched", got "{self.level_membrane}"')
        if self.iteration not in ("mixed", "displacement"):
            raise ValueError(f'solver.iteration must be "mixed" or "displacement", got "{self.iteration}"')
        if self.tangent not in ("auto", "exact", "psd"):
            raise ValueError(f'solver.tangent must be "auto", "exact" or "psd", got "{self.tangent}"')
        if not (0 < self.min_increment <= self.initial_increment <= self.max_increment <= 1):
            raise ValueError(
                "need 0 < min_increment <= initial_increment <= max_increment <= 1, got "
                f"{self.min_increment}, {self.initial_increment}, {self.max_increment}")
        if self.perturbation_folds < 0:
            raise ValueError(f"solver.perturbation_folds must be 0 (random modes) or a fold count, "
                             f"got {self.perturbation_folds}")
        if self.guide_folds < 0 or not (0.0 <= self.guide_weight < 1.0):
            raise ValueError(f"solver.guide_folds must be >= 0 and solver.guide_weight in [0, 1) (a weight "
                             f"modulation that keeps the weight downward), got {self.guide_folds}, {self.guide_weight}")
        if self.guide_folds and self.guide_weight and self.start != "relax":
            raise ValueError('solver.guide_folds guides the dynamic relaxation: it needs solver.start = "relax"')
        if self.rtol <= 0 or self.max_iterations < 1:
            raise ValueError(f"need rtol > 0 and max_iterations >= 1, got {self.rtol}, {self.max_iterations}")
        for name in ("rtol", "intermediate_rtol", "etol", "max_step", "increment_displacement", "guide_weight",
                     "perturbation"):
            v = getattr(self, name)
            if v is not None and not np.isfinite(v):
                raise ValueError(f"solver.{name} must be a finite number, got {v!r}")
        for name in ("intermediate_rtol", "max_step", "increment_displacement"):
            v = getattr(self, name)
            if v is not None and not v > 0:
                raise ValueError(f"solver.{name} must be > 0, got {v!r}")
        if self.perturbation < 0 or self.etol < 0:
            raise ValueError(f"need solver.perturbation >= 0 and solver.etol >= 0, got {self.perturbation}, "
                             f"{self.etol}")

    def single_step(self) -> StaticOptions:
        """These options with the whole load in one increment (no displacement-sized increments)."""
        return replace(self, initial_increment=1.0, max_increment=1.0, increment_displacement=1e30)

    def from_state(self, *, relax_fallback: bool | None = None) -> StaticOptions:
        """Options for Newton at full load straight from a given state (a relaxed or transferred
        equilibrium): one load step, no relaxation start, no perturbation or fold guide.
        ``relax_fallback``: override the fallback to relaxation when that Newton fails."""
        fallback = self.relax_fallback if relax_fallback is None else relax_fallback
        return replace(self.single_step(), start="load-steps", perturbation=0.0, guide_folds=0,
                       relax_fallback=fallback)


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
    self_contact_stiffenings, self_contact_scale : raises of the self-contact stiffness after convergence and
        the factor on it the equilibrium holds with (:func:`~rftstatic.solvers.static.solve_static`)
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
    self_contact_stiffenings: int = 0
    self_contact_scale: float = 1.0

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
    """Newton iterations at fixed load factor ``lam`` from ``U`` (not modified).

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
    parts = model.energies(U, lam, candidates=cand, pairs=ws.pairs, branches=ws.state.load_branches)
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
        alpha, parts = _line_search(model, U, step, lam, Pi, slope, opts, cand, ws.pairs, scale,
                                    branches=ws.state.load_branches)
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


def _line_search(model, U, step, lam, Pi0, slope, opts, candidates=None, pairs=None, scale=None, max_trials=12,
                 branches=None):
    """Armijo backtracking on Pi along ``step``: ``(alpha, parts)``, ``parts`` the energies
    (:meth:`~rftstatic.model.model.Model.energies`) at ``U + alpha step``; ``(None, None)`` when no trial
    lowers the energy. ``scale`` [J]: :func:`_energy_scale` of the energies at ``U`` (computed when None;
    the caller passes the last accepted step's, which saves an evaluation per iteration)."""
    def parts_at(alpha):
        return model.energies(U + alpha * step, lam, candidates=candidates, pairs=pairs, branches=branches)

    if not opts.line_search:
        return 1.0, parts_at(1.0)
    if scale is None:
        scale = _energy_scale(model.energies(U, lam, candidates=candidates, pairs=pairs, branches=branches))
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
        result.energies = model.energies(result.U, result.lam, candidates=ws.candidates, pairs=ws.pairs,
                                         branches=ws.state.load_branches)
        ws.state.U, ws.state.lam = result.U, result.lam
        result.state = ws.state
