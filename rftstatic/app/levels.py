"""Mesh sequencing (``solver.levels``): a fine drape by Newton from the solution of a coarser mesh.

A drape on a fine mesh (10^5 triangles) is out of reach of the routes that start from the flat sheet:
the relaxation's explicit steps shrink with the element size (its cost grows as N^1.5), and a path from
flat passes dozens of critical points, each with an L D L^T factorisation. Nested iteration (grid
continuation, as in multigrid's "full multigrid" start) instead solves the drape on a hierarchy of meshes
of the same sheet (:func:`rftstatic.scenes.levels.level_scenes`, each about twice as coarse as the next):

1. the coarsest mesh by the scene's own route (``solver.start``, ``solver.continuation``: load steps,
   arc-length or relaxation), where it is cheap;
2. its equilibrium carried to the next mesh (:func:`transfer_start`: linear in the coarse triangles,
   the new nodes lifted out of the obstacles), the prescribed displacements set to zero;
3. Newton at full load from there (:meth:`~rftstatic.solvers.options.StaticOptions.from_state`: one load
   step, the displacement iteration with its energy line search and trust region, the supernodal
   Cholesky factorisation wherever the tangent is positive definite), then the self-contact and stability
   checks of :func:`~rftstatic.solvers.static.solve_static`; repeated up to the scene's mesh.

The folds are found where they are cheap to find; the fine meshes only sharpen them.

A coarse mesh of RFT6 locks more than the fine one (the parasitic membrane energy of a fold grows with the
locking number ``(C/B) h^2``, :func:`~rftstatic.model.model.locking_number`), so its folds are another shape,
and the finest Newton has to carry them there along a curved, nearly flat valley (hundreds of short steps
on the 80 cm drape at 201 x 201 nodes). ``solver.level_membrane = "matched"`` solves every level below the
finest with its membrane rigidity scaled by :func:`membrane_match`, ``(h_finest / h)^2``, so that each has
the finest mesh's locking number; the coarsest level's route still finds the branch with the scene's own
fabric, and its equilibrium is then solved again with the matched membrane (Newton at full load) before it
is carried up. Only the finest level is the scene's model. Each level's
equilibrium is saved in the run folder (``level-K.npz``, with the fingerprint of its model) as soon as it
converges; ``--resume`` takes it up again, so an interrupted run loses at most the level it was on.
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError, ConvergenceError
from rftstatic.remesh.adapt import carry_slip
from rftstatic.remesh.transfer import transfer_fields
from rftstatic.scenes.build import build_mesh, build_model
from rftstatic.scenes.levels import level_scenes
from rftstatic.scenes.options import run_options
from rftstatic.model.state import State
from rftstatic.solvers.checkpoint import read_checkpoint, save_atomic, state_arrays
from rftstatic.solvers.drive import drive
from rftstatic.solvers.newton import start_state
from rftstatic.solvers.static import solve_static, static_route
from rftstatic.solvers.static_checkpoint import static_fingerprint

log = logging.getLogger(__name__)

__all__ = ["TRANSFER", "carry_slip", "membrane_match", "solve_levels", "transfer_start"]

TRANSFER = "mesh"
"""How an equilibrium goes to the next mesh (:func:`rftstatic.remesh.transfer.transfer_fields`): linear
in the coarse triangles. Measured on the 80 cm sheet (energies of the carried state on the fine mesh
against the coarse equilibrium's -0.1013 J, 101 x 101 -> 201 x 201 nodes): linear -0.0837 J, the patch
quadratic -0.0565 J (it overshoots at the kink over the pedestal's rim: membrane energy 0.042 against
0.014 J), both after the lift out of the pedestal (:meth:`~rftstatic.contact.penalty.PenaltyContact.project_out`),
without which the new nodes on coarse chords across the rounded rim lie inside it (penalty energy
0.16 J, more than the work of the weight)."""


def transfer_start(coarse_model, U, fine_model) -> np.ndarray:
    """The start (N_fine, 3) [m] on ``fine_model``'s mesh from the displacements ``U (N_coarse, 3)`` [m]
    of ``coarse_model`` (:data:`TRANSFER`), lifted out of the obstacles, prescribed displacements zero."""
    U0 = transfer_fields(coarse_model.mesh, fine_model.mesh.X, [U], method=TRANSFER)[0]
    if fine_model.contact is not None:
        U0 = fine_model.contact.project_out(fine_model.positions(U0)) - fine_model.mesh.X3
    U0[fine_model.fixed] = 0.0
    return U0


def solve_levels(scene, model, opts, *, folder=None, resume=False, callback=None, saver=None, state=None):
    """Solve ``model`` (the model of ``scene``) by mesh sequencing over the scene's ``solver.levels`` meshes
    (:func:`~rftstatic.scenes.options.run_options`).

    Parameters
    ----------
    scene : the :class:`~rftstatic.scenes.schema.Scene` (its coarser levels are built from it)
    model : the scene's :class:`~rftstatic.model.model.Model` (the finest level)
    opts : :class:`~rftstatic.solvers.options.StaticOptions` of every level's solve
    folder : run folder where each converged level is saved (``level-K.npz``); None: nothing saved
    resume : take up the levels saved in ``folder`` (those of the same model only)
    callback : ``callback(lam, U)`` after every converged increment of the finest level
    saver : a :class:`~rftstatic.solvers.checkpoint.CheckpointSaver` given the finest level's pauses (None: none)
    state : the finest level's :class:`~rftstatic.model.state.State`, fresh from
        :func:`~rftstatic.solvers.newton.start_state` on ``model``; after the solve it holds what the finest level
        ended with (the frictions' committed slips, the dissipation, the contact caches). None: made here

    Returns the finest level's :class:`~rftstatic.solvers.newton.StaticResult`, its ``route``
    ``"<coarsest route>+levels"``, ``levels`` one record per mesh, the counters summed over them, and
    ``path`` and ``relax`` those of the coarsest level's route (the path followed, the relaxation).

    Raises
    ------
    ConvergenceError
        when a level does not converge; the message names the level and its mesh, ``.result`` holds its
        last state when it is the finest (else None).
    """
    run = run_options(scene)
    scenes = level_scenes(scene, run.levels)
    records, totals = [], {"iterations": 0, "factorisations": 0, "cutbacks": 0, "retries": 0}
    prev = None
    first_path, first_relax = {}, {}  # the coarsest route's own record (its path or relaxation), if solved here
    matched = run.level_membrane == "matched"
    given = state
    t_all = time.perf_counter()
    for k, sc in enumerate(scenes, start=1):
        last = k == len(scenes)
        t0 = time.perf_counter()
        mesh = model.mesh if last else build_mesh(sc)
        scale = membrane_match(mesh, model.mesh) if matched and not last else 1.0
        # ``carry``: the model whose equilibrium goes to the next mesh (matched membrane, if asked)
        carry = model if last else build_model(sc, mesh, quiet=True, membrane_scale=scale)[0]
        build = time.perf_counter() - t0
        saved = _load_level(folder, k, carry) if resume else None
        if saved is not None:
            log.info("mesh sequencing: level %d of %d (%d nodes) taken from %s", k, len(scenes), carry.mesh.n_nodes,
                     _level_path(folder, k))
            records.append({**saved["record"], "resumed": True})
            prev = (carry, saved["U"], saved["slip"], saved["dissipated"])
            continue
        if prev is None:  # the route finds the branch with the scene's own fabric
            m = carry if scale == 1.0 else build_model(sc, mesh, quiet=True)[0]
            level_opts, U0 = replace(opts, progress=opts.progress and last), None
            what = f"the scene's route ({opts.route.start})"
        else:
            m = carry
            level_opts, U0 = _newton_options(opts, opts.progress and last), transfer_start(prev[0], prev[1], m)
            what = f"Newton at full load from level {k - 1}" + (f", membrane x {scale:.4g}" if scale != 1.0 else "")
        log.info("mesh sequencing: level %d of %d, %s nodes, by %s", k, len(scenes), m.mesh.n_nodes, what)
        try:
            state = start_state(m, level_opts.newton.linear_solver) if not last or given is None else given
            if prev is not None and prev[2] is not None and state.slip is not None:
                state.slip = carry_slip(prev[0], prev[2], m)
                state.dissipated = prev[3]  # the route's dissipation goes on from the coarser levels'
            route = static_route(m, state, level_opts, U0=U0, callback=callback if last else None)
            res = drive(route, saver.on(state) if last and saver is not None else None)
        except ConvergenceError as exc:
            failed = exc.result if last else None
            if failed is not None:  # the summary of the failed run lists the levels solved and this one
                _add_counts(totals, failed)
                failed = _sequence_outcome(failed, records + [_record(k, sc, m, failed, prev is None, build)], totals)
            raise ConvergenceError(
                f"mesh sequencing: level {k} of {len(scenes)} ({_nodes(sc)}, {m.mesh.n_nodes} nodes) did not "
                f"converge by {what}: {exc}", result=failed) from None
        records.append(_record(k, sc, m, res, prev is None, build))
        _add_counts(totals, res)
        if not res.converged:
            if last:
                res = _sequence_outcome(res, records, totals)
            raise ConvergenceError(f"mesh sequencing: level {k} of {len(scenes)} ({_nodes(sc)}) did not converge: "
                                   f"{res.message}", result=res if last else None)
        U = res.U
        if m is not carry:  # the coarsest level, matched: its equilibrium again with the matched membrane
            U, carry = _rematched(m, carry, res, opts, records[-1], totals)
        if folder is not None and not last:
            _save_level(folder, k, carry, U, records[-1], state.slip, state.dissipated)
        if prev is None:
            first_path, first_relax = res.path, res.relax
        prev = (carry, U, state.slip, state.dissipated)
    res = _sequence_outcome(res, records, totals)
    return replace(res, path=res.path or first_path, relax=res.relax or first_relax,
                   wall_time=time.perf_counter() - t_all)


def membrane_match(mesh, finest) -> float:
    """``min(1, (h_finest / h)^2)`` [-], ``h`` the mean element size of ``mesh`` and ``h_finest`` of the mesh
    ``finest``: the factor on a coarse level's membrane rigidity that gives it the finest mesh's locking number
    ``(C/B) h^2`` (:func:`~rftstatic.model.model.locking_number`), ``solver.level_membrane = "matched"``."""
    h, h_finest = float(mesh.element_size.mean()), float(finest.element_size.mean())
    return min(1.0, (h_finest / h) ** 2)


def _membrane_scale(model) -> float:
    """The factor on ``model``'s membrane rigidity (:meth:`~rftstatic.material.Material.membrane_scaled`; 1: the
    scene's fabric)."""
    return float(model.material.info.get("membrane_scale", 1.0))


def _newton_options(opts, progress: bool):
    """The options of a level's Newton at full load from a carried state (module docstring, step 3)."""
    return opts.from_state(relax_fallback=False).replace(iteration="displacement", continuation="load",
                                                          progress=progress)


def _rematched(model, matched, res, opts, record: dict, totals: dict):
    """``(U, carry)``: the coarsest level's equilibrium ``res`` on ``model`` (the scene's fabric) solved again by
    Newton on ``matched`` (its membrane scaled), and that model; ``record["matched"]`` tells how. A matched
    solve that fails carries the equilibrium of ``model`` instead (a warning)."""
    t0 = time.perf_counter()
    try:
        r = solve_static(matched, U0=res.U, options=_newton_options(opts, False))
        why = r.message
    except ConvergenceError as exc:
        r, why = exc.result, str(exc)
    ok = r is not None and r.converged
    record["matched"] = {"membrane_scale": _membrane_scale(matched), "converged": ok,
                         "iterations": getattr(r, "iterations", 0), "factorisations": getattr(r, "factorisations", 0),
                         "energy_J": r.energies.get("total") if ok else None, "wall_time_s": time.perf_counter() - t0}
    if r is not None:
        _add_counts(totals, r)
    if not ok:
        log.warning("mesh sequencing: the coarsest level did not converge with its membrane matched (%s); its "
                    "equilibrium with the scene's fabric goes to the next level", why)
        return res.U, model
    return r.U, matched


def _record(k, scene, model, res, coarsest: bool, build: float) -> dict:
    """The ``levels`` record of level ``k`` solved on ``model`` (its mesh, route, membrane scale, counts, residual
    [N], energy [J], times [s])."""
    return {"level": k, "mesh": _nodes(scene), "nodes": model.mesh.n_nodes, "elements": model.mesh.n_elements,
            "route": res.route if coarsest else "newton", "membrane_scale": _membrane_scale(model),
            "converged": bool(res.converged),
            "stable_minimum": res.stable, "iterations": res.iterations,
            "factorisations": res.factorisations, "residual_N": res.residual,
            "energy_J": res.energies.get("total"), "build_time_s": build, "wall_time_s": res.wall_time}


def _sequence_outcome(res, records, totals):
    """``res`` (the finest level's result) as the sequence's: its route, levels and counters over all levels."""
    return replace(res, route=f"{records[0]['route']}+levels", levels=records, iterations=totals["iterations"],
                   factorisations=totals["factorisations"], cutbacks=totals["cutbacks"], retries=totals["retries"])


def _add_counts(totals: dict, res) -> None:
    """Add the counters of one level's ``res`` (iterations, factorisations, cut backs, retries) to ``totals``."""
    for key in totals:
        totals[key] += getattr(res, key)


def remove_levels(folder) -> None:
    """Delete the saved levels of a finished run (``level-K.npz`` in ``folder``)."""
    for p in Path(folder).glob("level-*.npz"):
        p.unlink(missing_ok=True)


def _nodes(scene) -> str:
    m = scene.get("mesh", {})
    return f"h = {m['h']}" if "nodes" not in m and "h" in m else f"{m.get('nodes')}"


def _level_path(folder, k) -> Path:
    return Path(folder) / f"level-{k}.npz"


def _save_level(folder, k, model, U, record, slip=None, dissipated=0.0) -> None:
    """Level ``k``'s equilibrium ``U`` (N, 3) [m] of ``model``, its frictions' committed ``slip`` (E, k) (None:
    none), the energy they dissipated since the flat start [J] and its record, in the one checkpoint format (a
    State whose ``route["level"]`` is the record), keyed to the model's fingerprint."""
    state = State(U=np.array(U, dtype=float), V=np.zeros_like(U), route={"level": record}, slip=slip,
                  dissipated=float(dissipated))
    save_atomic(_level_path(folder, k), state_arrays(state, {"kind": "level", "level": k,
                                                             "model": static_fingerprint(model)}))


def _load_level(folder, k, model):
    """A saved level of this model (same fingerprint), or None (logged) when there is none or it differs."""
    if folder is None or not _level_path(folder, k).exists():
        return None
    path = _level_path(folder, k)
    try:
        header, saved = read_checkpoint(path)
    except CheckpointError as exc:
        log.warning("%s (level %d is solved again)", exc, k)
        return None
    if header.get("kind") != "level" or header.get("model") != static_fingerprint(model) or \
            saved["U"].shape != (model.mesh.n_nodes, 3):
        log.warning("%s was saved for another model: level %d is solved again", path, k)
        return None
    return {"U": saved["U"], "record": saved["route"]["level"], "slip": saved.get("slip"),
            "dissipated": float(saved.get("dissipated", 0.0))}
