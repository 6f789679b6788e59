"""One fresh-process harness: run ``module:function(**kwargs)`` in a new interpreter and measure it.

Every child process of the benchmarks and of the validation reports goes through :func:`run_child`.
The child is a new ``sys.executable`` -- what multiprocessing's "spawn" start method does -- and
never a fork of the calling process: a fork copies the parent's locks but not the threads that hold
them, so after the parent has run a parallel region (numba's OpenMP pool, CHOLMOD's supernodal
factorisation on libgomp, a BLAS thread pool) a forked child waits forever at its first barrier
(``validate --quick`` did so in the stability cell "clamped plate 41x41").

The child imports the same ``rftstatic`` as the caller (the package's folder is put on
``PYTHONPATH`` and the working directory is not, ``python -P``), so a run never measures other code.
It calls the function, writes its return value as JSON and exits; the caller reads that file.

Measured by the caller from the child's own resource usage (``os.wait4``):

- ``wall_s`` [s]: start to exit, interpreter start-up and imports included;
- ``cpu_s`` [s]: user + system time of the child (and of any process it waited for);
- ``peak_rss_mb`` [MB]: the child's peak resident memory.

A child that exceeds its ``timeout`` is killed with its process group and :class:`ChildTimeout`
is raised; one that fails (an exception, a crash, a signal) raises :class:`ChildError`. Both name
the run (``name``) and carry the tail of the child's stderr.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

__all__ = ["ChildError", "ChildRun", "ChildTimeout", "run_child"]

STDERR_TAIL = 2000  # characters of the child's stderr kept in an error message
KILL_GRACE_S = 2.0  # after SIGTERM, seconds before SIGKILL


@dataclass
class ChildRun:
    """What a child returned and what it cost.

    ``result``: the function's return value after a JSON round trip (tuples become lists, numpy
    scalars and arrays Python numbers and lists); ``wall_s``, ``cpu_s`` [s] and ``peak_rss_mb`` [MB]
    of the whole child process (see the module docstring); ``stdout``, ``stderr``: its output.
    """

    name: str
    result: object
    wall_s: float
    cpu_s: float
    peak_rss_mb: float
    stdout: str
    stderr: str


class ChildError(RuntimeError):
    """A child process failed: the function raised, the interpreter crashed or a signal killed it.

    ``name``: the run; ``returncode``: the exit code (negative: the signal); ``exception``: the
    type name of the function's exception, if it raised one; ``stderr``: the child's stderr.
    """

    def __init__(self, message: str, *, name: str, returncode: int | None = None, exception: str | None = None,
                 stderr: str = "", wall_s: float = math.nan):
        super().__init__(message)
        self.name, self.returncode, self.exception, self.stderr, self.wall_s = (name, returncode, exception, stderr,
                                                                                 wall_s)


class ChildTimeout(ChildError):
    """A child process gave no result within its timeout and was killed."""


def run_child(target: str, kwargs: dict | None = None, *, name: str, timeout: float, cwd=None,
              env: dict | None = None) -> ChildRun:
    """Call ``target`` (``"package.module:function"``) with ``kwargs`` in a fresh interpreter.

    Parameters
    ----------
    target : ``"module:function"``; the function must be importable at module level.
    kwargs : keyword arguments, JSON-serialisable (numbers, strings, lists, dicts, None).
    name : what the run is, for messages (e.g. ``"drape bench pedestal-square-20 [...]"``).
    timeout : seconds of wall time before the child (and its process group) is killed.
    cwd, env : working directory and extra environment variables of the child (a ``PYTHONPATH``
        here goes after the package's folder).

    Returns
    -------
    :class:`ChildRun`. Raises :class:`ChildTimeout` or :class:`ChildError` (see the module docstring).
    """
    module, _, func = target.partition(":")
    if not module or not func:
        raise ValueError(f'run_child target must be "module:function", got {target!r}')
    with tempfile.TemporaryDirectory(prefix="rftstatic-child-") as tmp:
        job = Path(tmp)
        (job / "kwargs.json").write_text(json.dumps(kwargs or {}), encoding="utf-8")
        cmd = [sys.executable, "-P", "-m", "rftstatic.bench.harness", target, str(job)]
        with open(job / "stdout", "wb") as out, open(job / "stderr", "wb") as err:
            t0 = time.perf_counter()
            status, usage, timed_out = _run(cmd, out, err, cwd=cwd, env=_child_env(env), timeout=timeout)
            wall = time.perf_counter() - t0
        stdout = (job / "stdout").read_text(encoding="utf-8", errors="replace")
        stderr = (job / "stderr").read_text(encoding="utf-8", errors="replace")
        code = os.waitstatus_to_exitcode(status)
        tail = stderr[-STDERR_TAIL:]
        if timed_out:
            raise ChildTimeout(f"{name}: no result within the timeout of {timeout:g} s; the child process was "
                               f"killed (a hang, or a run longer than its budget: raise the timeout if it needs "
                               f"longer){_tail(tail)}", name=name, returncode=code, stderr=stderr, wall_s=wall)
        error = _read_json(job / "error.json")
        if code != 0 or error is not None:
            if error is not None:
                what = f"raised {error['type']}: {error['message']}"
            elif code < 0:
                what = f"was killed by signal {signal.Signals(-code).name}"
            else:
                what = f"exited with code {code}"
            raise ChildError(f"{name}: the child process {what}{_tail(tail)}", name=name, returncode=code,
                             exception=error["type"] if error else None, stderr=stderr, wall_s=wall)
        if not (job / "result.json").exists():
            raise ChildError(f"{name}: the child process exited without a result{_tail(tail)}", name=name,
                             returncode=code, stderr=stderr, wall_s=wall)
        result = _read_json(job / "result.json")
    return ChildRun(name=name, result=result, wall_s=wall, cpu_s=usage.ru_utime + usage.ru_stime,
                    peak_rss_mb=_maxrss_mb(usage.ru_maxrss), stdout=stdout, stderr=stderr)


def _run(cmd, out, err, *, cwd, env, timeout):
    """Start ``cmd`` in its own session; reap it with ``os.wait4``; kill its group after ``timeout`` [s].

    Returns (wait status, resource usage of the child, whether it was killed for the timeout).
    """
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=out, stderr=err, cwd=cwd, env=env,
                            start_new_session=True)
    reaped = {}

    def reap():
        reaped["wait"] = os.wait4(proc.pid, 0)

    waiter = threading.Thread(target=reap, name=f"wait4-{proc.pid}", daemon=True)
    waiter.start()
    timed_out = False
    try:
        waiter.join(timeout)
        if waiter.is_alive():
            timed_out = True
            _kill_group(proc.pid, waiter)
    finally:
        if waiter.is_alive():  # interrupted (Ctrl-C) or another error: the child must not outlive us
            _kill_group(proc.pid, waiter)
    _, status, usage = reaped["wait"]
    proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
    return status, usage, timed_out


def _kill_group(pid: int, waiter: threading.Thread) -> None:
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(pid, sig)
        except ProcessLookupError:
            pass
        waiter.join(KILL_GRACE_S if sig == signal.SIGTERM else None)
        if not waiter.is_alive():
            return


def _child_env(extra: dict | None) -> dict:
    from rftstatic.provenance import PACKAGE_DIR

    extra = dict(extra or {})
    env = dict(os.environ)
    paths = [str(PACKAGE_DIR.parent), extra.pop("PYTHONPATH", ""), env.get("PYTHONPATH", "")]
    env["PYTHONPATH"] = os.pathsep.join(p for part in paths for p in part.split(os.pathsep) if p)
    env.update(extra)
    return env


def _maxrss_mb(maxrss: int) -> float:
    return maxrss / 1024**2 if sys.platform == "darwin" else maxrss / 1024  # bytes on macOS, KiB on Linux


def _tail(stderr: str) -> str:
    return f"; its stderr ends:\n{stderr}" if stderr.strip() else ""


def _read_json(path: Path):
    return json.loads(path.read_text(encoding="utf-8")) if path.exists() else None


def _jsonable(v):
    if hasattr(v, "tolist"):  # numpy scalars and arrays
        return v.tolist()
    if isinstance(v, (set, frozenset)):
        return sorted(v)
    if isinstance(v, Path):
        return str(v)
    return float(v)


def _write_json(path: Path, value) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(value, default=_jsonable), encoding="utf-8")
    tmp.replace(path)  # the caller sees the whole file or none


def child_main(argv) -> int:
    """In the child: ``TARGET JOBDIR``; call the target with ``JOBDIR/kwargs.json``, write ``result.json``.

    An exception is written to ``error.json`` (type, message) and its traceback to stderr; exit code 1.
    """
    target, job = argv[0], Path(argv[1])
    module, _, func = target.partition(":")
    try:
        kwargs = json.loads((job / "kwargs.json").read_text(encoding="utf-8"))
        result = getattr(importlib.import_module(module), func)(**kwargs)
    except BaseException as exc:  # noqa: BLE001 -- every failure goes back to the caller
        traceback.print_exc()
        _write_json(job / "error.json", {"type": type(exc).__name__, "message": str(exc)})
        return 1
    sys.stdout.flush()
    _write_json(job / "result.json", result)
    return 0


if __name__ == "__main__":
    raise SystemExit(child_main(sys.argv[1:]))
