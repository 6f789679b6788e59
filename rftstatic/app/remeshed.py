"""Run a scene with a ``[remesh]`` table: global adaptive remeshing (Sze & Zhou 2016, §5.2 and §6).

``analysis = "static"``
    :func:`rftstatic.remesh.static_driver.remesh_static`: Newton solve, size a new mesh from the converged
    curvature by Eq. 28-29 (|kappa| h_new^2 = const, h clipped to [h_lower, h_upper]), transfer U,
    solve again, until the node count changes by less than ``tol`` (and max |kappa| h <= ``kappa_h_max``
    when the scene sets it).
``analysis = "relax"`` (§6, Figs. 14-16)
    :func:`rftstatic.remesh.relax_driver.remesh_relax`: the damped explicit motion (Eq. 16-22, damping Eq. 27
    with ``[dynamics] alpha``) with the mass scaled by ``[dynamics] mass_scale`` (§6: 100; the weight
    is not scaled), remeshed every ``every`` steps or when max |kappa| h^2 > ``kappa_h2_max``, U and V
    transferred, until the sheet rests on a mesh that no longer changes, or ``[dynamics] t_end``.
    Obstacles act kinematically (§6.3): the static solver's penalty contact is dropped.

Outputs in the run folder, every number in the scene's units:

* ``summary.json``: scene, element, route, final node and triangle counts, converged flag, wall
  time, the ``[remesh]`` settings, one record per mesh (cycle, time and step, reason, node and
  triangle counts, mesher quality, largest |kappa| h and |kappa| h^2, node-count change, wall time),
  the drape measures of the final state (:func:`rftstatic.io.summary.drape_summary`), its self-intersection
  check (:func:`rftstatic.io.summary.self_intersection_summary`), the probes and, with bending or shear hysteresis,
  what the frictions dissipated over all the meshes (their slips carried at every remesh,
  :func:`rftstatic.remesh.adapt.carry_slip`) and the share slipping on the last;
* ``mesh_<k>_{top,iso}.png``: the deformed sheet with its mesh edges at each successive mesh
  (relax: the transferred state just after remesh k; static: the equilibrium on mesh k is only
  known for the last mesh, so the earlier ones are drawn flat in the top view), ``remesh.gif``
  (the isometric frames), ``nodes.png`` (node count against time or cycle);
* ``deformed.vtu`` and ``view_{side,top,iso}.png`` of the final state (:func:`rftstatic.io.results.write_outputs`);
* ``meshes/mesh_<k>.vtu`` indexed by ``meshes.pvd`` (each mesh's state, as the PNGs draw it) and ``view.html``
  (:mod:`rftstatic.io.viewer`, a slider over the meshes);
* ``checkpoint.npz`` (:mod:`rftstatic.remesh.checkpoint`): after every solved cycle (static), after every
  remesh, at most every 10 s between remeshes and at the end (relax); ``--resume`` (:func:`resume_scene`)
  continues from it to the meshes and state of the uninterrupted run.
"""

from __future__ import annotations

import logging
import math
import time
from pathlib import Path

import numpy as np

from rftstatic.app.result import RunResult
from rftstatic.contact.kinematic import contact_reaction_residual
from rftstatic.errors import CheckpointError, InstabilityError, ParameterError
from rftstatic.io.files import to_jsonable
from rftstatic.io.results import write_mesh_series, write_outputs
from rftstatic.io.summary import (drape_summary, obstacle_crossing_summary, probe_summary, self_contact_summary,
                                  self_intersection_summary, summary_header, warn_crossings)
from rftstatic.optionspec import scene_values
from rftstatic.remesh.adapt import RemeshRecord, _curvature_figures, refinable_maxima
from rftstatic.model.state import State
from rftstatic.remesh.checkpoint import FIX, REMESH_RELAX, REMESH_STATIC, load_remesh_state, remesh_saver, where
from rftstatic.remesh.options import RemeshRelaxOptions
from rftstatic.remesh.relax_driver import explicit_advance, remesh_relax_route
from rftstatic.remesh.static_driver import remesh_static_route
from rftstatic.solvers.drive import drive
from rftstatic.scenes.build import MAX_MESH_NODES, build_model
from rftstatic.scenes.options import dynamics_options, remesh_options, static_options
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.static_checkpoint import CHECKPOINT_SECONDS, remove_stale
from rftstatic.solvers.step_plan import plan_steps

log = logging.getLogger(__name__)

