"""Checkpoints of long explicit runs: save the state at intervals, resume from the last one.

A checkpoint is one ``.npz`` file holding the state (t, step, D_n, v_(n-1/2)), the step size, the
energy accumulators, the history, probe records and frames so far, the run's options and a
fingerprint of the model (mesh, supports, load, material, element). It is written to a temporary
file in the same directory, flushed to disk and moved over the old one with ``os.replace``, which is
atomic: a Ctrl-C or kill at any moment leaves either the previous checkpoint or the new one, never
a partial file. :func:`resume` continues from it and, because the loop is restarted from exactly
the saved numbers, reproduces the uninterrupted run bitwise.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
import time
import zipfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError

log = logging.getLogger(__name__)

FORMAT = 1



def model_fingerprint(model) -> str:
    """SHA-1 of what the explicit run depends on: mesh, element, supports, load and material."""
    h = hashlib.sha1()
    for a in (model.mesh.X, model.mesh.tri, model.free, model.load, model.material.Dm, model.material.Db,
              np.array([model.material.weight, model.mesh.z0, float(model.with_membrane)])):
        a = np.ascontiguousarray(a)
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    h.update(model.element.encode())
    return h.hexdigest()


def _obstacles_spec(obstacles) -> str:
    return json.dumps([ob.as_dict() for ob in obstacles], sort_keys=True, default=float)


def plain(v):
    """A JSON-able form of numpy scalars and arrays (json's ``default`` for the checkpoints' records)."""
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise TypeError(f"{type(v).__name__} is not JSON serialisable")


def json_array(value) -> np.ndarray:
    """``value`` as a JSON string in a 0-d array, the form a checkpoint's ``.npz`` keeps a record in."""
    return np.array(json.dumps(value, default=plain))


def save_atomic(path, arrays: dict) -> None:
    """Write ``arrays`` with ``np.savez`` to ``path`` atomically (temporary file + ``os.replace``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


class ThrottledWriter:
    """A checkpoint file written atomically (:func:`save_atomic`) at most every ``every_seconds`` of wall
    time, the snapshot kept back by the throttle written by :meth:`flush` and on a Ctrl-C
    (:meth:`on_interrupt`). The base of the static and the remeshed checkpointers; ``run`` names the run
    in the interrupt message (e.g. ``"the static solve"``).

    Attributes
    ----------
    writes : files written; write_time : wall time spent writing them [s]
    saved : what the last write holds (e.g. ``"load factor 0.42"``), for messages
    """

    run = "the run"

    def __init__(self, path, every_seconds: float):
        self.path = Path(path)
        self.every_seconds = float(every_seconds)
        self.writes, self.write_time, self.saved = 0, 0.0, ""
        self._pending = None
        self._last = time.monotonic()

    def due(self, step=None) -> bool:
        """Whether ``every_seconds`` have passed since the last write (``step`` unused: the explicit loop's call)."""
        return time.monotonic() - self._last >= self.every_seconds

    def _write(self, arrays, what) -> None:
        t = time.perf_counter()
        save_atomic(self.path, arrays)
        self.write_time += time.perf_counter() - t
        self.writes += 1
        self.saved, self._pending, self._last = what, None, time.monotonic()
        log.info("checkpoint (%s) -> %s", what, self.path)

    def flush(self) -> None:
        """Write the snapshot kept back by the throttle, if any."""
        if self._pending is not None:
            self._write(*self._pending)

    @contextmanager
    def on_interrupt(self):
        """A KeyboardInterrupt inside writes the last snapshot kept back before it goes on."""
        try:
            yield self
        except KeyboardInterrupt:
            self.flush()
            if self.writes:
                log.warning("interrupted: %s is saved in %s (%s); continue it with --resume", self.run, self.path,
                            self.saved)
            raise


class Checkpointer:
    """Saves the explicit state every ``every_steps`` steps and/or every ``every_seconds`` of wall time.

    Parameters
    ----------
    path : checkpoint file (``.npz``)
    every_steps : save interval in steps
    every_seconds : save interval in wall-clock seconds [s]
    """

    def __init__(self, path, *, every_steps: int | None = None, every_seconds: float | None = None):
        if every_steps is None and every_seconds is None:
            raise ValueError("a Checkpointer needs every_steps or every_seconds")
        if every_steps is not None and every_steps < 1:
            raise ValueError(f"every_steps must be >= 1, got {every_steps}")
        self.path = Path(path)
        self.every_steps = every_steps
        self.every_seconds = every_seconds
        self._last_wall = time.monotonic()
        self.saved = 0

    def due(self, step: int) -> bool:
        if self.every_steps is not None and step % self.every_steps == 0:
            return True
        return self.every_seconds is not None and time.monotonic() - self._last_wall >= self.every_seconds

    def save(self, model, obstacles, state, *, dt, n_steps, estimate, acc, history, probes, frames, options):
        """Write the state after ``state.step`` steps (called by :func:`rftstatic.solvers.explicit.run_explicit`)."""
        save_atomic(self.path, state_arrays(model, obstacles, state, dt=dt, n_steps=n_steps, estimate=estimate,
                                            acc=acc, history=history, probes=probes, frames=frames, options=options))
        self._last_wall = time.monotonic()
        self.saved += 1
        log.info("checkpoint at t = %.6g s (step %d) -> %s", state.t, state.step, self.path)


def state_arrays(model, obstacles, state, *, dt, n_steps, estimate, acc, history, probes, frames, options) -> dict:
    """The arrays of a checkpoint of an explicit run after ``state.step`` steps (what :func:`load_checkpoint`
    reads): the state ``U``, ``V_half`` (N, 3) [m, m/s], step, step size [s], accumulators, history,
    probe records (S, P, 3) [m], frames and the run's options."""
    N = model.mesh.n_nodes
    P = len(options["probe_nodes"])
    arrays = {
        "format": np.array(FORMAT), "fingerprint": np.array(model_fingerprint(model)),
        "obstacles": np.array(_obstacles_spec(obstacles)),
        "t": np.array(state.t), "step": np.array(state.step), "n_steps": np.array(n_steps),
        "dt": np.array(dt), "U": state.U, "V_half": state.V_half,
        "acc": np.array(json.dumps(acc)),
        "estimate": np.array(json.dumps(None if estimate is None else estimate.__dict__)),
        "probes": np.asarray(probes, dtype=float).reshape(len(probes), P, 3),
        "frame_t": np.array([t for t, _ in frames], dtype=float),
        "frame_U": np.asarray([u for _, u in frames], dtype=float).reshape(len(frames), N, 3),
    }
    for k, v in history.items():
        arrays["history_" + k] = np.asarray(v, dtype=float)
    for k, v in options.items():
        arrays["option_" + k] = np.asarray(v)
    return arrays


def load_checkpoint(path) -> dict:
    """Read a checkpoint into a dict (state, accumulators, history, options)."""
    from rftstatic.solvers.explicit import HISTORY_KEYS
    from rftstatic.solvers.timestep import StepEstimate

    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"checkpoint {path} does not exist")
    try:
        with np.load(path, allow_pickle=False) as z:
            if int(z["format"]) != FORMAT:
                raise CheckpointError(f"checkpoint {path}: format {int(z['format'])}, this version reads {FORMAT}")
            est = json.loads(str(z["estimate"]))
            out = {
                "fingerprint": str(z["fingerprint"]), "obstacles": str(z["obstacles"]),
                "t": float(z["t"]), "step": int(z["step"]), "n_steps": int(z["n_steps"]), "dt": float(z["dt"]),
                "U": z["U"].copy(), "V_half": z["V_half"].copy(), "acc": json.loads(str(z["acc"])),
                "estimate": None if est is None else StepEstimate(**est),
                "history": {k: z["history_" + k].tolist() for k in HISTORY_KEYS},
                "probes": list(z["probes"]),
                "frames": list(zip(z["frame_t"].tolist(), list(z["frame_U"]))),
                "options": {k[len("option_"):]: z[k] for k in z.files if k.startswith("option_")},
            }
    except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        if isinstance(exc, CheckpointError):
            raise
        raise CheckpointError(f"checkpoint {path} is corrupt or incomplete ({type(exc).__name__}: {exc}); "
                              "run without --resume to start again") from None
    return out


