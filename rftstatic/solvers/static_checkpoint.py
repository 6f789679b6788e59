"""Checkpoints of static solves: a long static run never loses finished work.

During :func:`rftstatic.solvers.static.solve_static` a :class:`StaticCheckpointer` keeps one ``.npz``
file, written atomically (:func:`rftstatic.solvers.checkpoint.save_atomic`: temporary file, fsync,
``os.replace``), holding

* on the load-steps route, after a converged increment (:class:`~rftstatic.solvers.load_steps.LoadPath`):
  the equilibrium U (N, 3) [m], its load factor, the next increment, the target displacement [m], the
  previous equilibrium (secant predictor), the load-step records and counts;
* on the relaxation route (:class:`~rftstatic.solvers.static.RelaxRoute`): U and the half-step velocities
  V (N, 3) [m, m/s], the relaxation time used [s], the peak kinetic energy [J] and the handover records,
  at the end of every relaxation segment and after every failed handover; during a segment also the
  explicit state (:func:`~rftstatic.solvers.checkpoint.state_arrays`), from which the segment goes on
  step for step as the uninterrupted one;
* at the end, the result (``"done"``), so that an interruption while the outputs are written loses nothing.

Writes are throttled to one per ``every_seconds`` of wall time (:data:`CHECKPOINT_SECONDS`), except at
the end of a phase (the last increment, the end of a relaxation segment, a failed handover, the failed
load steps before the relaxation fallback), which is always written. A converged increment not yet
written is kept in memory and written when the solve is interrupted (:meth:`StaticCheckpointer.on_interrupt`);
a Ctrl-C during a relaxation segment stops it at a whole step, which is saved. A kill loses at most
``every_seconds`` of work.

Every file names the scene, the mesh size, a fingerprint of the model (mesh, supports, load, material,
element, contact) and the solver options; :func:`load_static_checkpoint` refuses a file written for
another scene, mesh, model or options, or a corrupt one, with a :class:`~rftstatic.errors.CheckpointError`
naming the file and what differs.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError, ConvergenceError
from rftstatic.solvers.checkpoint import (
    ThrottledWriter,
    json_array,
    load_checkpoint,
    model_fingerprint,
    plain,
    state_arrays,
)
from rftstatic.solvers.load_steps import LoadPath
from rftstatic.solvers.newton import StaticResult
from rftstatic.solvers.static import RelaxRoute


FORMAT = 1
"""Version of the static checkpoint layout (key ``static_format``)."""

CHECKPOINT_SECONDS = 10.0
"""Least wall time [s] between two checkpoint writes of a static solve (the ends of phases excepted). A
write of the 51 x 11 strip or the 33 x 33 drape (about 35 kB) took 7-17 ms on the 2-core test machine,
nearly all of it the fsync: written after each of the strip's 7 increments, 4-6 % of its 1.3 s solve."""

_RESULT_FIELDS = [f.name for f in fields(StaticResult) if f.name not in ("U", "state")]


def static_fingerprint(model) -> str:
    """SHA-1 of what a static solve of ``model`` depends on: :func:`model_fingerprint` (mesh, supports,
    load, material, element) and the penalty contact (obstacles, stiffness, smoothing) and potential loads."""
    h = hashlib.sha1(model_fingerprint(model).encode())
    c = model.contact
    contact = None if c is None else {"obstacles": [ob.as_dict() for ob in c.obstacles], "stiffness": c.stiffness,
                                      "smoothing": c.smoothing}
    h.update(json.dumps([contact, [type(t).__name__ for t in model.load_terms]], sort_keys=True,
                        default=plain).encode())
    return h.hexdigest()


def options_spec(options) -> dict:
    """The solver options that decide the result (all of :class:`StaticOptions` but ``progress``)."""
    return {k: v for k, v in asdict(options).items() if k != "progress"}


def remove_stale(path) -> None:
    """Delete the temporary files of checkpoint writes to ``path`` that a kill cut short."""
    path = Path(path)
    for stale in path.parent.glob(path.name + ".*.tmp"):
        stale.unlink(missing_ok=True)


def _field(U) -> np.ndarray:
    """(N, 3) displacements or velocities, or an empty (0, 3) array for None."""
    return np.zeros((0, 3)) if U is None else np.array(U, dtype=float)


def _unfield(a) -> np.ndarray | None:
    return None if a.shape[0] == 0 else a.copy()


def result_arrays(prefix, result: StaticResult) -> dict:
    """The arrays of a :class:`StaticResult` under keys starting with ``prefix`` (U (N, 3) [m], the rest as JSON)."""
    return {prefix + "U": _field(result.U),
            prefix + "result": json_array({k: getattr(result, k) for k in _RESULT_FIELDS})}