__all__ = ["run", "resume_scene", "run_remesh_scene", "solve_remesh_scene", "summarize", "checkpoint_header"]

CHECKPOINT = "checkpoint.npz"

TRACK = "remesh-track"
"""The key in ``State.route`` of the remeshed relaxation's tracker (:meth:`_Tracker.position`)."""

SAFETY = 0.5
"""Safety factor on the critical explicit step of the remeshed relaxation (a new mesh starts moving)."""


class _TimeUp(Exception):
    """Raised by the stepper when the simulated time reaches ``[dynamics] t_end``."""


class _Tracker:
    """Wraps the explicit stepper: snapshots each new mesh (mesh, model, U, t, steps) and stops at t_end (the
    stepper takes ``max_time``: its last chunk ends there)."""

    def __init__(self, advance, t_end):
        self.advance, self.t_end = advance, t_end
        self.t, self.steps, self.meshes, self.last = 0.0, 0, [], None
        self._rebind = False

    def position(self) -> dict:
        """What a checkpoint keeps (``State.route[TRACK]``): time, steps, the snapshots' times, steps and U, and the
        stepper's damping history and step."""
        return {"t": self.t, "steps": self.steps, "snap_t": [m["t"] for m in self.meshes],
                "snap_step": [m["step"] for m in self.meshes], "snap_U": [m["U"] for m in self.meshes],
                **self.advance.state()}

    def restore(self, fields: dict, meshes: list) -> None:
        """Continue from :meth:`position` of a run whose driver had made ``meshes``."""
        self.t, self.steps = float(fields["t"]), int(fields["steps"])
        self.meshes = [{"mesh": meshes[k], "model": None, "U": np.array(U), "t": t, "step": step}
                       for k, (t, step, U) in enumerate(zip(fields["snap_t"], fields["snap_step"], fields["snap_U"]))]
        self._rebind = len(self.meshes) == len(meshes)  # the next call is on the last snapshot's mesh
        self.advance.restore(fields, same_mesh=self._rebind)

    def __call__(self, model, U, V, n, **history):
        """The stepper's chunk (``history``: the frictions' ``slip``, passed on; its returns, passed back)."""
        if self._rebind:
            self.meshes[-1]["model"], self._rebind = model, False
        if not self.meshes or self.meshes[-1]["model"] is not model:
            self.meshes.append({"mesh": model.mesh, "model": model, "U": U.copy(), "t": self.t, "step": self.steps})
        if self.t >= self.t_end * (1 - 1e-12):
            self.last = (model, U, V)
            raise _TimeUp
        # the last chunk ends at t_end itself (its last step shortened), not a chunk beyond it
        out = self.advance(model, U, V, n, max_time=self.t_end - self.t, **history)
        U, V, dt = out[:3]
        self.t += float(dt)
        self.steps += getattr(self.advance, "last_steps", n)
        self.last = (model, U, V)
        return out


def run(scene, out: Path, *, progress=True, figures=True, resume=False,
        checkpoint_seconds: float = CHECKPOINT_SECONDS) -> RunResult:
    """Run a scene that has a ``[remesh]`` table and write its outputs into ``out`` (module docstring).

    The run keeps ``out/checkpoint.npz`` (:mod:`rftstatic.remesh.checkpoint`): after every solved cycle of the
    static route, after every remesh of the relaxation and between remeshes at most once per
    ``checkpoint_seconds`` of wall time, and at the end. ``resume``: continue from it (a fresh run, logged, when
    there is none; a :class:`~rftstatic.errors.CheckpointError` when it is corrupt or another scene's or
    overrides').
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    opts = remesh_options(scene)
    path = out / CHECKPOINT
    remove_stale(path)  # the temporary file of a write that a kill cut short
    state, resumed = None, None
    if resume and path.exists():
        state = load_remesh_state(path, checkpoint_header(scene))
        resumed = where(state)
        log.info("resuming the remeshed run from %s (%s)", path, resumed)
    elif resume:
        log.warning("no checkpoint %s: running from the start", path)
    saver = remesh_saver(path, checkpoint_header(scene), every_seconds=checkpoint_seconds)
    with saver.stopping():
        solved = solve_remesh_scene(scene, opts, state=state, saver=saver)
    summary = summarize(scene, opts, solved)
    summary["checkpoint"] = {"file": CHECKPOINT if saver.writes or resumed else None, "writes": saver.writes,
                             "write_time_s": saver.write_time, "resumed_from": resumed}
    _write(scene, solved, out, summary, figures=figures)
    return RunResult(to_jsonable(summary), solved["model"], solved["U"], solved["extras"], out, slip=solved.get("slip"))


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue the remeshed run of ``scene`` from ``out_dir/checkpoint.npz`` (``case NAME --resume``)."""
    return run(scene, Path(out_dir), progress=progress, figures=figures, resume=True).summary


