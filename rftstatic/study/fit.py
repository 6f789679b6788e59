"""``python -m rftstatic fit SCENE --free KEY=LO:HI [...] --target MEASURE=VALUE [...]``: fabric parameters
from measurements.

The free keys are mapped to u in [0, 1] (log(value) when LO > 0, so a rigidity is searched by its order
of magnitude) and ``scipy.optimize.least_squares`` (trust-region reflective, bounds [0, 1]) minimises
0.5 sum_i r_i^2 with r_i = (m_i(u) - t_i) / |t_i| (t_i = 0: the absolute difference), starting from
the middle of the box. Every evaluation is a point of a study (:mod:`rftstatic.study.sweep`): it runs
on the Dask client, is kept in ``results.csv`` and is never run twice, so a repeated fit replays from
its table without a cluster. Each evaluation of r(u) sends u together with its forward-difference
neighbours u + h e_j in one batch (the Jacobian's points run in parallel with it; on a rejected trial
step they are wasted: n points that ran beside the one that had to).

At the optimum, the sensitivity of each target to each free key, s = d log m / d log k, comes from
central differences at k (1 +- :data:`SENSITIVITY_STEP`), again in one batch. A target with
|s| < :data:`WEAK_SENSITIVITY` is reported: a relative error e of the measurement (or of the mesh)
becomes about e / |s| in the fitted key (the strip's tip drop: s = -0.10, 10 x; its reach: 0.65).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from rftstatic.io.files import write_json
from rftstatic.study.measures import check_measure, standard_columns
from rftstatic.study.runner import Engine
from rftstatic.study.space import StudyError, parse_free, parse_value
from rftstatic.study.store import Store, record_run
from rftstatic.study.sweep import Study, load_base

FD_STEP = 1e-3
"""Forward-difference step in u (the unit box): 0.23 % of the value for a decade-wide log range."""
SENSITIVITY_STEP = 0.01
"""Relative change of a key for the sensitivities at the optimum (1 %)."""
WEAK_SENSITIVITY = 0.2
"""Below this |d log measure / d log key| a target is reported as barely depending on the key."""


class FitFailed(RuntimeError):
    """An evaluation of the fit failed or did not converge (the command exits with status 3)."""


def parse_targets(texts, scene) -> dict:
    """``--target MEASURE=VALUE`` -> {MEASURE: value}, each path checked against ``scene``."""
    if not texts:
        raise StudyError("--target: give at least one, e.g. --target probes.tip.x=1.77")
    out = {}
    for text in texts:
        if "=" not in text:
            raise StudyError(f'--target "{text}": expected MEASURE=VALUE, e.g. --target probes.tip.z=-4.35')
        path, raw = (s.strip() for s in text.split("=", 1))
        check_measure(path, scene, "--target")
        value = parse_value(raw)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise StudyError(f'--target "{text}": the value "{raw}" is not a finite number')
        out[path] = float(value)
    return out


class Evaluator:
    """Measures at batches of points of the unit box, from the store or run on the engine."""

    def __init__(self, study: Study, store: Store, engine: Engine, free, targets: dict):
        self.study, self.store, self.engine, self.free, self.targets = study, store, engine, free, targets
        self.points_run = 0
        self.history: list[dict] = []

    def values(self, u) -> dict:
        return {r.key: r.value(float(ui)) for r, ui in zip(self.free, u)}

    def rows(self, points: list[dict], label: str) -> list[dict]:
        """The rows at ``points`` ({key: value} each), running those not in the store in one batch."""
        specs = [self.study.spec(p, arg="--free") for p in points]
        self.store.recover([s["key"] for s in specs])
        todo, seen = [], set()
        for s in specs:
            if s["key"] not in seen and not self.store.done(s["key"], needs=self.targets):
                todo.append(s)
                seen.add(s["key"])
        self.engine.run(todo, self.store.add, label=label)
        self.points_run += len(todo)
        rows = [self.store.rows[s["key"]] for s in specs]
        for row in rows:
            if row.get("status") != "ok":
                raise FitFailed(f"the evaluation at {_shown(row, self.free)} {row.get('status')}: "
                                f"{row.get('error') or 'converged = false'} (its folder: {row.get('folder')})")
            missing = [m for m in self.targets if row.get(m) is None]
            if missing:
                raise StudyError(f"--target {missing[0]}: the scene's summary has no value for it (at "
                                 f"{_shown(row, self.free)}); see its summary.json in {row.get('folder')}")
        return rows

    def residuals(self, row: dict) -> np.ndarray:
        return np.array([(row[m] - t) / (abs(t) if t else 1.0) for m, t in self.targets.items()])


def _shown(row, free) -> str:
    return ", ".join(f"{r.key}={row.get(r.key)!r}" for r in free)


def _neighbour(u: np.ndarray, j: int) -> tuple[np.ndarray, float]:
    step = FD_STEP if u[j] + FD_STEP <= 1.0 else -FD_STEP
    v = u.copy()
    v[j] += step
    return v, step


def minimise(ev: Evaluator, *, max_evaluations: int = 100):
    """Bounded least squares over the unit box (module docstring); returns scipy's result."""
    from scipy.optimize import least_squares

    cache: dict[tuple, np.ndarray] = {}

    def fun(u):
        u = np.clip(np.asarray(u, float), 0.0, 1.0)
        batch = [u] + [_neighbour(u, j)[0] for j in range(len(u))]
        rows = ev.rows([ev.values(v) for v in batch], label=f"fit evaluation {len(ev.history) + 1}")
        for v, row in zip(batch, rows):
            cache[tuple(v)] = ev.residuals(row)
        r = cache[tuple(u)]
        ev.history.append({"evaluation": len(ev.history) + 1, "values": ev.values(u),
                           "measures": {m: rows[0][m] for m in ev.targets}, "objective": 0.5 * float(r @ r)})
        return r

    def jac(u):
        u = np.clip(np.asarray(u, float), 0.0, 1.0)
        r0 = cache[tuple(u)] if tuple(u) in cache else fun(u)
        J = np.empty((len(r0), len(u)))
        for j in range(len(u)):
            v, step = _neighbour(u, j)
            J[:, j] = (cache[tuple(v)] - r0) / step
        return J

    u0 = np.array([0.5] * len(ev.free))
    return least_squares(fun, u0, jac=jac, bounds=(0.0, 1.0), method="trf", x_scale=1.0, ftol=1e-12,
                         xtol=1e-10, gtol=1e-12, max_nfev=max_evaluations)


