"""Checkpoints of remeshed runs: a long adaptive run never loses a finished remesh cycle.

The remesh drivers are routes (:mod:`rftstatic.solvers.drive`) whose position lives in the run's State; the
app layer saves that State at their pauses in the one checkpoint format
(:class:`~rftstatic.solvers.checkpoint.CheckpointSaver`):

* :func:`~rftstatic.remesh.static_driver.remesh_static_route` (``State.route["remesh-static"]``, a
  :class:`StaticCycleState`), after every solved cycle: every mesh so far (nodes (N_k, 2) [m], triangles
  (E_k, 3)), the equilibrium of the last solve (:class:`~rftstatic.solvers.newton.StaticResult`, U (N, 3) [m]),
  the cycle records and the cycle index;
* :func:`~rftstatic.remesh.relax_driver.remesh_relax_route` (``State.route["remesh-relax"]``, a
  :class:`RelaxState`), before each chunk of explicit steps: the meshes so far, U and V (N, 3) [m, m/s] on the
  last one, t [s], steps, the steps since the last remesh, remeshes, skipped remeshes, the peak kinetic energy
  [J] on the mesh and the records; at the end, the final state (``done``).

A cycle, a remesh and the end are always written; the chunks between remeshes at most once per
``every_seconds`` of wall time (:data:`~rftstatic.solvers.static_checkpoint.CHECKPOINT_SECONDS`), the last
one kept back being written on a Ctrl-C. The caller's own position (the remeshed relaxation's frames and the
stepper's damping history) rides along in the same State.

Every file carries a ``header`` (for a scene: its name, analysis and the resolved scene data);
:func:`load_remesh_state` refuses a file with another header, another run's checkpoint or a corrupt file with
a :class:`~rftstatic.errors.CheckpointError` that names the file, the difference and the fix.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError
from rftstatic.solvers.checkpoint import CheckpointSaver, plain, read_checkpoint, restore_state
from rftstatic.solvers.newton import StaticResult
from rftstatic.solvers.static_checkpoint import CHECKPOINT_SECONDS

__all__ = ["REMESH_RELAX", "REMESH_STATIC", "StaticCycleState", "RelaxState", "remesh_saver", "load_remesh_state",
           "where"]

REMESH_STATIC = "remesh-static"
"""The static remesh route's key in ``State.route``: its :class:`StaticCycleState`."""

REMESH_RELAX = "remesh-relax"
"""The remeshed relaxation's key in ``State.route``: its :class:`RelaxState`."""

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
    phase : what the pause was: ``"chunk"`` (before a chunk), ``"remesh"`` (after a remesh) or ``"done"``
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
    phase: str = "chunk"



def remesh_saver(path, header: dict, *, every_seconds: float = CHECKPOINT_SECONDS) -> CheckpointSaver:
    """The saver of a remeshed run keyed to ``header`` (JSON-able; a scene's name, analysis and resolved data)."""
    return CheckpointSaver(path, {"kind": "remesh", **json.loads(json.dumps(header, default=plain))},
                           every_seconds=every_seconds, run="the remeshed run")


def load_remesh_state(path, header: dict):
    """The State of the remeshed run keyed to ``header`` saved in ``path`` (its ``route`` holds the driver's
    position, and the caller's).

    Raises
    ------
    CheckpointError
        if the file is corrupt or incomplete, not a remeshed run's, or written for another header (the
        message names the file, the first differences and the fix).
    """
    path = Path(path)
    saved_header, saved = read_checkpoint(path)
    if saved_header.get("kind") != "remesh":
        raise CheckpointError(f"checkpoint {path} was not written by a remeshed run (a {saved_header.get('kind')} "
                              f"run's); {FIX}")
    saved_header = {k: v for k, v in saved_header.items() if k != "kind"}
    _check_header(path, saved_header, json.loads(json.dumps(header, default=plain)))
    state = restore_state(None, saved)
    position = state.route.get(REMESH_STATIC) or state.route.get(REMESH_RELAX)
    if position is None:
        raise CheckpointError(f"checkpoint {path} holds no remesh route's position; {FIX}")
    U = position.result.U if isinstance(position, StaticCycleState) else position.U
    if len(U) != position.meshes[-1].n_nodes:
        raise CheckpointError(f"checkpoint {path} is inconsistent (its state does not fit its last mesh); {FIX}")
    return state


def where(state) -> dict:
    """Where the saved remeshed run ``state`` stood (for ``summary.json``): phase, mesh index and nodes, and the
    relaxation's time [s] and steps."""
    if REMESH_STATIC in state.route:
        p = state.route[REMESH_STATIC]
        return {"phase": "cycle", "mesh": len(p.meshes) - 1, "nodes": p.meshes[-1].n_nodes}
    p = state.route[REMESH_RELAX]
    return {"phase": p.phase, "mesh": len(p.meshes) - 1, "nodes": p.meshes[-1].n_nodes, "t": p.t, "steps": p.steps}


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

