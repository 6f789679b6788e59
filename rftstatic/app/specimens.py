"""Several specimens of one drape test: the static drape solved from ``solver.seeds`` seeded starts.

A drape tester's result scatters from specimen to specimen (the fold count above all: a drape has several
stable equilibria, §6.2), so labs average several specimens (how many the
standards ask for is unverified here: docs/howto/textile-tests.md).
The same scatter appears in the simulation when the seeded lift that tips the flat start off its
bifurcation changes: :func:`seeded_specimens` solves the scene's model from seeds ``seed + 1, ...`` (the
first specimen is the run itself) and reports every drape coefficient and fold count with their mean
and range, in the scene's units.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from rftstatic.app.levels import solve_levels
from rftstatic.app.starts import keep_lower
from rftstatic.errors import ConvergenceError
from rftstatic.io.summary import drape_summary
from rftstatic.scenes.options import run_options
from rftstatic.solvers.static import solve_static

log = logging.getLogger(__name__)


def seeded_specimens(scene, model, extras, opts, first: dict, n: int, first_energy: float | None = None,
                     compare: str | None = None) -> dict:
    """Solve ``model`` from ``n - 1`` further seeds after ``opts.route.seed`` and summarise all ``n`` drapes.

    ``first``: the drape summary of the run's own solve (seed ``opts.route.seed``), ``first_energy`` its total
    potential energy (scene units). A seed whose solve does not converge is listed (``converged: false``) and left
    out of the statistics. ``lowest_energy``: the specimen whose drape has the lowest total potential energy, the
    best minimum found of the one model (the drapes of a drape test are several stable equilibria, §6.2).
    ``compare``: every further specimen is also solved from that start and keeps the lower stable minimum
    (:func:`rftstatic.app.starts.keep_lower`; its row names the ``start`` kept).
    """
    rows = [{"seed": opts.route.seed, "converged": True, **_row(first), "energy": first_energy}]
    levels = run_options(scene).levels
    for k in range(1, n):
        t0 = time.perf_counter()
        start = None
        seeded = opts.replace(seed=opts.route.seed + k, progress=False)
        try:
            res = solve_levels(scene, model, seeded) if levels > 1 else solve_static(model, options=seeded)
            ok = bool(res.converged)
            if ok and compare is not None:
                res, kept = keep_lower(scene, model, seeded, res, compare, lambda U: {})
                start = kept["kept"]
        except ConvergenceError as exc:
            log.warning("seed %d: %s", seeded.route.seed, exc)
            res, ok = exc.result, False
        row = {"seed": seeded.route.seed, "converged": ok, "wall_time_s": time.perf_counter() - t0}
        if compare is not None:
            row["start"] = start if ok else None
        if ok:
            row.update(_row(drape_summary(scene, model, extras, res.U)), stable_minimum=res.stable,
                       energy=res.energies.get("total", np.nan) / scene.units.energy)
        rows.append(row)
    good = [r for r in rows if r["converged"] and r.get("drape_coefficient_percent") is not None]
    dc = np.array([r["drape_coefficient_percent"] for r in good])
    folds = [r["fold_count"] for r in good]
    out = {"count": n, "solved": len(good), "specimens": rows, "fold_counts": folds}
    if len(dc):
        out.update(drape_coefficient_percent_mean=float(dc.mean()), drape_coefficient_percent_min=float(dc.min()),
                   drape_coefficient_percent_max=float(dc.max()),
                   drape_coefficient_percent_std=float(dc.std(ddof=1)) if len(dc) > 1 else 0.0,
                   fold_count_mean=float(np.mean(folds)))
    known = [r for r in good if r.get("energy") is not None and np.isfinite(r["energy"])]
    if known:
        out["lowest_energy"] = min(known, key=lambda r: r["energy"])
    return out


def _row(drape: dict) -> dict:
    return {k: drape.get(k) for k in ("drape_coefficient_percent", "fold_count", "fold_angles_deg")}