def resume(path, model, *, obstacles=(), callback=None, checkpoint=None, progress=True):
    """Continue the run saved in ``path`` to its ``t_end``; the result equals the uninterrupted run.

    Parameters
    ----------
    path : checkpoint written by a :class:`Checkpointer`
    model : the same model as the interrupted run (checked by fingerprint)
    obstacles : the same obstacles (checked against the saved descriptions)
    callback : as in :func:`rftstatic.solvers.explicit.run_explicit`
    checkpoint : a :class:`Checkpointer` for the continued run (default: none)

    Raises
    ------
    CheckpointError
        if the model or the obstacles differ from those of the saved run.
    """
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    data = load_checkpoint(path)
    if data["fingerprint"] != model_fingerprint(model):
        raise CheckpointError(
            f"checkpoint {path} was written for another model (mesh, supports, load, material or element "
            "differ); rebuild the model of the interrupted run")
    obstacles = tuple(obstacles) if not hasattr(obstacles, "signed_distance") else (obstacles,)
    if data["obstacles"] != _obstacles_spec(obstacles):
        raise CheckpointError(f"checkpoint {path}: obstacles differ from the saved run ({data['obstacles']})")
    o = data["options"]
    options = ExplicitOptions(t_end=float(o["t_end"]), dt=float(data["dt"]), alpha=float(o["alpha"]),
                              mass_scale=float(o["mass_scale"]), sample_every=int(o["sample_every"]),
                              energy_check=bool(o["energy_check"]), energy_tol=float(o["energy_tol"]),
                              rest_tol=float(o["rest_tol"]), safety=float(o["safety"]), backend=str(o["backend"]),
                              progress=progress)
    return run_explicit(model, options, obstacles=obstacles, frame_times=o["frame_times"], probes=o["probe_nodes"],
                        callback=callback, checkpoint=checkpoint, _restart=data)
