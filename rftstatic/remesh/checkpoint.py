"""Checkpoints of remeshed runs: a long adaptive run never loses a finished remesh cycle.

One ``.npz`` file, written atomically (:func:`rftstatic.solvers.checkpoint.save_atomic`: temporary file,
fsync, ``os.replace``), holds the state a driver continues from:

* :func:`~rftstatic.remesh.static_driver.remesh_static` (:class:`StaticCycleState`), after every solved
  cycle: every mesh so far (nodes (N_k, 2) [m], triangles (E_k, 3)), the equilibrium of the last solve
  (:class:`~rftstatic.solvers.newton.StaticResult`, U (N, 3) [m]), the cycle records and the cycle index;
* :func:`~rftstatic.remesh.relax_driver.remesh_relax` (:class:`RelaxState`), before each chunk of explicit
  steps: the meshes so far, U and V (N, 3) [m, m/s] on the last one, t [s], steps, the steps since the
  last remesh, remeshes, skipped remeshes, the peak kinetic energy [J] on the mesh and the records; at the
  end, the final state (``done``).

A cycle, a remesh and the end are always written; the chunks between remeshes at most once per
``every_seconds`` of wall time (:data:`~rftstatic.solvers.static_checkpoint.CHECKPOINT_SECONDS`), the last
one kept back being written on a Ctrl-C (:meth:`RemeshCheckpointer.on_interrupt`). The caller's own state
(the remeshed relaxation's frames and the stepper's damping history) rides along as ``app`` fields.

Every file carries a ``header`` (for a scene: its name, analysis and the resolved scene data);
:func:`load_remesh_checkpoint` refuses a file with another header, another run's checkpoint or a corrupt
file with a :class:`~rftstatic.errors.CheckpointError` that names the file, the difference and the fix.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError
from rftstatic.remesh.adapt import RemeshRecord
from rftstatic.solvers.checkpoint import ThrottledWriter, json_array, plain
from rftstatic.solvers.newton import StaticResult
from rftstatic.solvers.static_checkpoint import CHECKPOINT_SECONDS, result_arrays, result_from


__all__ = ["FORMAT", "StaticCycleState", "RelaxState", "RemeshCheckpointer", "RemeshRestart",
           "load_remesh_checkpoint"]

FORMAT = 1
"""Version of the remesh checkpoint layout (key ``remesh_format``)."""

FIX = "delete it or run without --resume"


@dataclass
class StaticCycleState:
    """Where :func:`~rftstatic.remesh.static_driver.remesh_static` stands after solving cycle ``cycle``.

    Attributes
    ----------
    cycle : index of the last solved mesh (0: the initial one)
    meshes : the :class:`~rftstatic.mesh.trimesh.TriMesh` of cycles 0..cycle
    result : the :class:`StaticResult` on ``meshes[-1]`` (``U`` (N, 3) [m])
    records : one :class:`RemeshRecord` per mesh
    """

    cycle: int
    meshes: list
    result: StaticResult
    records: list


@dataclass
class RelaxState:
    """Where :func:`~rftstatic.remesh.relax_driver.remesh_relax` stands before its next chunk of steps.

    Attributes
    ----------
    meshes : every mesh so far (the last carries U, V)
    U, V : (N, 3) displacements [m] and half-step velocities [m/s] on ``meshes[-1]``
    t : simulated time [s]; steps : explicit steps taken; since : steps since the last remesh
    n_remesh, skipped : remeshes made and skipped (mesh settled)
    peak : peak kinetic energy on the present mesh [J]
    records : one :class:`RemeshRecord` per mesh
    done : the loop has ended (``converged`` then says how)
    """

    meshes: list
    U: np.ndarray
    V: np.ndarray
    t: float
    steps: int
    since: int
    n_remesh: int
    skipped: int
    peak: float
    records: list
    done: bool = False
    converged: bool = False


_RELAX_SCALARS = ("t", "steps", "since", "n_remesh", "skipped", "peak", "done", "converged")


@dataclass
class RemeshRestart:
    """A loaded remesh checkpoint (:func:`load_remesh_checkpoint`).

    Attributes
    ----------
    path : the file; phase : ``"cycle"`` (static route), ``"chunk"``, ``"remesh"`` or ``"done"`` (relaxation)
    state : :class:`StaticCycleState` or :class:`RelaxState`
    app : the caller's JSON fields; app_arrays : the caller's arrays (keys without the ``app_`` prefix)
    where : where the run stood, for ``summary.json``
    """

    path: Path
    phase: str
    state: object
    app: dict = field(default_factory=dict)
    app_arrays: dict = field(default_factory=dict)
    where: dict = field(default_factory=dict)


def _mesh_arrays(meshes) -> dict:
    """The meshes as flat arrays: nodes (sum N_k, 2) [m], triangles (sum E_k, 3), their counts and labels."""
    return {"mesh_X": np.concatenate([m.X for m in meshes]), "mesh_tri": np.concatenate([m.tri for m in meshes]),
            "mesh_nodes": np.array([m.n_nodes for m in meshes]),
            "mesh_elements": np.array([m.n_elements for m in meshes]),
            "mesh_meta": json_array([{"z0": m.z0, "name": m.name, "info": m.info} for m in meshes])}


def _meshes_from(z) -> list:
    from rftstatic.mesh.trimesh import TriMesh

    n, e = np.cumsum(np.r_[0, z["mesh_nodes"]]), np.cumsum(np.r_[0, z["mesh_elements"]])
    X, tri = z["mesh_X"], z["mesh_tri"]
    return [TriMesh(X[n[k]:n[k + 1]].copy(), tri[e[k]:e[k + 1]].copy(), z0=m["z0"], name=m["name"], info=m["info"])
            for k, m in enumerate(json.loads(str(z["mesh_meta"])))]


def _records_json(records) -> np.ndarray:
    return json_array([r.as_dict() for r in records])


class RemeshCheckpointer(ThrottledWriter):
    """Saves a remeshed run to ``path`` (module docstring); given to the drivers as ``checkpoint``.

    Parameters
    ----------
    path : the checkpoint file (``.npz``)
    header : what the run is keyed to (JSON-able; a scene's name, analysis and resolved data)
    every_seconds : least wall time between two chunk writes [s] (0: every chunk)
    app : ``app() -> (dict, dict)``: the caller's JSON fields and arrays, saved with every snapshot

    Attributes
    ----------
    writes, write_time : files written and the wall time spent writing them [s]; saved : what the last holds
    """

    run = "the remeshed run"

    def __init__(self, path, header: dict, *, every_seconds: float = CHECKPOINT_SECONDS, app=None):
        super().__init__(path, every_seconds)
        self.header = json.loads(json.dumps(header, default=plain))
        self.app = app
        self._meshes = (0, {})  # the mesh arrays of the first k meshes (a run's meshes only grow)

    def _mesh_arrays(self, meshes) -> dict:
        if self._meshes[0] != len(meshes):
            self._meshes = (len(meshes), _mesh_arrays(meshes))
        return self._meshes[1]

    def _snapshot(self, phase, arrays, what):
        fields, extra = self.app() if self.app is not None else ({}, {})
        arrays = {"remesh_format": np.array(FORMAT), "header": json_array(self.header), "phase": np.array(phase),
                  "app": json_array(fields), **{"app_" + k: np.asarray(v) for k, v in extra.items()}, **arrays}
        return arrays, what

    def cycle(self, state: StaticCycleState) -> None:
        """After a solved cycle of the static route (always written)."""
        arrays = {**self._mesh_arrays(state.meshes), **result_arrays("result_", state.result),
                  "cycle": np.array(state.cycle), "records": _records_json(state.records)}
        self._write(*self._snapshot("cycle", arrays, f"cycle {state.cycle}, {state.meshes[-1].n_nodes} nodes"))

    def relax(self, state: RelaxState, *, phase: str) -> None:
        """Before a chunk of the remeshed relaxation: ``phase`` ``"remesh"`` or ``"done"`` is written, ``"chunk"``
        when ``every_seconds`` have passed (else kept back for :meth:`flush`)."""
        arrays = {**self._mesh_arrays(state.meshes), "U": np.array(state.U, dtype=float),
                  "V": np.array(state.V, dtype=float), "records": _records_json(state.records),
                  "relax": json_array({k: getattr(state, k) for k in _RELAX_SCALARS})}
        what = (f"t = {state.t:.4g} s, step {state.steps}, mesh {len(state.meshes) - 1} "
                f"({state.meshes[-1].n_nodes} nodes)")
        self._pending = self._snapshot(phase, arrays, what)
        if phase != "chunk" or self.due():
            self.flush()


def load_remesh_checkpoint(path, header: dict) -> RemeshRestart:
    """Read the remesh checkpoint ``path`` of a run keyed to ``header``.

    Raises
    ------
    CheckpointError
        if the file is corrupt or incomplete, not a remeshed run's, of another format, or written for
        another header (the message names the file, the first differences and the fix).
    """
    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"checkpoint {path} does not exist")
    try:
        with np.load(path, allow_pickle=False) as z:
            if "remesh_format" not in z.files:
                raise CheckpointError(f"checkpoint {path} was not written by a remeshed run (a static, dynamic or "
                                      f"relax run's?); {FIX}")
            if int(z["remesh_format"]) != FORMAT:
                raise CheckpointError(f"checkpoint {path}: remesh format {int(z['remesh_format'])}, this version "
                                      f"reads {FORMAT}; {FIX}")
            _check_header(path, json.loads(str(z["header"])), json.loads(json.dumps(header, default=plain)))
            phase = str(z["phase"])
            meshes = _meshes_from(z)
            records = [RemeshRecord(**r) for r in json.loads(str(z["records"]))]
            if phase == "cycle":
                state = StaticCycleState(cycle=int(z["cycle"]), meshes=meshes, result=result_from("result_", z),
                                         records=records)
            elif phase in ("chunk", "remesh", "done"):
                state = RelaxState(meshes=meshes, U=z["U"].copy(), V=z["V"].copy(), records=records,
                                   **json.loads(str(z["relax"])))
            else:
                raise CheckpointError(f"checkpoint {path}: unknown phase {phase!r}; {FIX}")
            app = json.loads(str(z["app"]))
            app_arrays = {k[4:]: z[k].copy() for k in z.files if k.startswith("app_")}
    except CheckpointError:
        raise
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise CheckpointError(f"checkpoint {path} is corrupt or incomplete ({type(exc).__name__}: {exc}); "
                              f"{FIX}") from None
    if len(state.U if phase != "cycle" else state.result.U) != meshes[-1].n_nodes:
        raise CheckpointError(f"checkpoint {path} is inconsistent (its state does not fit its last mesh); {FIX}")
    where = {"phase": phase, "mesh": len(meshes) - 1, "nodes": meshes[-1].n_nodes}
    if phase != "cycle":
        where.update(t=state.t, steps=state.steps)
    return RemeshRestart(path=path, phase=phase, state=state, app=app, app_arrays=app_arrays, where=where)


def _flat(d, prefix="") -> dict:
    if not isinstance(d, dict):
        return {prefix: d}
    out = {}
    for k, v in d.items():
        out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
    return out


def _check_header(path, saved, now) -> None:
    """CheckpointError naming the first differences between the saved run's header and this run's."""
    if saved.get("scene") != now.get("scene"):
        raise CheckpointError(f"checkpoint {path} was written by scene {saved.get('scene')!r}, not "
                              f"{now.get('scene')!r}; {FIX}, or give the --out of that scene's run")
    a, b = _flat(saved), _flat(now)
    diff = [f"{k} = {a.get(k)!r} there, {b.get(k)!r} here" for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
    if diff:
        more = f" and {len(diff) - 4} more" if len(diff) > 4 else ""
        raise CheckpointError(f"checkpoint {path} was written with other scene values ({'; '.join(diff[:4])}{more}); "
                              f"{FIX}, or with the --set overrides of the interrupted run")