def result_from(prefix, z) -> StaticResult:
    """The :class:`StaticResult` saved by :func:`result_arrays` in the open ``.npz`` ``z``."""
    return StaticResult(U=z[prefix + "U"].copy(), **json.loads(str(z[prefix + "result"])))


class StaticCheckpointer(ThrottledWriter):
    """Saves a static solve to ``path`` (module docstring); given to :func:`solve_static` as ``checkpoint``.

    Parameters
    ----------
    path : the checkpoint file (``.npz``)
    model, options : the model and :class:`StaticOptions` of the solve (their fingerprints are saved)
    scene : the scene's name, saved to refuse another scene's checkpoint
    every_seconds : least wall time between two writes [s] (0: write every increment)

    Attributes
    ----------
    writes : files written; write_time : wall time spent writing them [s]
    saved : what the last write holds (e.g. ``"load factor 0.42"``), for messages
    state : the solve's :class:`~rftstatic.model.state.State` (set by :func:`solve_static`; its factorisation
        count, damping scale and load branches are saved)
    """

    run = "the static solve"

    def __init__(self, path, model, options, *, scene: str = "", every_seconds: float = CHECKPOINT_SECONDS):
        super().__init__(path, every_seconds)
        self.header = {"scene": scene, "nodes": model.mesh.n_nodes, "elements": model.mesh.n_elements,
                       "element": model.element, "model": static_fingerprint(model), "options": options_spec(options)}
        self.model = model
        self.state = None

    def _common(self, phase) -> dict:
        state = self.state
        branches = list(state.load_branches or ()) if state is not None else []  # committed angle branches
        return {"static_format": np.array(FORMAT), "static_header": json_array(self.header), "phase": np.array(phase),
                "workspace": json_array({"factorisations": 0 if state is None else state.factorisations,
                                    "lm_scale": None if state is None else state.lm_scale, "load_terms": branches})}

    def load_step(self, path: LoadPath) -> None:
        """After a converged increment: keep the load path, write it when due and at full load."""
        r = path.result
        counts = {k: getattr(r, k) for k in ("iterations", "cutbacks", "retries", "residual", "seed")}
        counts["tangent_modes"] = dict(self.state.modes) if self.state is not None else {}
        arrays = {**self._common("load-steps"), "U": _field(path.U), "U_prev": _field(path.U_prev),
                  "path": json_array({"lam": path.lam, "dlam": path.dlam, "target": path.target,
                                 "lam_prev": path.lam_prev, "load_steps": list(r.load_steps), **counts})}
        self._pending = (arrays, f"load factor {path.lam:.6g}, {len(r.load_steps)} increments")
        if path.lam >= 1.0 or self.due():
            self.flush()

    def _route_arrays(self, route: RelaxRoute) -> dict:
        first = route.first
        arrays = {**self._common(route.phase), "route_U": _field(route.U), "route_V": _field(route.V),
                  "route": json_array({k: getattr(route, k) for k in ("phase", "t_used", "peak", "tol_force", "span",
                                                                  "at_rest", "seed", "info")}),
                  "first": json_array(None if first is None else str(first))}
        if first is not None and first.result is not None:
            arrays.update(result_arrays("first_", first.result))
        return arrays

    def route(self, route: RelaxRoute) -> None:
        """Write the relaxation route where it stands (the end of a phase: not throttled)."""
        self._write(self._route_arrays(route), f"relaxation to t = {route.t_used:.4g} s, {route.phase}")

    def segment(self, route: RelaxRoute) -> _SegmentSaver:
        """The explicit run's checkpoint object for the relaxation segment that starts from ``route``."""
        return _SegmentSaver(self, route)

    def done(self, result: StaticResult) -> None:
        """Write the solve's result (not throttled)."""
        self._write({**self._common("done"), **result_arrays("", result)}, "the result")


class _SegmentSaver:
    """The checkpoint object of :func:`~rftstatic.solvers.explicit.run_explicit` during one relaxation segment
    (``due(step)``, ``save(...)``): the explicit state with the route where the segment started."""

    def __init__(self, owner: StaticCheckpointer, route: RelaxRoute):
        self.owner, self.route = owner, route

    def due(self, step: int) -> bool:
        return self.owner.due()

    def save(self, model, obstacles, state, **explicit) -> None:
        arrays = {**state_arrays(model, obstacles, state, **explicit), **self.owner._route_arrays(self.route)}
        t = self.route.t_used + state.t
        self.owner._write(arrays, f"relaxation to t = {t:.4g} s, step {state.step} of a segment")