def checkpoint_header(scene) -> dict:
    """What a remeshed run's checkpoint is keyed to: the scene's name, analysis and its data after the ``--set``
    overrides (but the ``[output]`` table, which does not change the run)."""
    return {"scene": scene.name, "analysis": scene.analysis,
            "data": {k: v for k, v in scene.data.items() if k != "output"}}


def run_remesh_scene(scene, out, *, progress=True, figures=True) -> dict:
    """:func:`run` into ``out`` (created), returning the summary as written to ``summary.json``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return run(scene, out, progress=progress, figures=figures).summary


def solve_remesh_scene(scene, opts=None, *, state=None, saver=None) -> dict:
    """Run the remeshing route of ``scene``; return the final ``model``, ``U`` [m], ``extras``,
    ``records``, ``converged``, ``meshes`` (the snapshots drawn as frames) and ``wall_time_s``.

    ``state``: the run's State (a saved one, :func:`~rftstatic.remesh.checkpoint.load_remesh_state`, to continue
    from; default a new one); ``saver``: a :class:`~rftstatic.solvers.checkpoint.CheckpointSaver` given the
    route's pauses (None: none)."""
    state = State(U=np.zeros((0, 3)), V=np.zeros((0, 3))) if state is None else state
    opts = remesh_options(scene) if opts is None else opts
    analysis = scene.analysis
    t0 = time.perf_counter()
    if analysis not in ("static", "relax"):
        raise scene.error("analysis", f'"{analysis}" cannot be remeshed; use "static" or "relax" with [remesh]')
    try:
        solved = (_static if analysis == "static" else _relax)(scene, opts, state, saver)
    except ParameterError as exc:  # checked against the mesh: sizes larger than the sheet
        raise scene.error(f"remesh.{exc.key}", exc.detail) from None
    solved["wall_time_s"] = time.perf_counter() - t0
    return solved


def _static(scene, opts, state, saver) -> dict:
    def factory(mesh=None):
        model, extras = build_model(scene, mesh=mesh, quiet=mesh is not None)
        if mesh is None:
            _check_node_budget(scene, opts, model.mesh)
        return model, extras

    if REMESH_RELAX in state.route:
        raise CheckpointError(f"the checkpoint is a remeshed relaxation's, this scene's route is static; {FIX}")
    route = remesh_static_route(factory, opts, state, solver=static_options(scene, progress=False))
    res = drive(route, None if saver is None else saver.on(state))
    meshes = [{"mesh": m, "U": None, "t": 0.0, "step": 0} for m in res.meshes]
    meshes[-1]["U"] = res.result.U
    return {"route": "remesh_static", "model": res.model, "extras": res.extras, "U": res.result.U,
            "records": res.records, "converged": bool(res.converged and res.result.converged),
            "self_contact_scale": res.result.self_contact_scale, "slip": res.slip, "dissipated": res.dissipated,
            "meshes": meshes, "t": None, "steps": None, "skipped": 0}


