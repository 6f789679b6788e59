"""What a Dask worker runs for one point of a study: :func:`run_point`.

The worker process is a fresh interpreter (Dask's nanny spawns it; never a fork of a process whose
numba or BLAS threads have started). One point runs on one thread: :data:`THREAD_VARIABLES` are set
to 1 before numpy or numba are first imported in the process (the LocalCluster passes them in the
workers' environment; :func:`run_point` sets what is still unset), so that N workers use N cores.
"""

from __future__ import annotations

import os
import time
import traceback

THREAD_VARIABLES = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "RFTSTATIC_THREADS")
"""Environment of a worker: one thread for numba, OpenMP (CHOLMOD), BLAS and the explicit kernel."""
STARTED = ".started"
"""Suffix of the file beside a point's folder (``points/KEY.started``) while the point runs: its existence
tells the driver (which enforces ``--timeout``) that the point left the queue and is running, whatever
the clocks of driver and worker (the run replaces its folder as a whole, so the file is not inside)."""


def started_marker(folder) -> str:
    """``points/KEY.started`` for the point folder ``points/KEY``."""
    return os.fspath(folder).rstrip("/\\") + STARTED


def worker_environment() -> dict:
    """:data:`THREAD_VARIABLES` set to ``"1"``."""
    return {name: "1" for name in THREAD_VARIABLES}


def _worker_address() -> str:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):  # not in a Dask worker (a test, or an in-process run)
        return f"pid:{os.getpid()}"


def run_point(spec: dict) -> dict:
    """Run one point and return its row (also written to ``point.json`` in its folder).

    ``spec``: ``scene`` (name or path), ``overrides`` (``["key=value", ...]``: the study's and the
    point's), ``key``, ``folder``, ``values`` (the varied keys' values), ``measures`` (MEASURE paths),
    ``figures``, ``code`` (the driver's code fingerprint: a worker with other code refuses the point).
    A failure is a row with ``status = "failed"`` and the error, never an exception.
    """
    for name, value in worker_environment().items():
        os.environ.setdefault(name, value)
    from rftstatic import api
    from rftstatic.io.files import write_json
    from rftstatic.provenance import code_fingerprint
    from rftstatic.study.measures import flat_measures

    t0 = time.perf_counter()
    stale = os.path.join(spec["folder"], "point.json")
    if os.path.exists(stale):  # a failed point's row, retried: the run needs an empty or a run's folder
        os.remove(stale)
    row = {"key": spec["key"], **spec["values"], "worker": _worker_address(), "folder": f"points/{spec['key']}"}
    summary, error = None, None
    started = started_marker(spec["folder"])
    os.makedirs(os.path.dirname(started), exist_ok=True)
    with open(started, "w", encoding="utf-8") as fh:  # the --timeout clock starts (the imports are done)
        fh.write(row["worker"])
    try:
        if code_fingerprint() != spec["code"]:
            raise RuntimeError(f"this worker runs other rftstatic code (fingerprint {code_fingerprint()[:12]}) "
                               f"than the driver ({spec['code'][:12]}): install the same version on every worker")
        scene = api.load_scene(spec["scene"], spec["overrides"])
        summary = api.run(scene, spec["folder"], figures=spec["figures"]).summary
    except api.ConvergenceError as exc:  # the last equilibrium was written, labelled converged = false
        error = f"ConvergenceError: {exc}"
        summary = _read_summary(spec["folder"])
    except Exception as exc:  # noqa: BLE001 - a failed point is a row, never a lost study
        error = f"{type(exc).__name__}: {exc}"
        traceback.print_exc()
    if summary is not None:
        row.update(flat_measures(summary, spec["measures"]))
        row.update(converged=bool(summary.get("converged")), route=summary.get("route"))
    row["status"] = "failed" if summary is None else ("ok" if row.get("converged") else "not converged")
    row["error"] = None if error is None else " ".join(error.split())[:500]
    row["wall_time_s"] = time.perf_counter() - t0
    os.makedirs(spec["folder"], exist_ok=True)
    write_json(os.path.join(spec["folder"], "point.json"), row)
    if os.path.exists(started):
        os.remove(started)
    return row


def _read_summary(folder: str) -> dict | None:
    import json

    path = os.path.join(folder, "summary.json")
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as fh:
        return json.load(fh)
