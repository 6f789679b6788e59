"""The drape solved from a second start, and the lower of the two equilibria kept (``solver.compare``).

A drape test has several stable equilibria (§6.2), and which one a route reaches depends on the route: the dynamic
relaxation and the quasi-static release keep the folds that form first as the specimen falls, the load steps follow
the branch that the gravity ramp picks from the flat sheet (on ``cusick-30``, the orthotropic wool's four nodes). A
specimen that settles, tapped or touched, leaves a shallow minimum for a deeper one. With ``solver.compare = START``
the drape is also solved from ``START`` (a ``solver.start`` value) and :func:`keep_lower` keeps the equilibrium of
lower total potential energy among those that converged to a stable minimum; both are listed in ``summary.json``
(``starts``). With ``solver.seeds`` every specimen is compared so.
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.solvers.static import solve_static

log = logging.getLogger(__name__)

__all__ = ["keep_lower"]


def _row(start, result, ok, wall, scene, summarise) -> dict:
    row = {"start": start, "converged": bool(ok), "stable_minimum": result.stable if result is not None else None,
           "wall_time_s": wall}
    if ok:
        row["energy"] = result.energies.get("total", np.nan) / scene.units.energy
        row.update(summarise(result.U))
    return row


def keep_lower(scene, model, opts, result, other: str, summarise, *, wall: float = float("nan")):
    """``(kept, table)``: the equilibrium ``result`` of the route ``opts.route.start`` against the one
    :func:`~rftstatic.solvers.static.solve_static` reaches from ``solver.start = other`` (same model and options); the
    kept one is the stable minimum of lower total energy (the first when neither or only it is a stable minimum).

    ``summarise(U)``: the drape's measures for the table (e.g. its fold count and DC); ``wall``: the first solve's
    wall time [s] (given, the kept result's ``wall_time`` is the two solves' together). ``table``: ``{"compared": [row, row], "kept": start}``, each row with the start, converged,
    stable_minimum, energy (scene units), the measures and the wall time; a failed second solve is logged and listed
    (``converged: false``)."""
    rows = [_row(opts.route.start, result, True, wall, scene, summarise)]
    t0 = time.perf_counter()
    try:
        second = solve_static(model, options=opts.replace(start=other, progress=False))
        ok = bool(second.converged)
    except ConvergenceError as exc:
        log.warning("solver.compare = %r: %s", other, exc)
        second, ok = exc.result, False
    rows.append(_row(other, second, ok, time.perf_counter() - t0, scene, summarise))
    kept = result
    if ok and second.stable and (not result.stable or rows[1]["energy"] < rows[0]["energy"]):
        kept = second
    start = other if kept is second else opts.route.start
    if np.isfinite(wall) and kept.wall_time is not None:  # the drape's solve time: both routes'
        kept = replace(kept, wall_time=wall + rows[1]["wall_time_s"])
    log.info("solver.compare: %s drape kept (energies %s)", start,
             ", ".join(f"{r['start']} {r.get('energy', float('nan')):.6g}" for r in rows))
    return kept, {"compared": rows, "kept": start}