def _relax(scene, opts, state, saver) -> dict:
    d = dynamics_options(scene)

    def factory(mesh=None):
        # a relax scene: the obstacles act kinematically; the first mesh's model warns, the others are quiet
        return build_model(scene, mesh=mesh, quiet=mesh is not None)

    model0, extras0 = factory(None)
    finest = _check_node_budget(scene, opts, model0.mesh)
    max_steps = d.step_limit(max(finest, model0.mesh.n_nodes))
    _check_step_budget(scene, d, model0, max_steps)
    obstacles = tuple(extras0.get("obstacles", ()))
    stepper = explicit_advance(alpha=d.alpha, mass_scale=d.mass_scale, dt=d.dt, safety=SAFETY,
                               obstacles=obstacles, damping=opts.damping)
    track = _Tracker(stepper, d.t_end)
    if REMESH_STATIC in state.route:
        raise CheckpointError(f"the checkpoint is a static remesh run's, this scene's route is the remeshed "
                              f"relaxation; {FIX}")
    if REMESH_RELAX in state.route:
        track.restore(state.route[TRACK], state.route[REMESH_RELAX].meshes)

    def on_pause(pause):  # the tracker's position rides along with the driver's
        state.route[TRACK] = track.position()
        saver.pause(state, pause)
    first = [(model0, extras0)]

    def make(mesh=None):  # hand the already built initial model to the driver
        return first.pop() if mesh is None and first else factory(mesh)

    def residual(model, U, slip=None):  # the pedestal carries the weight of the nodes on it
        return contact_reaction_residual(model, obstacles, U, slip=slip)

    try:
        motion = RemeshRelaxOptions(mass_scale=d.mass_scale, max_steps=max_steps,
                                    rest=RestCriterion(d.rest_tolerance, d.force_tolerance))
        route = remesh_relax_route(make, opts, state, motion, advance=track, residual=residual)
        res = drive(route, None if saver is None else on_pause)
        model, U, records, converged, skipped = res.model, res.U, res.records, res.converged, res.skipped
        history = (res.slip, res.dissipated)
        t, steps = res.t, res.steps
        stopped_by = "rest" if converged else "max_steps" if steps >= max_steps else "max_remesh"
    except FloatingPointError:  # the explicit motion blew up: a goal not reached, not a bug
        nodes = track.last[0].mesh.n_nodes if track.last else model0.mesh.n_nodes
        raise InstabilityError(f"the state became non-finite by t = {track.t:.4g} s (step {track.steps}, a mesh of "
                               f"{nodes} nodes); give a smaller dynamics.dt (or none: the stable step), or a larger "
                               "dynamics.mass_scale or alpha", t=track.t, step=track.steps, dt=d.dt,
                               suggested_dt=None) from None
    except _TimeUp:
        # the driver keeps its records to itself; rebuild them from the meshes the stepper saw
        model, U, _ = track.last
        history = (state.slip, state.dissipated)  # the route's last pause, just before this chunk
        records = []
        for k, m in enumerate(track.meshes):
            mm = m["mesh"]
            records.append(RemeshRecord(k, mm.n_nodes, mm.n_elements,
                                        dict(mm.info.get("quality", {})), time=m["t"], step=m["step"],
                                        reason="initial" if k == 0 else "remesh"))
        kappa, records[-1].max_kappa_h, records[-1].max_kappa_h2 = _curvature_figures(model, U)
        records[-1].refinable_kappa_h, records[-1].refinable_kappa_h2 = refinable_maxima(
            model.mesh, kappa, const=opts.const, h_lower=opts.h_lower)
        converged, skipped, t, steps, stopped_by = False, 0, track.t, track.steps, "t_end"
        log.warning("remesh relax: t_end = %.4g s reached before the sheet came to rest on a settled mesh",
                    d.t_end)
    U = _settle(model, obstacles, U)
    meshes = track.meshes
    meshes.append({"mesh": model.mesh, "model": model, "U": U, "t": t, "step": steps, "final": True})
    extras = extras0  # probes and obstacles are defined in reference coordinates: the same on every mesh
    return {"route": "remesh_relax", "model": model, "extras": extras, "U": U, "records": records,
            "converged": bool(converged), "meshes": meshes, "t": t, "steps": steps, "skipped": skipped,
            "slip": history[0], "dissipated": history[1],
            "dynamics": d, "alphas": list(stepper.alphas), "stopped_by": stopped_by, "max_steps": max_steps}


def _settle(model, obstacles, U):
    """The final displacements ``U (N, 3)`` [m] with every free node inside an obstacle moved onto its surface (the
    kinematic contact's projection, :func:`rftstatic.contact.kinematic.kinematic_contact`): a run that stops on a
    remesh (``t_end`` reached in the step that remeshed) ends on the transfer's interpolation, which no explicit
    step has corrected; supported dofs are kept."""
    from rftstatic.contact.kinematic import kinematic_contact

    if not obstacles:
        return U
    x = model.X3 + U
    x_new, _, n = kinematic_contact(obstacles, x, np.zeros_like(x))
    if n:
        log.info("remesh relax: %d nodes inside an obstacle after the last transfer moved onto its surface", n)
    return np.where(model.free, x_new - model.X3, U)


