"""Checkpoints of static solves: a long static run never loses finished work.

The app layer drives :func:`~rftstatic.solvers.static.static_route` and saves the solve's State at its pauses
(:class:`~rftstatic.solvers.checkpoint.CheckpointSaver`, the one checkpoint format: the State with the position
of every route under way, one ``.npz`` written atomically):

* on the load-steps route, after a converged increment (``State.route["load-steps"]``, a
  :class:`~rftstatic.solvers.load_steps.LoadPath`: the equilibrium U (N, 3) [m], its load factor, the next
  increment, the target displacement [m], the previous equilibrium and the load-step records);
* on the relaxation route (``State.route["relax-route"]``, a :class:`~rftstatic.solvers.static.RelaxRoute`):
  U and the half-step velocities V (N, 3) [m, m/s], the relaxation time used [s], the peak kinetic energy [J]
  and the handover records, at the end of every relaxation segment and after every failed handover; during a
  segment also the segment's explicit State (``State.route["relax-segment"]``), from which it goes on step
  for step as the uninterrupted one;
* at the end, the result (``State.route["static"]``), so that an interruption while the outputs are written
  loses nothing.

Writes are throttled to one per ``every_seconds`` of wall time (:data:`CHECKPOINT_SECONDS`), except at the end
of a phase (the last increment, the end of a relaxation segment, a failed handover, the failed load steps
before the relaxation fallback, the result), which is always written. A converged increment not yet written is
kept in memory and written when the solve is interrupted; a Ctrl-C stops the solve at its next pause, saved. A
kill loses at most ``every_seconds`` of work.

Every file's header names the scene, the mesh size, a fingerprint of the model (mesh, supports, load, material,
element, contact) and the solver options; :func:`load_static_state` refuses a file written for another scene,
mesh, model or options, or a corrupt one, with a :class:`~rftstatic.errors.CheckpointError` naming the file and
what differs.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from pathlib import Path

from rftstatic.errors import CheckpointError
from rftstatic.solvers.checkpoint import (
    CheckpointSaver,
    model_fingerprint,
    plain,
    read_checkpoint,
    restore_state,
)
from rftstatic.solvers.load_steps import LOAD_STEPS
from rftstatic.solvers.newton import start_state
from rftstatic.solvers.release import RELEASE
from rftstatic.solvers.static import RELAX_ROUTE, SEGMENT, STATIC

CHECKPOINT_SECONDS = 10.0
"""Least wall time [s] between two checkpoint writes of a static solve (the ends of phases excepted). A
write of the 51 x 11 strip or the 33 x 33 drape (about 35 kB) took 7-17 ms on the 2-core test machine,
nearly all of it the fsync."""

def static_fingerprint(model) -> str:
    """SHA-1 of what a static solve of ``model`` depends on: :func:`model_fingerprint` (mesh, supports,
    load, material, element) and the penalty contact (obstacles, stiffness, smoothing) and potential loads."""
    h = hashlib.sha1(model_fingerprint(model).encode())
    c = model.contact
    contact = None if c is None else {"obstacles": [_by_content(ob.as_dict()) for ob in c.obstacles],
                                      "stiffness": c.stiffness, "smoothing": c.smoothing}
    h.update(json.dumps([contact, [type(t).__name__ for t in model.load_terms]], sort_keys=True,
                        default=plain).encode())
    return h.hexdigest()


def _by_content(spec: dict) -> dict:
    """An obstacle's ``spec`` with its mesh files (``path``, ``paths``) named by the SHA-1 of their bytes: a run
    continued in another folder (a finished run's, after its ``.partial`` folder was published) reads the same
    surface from another path."""
    def digest(name):
        try:
            return hashlib.sha1(Path(name).read_bytes()).hexdigest()
        except (OSError, TypeError):
            return name

    out = dict(spec)
    if isinstance(out.get("path"), str):
        out["path"] = digest(out["path"])
    if isinstance(out.get("paths"), (list, tuple)):
        out["paths"] = [digest(p) for p in out["paths"]]
    return out


def options_spec(options) -> dict:
    """The solver options that decide the result (all of :class:`StaticOptions` but ``progress``)."""
    return {k: v for k, v in asdict(options).items() if k != "progress"}


def static_header(model, options, scene: str = "") -> dict:
    """What a static solve's checkpoint is for: the scene's name, the mesh size, the element, the model's
    fingerprint and the solver options."""
    return {"kind": "static", "scene": scene, "nodes": model.mesh.n_nodes, "elements": model.mesh.n_elements,
            "element": model.element, "model": static_fingerprint(model), "options": options_spec(options)}


def static_saver(path, model, options, *, scene: str = "", every_seconds: float = CHECKPOINT_SECONDS) -> CheckpointSaver:
    """The saver of a static solve of ``model`` with ``options`` to ``path`` (module docstring)."""
    return CheckpointSaver(path, static_header(model, options, scene), every_seconds=every_seconds,
                           run="the static solve")


def load_static_state(path, model, options, *, scene: str = ""):
    """The State of a static solve of ``model`` with ``options`` (of scene ``scene``) saved in ``path``, with a
    new linear solver and contact caches: :func:`~rftstatic.solvers.static.static_route` goes on from it.

    Raises
    ------
    CheckpointError
        if the file is missing, corrupt, not a static run's, or written for another scene, mesh, model or
        solver options (the message names the file and the difference).
    """
    path = Path(path)
    header, saved = read_checkpoint(path)
    if header.get("kind") != "static":
        raise CheckpointError(f"checkpoint {path} was not written by a static solve (a {header.get('kind')} "
                              "run's?); run without --resume")
    _check_header(path, header, model, options, scene)
    return restore_state(model, saved, start_state(model, options.newton.linear_solver))


def where(state) -> dict:
    """Where the saved static solve ``state`` stood (for ``summary.json``): phase, and load factor and load
    steps, or relaxation time [s] and handovers, or the release route's support height [m] and steps."""
    r = state.route
    if STATIC in r:
        res = r[STATIC]["result"]
        return {"phase": "done", "load_factor": res.lam, "load_steps": len(res.load_steps)}
    if RELAX_ROUTE in r:
        route = r[RELAX_ROUTE]
        seg = r.get(SEGMENT)
        t = route.t_used + (0.0 if seg is None else seg["t"] if isinstance(seg, dict) else seg.t)
        return {"phase": route.phase, "relaxation_time_s": t, "handovers": len(route.info.get("handovers", []))}
    if RELEASE in r:
        path = r[RELEASE]
        return {"phase": "release", "support_height_m": path.height, "steps": len(path.result.load_steps)}
    if LOAD_STEPS in r:
        path = r[LOAD_STEPS]
        return {"phase": "load-steps", "load_factor": path.lam, "load_steps": len(path.result.load_steps)}
    return {"phase": "start"}


def remove_stale(path) -> None:
    """Delete the temporary files of checkpoint writes to ``path`` that a kill cut short."""
    path = Path(path)
    for stale in path.parent.glob(path.name + ".*.tmp"):
        stale.unlink(missing_ok=True)


def _check_header(path, head, model, options, scene) -> None:
    """CheckpointError naming the first difference between the saved run and this one."""
    if scene and head["scene"] and head["scene"] != scene:
        raise CheckpointError(f"checkpoint {path} was written by scene {head['scene']!r}, not {scene!r}; run "
                              "without --resume, or give the --out of that scene's run")
    mine = (model.mesh.n_nodes, model.mesh.n_elements)
    if (head["nodes"], head["elements"]) != mine:
        raise CheckpointError(f"checkpoint {path} was written for a mesh of {head['nodes']} nodes and "
                              f"{head['elements']} elements; this run's mesh has {mine[0]} nodes and {mine[1]} "
                              "elements (mesh.nodes?); run without --resume or with the same mesh")
    if head["model"] != static_fingerprint(model):
        raise CheckpointError(f"checkpoint {path} was written for another model of the same size (element "
                              f"{head['element']} there, {model.element} here; or the mesh coordinates, supports, "
                              "loads, material or contact differ); run without --resume")
    saved, now = head["options"], json.loads(json.dumps(options_spec(options), default=plain))
    diff = [f"{k} {saved.get(k)!r} there, {now.get(k)!r} here" for k in sorted(set(saved) | set(now))
            if saved.get(k) != now.get(k)]
    if diff:
        raise CheckpointError(f"checkpoint {path} was written with other solver options ({'; '.join(diff)}); "
                              "run without --resume or with the options of the interrupted run")


