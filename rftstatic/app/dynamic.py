"""Run a dynamic scene (``analysis = "dynamic"`` or ``"relax"``) and write what users look at.

``dynamic``: the explicit central-difference motion of Sze & Zhou (2016) §2.4 (Eq. 16-22) with the
mass damping ``alpha M v`` of Eq. 27 (opposing the motion), as in their §4.6 (Figs. 12-13: sheets
hung at two adjacent corners, alpha = 5/s, falling from flat at t = 0). ``relax``: the same motion
with mass scaling (§6, default s = 100), stopped when the sheet is at rest (kinetic energy below
``rest_tolerance`` of its peak and out-of-balance force below ``force_tolerance`` of the load); with
``compare_static = true`` the resting state is compared with the static Newton solution.

Obstacles act kinematically (§6.3): the penalty contact (and, for true dynamics, the in-plane holds) that
:func:`rftstatic.scenes.build.build_model` adds for the static solver are dropped for these runs.

Outputs in the run folder, every number in the scene's units:

* ``frame_t<time>_{iso,side}.png`` at the scene's ``frames`` times;
* ``series/state_<k>.vtu`` (the frames and ``samples`` regular states) indexed by ``series.pvd``;
* ``animation.gif`` (the sampled states, isometric view), ``energy.png`` (kinetic and potential
  energy against time), ``view.html`` (:mod:`rftstatic.io.viewer`: the saved states in 3-D, with a slider);
* ``summary.json`` (written once, at the end): counts, step, its estimate and why it was chosen (``dt_reason``,
  :func:`~rftstatic.solvers.step_plan.plan_steps`), steps, wall time, element-steps per second, probe
  trajectories (t, x, y, z), time at rest and the at-rest test's criterion and tolerances (``rest_test``:
  ``at_rest`` of a relax run is the kinetic energy and the force, ``time_at_rest`` and a dynamic run's
  ``at_rest`` the kinetic energy alone, :class:`~rftstatic.solvers.rest.RestCriterion`), energies, flags,
  the self-intersection check of the final state and of every saved state
  (:func:`rftstatic.io.summary.self_intersection_summary`) and, for a triangle-surface obstacle, the final
  state's sheet/obstacle crossing check (:func:`rftstatic.io.summary.obstacle_crossing_summary`), and with
  moving supports their mean reaction (``drive``, :func:`rftstatic.scenes.drive.drive_summary`);
* ``checkpoint.npz`` every ``checkpoint_every`` of simulated time (default 0.2 s); ``--resume``
  continues from it and reproduces the uninterrupted run bitwise (:mod:`rftstatic.solvers.checkpoint`).

All files are written atomically (:mod:`rftstatic.io.files`), so an interrupted run leaves no partial file.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from rftstatic.app.result import RunResult
from rftstatic.errors import CheckpointError, StepLimitError
from rftstatic.io.files import to_jsonable, write_json, write_pvd, write_vtu
from rftstatic.io.results import run_label, write_run_view
from rftstatic.io.summary import (obstacle_crossing_summary, self_contact_summary, self_intersection_summary,
                                  summary_header)
from rftstatic.post.probes import probe_interpolation
from rftstatic.scenes.build import build_model
from rftstatic.scenes.drive import drive_summary
from rftstatic.scenes.friction import contact_friction
from rftstatic.scenes.options import contact_options, dynamics_options, static_options
from rftstatic.model.state import State
from rftstatic.solvers.checkpoint import CheckpointSaver, explicit_header, load_explicit_state
from rftstatic.solvers.drive import drive
from rftstatic.solvers.explicit import EXPLICIT, explicit_steps
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.rest import AtRest, RestCriterion
from rftstatic.solvers.static import compare_with_static, solve_static
from rftstatic.solvers.step_plan import STEPS_PER_SIDE_NODE, default_max_steps, plan_steps

log = logging.getLogger(__name__)

CHECKPOINT = "checkpoint.npz"


MIN_DT_SHARE = 1e-9
"""Smallest ``dynamics.dt`` as a share of the stable step estimate: below it a step moves the sheet by
round-off only (at dt = 5e-324 s the velocity update underflowed to zero and the rest test saw a sheet at
rest), and an explicit run could not reach any time of interest within the step limit."""


def checkpoint_steps(every: float, dt: float) -> int:
    """Explicit steps between checkpoints: ``every`` [s] of simulated time at step ``dt`` [s], at least 1
    (a subnormal ``dt`` makes the ratio overflow: then every 10^12 steps, i.e. only at the end)."""
    ratio = every / dt
    return max(1, int(round(min(ratio, 1e12)))) if np.isfinite(ratio) else 10**12


def run(scene, out: Path, *, progress=True, figures=True, resume=False) -> RunResult:
    """Build ``scene``'s model (obstacles acting kinematically) and run it (:func:`run_dynamic_scene`)."""
    model, extras = build_model(scene)
    summary, explicit = _run(scene, model, extras, out, progress=progress, figures=figures, resume=resume)
    return RunResult(summary, model, explicit.U, extras, out, slip=explicit.state.slip)


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue the dynamic run of ``scene`` from ``out_dir/checkpoint.npz`` (``case NAME --resume``)."""
    if scene.analysis == "static":
        raise scene.error("analysis", "--resume continues a dynamic or relax run; this scene is static")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return run(scene, out, progress=progress, figures=figures, resume=True).summary


def run_dynamic_scene(scene, model, extras, out, *, progress=True, figures=True, resume=False,
                      callback=None, backend="auto", U0=None, slip=None) -> dict:
    """:func:`_run`, returning only the summary."""
    return _run(scene, model, extras, out, progress=progress, figures=figures, resume=resume, callback=callback,
                backend=backend, U0=U0, slip=slip)[0]


def _run(scene, model, extras, out, *, progress=True, figures=True, resume=False, callback=None, backend="auto",
         U0=None, slip=None):
    """Run a ``dynamic`` or ``relax`` scene and write its outputs into ``out`` (module docstring).

    Parameters
    ----------
    scene : validated :class:`rftstatic.scenes.schema.Scene`
    model, extras : from :func:`rftstatic.scenes.build.build_model` (extras: obstacles, probes [m])
    out : output folder
    resume : continue from ``out/checkpoint.npz`` (a fresh run, logged, when there is none)
    callback : extra ``callback(state, sample)`` at every history sample; returning True stops the run
    backend : force back end of :func:`rftstatic.solvers.explicit.run_explicit`
    U0 : (N, 3) displacements [m] the run starts from at rest (None: the reference), e.g. a drape's equilibrium
    slip : the frictions' committed slips (E, k) at ``U0`` (bending 2HB, shear 2HG; that drape's
        :attr:`~rftstatic.app.result.RunResult.slip`): the run goes on from them (None: the virgin fabric, right
        for a sheet put in the shape ``U0`` but not for one that reached it along a route)

    Returns
    -------
    The summary as written to ``summary.json`` (plain Python types, scene units) and the
    :class:`~rftstatic.solvers.explicit.ExplicitResult`.
    """

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    analysis = scene.analysis
    o = dynamics_options(scene)
    # obstacles act kinematically, unless one moves (rftstatic.scenes.motion): then all act by the model's penalty
    obstacles = tuple(extras.get("obstacles", ())) if model.contact is None else ()
    friction = contact_friction(scene, contact_options(scene), len(obstacles), model.mesh) if obstacles else None
    names, pnodes, pw = probe_interpolation(model.mesh, extras.get("probes", {}))
    t_end = o.t_end
    regular = np.linspace(0.0, t_end, o.samples + 1) if o.samples else np.zeros(0)
    save_times = np.unique(np.concatenate([o.frames, regular]))

    free_load = float(np.linalg.norm(np.where(model.free, model.load, 0.0)))
    rest = AtRest(RestCriterion(o.rest_tolerance, o.force_tolerance), load_norm=free_load)

    def watch(state, rec):
        at_rest = rest(state, rec)  # tracks the peak kinetic energy at every sample
        stop = callback(state, rec) if callback is not None else False
        return bool(stop or (analysis == "relax" and at_rest))

    limit = o.step_limit(model.mesh.n_nodes)
    ckpt_path = out / CHECKPOINT
    for stale in out.glob(CHECKPOINT + ".*.tmp"):  # a checkpoint write cut short by a kill
        stale.unlink(missing_ok=True)
    wall0 = time.perf_counter()
    resumed_from = None
    if resume and ckpt_path.exists():
        try:
            state, options, frame_times, probe_nodes = load_explicit_state(ckpt_path, model, obstacles,
                                                                           progress=progress)
        except CheckpointError as exc:
            raise scene.error("--resume", f"{exc}") from None
        data = state.route[EXPLICIT]
        saved = data["options"]
        horizon = _plan(scene, model, o, float(data["dt"]), check_dt=False).t_end
        for key, want in (("t_end", horizon), ("alpha", o.alpha), ("mass_scale", o.mass_scale)):
            if not np.isclose(float(saved[key]), want, rtol=1e-12, atol=0.0):
                raise scene.error(f"dynamics.{key}", f"the checkpoint {ckpt_path} was written with {key} = "
                                  f"{float(saved[key]):g} (SI), the scene asks {want:g}; run without --resume")
        if not np.array_equal(np.asarray(saved["frame_times"], float), save_times):
            raise scene.error("dynamics.frames", f"the checkpoint {ckpt_path} saved other frame times; run "
                              "without --resume")
        rest.resume_from(data["history"])
        every = checkpoint_steps(o.checkpoint_every, data["dt"])
        resumed_from, reason = state.t, "the step of the checkpoint's run"
        route = explicit_steps(model, state, options, obstacles=obstacles, frame_times=frame_times, probes=probe_nodes,
                               callback=watch, friction=friction)
    else:
        if resume:
            log.warning("no checkpoint %s: starting the run from t = 0", ckpt_path)
        plan = _plan(scene, model, o, o.dt, check_dt=True)
        if o.dt is not None and o.dt < MIN_DT_SHARE * plan.estimate.dt:
            # the velocity update dt M^-1 (P - F) would lose the force to round-off
            raise scene.error("dynamics.dt", f"{o.dt / scene.units.time:.4g} is below {MIN_DT_SHARE:g} of the stable "
                              f"step estimate {plan.estimate.dt / scene.units.time:.4g} (scene time units): the steps "
                              "would not move the sheet; give a dt near the estimate or leave dynamics.dt out")
        every = checkpoint_steps(o.checkpoint_every, plan.dt)
        options = ExplicitOptions(t_end=plan.t_end, dt=plan.dt, alpha=o.alpha, mass_scale=o.mass_scale,
                                  rest_tol=o.rest_tolerance, backend=backend, max_steps=limit,
                                  max_steps_name=_limit_name(o, model.mesh.n_nodes), progress=progress)
        state = State.initial(model, U0)
        if slip is not None and state.slip is not None:  # the friction's history goes on (the at-rest test too)
            if np.shape(slip) != state.slip.shape:
                raise ValueError(f"slip must have the shape {state.slip.shape} of the model's frictions, got "
                                 f"{np.shape(slip)}")
            state.slip = np.array(slip, dtype=float)
        route = explicit_steps(model, state, options, obstacles=obstacles, frame_times=save_times,
                               probes=pnodes.ravel(), callback=watch, plan=plan, friction=friction)
        reason = plan.reason
    saver = CheckpointSaver(ckpt_path, explicit_header(model, obstacles), every_steps=every, run=f"the {analysis} run")
    with saver.stopping():
        run = drive(route, saver.on(state))
    wall = time.perf_counter() - wall0

    summary = _summary(scene, model, analysis, o, run, names, pnodes, pw, wall, resumed_from)
    summary["max_steps"] = limit
    poses = run.state.obstacle_poses if run.state is not None else None  # a moved body: checked in its pose
    if (crossings := obstacle_crossing_summary(scene, model, extras, run.U, poses=poses)) is not None:
        summary["obstacle_crossings"] = crossings
    summary["dt_reason"] = reason
    if (dragged := drive_summary(scene, model, run, friction)) is not None:
        summary["drive"] = dragged
    reading = RestCriterion(o.rest_tolerance).record()  # time_at_rest: the kinetic energy alone
    summary["rest_test"] = {"at_rest": rest.criterion.record() if analysis == "relax" else reading,
                            "time_at_rest": reading}
    if analysis == "relax":
        summary["converged"] = summary["at_rest"] = bool(run.stopped)
        summary["stopped_by"] = "rest" if run.stopped else "t_end" if run.t >= t_end * (1 - 1e-9) else "max_steps"
        if o.compare_static:
            summary["static_comparison"] = _compare_static(scene, run.U)
    _write(scene, model, out, run, summary, o, save_times, figures=figures)
    return to_jsonable(summary), run


def _limit_name(o, n_nodes) -> str:
    """How the step limit came about, for the messages."""
    if o.max_steps is not None:
        return "dynamics.max_steps"
    return (f"dynamics.max_steps, by default {STEPS_PER_SIDE_NODE:,} x sqrt(nodes) = {default_max_steps(n_nodes)} "
            f"for {n_nodes} nodes")


def _plan(scene, model, o, dt, *, check_dt):
    """The :class:`~rftstatic.solvers.step_plan.StepPlan` of the scene's run with step ``dt`` [s] (None: the stable
    step): to ``t_end``; for a relaxation whose ``t_end`` lies more than the step limit away, to the time of those
    steps (it stops there, not at rest: exit status 3). A dynamic run that needs more steps, or a step that is not
    a positive finite number, is a scene error naming the key to change."""
    try:
        return plan_steps(model, t_end=o.t_end, dt=dt, alpha=o.alpha, mass_scale=o.mass_scale,
                          max_steps=o.step_limit(model.mesh.n_nodes), limit_name=_limit_name(o, model.mesh.n_nodes),
                          check_dt=check_dt, stop_at_limit=scene.analysis == "relax")
    except StepLimitError as exc:
        raise scene.error("dynamics.dt" if scene.get("dynamics.dt") is not None else "dynamics.t_end",
                          str(exc)) from None


def _summary(scene, model, analysis, o, run, names, pnodes, pw, wall, resumed_from) -> dict:
    u = scene.units
    h = run.history
    est = run.estimate
    X3 = model.X3
    # probe trajectories: barycentric interpolation of the recorded node displacements
    rec = run.probes.reshape(len(h["time"]), len(names), 3, 3)  # (S, P, a, i)
    ref = np.einsum("pa,pai->pi", pw, X3[pnodes]) if names else np.zeros((0, 3))
    traj = ref[None] + np.einsum("pa,spai->spi", pw, rec)
    t_scene = h["time"] / u.time
    probes = {name: {"reference": ref[k] / u.length, "time": t_scene, "x": traj[:, k, 0] / u.length,
                     "y": traj[:, k, 1] / u.length, "z": traj[:, k, 2] / u.length,
                     "final": traj[-1, k] / u.length} for k, name in enumerate(names)}
    energy = lambda v: float(v) / u.energy  # noqa: E731
    final = {k: energy(h[k][-1]) for k in ("kinetic", "potential", "strain", "external_work", "dissipated",
                                           "contact_loss", "total")}
    t_rest = run.time_at_rest
    summary = summary_header(scene, model, analysis)
    summary.update({
        "t_end": o.t_end / u.time, "t": run.t / u.time,
        "alpha": o.alpha * u.time, "mass_scale": o.mass_scale,
        "dt": run.dt / u.time,
        "dt_estimate": None if est is None else {"dt": est.dt / u.time, "dt_crit": est.dt_crit / u.time,
                                                 "omega_max": est.omega_max * u.time, "method": est.method,
                                                 "safety": est.safety},
        "steps": run.steps,
        "wall_time_s": wall,
        "element_steps_per_second": model.mesh.n_elements * run.steps / max(wall, 1e-12),
        "loop_element_steps_per_second": run.element_steps_per_second,
        "resumed_from_t": None if resumed_from is None else resumed_from / u.time,
        "time_at_rest": None if t_rest is None else t_rest / u.time,
        "rest_tolerance": o.rest_tolerance,
        "at_rest": t_rest is not None,
        # a dynamic run has nothing to converge to: "converged" means the integration reached t_end
        # with a finite state (relax: overwritten with "at rest", below)
        "finite": bool(run.steps > 0 and np.isfinite(h["total"]).all()),
        "completed": bool(run.t >= o.t_end * (1 - 1e-9)),
        "converged": bool(run.steps > 0 and np.isfinite(h["total"]).all() and run.t >= o.t_end * (1 - 1e-9)),
        "stopped_early": bool(run.stopped),
        "energies": {"final": final, "peak_kinetic": energy(h["kinetic"].max()),
                     "energy_drift": energy(h["total"][-1] - h["total"][0])},
        "residual": float(h["residual"][-1]) / u.force,
        "probes": probes,
    })
    if run.contact_nodes:
        summary["contact_nodes"] = run.contact_nodes
    summary["self_intersections"] = self_intersection_summary(scene, model, run.U, states=run.frames)
    if getattr(model, "self_contact", None) is not None:
        summary["self_contact"] = self_contact_summary(scene, model)
    return summary


def _compare_static(scene, U) -> dict:
    """The relaxed state ``U`` [m] against the static Newton solution of the scene (penalty contact)."""
    model, _ = build_model(scene, contact="penalty")
    res = solve_static(model, options=static_options(scene, progress=False))
    cmp = compare_with_static(model, U, res.U)
    u = scene.units.length
    return {"max_difference": cmp["max_difference"] / u, "max_displacement": cmp["max_displacement"] / u,
            "relative": cmp["relative"], "static_converged": bool(res.converged)}


def _tag(t: float) -> str:
    return f"{t:.4f}".rstrip("0").rstrip(".") if t else "0"


def _write(scene, model, out: Path, run, summary, o, save_times, *, figures=True) -> None:

    u = scene.units
    tri = model.mesh.tri
    X3 = model.X3
    frames = run.frames  # (t [s], U [m]) at save_times (up to where the run stopped)
    series = []
    if scene.get("output.vtu", True):
        (out / "series").mkdir(exist_ok=True)
        for k, (t, U) in enumerate(frames):
            name = f"series/state_{k:04d}.vtu"
            cell = {"relative_curvature": model.relative_curvature(U), "membrane_strain": model.membrane_strain(U)}
            write_vtu(out / name, X3, U, tri, length_unit_scale=u.length, cell_data=cell)
            series.append((t / u.time, name))
        write_pvd(out / "series.pvd", series)
        summary["vtu_series"] = {"pvd": "series.pvd", "states": len(series)}
    requested = o.frames
    idx = np.searchsorted(save_times, requested)
    summary["frames"] = [{"time": float(tr / u.time), "state_time": float(frames[i][0] / u.time)}
                         for tr, i in zip(requested, idx) if i < len(frames)]
    try:
        if figures:
            _figures(scene, model, out, run, summary, o, save_times, idx)
            if series:  # view.html: a slider over the saved states
                write_run_view(out, summary)
    finally:  # written once, with the figures drawn so far (a plot that fails leaves the numbers written)
        write_json(out / "summary.json", summary)


def _figures(scene, model, out: Path, run, summary, o, save_times, idx) -> None:
    """The PNG frames, the GIF and the energy plot; their files are entered in ``summary``."""
    u = scene.units
    tri = model.mesh.tri
    X3 = model.X3
    frames = run.frames
    from rftstatic.io.animation import animate
    from rftstatic.io.charts import plot_history
    from rftstatic.io.solids import run_solids
    from rftstatic.io.views import plot_views

    lu = {"cm-gf-s": "cm", "mm-N-s": "mm", "SI": "m"}.get(u.name, "")
    short = f"{scene.name} ({run_label(model)})"
    views = [v for v in scene.get("output.views", ["iso", "side"]) if v in ("iso", "side", "top")]
    shown = [(X3 + frames[i][1]) / u.length for i in idx[: len(summary["frames"])]]
    # a moving obstacle (rftstatic.contact.motion) is not drawn: one pose would be wrong in the other frames
    moving = getattr(model.contact, "motion", None) is not None
    solids = run_solids(scene.data, X3 / u.length, np.concatenate(shown)) if shown and not moving else []
    for entry, i in zip(summary["frames"], idx):
        t, U = frames[i]
        files = plot_views(str(out / f"frame_t{_tag(entry['time'])}"), (X3 + U) / u.length, tri, views=views,
                           title=f"{short}: t = {entry['time']:g} s", length_unit=lu, solids=solids)
        entry["files"] = {v: p.name for v, p in files.items()}
    reg = np.linspace(0.0, o.t_end, o.samples + 1) if o.samples else save_times
    pick = sorted(set(np.searchsorted(save_times, reg).tolist()) & set(range(len(frames))))
    if pick:
        animate(out / "animation.gif", [(X3 + frames[i][1]) / u.length for i in pick], tri,
                times=[frames[i][0] / u.time for i in pick], view="iso", fps=12, title=scene.name,
                length_unit=lu, solids=solids)
        summary["animation"] = {"file": "animation.gif", "frames": len(pick)}
    h = run.history
    plot_history(out / "energy.png", h["time"] / u.time,
                 {"kinetic": h["kinetic"] / u.energy, "potential (stored - P.D)": h["potential"] / u.energy,
                  "dissipated (damping, frictions)": h["dissipated"] / u.energy},
                 xlabel="time [s]", ylabel=f"energy [{u.name.split('-')[1] if '-' in u.name else 'J'}"
                 f"{' ' + lu if lu else ''}]", title=f"{scene.name}: energies (alpha = {o.alpha * u.time:g} /s)")
    summary["energy_plot"] = "energy.png"