def _check_node_budget(scene, opts, mesh) -> float:
    """Refuse a ``remesh.h_lower`` [m in ``opts``] that would let a remeshed sheet (the area of ``mesh``) have
    more than :data:`~rftstatic.scenes.build.MAX_MESH_NODES` nodes; return the nodes it may have."""
    nodes = 2.0 / math.sqrt(3.0) * float(mesh.area.sum()) / float(opts.h_lower) / float(opts.h_lower)  # inf, no warning
    if nodes > MAX_MESH_NODES:
        u = scene.units.length
        raise scene.error("remesh.h_lower", f"{opts.h_lower / u:g} would let the remeshed sheet have up to "
                          f"{nodes:.3g} nodes, more than {MAX_MESH_NODES:,}; give a larger h_lower (scene length "
                          "units)")
    return nodes


def _check_step_budget(scene, d, model, max_steps) -> None:
    """Refuse, before it starts, a remeshed relaxation whose first mesh needs more than ``max_steps`` (the step
    limit, ``dynamics.max_steps`` or its default for the finest mesh ``remesh.h_lower`` allows) explicit steps to reach ``t_end`` (the run also stops at ``max_steps`` on the later meshes)."""
    try:
        plan_steps(model, t_end=d.t_end, dt=d.dt, alpha=d.alpha, mass_scale=d.mass_scale, safety=SAFETY,
                   max_steps=max_steps, check_dt=False)
    except ValueError as exc:
        raise scene.error("dynamics.dt" if d.dt is not None else "dynamics.t_end", f"{exc} (on the first "
                          "mesh)") from None


def summarize(scene, opts, solved) -> dict:
    """The summary (scene units) of a :func:`solve_remesh_scene` run."""
    u = scene.units
    model, U = solved["model"], solved["U"]
    records = []
    for r in solved["records"]:
        d = r.as_dict()
        d["time"] = d["time"] / u.time
        d["max_kappa_h2"] = d["max_kappa_h2"] / u.length
        d["refinable_kappa_h2"] = d["refinable_kappa_h2"] / u.length
        records.append(d)
    settings = scene_values(opts, u)
    summary = summary_header(scene, model, scene.analysis)
    summary.update({
        "route": solved["route"], "initial_nodes": records[0]["nodes"],
        "remeshes": len(records) - 1, "converged": solved["converged"], "wall_time_s": solved["wall_time_s"],
        "remesh": settings, "records": records,
        "max_relative_curvature": float(model.relative_curvature(U).max()),
        "self_intersections": self_intersection_summary(scene, model, U),
    })
    if model.self_contact is not None:  # the counters of the last mesh's model (each remesh builds its own)
        summary["self_contact"] = self_contact_summary(scene, model, scale=solved.get("self_contact_scale", 1.0))
    warn_crossings(summary, self_contact=model.self_contact is not None)
    if solved["route"] == "remesh_relax":
        d = solved["dynamics"]
        summary.update(t=solved["t"] / u.time, steps=solved["steps"], skipped_remeshes=solved["skipped"],
                       stopped_by=solved["stopped_by"], max_steps=solved["max_steps"], t_end=d.t_end / u.time,
                       alpha=d.alpha * u.time, mass_scale=d.mass_scale, damping=settings["damping"],
                       alpha_final=(solved["alphas"][-1] if solved.get("alphas") else d.alpha) * u.time)
        P = np.where(model.free, model.load, 0.0)
        r = np.where(model.free, contact_reaction_residual(model, solved["extras"].get("obstacles", ()), U,
                                                           slip=solved.get("slip")), 0.0)
        summary["residual_relative"] = float(np.linalg.norm(r) / max(np.linalg.norm(P), 1e-300))
        summary["rest_test"] = RestCriterion(d.rest_tolerance, d.force_tolerance).record()
    else:
        summary["newton_iterations"] = int(solved["records"][-1].solve.get("iterations", 0))
    if solved["extras"].get("obstacles"):
        summary["drape"] = drape_summary(scene, model, solved["extras"], U)
    _friction_summaries(scene, model, solved, summary)
    if (crossings := obstacle_crossing_summary(scene, model, solved["extras"], U)) is not None:
        summary["obstacle_crossings"] = crossings
    summary["probes"] = probe_summary(scene, model, solved["extras"].get("probes", {}), U)
    return summary


def _friction_summaries(scene, model, solved, summary: dict) -> None:
    """With bending or shear hysteresis, the frictions at the end of the run (the static route's summaries,
    :func:`rftstatic.app.static.hysteresis_summary`): energy dissipated along the run, over all its meshes [scene
    units], and the share of the final mesh's elements slipping."""
    if solved.get("slip") is None:
        return
    from rftstatic.app.static import hysteresis_summary, shear_hysteresis_summary

    U = solved["U"]
    state = State(U=U, V=np.zeros_like(U), slip=solved["slip"], dissipated=float(solved["dissipated"]))
    if model.bending_friction is not None:
        summary["bending_hysteresis"] = hysteresis_summary(scene, model, state, U)
    if model.shear_friction is not None:
        summary["shear_hysteresis"] = shear_hysteresis_summary(scene, model, state, U)