def sensitivities(ev: Evaluator, fitted: dict) -> dict:
    """{measure: {key: d log measure / d log key}} at ``fitted``, by central differences of 1 % (one batch)."""
    points = []
    for r in ev.free:
        for sign in (1, -1):
            points.append({**fitted, r.key: fitted[r.key] * (1 + sign * SENSITIVITY_STEP)})
    rows = ev.rows([fitted] + points, label="fit sensitivities")
    centre, out = rows[0], {m: {} for m in ev.targets}
    for j, r in enumerate(ev.free):
        plus, minus = rows[1 + 2 * j], rows[2 + 2 * j]
        for m in ev.targets:
            denom = 2 * SENSITIVITY_STEP * centre[m]
            out[m][r.key] = (plus[m] - minus[m]) / denom if denom else None
    return out


def weak_warnings(sens: dict) -> list[str]:
    """One line per target that barely depends on a free key (|s| < :data:`WEAK_SENSITIVITY`)."""
    lines = []
    for m, by_key in sens.items():
        for k, s in by_key.items():
            if s is not None and abs(s) < WEAK_SENSITIVITY:
                amp = f"~{1 / abs(s):.0f} x" if s else "without bound"
                lines.append(f"target {m} barely depends on {k}: it moves {s:+.3g} % per 1 % of {k}, so an "
                             f"error in the measurement or the mesh is amplified {amp} in the fitted {k}")
    return lines


def run_fit(scene: str, free_texts, target_texts, *, sets=(), out=None, scheduler=None, workers=None,
            figures=False, max_evaluations=100, argv=None) -> dict:
    """The ``fit`` command (module docstring); returns what ``fit.json`` holds."""
    t0 = time.perf_counter()
    base = load_base(scene, sets)
    free = parse_free(free_texts)
    targets = parse_targets(target_texts, base)
    out = Path(out) if out else Path("out") / f"fit-{base.name}"
    study = Study(scene, list(sets), out, list(dict.fromkeys(standard_columns(base) + list(targets))), figures)
    for r in free:  # each key alone first, so that the error names its --free argument
        study.spec({r.key: r.lo}, arg="--free")
    store = Store(out, [r.key for r in free] + study.measures)
    engine = Engine(scheduler, workers)
    ev = Evaluator(study, store, engine, free, targets)
    try:
        res = minimise(ev, max_evaluations=max_evaluations)
        fitted = ev.values(np.clip(res.x, 0.0, 1.0))
        sens = sensitivities(ev, fitted)
        optimum = ev.rows([fitted], label="fit optimum")[0]  # in the store already (the sensitivities' centre)
        achieved = {m: optimum[m] for m in targets}
        info = engine.info()
    finally:
        engine.close()
    warnings = weak_warnings(sens)
    result = {"scene": base.name, "sets": list(sets), "free": {r.key: [r.lo, r.hi] for r in free},
              "targets": targets, "fitted": fitted, "achieved": achieved,
              "relative_mismatch": {m: (achieved[m] - t) / abs(t) if t else achieved[m] - t for m, t in targets.items()},
              "success": bool(res.success), "message": res.message, "objective": 0.5 * float(res.fun @ res.fun),
              "evaluations": len(ev.history), "points": len(store.rows), "points_run": ev.points_run,
              "sensitivity": sens, "warnings": warnings, "history": ev.history, "engine": info,
              "wall_time_s": time.perf_counter() - t0}
    write_json(out / "fit.json", result)
    record_run(out, {"kind": "fit", "command": argv, "scene": base.name, "sets": list(sets),
                     "free": result["free"], "targets": targets},
               {**info, "points_run": ev.points_run, "wall_time_s": result["wall_time_s"]})
    _report(result, out)
    return result


def _report(result: dict, out: Path) -> None:
    for k, v in result["fitted"].items():
        print(f"fitted {k} = {v:.6g}")
    for m, t in result["targets"].items():
        print(f"  {m}: target {t:.6g}, fitted {result['achieved'][m]:.6g} "
              f"({100 * result['relative_mismatch'][m]:+.3g} %); d log / d log: "
              + ", ".join(f"{k} {s:+.3f}" for k, s in result["sensitivity"][m].items() if s is not None))
    print(f"{result['evaluations']} evaluations, {result['points_run']} points run ({result['points']} kept) in "
          f"{result['wall_time_s']:.1f} s; {out}/fit.json", flush=True)
    for line in result["warnings"]:
        print(f"warning: {line}", file=sys.stderr)
