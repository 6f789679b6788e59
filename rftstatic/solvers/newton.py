"""Load-scaled Newton iteration on the total potential energy (§4).

The gravity/load factor ``lam`` rises from 0 to 1 in adaptive increments. At each increment a
Newton iteration minimises Pi(U) = E_b + E_m + E_c - lam P.U. Two iterations are offered:

- ``iteration = "mixed"`` (default): MIP Newton (:mod:`rftstatic.solvers.mixed`), the membrane stress
  of every element carried as an unknown of its own, so that a step that rotates a stiff membrane does
  not see the spurious second-order stretch; no energy line search, the step cap only;
- ``iteration = "displacement"``: Newton on the displacements alone (:mod:`rftstatic.solvers.displacement`),
  safeguarded for any start:

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

Both run the one Newton loop (:func:`rftstatic.solvers.loop.newton_loop`) with their own direction and
globalisation. This module holds the iteration at one load factor (:func:`newton`), which picks the
scheme, and the static result; the options are :mod:`rftstatic.solvers.options`, the load steps :mod:`rftstatic.solvers.load_steps`, the route that
chains them with dynamic relaxation :mod:`rftstatic.solvers.static`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.model.state import State
from rftstatic.solvers.displacement import displacement_iterations
from rftstatic.solvers.iteration import Iteration
from rftstatic.solvers.linear import make_solver
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
    path: dict = field(default_factory=dict)
    levels: list = field(default_factory=list)
    self_contact_stiffenings: int = 0
    self_contact_scale: float = 1.0

def start_state(model, linear_solver: str = "auto") -> State:
    """The State a static solve starts from: the flat sheet at load factor 0, fresh contact caches and the
    solve's one linear solver (``linear_solver``, :class:`~rftstatic.solvers.options.NewtonOptions`), which
    every phase of the solve shares (its symbolic analysis too, while the tangent's pattern holds)."""
    state = State.initial(model, lam=0.0)
    state.solver = make_solver(linear_solver, coordinates=model.X3, free_dofs=model.plan.free_dofs)
    return state


def mixed_scheme(model, scheme: str) -> bool:
    """Whether the iteration ``scheme`` (``"mixed"`` or ``"displacement"``) runs as MIP Newton on ``model``: ``"mixed"``
    on a model with a membrane and without shear hysteresis. The shear friction (:mod:`rftstatic.element.shear_friction`)
    is a Huber law of the membrane strain whose stick stiffness (10 G by default) may exceed the membrane's; the
    mixed iteration, without an energy line search, cycles across its kink between stick and slip: cusick-30 with
    2HG = 1 gf/cm on the load steps cut its increments to 1e-5 and reached load factor 0.11 in 7 min (13 x 160) and
    0.15 in 40 s (6 x 96), where the displacement iteration (Armijo line search on the incremental potential) took
    14 load steps and 3.3 s (6 x 96), and the elastic fabric with G x 11 in D^m took 224 load steps, 70 s
    (13 x 160; 2026-12-05)."""
    return scheme == "mixed" and model.with_membrane and getattr(model, "shear_friction", None) is None


def newton(model, U, lam, opts, state, max_step, *, stress=None, scheme=None, reach=None,
           refine=False) -> Iteration:
    """Newton iterations at fixed load factor ``lam`` from ``U`` (not modified), with the options ``opts``
    (:class:`~rftstatic.solvers.options.NewtonOptions`).

    ``scheme``: ``"mixed"`` (MIP Newton, :func:`~rftstatic.solvers.mixed.mixed_iterations`; not with shear hysteresis,
    :func:`mixed_scheme`) or ``"displacement"`` (:func:`~rftstatic.solvers.displacement.displacement_iterations`);
    default ``opts.iteration``. ``stress (E, 3)`` [N/m]: the
    mixed membrane stress at ``U`` (default ``D^m eps(U)``). ``reach`` [m]: the mixed iteration gives up at once when
    its first step would move a node farther, or its first tangent is indefinite (None: it does not). ``refine``: the
    displacement iteration's walk from a given state (:func:`~rftstatic.solvers.displacement.displacement_iterations`).
    """
    scheme = scheme or opts.iteration
    if mixed_scheme(model, scheme):
        return mixed_iterations(model, U, lam, opts, state, max_step, stress, reach)
    return displacement_iterations(model, U, lam, opts, state, max_step, refine)

def close_record(model, result: StaticResult, state: State, t0: float, error: ConvergenceError | None = None,
                 counts=None) -> StaticResult:
    """The end of a static route's record ``result``, by the route that built it: converged and ``"converged"``,
    or not and the ``error``'s message (the error then carries ``result``, its last equilibrium); the solve's
    tangent modes and factorisations (plus ``counts(result)``, a route's own), wall time [s] from ``t0`` and
    energies [J]. The State takes the result's U and load factor."""
    result.converged = error is None
    result.message = "converged" if error is None else str(error)
    result.tangent_modes = dict(state.modes)
    result.factorisations = state.factorisations
    if counts is not None:
        counts(result)
    result.wall_time = time.perf_counter() - t0
    result.energies = model.energies(result.U, result.lam, candidates=state.candidates, pairs=state.self_pairs,
                                     slip=state.slip,
                                     branches=state.load_branches)
    state.U, state.lam = result.U, result.lam
    if error is not None:
        error.result = result
    return result