def _write(scene, solved, out: Path, summary: dict, *, figures=True) -> None:
    """The frames and node-count plot (with figures), then the final state and ``summary.json`` (once)."""
    if figures:
        summary["frames"] = _frames(scene, solved, out)
        _node_plot(scene, summary, out)
        summary["node_plot"] = "nodes.png"
    write_mesh_series(scene, solved["meshes"], out)  # meshes.pvd: the viewer's slider over the meshes
    write_outputs(scene, solved["model"], solved["extras"], solved["U"], out, summary, figures=figures)


def _frames(scene, run, out: Path) -> list:
    """``mesh_<k>_{top,iso}.png`` per mesh (edges drawn) and their GIF ``remesh.gif``."""
    from rftstatic.io.solids import run_solids
    from rftstatic.io.views import plot_views

    u = scene.units
    lu = {"cm-gf-s": "cm", "mm-N-s": "mm", "SI": "m"}.get(u.name, "")
    frames, lo, hi = [], None, None
    states = []
    for k, m in enumerate(run["meshes"]):
        mesh = m["mesh"]
        U = m["U"] if m["U"] is not None else np.zeros_like(mesh.X3)
        x = (mesh.X3 + U) / u.length
        states.append((k, m, mesh, x))
        lo = x.min(axis=0) if lo is None else np.minimum(lo, x.min(axis=0))
        hi = x.max(axis=0) if hi is None else np.maximum(hi, x.max(axis=0))
    solids = run_solids(scene.data, states[0][2].X3 / u.length, np.concatenate([x for *_, x in states]))
    for k, m, mesh, x in states:
        label = "final" if m.get("final") else f"mesh {k}"
        when = (f"t = {m['t'] / u.time:.3g} s" if run["route"] == "remesh_relax" else
                ("equilibrium" if m["U"] is not None else "flat reference"))
        title = f"{scene.name}: {label}, {mesh.n_nodes} nodes, {when} (fabric {run['model'].material.name})"
        name = f"mesh_{k:02d}" if not m.get("final") else "mesh_final"
        files = plot_views(str(out / name), x, mesh.tri, views=("top", "iso"), title=title, length_unit=lu,
                           solids=solids)
        frames.append({"mesh": label, "nodes": mesh.n_nodes, "triangles": mesh.n_elements,
                       "time": None if run["route"] != "remesh_relax" else m["t"] / u.time,
                       "files": {v: p.name for v, p in files.items()}})
    _gif(out / "remesh.gif", [out / f["files"]["iso"] for f in frames])
    return frames


def _gif(path: Path, pngs: list) -> None:
    """A GIF of PNG frames (each shown 1 s, the last 3 s), resized to the first frame."""
    from PIL import Image

    from rftstatic.io.files import atomic_write

    imgs = [Image.open(p).convert("RGB") for p in pngs]
    size = imgs[0].size
    imgs = [im if im.size == size else im.resize(size) for im in imgs]
    durations = [1000] * (len(imgs) - 1) + [3000]
    with atomic_write(path) as tmp:
        imgs[0].save(tmp, format="GIF", save_all=True, append_images=imgs[1:], duration=durations, loop=0)


def _node_plot(scene, summary, out: Path) -> None:
    from rftstatic.io.figure import new_figure, save_png, set_title

    recs = summary["records"]
    relax = summary["route"] == "remesh_relax"
    x = [r["time"] for r in recs] + ([summary["t"]] if relax else [])
    n = [r["nodes"] for r in recs] + ([recs[-1]["nodes"]] if relax else [])
    if not relax:
        x = [r["cycle"] for r in recs]
    fig = new_figure((6.4, 4.0))
    ax = fig.add_subplot()
    ax.step(x, n, where="post", marker="o")
    ax.set_xlabel(f"time [{scene.units.name.split('-')[-1] if '-' in scene.units.name else 's'}]" if relax
                  else "remesh cycle")
    ax.set_ylabel("nodes")
    set_title(ax, f"{scene.name}: node count ({summary['element']})")
    ax.grid(alpha=0.3)
    save_png(fig, out / "nodes.png")
