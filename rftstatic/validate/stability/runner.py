"""Running one cell of the stability matrix in a fresh child interpreter, within its budget.

:func:`run_cell` (in the caller) starts the child with :func:`rftstatic.bench.harness.run_child` --
a new interpreter, as multiprocessing's "spawn" start method makes, never a fork: a forked child
inherits the locks of the caller's threads (numba's OpenMP pool, CHOLMOD's libgomp team) without the
threads, and hung at its first parallel region once the caller had solved a large model (``validate
--quick`` in "clamped plate 41x41"). A child still running after the cell's budget is killed, and
the cell is a FAIL ("hang") named in the report, so nothing can hang the matrix.

:func:`cell_record` (in the child) calls the cell's function and turns its result, or its exception
(type, message, the end of the traceback and the solver statistics it carries), into a JSON record.
"""

from __future__ import annotations

import time
import traceback

import numpy as np

from rftstatic.validate.stability.matrix import Cell, verdict


def run_cell(cell: Cell) -> dict:
    """Run one cell in a fresh child process with its budget; return its record with the verdict.

    The record adds ``wall_time_s`` [s] (the cell's function in the child; for a cell that produced
    no result, the child process's time), ``process_s`` [s] and ``cpu_s`` [s] (the whole child,
    start-up included), ``peak_rss_mb`` [MB] (its peak memory), ``group``, ``case``, ``tolerance``,
    ``budget_s``, ``verdict`` and ``reason``.
    """
    from rftstatic.bench.harness import ChildError, ChildTimeout, run_child

    label = f'stability cell "{cell.group}: {cell.name}"'
    try:
        run = run_child("rftstatic.validate.stability.runner:cell_record", {"func": cell.func, "kw": cell.kw},
                        name=label, timeout=cell.budget)
    except ChildTimeout as exc:
        rec = {"exception": "timeout", "message": f"{label}: no result within the budget of {cell.budget:g} s; the "
                                                  "child process was killed", "wall_time_s": exc.wall_s,
               "process_s": exc.wall_s}
    except ChildError as exc:
        rec = {"exception": "process died", "message": str(exc).split("; its stderr ends:")[0],
               "traceback": exc.stderr[-600:], "wall_time_s": exc.wall_s, "process_s": exc.wall_s}
    else:
        rec = run.result
        rec.update(process_s=run.wall_s, cpu_s=run.cpu_s, peak_rss_mb=run.peak_rss_mb)
    rec.update(group=cell.group, case=cell.name, tolerance=cell.tolerance, budget_s=cell.budget)
    rec["verdict"], rec["reason"] = verdict(cell, rec)
    return rec


def cell_record(func: str, kw: dict) -> dict:
    """In the child: ``func(**kw)`` of :mod:`~rftstatic.validate.stability.cell_functions` as a plain record.

    An exception is the record (``exception``: its type name, ``message``, ``traceback``: its last
    frames, and the solver statistics of the result it carries, if any); ``wall_time_s`` [s]: the call.
    """
    import logging

    from rftstatic.validate.stability import cell_functions

    logging.disable(logging.WARNING)
    t0 = time.perf_counter()
    try:
        rec = getattr(cell_functions, func)(**kw)
    except BaseException as exc:  # noqa: BLE001 -- recorded, judged by the parent
        rec = {"exception": type(exc).__name__, "message": str(exc),
               "traceback": "".join(traceback.format_exception(exc)[-6:])}
        res = getattr(exc, "result", None)
        if res is not None and hasattr(res, "tangent_modes"):
            rec.update(iterations=res.iterations, load_steps=len(res.load_steps), cutbacks=res.cutbacks,
                       tangent_modes=dict(res.tangent_modes), lam=res.lam)
    rec["wall_time_s"] = time.perf_counter() - t0
    return _plain(rec)


def _plain(v):
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    return v
