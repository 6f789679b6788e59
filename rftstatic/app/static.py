"""The ``static`` analysis: build the scene's model, solve the static drape, write the outputs.

The route (load-scaled Newton, dynamic relaxation, or both) is :func:`rftstatic.solvers.static.solve_static`.
Every number written is in the scene's units. A solve that fails still writes its last equilibrium,
labelled ``"converged": false``, before the :class:`~rftstatic.errors.ConvergenceError` is raised again
(the command line exits with status 3).

The solve's State is saved in ``checkpoint.npz`` in the run folder at the pauses of its route (after converged
increments, relaxation segments and explicit steps; :mod:`rftstatic.solvers.static_checkpoint`: at most one
write per :data:`~rftstatic.solvers.static_checkpoint.CHECKPOINT_SECONDS` of wall time, the end of every phase
always, the last converged increment on a Ctrl-C); ``--resume`` (:func:`resume_scene`) continues from it
to the same equilibrium as the uninterrupted run.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from rftstatic.app.levels import remove_levels, solve_levels
from rftstatic.app.result import RunResult
from rftstatic.errors import ConvergenceError
from rftstatic.io.files import to_jsonable
from rftstatic.io.results import write_outputs
from rftstatic.io.summary import (drape_summary, obstacle_crossing_summary, probe_summary, self_contact_summary,
                                  self_intersection_summary, summary_header, warn_crossings)
from rftstatic.scenes.build import build_model
from rftstatic.app.specimens import seeded_specimens
from rftstatic.app.starts import keep_lower
from rftstatic.scenes.options import compare_start, run_options, seed_count, static_options
from rftstatic.solvers.drive import drive
from rftstatic.solvers.newton import start_state
from rftstatic.solvers.static import static_route
from rftstatic.solvers.static_checkpoint import CHECKPOINT_SECONDS, load_static_state, remove_stale, static_saver, where

log = logging.getLogger(__name__)

CHECKPOINT = "checkpoint.npz"


def run(scene, out: Path, *, progress=True, figures=True, resume=False, callback=None,
        checkpoint_seconds: float = CHECKPOINT_SECONDS, mesh=None, start_check: bool = True) -> RunResult:
    """Build and solve ``scene``; write the outputs into ``out``; return the result.

    ``resume``: continue from ``out/checkpoint.npz`` (a fresh solve, logged, when there is none; a
    :class:`~rftstatic.errors.CheckpointError` when it is corrupt or another scene's, mesh's or options'); with
    ``solver.levels`` > 1 (mesh sequencing, :mod:`rftstatic.app.levels`), from the levels saved in ``out``.
    ``callback``: ``callback(lam, U)`` after every converged increment. ``checkpoint_seconds``: least wall
    time between two checkpoint writes [s]. ``mesh``: the sheet's reference mesh in place of the scene's
    ``[mesh]`` (a garment's, :mod:`rftstatic.app.garment`); ``start_check``: refuse surface obstacles cutting the
    sheet at the start (:func:`rftstatic.scenes.build.build_contact`; a sewn garment's stage checks its own).
    """
    t0 = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    model, extras = build_model(scene, mesh=mesh, start_check=start_check)
    build_time = time.perf_counter() - t0
    opts = static_options(scene, progress=progress)
    seeds = seed_count(scene)
    other = compare_start(scene)
    if other is not None and model.has_friction:
        raise scene.error("solver.compare", f"{other!r}: a drape with bending or shear hysteresis depends on its route "
                          "(the friction's history), so two routes' energies do not tell which drape a specimen keeps; "
                          "remove solver.compare or the kes_2HB / kes_2HG keys")
    path = out / CHECKPOINT
    remove_stale(path)
    resumed = None
    single = run_options(scene).levels == 1  # mesh sequencing resumes from its own saved levels (level-K.npz)
    state = None  # the solve's State (with mesh sequencing the finest level's)
    if resume and single and path.exists():
        state = load_static_state(path, model, opts, scene=scene.name)
        resumed = where(state)
        log.info("resuming the static solve from %s (%s)", path, resumed)
    elif resume and single:
        log.warning("no checkpoint %s: solving from the start", path)
    saver = static_saver(path, model, opts, scene=scene.name, every_seconds=checkpoint_seconds)
    error = None
    try:
        with saver.stopping():
            state = state or start_state(model, opts.newton.linear_solver)
            if not single:  # mesh sequencing: ``state`` becomes the finest level's
                result = solve_levels(scene, model, opts, folder=out, resume=resume, callback=callback,
                                      saver=saver, state=state)
            else:
                result = drive(static_route(model, state, opts, callback=callback), saver.on(state))
    except ConvergenceError as exc:
        error, result = exc, exc.result
        if result is None:
            raise
    starts = None
    if other is not None and error is None:
        result, starts = keep_lower(scene, model, opts, result, other, _measures(scene, model, extras),
                                    wall=result.wall_time)
    summary = static_summary(scene, model, extras, result, build_time)
    if starts is not None:
        summary["starts"] = starts
    if model.bending_friction is not None and state is not None:  # bending hysteresis: what the route dissipated
        summary["bending_hysteresis"] = hysteresis_summary(scene, model, state, result.U)
    if model.shear_friction is not None and state is not None:
        summary["shear_hysteresis"] = shear_hysteresis_summary(scene, model, state, result.U)
    if model.bending_softening is not None:  # nonlinear bending: how far the drape went along its law
        summary["nonlinear_bending"] = softening_summary(scene, model, result.U)
    if seeds > 1 and error is None and isinstance(summary.get("drape"), dict):
        summary["seeds"] = seeded_specimens(scene, model, extras, opts, summary["drape"], seeds,
                                            first_energy=summary["energies"].get("total"), compare=other)
        if starts is not None:
            summary["seeds"]["specimens"][0]["start"] = starts["kept"]
    summary["checkpoint"] = {"file": CHECKPOINT if saver.writes or resumed else None, "writes": saver.writes,
                             "write_time_s": saver.write_time, "resumed_from": resumed}
    write_outputs(scene, model, extras, result.U, out, summary, figures=figures)
    if error is not None:
        raise error
    remove_levels(out)
    return RunResult(to_jsonable(summary), model, result.U, extras, out, slip=None if state is None else state.slip)


def _measures(scene, model, extras):
    """``U -> dict``: a drape's DC and fold count for the compared starts' table (empty without a drape)."""
    def measures(U):
        if model.contact is None and extras.get("disc") is None:
            return {}
        d = drape_summary(scene, model, extras, U)
        return {k: d.get(k) for k in ("drape_coefficient_percent", "fold_count")}

    return measures


def hysteresis_summary(scene, model, state, U) -> dict:
    """The bending friction at the end of a solve (scene units): energy dissipated along the route (with shear
    hysteresis too: by both frictions), and the
    share of element-directions (warp, weft) whose friction moment is at its yield M0 (slipping) [-]."""
    fr = model.bending_friction
    moment = fr.moment(U, model.positions(U), model.split_slip(state.slip)[0])
    at_yield = np.abs(moment) >= fr.M0 * (1 - 1e-9)
    return {"dissipated": scene.units.from_si(state.dissipated, "energy"),
            "yielded_share_warp": float(at_yield[:, 0].mean()), "yielded_share_weft": float(at_yield[:, 1].mean())}


def shear_hysteresis_summary(scene, model, state, U) -> dict:
    """The shear friction at the end of a solve (:mod:`rftstatic.element.shear_friction`, scene units): energy
    dissipated along the route by both frictions (one total), the share of elements whose friction shear force is at
    its yield tau0 (slipping; the threshold tau_0(gamma) of its shear angle with 2HG5) and the largest shear angle
    [deg]."""
    fr = model.shear_friction
    tau = fr.force(U, model.split_slip(state.slip)[1])
    yield_ = fr.tau0 if fr.tau5 is None else fr.threshold(fr.shear_angle(U))
    return {"dissipated_both_frictions": scene.units.from_si(state.dissipated, "energy"),
            "yielded_share": float((np.abs(tau) >= yield_ * (1 - 1e-9)).mean()),
            "max_shear_angle_deg": float(np.degrees(np.abs(fr.shear_angle(U)).max()))}


def softening_summary(scene, model, U) -> dict:
    """Nonlinear bending at the end of a solve (:mod:`rftstatic.element.nonlinear_bending`): per direction the
    share of elements past the floor curvature kappa_f (on the floor branch, slope phi B) [-], the largest
    |kappa_m| [1/length, scene units] and its ratio to kappa_f [-]."""
    term = model.bending_softening
    x = model.positions(U)
    k = np.abs(term.curvature(model.bending_displacement(U), x)[:, :2])
    kf = term.kappa_floor
    out = {}
    for i, d in enumerate(("warp", "weft")):
        out[f"floor_share_{d}"] = float((k[:, i] > kf[i]).mean())
        out[f"max_curvature_{d}"] = float(k[:, i].max()) * scene.units.length
        out[f"max_over_floor_curvature_{d}"] = float(k[:, i].max() / kf[i]) if np.isfinite(kf[i]) else 0.0
    return out


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue the static solve of ``scene`` from ``out_dir/checkpoint.npz`` (``case NAME --resume``)."""
    return run(scene, Path(out_dir), progress=progress, figures=figures, resume=True).summary


def static_summary(scene, model, extras, result, build_time) -> dict:
    """The summary (scene units) of a :class:`~rftstatic.solvers.newton.StaticResult` of ``model``."""
    u = scene.units
    U = result.U
    summary = summary_header(scene, model, "static")
    summary.update({
        "linear_solver": result.linear_solver,
        "converged": bool(result.converged),
        "message": result.message,
        "load_factor": result.lam,
        "load_steps": len(result.load_steps),
        "newton_iterations": result.iterations,
        "cutbacks": result.cutbacks,
        "factorisations": result.factorisations,
        "iteration_retries": result.retries,
        "solver_path": [{"lam": s["lam"], "iterations": s["iterations"], "scheme": s.get("scheme", "")}
                        for s in result.load_steps],
        "tangent_modes": result.tangent_modes,
        "route": result.route,
        "path": result.path,
        "levels": result.levels,
        "relax": result.relax,
        "stable_minimum": result.stable,
        "self_contact_stiffenings": result.self_contact_stiffenings,
        "perturbation_seed": result.seed,
        "residual": result.residual / u.force,
        "wall_time_s": result.wall_time,
        "build_time_s": build_time,
        "energies": {k: v / u.energy for k, v in result.energies.items()},
        "probes": probe_summary(scene, model, extras["probes"], U),
        "max_relative_curvature": float(model.relative_curvature(U).max()),
        "self_intersections": self_intersection_summary(scene, model, U),
    })
    if (crossings := obstacle_crossing_summary(scene, model, extras, U)) is not None:
        summary["obstacle_crossings"] = crossings
    if model.self_contact is not None:
        summary["self_contact"] = self_contact_summary(scene, model, scale=result.self_contact_scale)
    warn_crossings(summary, self_contact=model.self_contact is not None)
    if model.contact is not None:
        x = model.positions(U)
        summary["max_penetration"] = model.contact.max_penetration(x) / u.length
        summary["contact_nodes"] = int(model.contact.active(x).sum())
    if model.contact is not None or extras.get("disc") is not None:
        summary["drape"] = drape_summary(scene, model, extras, U)
    return summary