@dataclass
class StaticRestart:
    """A loaded static checkpoint (:func:`load_static_checkpoint`), for :func:`solve_static`'s ``restart``.

    Attributes
    ----------
    path : the file; phase : ``"load-steps"``, ``"start"``, ``"guide"``, ``"relax"``, ``"handover"`` or ``"done"``
    load_path : the load steps' state (phase ``"load-steps"``)
    route : the relaxation route's state (the relaxation phases)
    segment : the explicit state inside a relaxation segment (:func:`load_checkpoint`), or None
    result : the finished solve's result (phase ``"done"``)
    factorisations, lm_scale : the solve State's counts (:class:`~rftstatic.model.state.State`)
    load_terms : the committed branch of each of the model's potential loads (``State.load_branches``)
    where : where the saved solve stood (for ``summary.json``): phase, load factor and load steps, or
        relaxation time [s]
    """

    path: Path
    phase: str
    load_path: LoadPath | None = None
    route: RelaxRoute | None = None
    segment: dict | None = None
    result: StaticResult | None = None
    factorisations: int = 0
    lm_scale: float | None = None
    load_terms: list | None = None
    where: dict | None = None

    def restore(self, model, state) -> None:
        """Give the solve's State ``state`` its saved counts and the saved branches of ``model``'s
        potential loads, before the solve continues."""
        state.factorisations, state.lm_scale = self.factorisations, self.lm_scale
        if self.load_terms and len(self.load_terms) == len(model.load_terms):
            state.load_branches = tuple(None if b is None else np.asarray(b, dtype=float) for b in self.load_terms)

    def _where(self) -> dict:
        out = {"phase": self.phase}
        if self.load_path is not None:
            out.update(load_factor=self.load_path.lam, load_steps=len(self.load_path.result.load_steps))
        if self.route is not None:
            t = self.route.t_used + (self.segment["t"] if self.segment is not None else 0.0)
            out.update(relaxation_time_s=t, handovers=len(self.route.info.get("handovers", [])))
        if self.result is not None:
            out.update(load_factor=self.result.lam, load_steps=len(self.result.load_steps))
        return out


def load_static_checkpoint(path, model, options, *, scene: str = "") -> StaticRestart:
    """Read the static checkpoint ``path`` of a solve of ``model`` with ``options`` (of scene ``scene``).

    Raises
    ------
    CheckpointError
        if the file is missing, corrupt, not a static run's, or written for another scene, mesh, model or
        solver options (the message names the file and the difference).
    """
    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"checkpoint {path} does not exist")
    try:
        with np.load(path, allow_pickle=False) as z:
            if "static_format" not in z.files:
                raise CheckpointError(f"checkpoint {path} was not written by a static solve (a dynamic or relax "
                                      "run's?); run without --resume")
            if int(z["static_format"]) != FORMAT:
                raise CheckpointError(f"checkpoint {path}: static format {int(z['static_format'])}, this version "
                                      f"reads {FORMAT}; run without --resume")
            _check_header(path, json.loads(str(z["static_header"])), model, options, scene)
            restart = _restart_from(path, z)
            in_segment = restart.phase in ("guide", "relax") and "format" in z.files  # the explicit state too
    except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        if isinstance(exc, CheckpointError):
            raise
        raise CheckpointError(f"checkpoint {path} is corrupt or incomplete ({type(exc).__name__}: {exc}); "
                              "run without --resume to start again") from None
    if in_segment:
        restart.segment = load_checkpoint(path)
        if restart.segment["fingerprint"] != model_fingerprint(model):
            raise CheckpointError(f"checkpoint {path}: its relaxation state was written for another model")
    restart.where = restart._where()
    return restart


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


def _restart_from(path, z) -> StaticRestart:
    phase = str(z["phase"])
    saved = json.loads(str(z["workspace"]))
    out = StaticRestart(path=path, phase=phase, factorisations=int(saved["factorisations"]), lm_scale=saved["lm_scale"],
                        load_terms=saved["load_terms"])
    if phase == "done":
        out.result = result_from("", z)
    elif phase == "load-steps":
        p = json.loads(str(z["path"]))
        result = StaticResult(U=z["U"].copy(), lam=p["lam"], converged=False, load_steps=p["load_steps"],
                              iterations=p["iterations"], cutbacks=p["cutbacks"], retries=p["retries"],
                              residual=p["residual"], seed=p["seed"], tangent_modes=p["tangent_modes"])
        out.load_path = LoadPath(lam=p["lam"], U=z["U"].copy(), dlam=p["dlam"], target=p["target"],
                                 lam_prev=p["lam_prev"], U_prev=_unfield(z["U_prev"]), result=result)
    elif phase in ("start", "guide", "relax", "handover"):
        r = json.loads(str(z["route"]))
        message = json.loads(str(z["first"]))
        first = None
        if message is not None:
            first = ConvergenceError(message, result_from("first_", z) if "first_U" in z.files else None)
        out.route = RelaxRoute(U=_unfield(z["route_U"]), V=_unfield(z["route_V"]), first=first, **r)
    else:
        raise CheckpointError(f"checkpoint {path}: unknown phase {phase!r}; run without --resume")
    return out
