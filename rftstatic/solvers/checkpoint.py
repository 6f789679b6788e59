"""Checkpoints: one format for every run, a long run never loses finished work.

A checkpoint is one ``.npz`` file holding a header (what the run is: its kind, the model's fingerprint, the
scene, the options) and a :class:`~rftstatic.model.state.State`'s saved fields (:data:`SAVED`: U, V, t, step,
load factor, load branches, self-contact scale, Newton counts and, in ``State.route``, the position of every
route under way: an explicit run's records, the load steps' next increment, the relaxation route's phase, a
remesh driver's meshes). Arrays are stored as arrays, the rest as JSON (:func:`encode`). It is written to a
temporary file in the same directory, flushed to disk and moved over the old one with ``os.replace``, which is
atomic: a Ctrl-C or kill at any moment leaves either the previous checkpoint or the new one, never a partial
file. The routes (:mod:`rftstatic.solvers.drive`) go on from a restored State with exactly the saved numbers,
so a resumed run reproduces the uninterrupted one bitwise. :class:`CheckpointSaver` writes at the routes'
pauses; the app layer drives the routes with it.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import json
import logging
import os
import tempfile
import time
import zipfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from rftstatic.errors import CheckpointError, ConvergenceError

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


CHECKPOINT_FORMAT = 3
"""Version of the one checkpoint layout (key ``checkpoint_format``): a State and a header (3: the frictions' slips
as ``slip``, for both the bending and the shear friction)."""

SAVED = ("U", "V", "t", "step", "lam", "load_branches", "contact_history", "modes", "factorisations", "lm_scale",
         "modified_shift", "fallback", "route", "slip", "dissipated")
"""The :class:`~rftstatic.model.state.State` fields a checkpoint keeps (with ``self_contact_scale``,
``obstacle_offsets`` and ``obstacle_poses``); the contact candidate list, the self-contact pair cache and the linear solver are caches,
made again."""


def encode(value, arrays: dict):
    """``value`` as a JSON-able tree, its arrays stored in ``arrays`` (key ``"a<k>"``) and referenced by key.

    Takes None, bool, int, float (NaN and inf too), str, numpy scalars and arrays, lists (a list of arrays of one
    shape and type stored as one stacked array, a list of floats as one float array), tuples, dicts with
    str keys, the dataclasses of this package (by qualified name) and a
    :class:`~rftstatic.errors.ConvergenceError` (message and its ``result``). Arrays are copied: a snapshot
    kept in memory does not change with the State.
    """
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        key = f"a{len(arrays)}"
        arrays[key] = np.array(value)
        return {"@array": key}
    if isinstance(value, list):
        if len(value) > 1 and all(isinstance(v, np.ndarray) for v in value) and len({(v.shape, v.dtype) for v in value}) == 1:
            key = f"a{len(arrays)}"  # a list of like arrays (an explicit run's probe records): one stacked array
            arrays[key] = np.stack(value)
            return {"@stack": key}
        if len(value) > 1 and all(type(v) in (float, np.float64) for v in value):  # a history: one float array
            key = f"a{len(arrays)}"
            arrays[key] = np.array(value, dtype=float)
            return {"@floats": key}
        return [encode(v, arrays) for v in value]
    if isinstance(value, tuple):
        return {"@tuple": [encode(v, arrays) for v in value]}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError(f"a checkpoint keeps dicts with str keys only, got keys {list(value)[:3]!r}")
        return {"@dict": {k: encode(v, arrays) for k, v in value.items()}}
    if isinstance(value, ConvergenceError):
        return {"@error": str(value), "result": encode(value.result, arrays)}
    cls = type(value)
    if cls.__module__ == "rftstatic.model.state" and cls.__name__ == "State":  # a route's own State: its saved fields
        return {"@state": encode(saved_fields(value), arrays)}
    if dataclasses.is_dataclass(value) and cls.__module__.startswith("rftstatic."):
        return {"@dataclass": f"{cls.__module__}:{cls.__qualname__}",
                "fields": {f.name: encode(getattr(value, f.name), arrays) for f in dataclasses.fields(value)
                           if f.init}}
    raise TypeError(f"{cls.__name__} cannot be saved in a checkpoint")


def decode(tree, arrays):
    """The value :func:`encode` wrote (``arrays``: the open ``.npz`` or a dict)."""
    if isinstance(tree, list):
        return [decode(v, arrays) for v in tree]
    if not isinstance(tree, dict):
        return tree
    if "@array" in tree:
        return np.array(arrays[tree["@array"]])
    if "@floats" in tree:
        return arrays[tree["@floats"]].tolist()
    if "@stack" in tree:
        return list(np.array(arrays[tree["@stack"]]))
    if "@tuple" in tree:
        return tuple(decode(v, arrays) for v in tree["@tuple"])
    if "@dict" in tree:
        return {k: decode(v, arrays) for k, v in tree["@dict"].items()}
    if "@error" in tree:
        return ConvergenceError(tree["@error"], decode(tree["result"], arrays))
    if "@state" in tree:
        return SavedState(decode(tree["@state"], arrays))
    if "@dataclass" in tree:
        module, name = tree["@dataclass"].split(":")
        if not module.startswith("rftstatic."):
            raise ValueError(f"a checkpoint names class {tree['@dataclass']!r}, not one of rftstatic's")
        cls = importlib.import_module(module)
        for part in name.split("."):
            cls = getattr(cls, part)
        return cls(**{k: decode(v, arrays) for k, v in tree["fields"].items()})
    raise ValueError(f"unknown record in a checkpoint: keys {sorted(tree)!r}")


class SavedState(dict):
    """The saved fields of a State (:data:`SAVED`) read back from a checkpoint; :func:`as_state` makes the State."""


def saved_fields(state) -> dict:
    """The fields of ``state`` a checkpoint keeps (:data:`SAVED`, and the self-contact stiffness scale)."""
    saved = {name: getattr(state, name) for name in SAVED}
    saved["self_contact_scale"] = state.self_contact_scale
    saved["obstacle_offsets"] = state.obstacle_offsets
    saved["obstacle_poses"] = state.obstacle_poses
    return saved


def as_state(model, value):
    """``value`` itself, or the State of ``model`` it was saved as (a :class:`SavedState`, its caches new)."""
    return restore_state(model, value) if isinstance(value, SavedState) else value


def state_arrays(state, header: dict) -> dict:
    """The arrays of a checkpoint of ``state`` (its :data:`SAVED` fields and self-contact scale) under
    ``header`` (JSON-able: what the run was, checked on resume)."""
    arrays = {}
    tree = encode(saved_fields(state), arrays)
    return {"checkpoint_format": np.array(CHECKPOINT_FORMAT), "header": json_array(header),
            "state": json_array(tree), **arrays}


def read_checkpoint(path) -> tuple[dict, dict]:
    """``(header, saved)``: the header and the saved State fields of the checkpoint ``path``.

    Raises
    ------
    CheckpointError
        if the file is missing, corrupt, or not written in this format (the message names the file and the fix).
    """
    path = Path(path)
    if not path.exists():
        raise CheckpointError(f"checkpoint {path} does not exist")
    try:
        with np.load(path, allow_pickle=False) as z:
            if "checkpoint_format" not in z.files:
                raise CheckpointError(f"checkpoint {path} was written by an older version of rftstatic; run "
                                      "without --resume")
            if int(z["checkpoint_format"]) != CHECKPOINT_FORMAT:
                raise CheckpointError(f"checkpoint {path}: format {int(z['checkpoint_format'])}, this version reads "
                                      f"{CHECKPOINT_FORMAT}; run without --resume")
            header = json.loads(str(z["header"]))
            saved = decode(json.loads(str(z["state"])), z)
    except (OSError, ValueError, KeyError, TypeError, AttributeError, ImportError, zipfile.BadZipFile,
            json.JSONDecodeError) as exc:
        if isinstance(exc, CheckpointError):
            raise
        raise CheckpointError(f"checkpoint {path} is corrupt or incomplete ({type(exc).__name__}: {exc}); "
                              "delete it or run without --resume to start again") from None
    return header, saved


def restore_state(model, saved: dict, state=None):
    """``state`` (default a fresh :meth:`~rftstatic.model.state.State.initial` of ``model``, its caches new; for
    ``model`` None, a State without caches: a remeshed run's, whose models its route makes) with the saved
    fields of :func:`read_checkpoint` set."""
    from rftstatic.model.state import State

    if state is None:
        state = State(U=saved["U"], V=saved["V"]) if model is None else State.initial(model)
    for name in SAVED:
        if name in saved:
            setattr(state, name, saved[name])
    if state.self_pairs is not None:
        state.self_contact_scale = saved.get("self_contact_scale", 1.0)
    if state.candidates is not None:
        state.obstacle_offsets = saved.get("obstacle_offsets")
        if saved.get("obstacle_poses") is not None:  # a rotated pose (offsets: its translation part)
            state.obstacle_poses = saved["obstacle_poses"]
    return state


class CheckpointSaver:
    """Saves a State at its routes' pauses (:class:`~rftstatic.solvers.drive.Pause`) to one file, in the one
    format (:func:`state_arrays`): a final pause at once, the others when due (every ``every_seconds`` of wall
    time, or every ``every_steps`` explicit steps), the last snapshot held back written on an interrupt.

    Interrupts (:meth:`stopping`): the first Ctrl-C asks the run to stop at its next pause, which is saved
    (``KeyboardInterrupt("... checkpoint saved")``); a second stops at once, and the snapshot held back, if any,
    is written.

    Attributes: ``writes`` (files written), ``write_time`` (wall time spent writing them [s]), ``saved`` (what the
    last write holds, for messages).

    Parameters
    ----------
    path : the checkpoint file (``.npz``)
    header : what the run is (JSON-able), saved to refuse another run's checkpoint
    every_seconds : least wall time between two writes [s] (0: every pause; None: not by wall time)
    every_steps : save after every so many explicit steps (None: not by steps)
    run : names the run in messages (e.g. ``"the static solve"``)
    """

    def __init__(self, path, header: dict, *, every_seconds: float | None = None, every_steps: int | None = None,
                 run: str = "the run"):
        if every_steps is not None and not every_steps >= 1:
            raise ValueError(f"every_steps must be >= 1, got {every_steps}")
        self.path = Path(path)
        self.every_seconds = float("inf") if every_seconds is None else float(every_seconds)
        self.header, self.run, self.every_steps = header, run, every_steps
        self.interrupted = False
        self.writes, self.write_time, self.saved = 0, 0.0, ""
        self._pending = None
        self._last = time.monotonic()

    def due(self) -> bool:
        """Whether ``every_seconds`` have passed since the last write."""
        return time.monotonic() - self._last >= self.every_seconds

    def _write(self, arrays, what) -> None:
        t = time.perf_counter()
        save_atomic(self.path, arrays)
        self.write_time += time.perf_counter() - t
        self.writes += 1
        self.saved, self._pending, self._last = what, None, time.monotonic()
        log.info("checkpoint (%s) -> %s", what, self.path)

    def flush(self) -> None:
        """Write the snapshot held back by the throttle, if any."""
        if self._pending is not None:
            self._write(*self._pending)

    @contextmanager
    def on_interrupt(self):
        """A KeyboardInterrupt inside writes the last snapshot held back before it goes on."""
        try:
            yield self
        except KeyboardInterrupt:
            self.flush()
            if self.writes:
                log.warning("interrupted: %s is saved in %s (%s); continue it with --resume", self.run, self.path,
                            self.saved)
            raise

    def pause(self, state, pause) -> None:
        """``state`` at a route's ``pause``: written when final or due (kept back, if ``pause.keep``, when not);
        after a first Ctrl-C, written and the run stopped."""
        by_step = self.every_steps is not None and pause.step is not None and pause.step % self.every_steps == 0
        write = self.interrupted or pause.final or by_step or self.due()
        if not (write or pause.keep):
            return  # the explicit runs' many pauses: no message formatted, nothing encoded
        what = pause.what or f"t = {state.t:.6g} s, step {state.step}"
        if write:
            self._write(state_arrays(state, self.header), what)
        else:
            self._pending = (state_arrays(state, self.header), what)
        if self.interrupted:
            raise KeyboardInterrupt(f"interrupted at {what}; checkpoint saved")

    def on(self, state):
        """The ``on_pause`` of :func:`~rftstatic.solvers.drive.drive` for a route stepping ``state``."""
        return lambda pause: self.pause(state, pause)

    @contextmanager
    def stopping(self):
        """Inside: Ctrl-C stops the run at its next pause (saved); a second Ctrl-C at once (the held-back
        snapshot saved). The SIGINT handler is installed only in the main thread, and restored after."""
        import signal
        import threading

        if threading.current_thread() is not threading.main_thread():
            with self.on_interrupt():
                yield self
            return
        previous = signal.getsignal(signal.SIGINT)

        def ask(signum, frame):
            if self.interrupted:
                raise KeyboardInterrupt
            self.interrupted = True
            log.warning("interrupt: stopping %s at its next pause (Ctrl-C again to stop at once)", self.run)

        signal.signal(signal.SIGINT, ask)
        try:
            with self.on_interrupt():
                yield self
        finally:
            signal.signal(signal.SIGINT, previous)


def explicit_header(model, obstacles) -> dict:
    """What an explicit run's checkpoint is for: the model's fingerprint and its obstacles."""
    obstacles = tuple(obstacles) if not hasattr(obstacles, "signed_distance") else (obstacles,)
    return {"kind": "explicit", "model": model_fingerprint(model), "obstacles": _obstacles_spec(obstacles)}


def load_explicit_state(path, model, obstacles=(), *, progress: bool = True):
    """``(state, options, frame_times, probes)``: the State of the explicit run of ``model`` saved in ``path``
    (its ``route`` holds the run's position) and the arguments of
    :func:`~rftstatic.solvers.explicit.explicit_steps` that continue it as the uninterrupted run.

    Raises
    ------
    CheckpointError
        if the file is missing, corrupt, not an explicit run's, or written for another model or obstacles.
    """
    from rftstatic.solvers.explicit import EXPLICIT
    from rftstatic.solvers.explicit_options import ExplicitOptions

    header, saved = read_checkpoint(path)
    if header.get("kind") != "explicit":
        raise CheckpointError(f"checkpoint {path} was not written by a dynamic or relax run (a {header.get('kind')} "
                              "run's); run without --resume")
    mine = explicit_header(model, obstacles)
    if header["model"] != mine["model"]:
        raise CheckpointError(
            f"checkpoint {path} was written for another model (mesh, supports, load, material or element "
            "differ); rebuild the model of the interrupted run")
    if header["obstacles"] != mine["obstacles"]:
        raise CheckpointError(f"checkpoint {path}: obstacles differ from the saved run ({header['obstacles']})")
    state = restore_state(model, saved)
    position = state.route[EXPLICIT]
    o = position["options"]
    options = ExplicitOptions(t_end=float(o["t_end"]), dt=float(position["dt"]), alpha=float(o["alpha"]),
                              damping=str(o.get("damping", "viscous")), mass_scale=float(o["mass_scale"]),
                              sample_every=int(o["sample_every"]),
                              energy_check=bool(o["energy_check"]), energy_tol=float(o["energy_tol"]),
                              rest_tol=float(o["rest_tol"]), safety=float(o["safety"]), backend=str(o["backend"]),
                              progress=progress)
    return state, options, o["frame_times"], o["probe_nodes"]
