"""Static solution with global adaptive remeshing (a step beyond the paper, which remeshes only during
dynamic relaxation): solve -> size a new mesh from the converged curvature (Eq. 28-29) -> transfer U ->
solve again at full load from the transferred state, until the node count settles.

With bending or shear hysteresis (``model.has_friction``) the frictions' committed slips go with U to every new mesh
(:func:`~rftstatic.remesh.adapt.carry_slip`: each new element takes the slip of the old element holding its centroid),
and the next solve goes on from them; the energy they dissipate adds up over the cycles. A cycle whose solve from the
transferred state fails solves again from the flat sheet, a new path: from the virgin fabric, its dissipation alone.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from rftstatic.remesh.adapt import (
    RemeshRecord,
    _check_extent,
    _curvature_figures,
    _factory,
    adapt_mesh,
    carry_slip,
    reference_domain,
    refinable_maxima,
    transfer_state,
)
from rftstatic.model.state import State
from rftstatic.remesh.checkpoint import REMESH_STATIC, StaticCycleState
from rftstatic.remesh.options import RemeshOptions
from rftstatic.solvers.drive import Pause, finish

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------- static
@dataclass
class RemeshStaticResult:
    """Outcome of :func:`remesh_static`.

    Attributes
    ----------
    result : the :class:`rftstatic.solvers.newton.StaticResult` on the final mesh (``result.U`` (N, 3) [m])
    model, extras : the final model and its extras (probes, obstacles)
    records : one :class:`RemeshRecord` per mesh solved
    converged : the mesh stopped changing (and, if given, |kappa| h <= kappa_h_max) within ``max_cycles``
    meshes : the :class:`~rftstatic.mesh.trimesh.TriMesh` of every record
    slip : the frictions' committed slips (E, k) on the final mesh (:meth:`rftstatic.model.model.Model.initial_slip`;
        None without hysteresis)
    dissipated : energy the frictions dissipated along the route that led to the final state [J] (module docstring)
    """

    result: object
    model: object
    extras: dict
    records: list
    converged: bool
    meshes: list = field(default_factory=list)
    slip: np.ndarray | None = None
    dissipated: float = 0.0


def _continuation(options):
    """Options that solve at full load straight from a transferred equilibrium (Newton from it: a
    ``start = "relax"`` of the first solve would throw the transferred state away and relax from flat)."""
    return options.from_state()


def remesh_static(problem, options: RemeshOptions, *, solver=None, domain=None) -> RemeshStaticResult:
    """Static solution with global adaptive remeshing (module docstring): :func:`remesh_static_route` run to its
    end without checkpoints."""
    return finish(remesh_static_route(problem, options, State(U=np.zeros((0, 3)), V=np.zeros((0, 3))), solver=solver,
                                      domain=domain))


def remesh_static_route(problem, options: RemeshOptions, state: State, *, solver=None, domain=None):
    """Static solution with global adaptive remeshing (module docstring) as a route
    (:mod:`rftstatic.solvers.drive`): its position is ``state.route[REMESH_STATIC]`` (a
    :class:`~rftstatic.remesh.checkpoint.StaticCycleState`), with a final pause after every solved cycle; given a
    State with a saved position, it goes on from the cycle after it as the uninterrupted run.

    Parameters
    ----------
    problem : a callable ``factory(mesh) -> Model`` or ``-> (Model, extras)``; ``factory(None)`` gives
        the initial mesh's model (for a scene: :func:`rftstatic.scenes.build.model_factory`)
    options : :class:`~rftstatic.remesh.options.RemeshOptions`; this route reads ``const``, ``h_lower``,
        ``h_upper`` (Eq. 29 [m]: h_new = sqrt(const / |kappa|) clipped to [h_lower, h_upper]), ``gradation``,
        ``transfer``, ``max_cycles`` (at most this many remeshes after the initial solve), ``tol`` (stop when the
        next mesh's node count differs by less than this fraction ...) and ``kappa_h_max`` (... and the largest
        |kappa| h on the present mesh is at most this, over the elements not already at the size floor h_lower,
        :func:`refinable_maxima`; None: the node count alone). An element at its Eq. 29 size has |kappa| h =
        sqrt(const |kappa|), up to const / h_lower where the size reaches the floor, so a cap below that is never
        met (the §6 scenes: const / h_lower = 1, measured max |kappa| h 0.86-1.5 on settled meshes)
    solver : :class:`rftstatic.solvers.options.StaticOptions` of the first solve (default: the
        defaults, without a progress bar); later solves start from the transferred state at
        full load (one load step) and fall back to the full load ramp from flat if that fails
    domain : mesher Domain of the sheet (default: :func:`reference_domain` of the initial mesh)
    state : the run's :class:`~rftstatic.model.state.State` (U is the last equilibrium at each pause, ``slip`` and
        ``dissipated`` the frictions' there: what a resumed run goes on from)

    Returns
    -------
    :class:`RemeshStaticResult`

    Raises
    ------
    rftstatic.errors.ConvergenceError
        when a solve fails even from flat (its ``.result`` is the last equilibrium)
    """
    from rftstatic.errors import ConvergenceError
    from rftstatic.solvers.static import StaticOptions

    o = options
    const, h_lower, h_upper = o.const, o.h_lower, o.h_upper
    solver = StaticOptions(progress=False) if solver is None else solver
    make = _factory(problem)
    t0 = time.perf_counter()
    model, extras = make(None)
    _check_extent(model.mesh, const, h_lower, h_upper)
    if domain is None:
        domain = reference_domain(model.mesh)
    restart = state.route.get(REMESH_STATIC)
    if restart is None:
        result, history = _solve(model, solver)
        records = [RemeshRecord(0, model.mesh.n_nodes, model.mesh.n_elements, dict(model.mesh.info.get("quality", {})),
                                solve=_static_figures(result, restarted=False))]
        meshes, first = [model.mesh], 1
        yield _cycle_pause(state, StaticCycleState(0, meshes, result, records), history)
    else:
        result, records, meshes, first = restart.result, list(restart.records), list(restart.meshes), restart.cycle + 1
        history = (state.slip, state.dissipated)  # the frictions' on the last mesh, saved with the position
        if restart.cycle > 0:  # the initial model serves cycle 0
            model, extras = make(meshes[-1])
    converged = False
    for cycle in range(first, int(o.max_cycles) + 1):
        kappa, kh, kh2 = _curvature_figures(model, result.U)
        rec = records[-1]
        rec.max_kappa_h, rec.max_kappa_h2 = kh, kh2
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        t_mesh = time.perf_counter()
        new_mesh, _ = adapt_mesh(model.mesh, kappa, const=const, h_lower=h_lower, h_upper=h_upper,
                                 gradation=o.gradation, domain=domain)
        rec.node_change = abs(new_mesh.n_nodes - model.mesh.n_nodes) / model.mesh.n_nodes
        rec.wall_time = t_mesh - t0
        log.info("remesh_static cycle %d: %d nodes, max |kappa| h %.3g, next mesh %d nodes (change %.1f %%)",
                 rec.cycle, rec.nodes, kh, new_mesh.n_nodes, 100 * rec.node_change)
        if rec.node_change < o.tol and (o.kappa_h_max is None or rec.refinable_kappa_h <= o.kappa_h_max):
            converged = True
            break
        t0 = t_mesh
        new_model, new_extras = make(new_mesh)
        U0, _ = transfer_state(model, new_model, result.U, method=o.transfer)
        restarted = False
        try:
            result, history = _solve(new_model, _continuation(solver), U0=U0,
                                     history=(carry_slip(model, history[0], new_model), history[1]))
        except ConvergenceError as exc:
            log.info("remesh_static cycle %d: no equilibrium from the transferred state (%s); solving from flat",
                     cycle, exc)
            restarted = True
            result, history = _solve(new_model, solver)  # a new path from flat: the virgin fabric
        model, extras = new_model, new_extras
        records.append(RemeshRecord(cycle, new_mesh.n_nodes, new_mesh.n_elements, new_mesh.info["quality"],
                                    reason="cycle", solve=_static_figures(result, restarted=restarted)))
        meshes.append(new_mesh)
        yield _cycle_pause(state, StaticCycleState(cycle, meshes, result, records), history)
    state.route.pop(REMESH_STATIC, None)
    rec = records[-1]
    if not converged:
        kappa, rec.max_kappa_h, rec.max_kappa_h2 = _curvature_figures(model, result.U)
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        rec.wall_time = time.perf_counter() - t0
        log.warning("remesh_static: the mesh still changes after %d cycles (max |kappa| h %.3g)",
                    o.max_cycles, rec.max_kappa_h)
    return RemeshStaticResult(result=result, model=model, extras=extras, records=records, converged=converged,
                              meshes=meshes, slip=history[0], dissipated=float(history[1]))


def _solve(model, options, *, U0=None, history=(None, 0.0)):
    """``(result, history)``: the static solve of ``model`` (:func:`~rftstatic.solvers.static.static_route` from a
    fresh :func:`~rftstatic.solvers.newton.start_state`, ``U0`` (N, 3) [m] or None) going on from the frictions'
    ``history``, ``(slip (E, k) or None: the virgin fabric, dissipated [J])``, and that history at its end."""
    from rftstatic.solvers.newton import start_state
    from rftstatic.solvers.static import static_route

    state = start_state(model, options.newton.linear_solver)
    slip, state.dissipated = history[0], float(history[1])
    if slip is not None and state.slip is not None:
        if np.shape(slip) != state.slip.shape:
            raise ValueError(f"slip has shape {np.shape(slip)}, the model's frictions need {state.slip.shape}")
        state.slip = np.array(slip, dtype=float)
    result = finish(static_route(model, state, options, U0=U0))
    return result, (state.slip, state.dissipated)


def _cycle_pause(state, position: StaticCycleState, history) -> Pause:
    """``position`` as the route's in ``state`` (U its equilibrium, ``history`` = (slip, dissipated) the frictions'
    there), and the final pause after its cycle."""
    state.route[REMESH_STATIC] = position
    state.U = position.result.U
    state.slip, state.dissipated = history
    return Pause(f"cycle {position.cycle}, {position.meshes[-1].n_nodes} nodes", final=True)


def _static_figures(result, *, restarted):
    return {"converged": bool(result.converged), "iterations": int(result.iterations),
            "load_steps": len(result.load_steps), "restarted": restarted, "solve_time": float(result.wall_time)}
