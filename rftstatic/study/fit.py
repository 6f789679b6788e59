"""``python -m rftstatic fit SCENE [--run LABEL[@SCENE]:KEY=VALUE,...] --free KEY=LO:HI [...] --target
[LABEL:]MEASURE=VALUE [...]``: fabric parameters from measurements, of one run or of several.

A fit has one or more *runs* of the scene: without ``--run``, the scene itself (targets ``MEASURE=VALUE``);
with ``--run LABEL[@SCENE]:OVERRIDES`` (repeated), one run per label, each the scene (or its own SCENE,
e.g. a cantilever tester beside a drape) with the study's ``--set`` and then its own overrides
(``--run warp:`` none, ``--run weft:material.warp_angle=90``; several ``KEY=VALUE`` separated by commas), each target naming its run (``--target weft:probes.tip.z=-4.5``).
The free keys are shared: every run takes the same values, so two strips cut along the warp and the
weft identify B_warp and B_weft together.

The free keys are mapped to u in [0, 1] (log(value) when LO > 0, so a rigidity is searched by its order
of magnitude) and ``scipy.optimize.least_squares`` (trust-region reflective, bounds [0, 1]) minimises
0.5 sum_i r_i^2 with r_i = (m_i(u) - t_i) / |t_i| (t_i = 0: the absolute difference), starting from
the middle of the box. Every evaluation is a point of a study (:mod:`rftstatic.study.sweep`) per run: it
runs on the Dask client, is kept in ``results.csv`` (column ``run``: its label) and is never run twice,
so a repeated fit replays from its table without a cluster. Each evaluation of r(u) sends u together
with its forward-difference neighbours u + h e_j, for every run, in one batch (runs x (1 + keys)
points in parallel; on a rejected trial step the neighbours are wasted).

At the optimum, the sensitivity of each target to each free key, s = d log m / d log k, comes from
central differences at k (1 +- :data:`SENSITIVITY_STEP`), again in one batch; :mod:`rftstatic.study.identify`
reads the matrix (which keys the targets barely determine, a near-singular matrix) for the warnings.
"""

from __future__ import annotations

import math
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rftstatic import api
from rftstatic.io.files import write_json
from rftstatic.study import identify
from rftstatic.study.measures import check_measure, standard_columns
from rftstatic.study.runner import Engine, Execution
from rftstatic.study.space import StudyError, parse_free, parse_value, split_values
from rftstatic.study.store import Store, record_run
from rftstatic.study.sweep import Study, load_base

FD_STEP = 1e-3
"""Forward-difference step in u (the unit box): 0.23 % of the value for a decade-wide log range."""
SENSITIVITY_STEP = 0.01
"""Relative change of a key for the sensitivities at the optimum (1 %)."""
LABEL = re.compile(r"[A-Za-z0-9_-]+\Z")


class FitFailed(RuntimeError):
    """An evaluation of the fit failed or did not converge (the command exits with status 3)."""


@dataclass(frozen=True)
class Run:
    """One run of a fit: ``label`` (None: the scene alone, no ``--run``), its own ``--set`` overrides and
    its own ``scene`` (None: the command's SCENE)."""

    label: str | None
    overrides: tuple = ()
    scene: str | None = None


@dataclass(frozen=True)
class Target:
    """``--target [LABEL:]MEASURE=VALUE``: the measured ``value`` of ``measure`` in the run ``run``."""

    run: str | None
    measure: str
    value: float

    @property
    def name(self) -> str:
        return self.measure if self.run is None else f"{self.run}:{self.measure}"


def parse_runs(texts, free) -> list[Run]:
    """``--run LABEL[@SCENE]:KEY=VALUE,...`` -> runs (none given: the scene alone). A run may not set a free
    key."""
    if not texts:
        return [Run(None)]
    runs = []
    for text in texts:
        head, sep, raw = (s.strip() for s in text.partition(":"))
        label, at, scene = (s.strip() for s in head.partition("@"))
        if not sep or not LABEL.match(label) or (at and not scene):
            raise StudyError(f'--run "{text}": expected LABEL[@SCENE]:[KEY=VALUE,...] with a label of letters, '
                             "digits, - or _, e.g. --run warp: --run weft:material.warp_angle=90")
        if label in [r.label for r in runs]:
            raise StudyError(f'--run "{text}": the label {label} is used twice')
        overrides = tuple(p for p in split_values(raw) if p)
        for o in overrides:
            key = o.split("=", 1)[0].strip()
            if "=" not in o:
                raise StudyError(f'--run "{text}": "{o}" is not KEY=VALUE')
            if key in [r.key for r in free]:
                raise StudyError(f'--run "{text}": {key} is a --free key; a run cannot set it')
        runs.append(Run(label, overrides, scene or None))
    return runs


def parse_targets(texts, bases: dict) -> list[Target]:
    """``--target [LABEL:]MEASURE=VALUE`` -> targets, each path checked against its run's scene
    (``bases``: {label: scene}); with runs, every target names one and every run has a target."""
    if not texts:
        raise StudyError("--target: give at least one, e.g. --target probes.tip.x=1.77")
    labelled = None not in bases
    out = []
    for text in texts:
        if "=" not in text:
            raise StudyError(f'--target "{text}": expected [LABEL:]MEASURE=VALUE, e.g. --target probes.tip.z=-4.35')
        path, raw = (s.strip() for s in text.split("=", 1))
        label, _, path = path.rpartition(":")
        label = label.strip() or None
        path = path.strip()
        if labelled and label not in bases:
            raise StudyError(f'--target "{text}": name one of the runs ({", ".join(bases)}) as LABEL:MEASURE=VALUE')
        if not labelled and label is not None:
            raise StudyError(f'--target "{text}": there is no --run {label}; without --run, a target is MEASURE=VALUE')
        check_measure(path, bases[label], "--target")
        value = parse_value(raw)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise StudyError(f'--target "{text}": the value "{raw}" is not a finite number')
        target = Target(label, path, float(value))
        if target.name in [t.name for t in out]:
            raise StudyError(f'--target "{text}": {target.name} has two targets')
        out.append(target)
    for label in bases:
        if label not in [t.run for t in out]:
            raise StudyError(f"--run {label}: no --target names it (give one as {label}:MEASURE=VALUE)")
    return out


class Evaluator:
    """Measures at batches of points of the unit box, for every run, from the store or run on the engine."""

    def __init__(self, studies: dict, store: Store, engine: Engine, free, targets: list[Target]):
        self.studies, self.store, self.engine, self.free, self.targets = studies, store, engine, free, targets
        self.points_run = 0
        self.history: list[dict] = []

    def values(self, u) -> dict:
        return {r.key: r.value(float(ui)) for r, ui in zip(self.free, u)}

    def rows(self, points: list[dict], label: str) -> list[dict]:
        """For each of ``points`` ({key: value}), its row in every run ({run label: row}), running those not
        in the store in one batch."""
        specs = []
        for p in points:
            for run, study in self.studies.items():
                spec = study.spec(p, arg="--free")
                if run is not None:
                    spec["values"] = {"run": run, **spec["values"]}
                specs.append((run, spec))
        self.store.recover([s["key"] for _, s in specs])
        todo, seen = [], set()
        for run, s in specs:
            needs = [t.measure for t in self.targets if t.run == run]
            if s["key"] not in seen and not self.store.done(s["key"], needs=needs):
                todo.append(s)
                seen.add(s["key"])
        self.engine.run(todo, self.store.add, label=label, brief=True)
        self.points_run += len(todo)
        out = []
        for i in range(len(points)):
            by_run = {}
            for run, s in specs[i * len(self.studies):(i + 1) * len(self.studies)]:
                by_run[run] = self._checked(self.store.rows[s["key"]], run)
            out.append(by_run)
        return out

    def _checked(self, row: dict, run) -> dict:
        where = _shown(row, self.free) + ("" if run is None else f" in run {run}")
        if row.get("status") != "ok":
            raise FitFailed(f"the evaluation at {where} {row.get('status')}: "
                            f"{row.get('error') or 'converged = false'} (its folder: {row.get('folder')})")
        for t in self.targets:
            if t.run == run and row.get(t.measure) is None:
                raise StudyError(f"--target {t.name}: the scene's summary has no value for it (at {where}); "
                                 f"see its summary.json in {row.get('folder')}")
        return row

    def measures(self, by_run: dict) -> dict:
        """{target name: measured value} from {run label: row}."""
        return {t.name: by_run[t.run][t.measure] for t in self.targets}

    def residuals(self, by_run: dict) -> np.ndarray:
        return np.array([(by_run[t.run][t.measure] - t.value) / (abs(t.value) if t.value else 1.0)
                         for t in self.targets])


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
        for v, by_run in zip(batch, rows):
            cache[tuple(v)] = ev.residuals(by_run)
        r = cache[tuple(u)]
        ev.history.append({"evaluation": len(ev.history) + 1, "values": ev.values(u),
                           "measures": ev.measures(rows[0]), "objective": 0.5 * float(r @ r)})
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


def sensitivities(ev: Evaluator, fitted: dict) -> tuple[dict, dict]:
    """{target: {key: d log measure / d log key}} at ``fitted`` (central differences of 1 %, one batch),
    and the measures there ({target: value})."""
    points = []
    for r in ev.free:
        for sign in (1, -1):
            points.append({**fitted, r.key: fitted[r.key] * (1 + sign * SENSITIVITY_STEP)})
    rows = [ev.measures(by_run) for by_run in ev.rows([fitted] + points, label="fit sensitivities")]
    centre, out = rows[0], {t.name: {} for t in ev.targets}
    for j, r in enumerate(ev.free):
        plus, minus = rows[1 + 2 * j], rows[2 + 2 * j]
        for name in out:
            denom = 2 * SENSITIVITY_STEP * centre[name]
            out[name][r.key] = (plus[name] - minus[name]) / denom if denom else None
    return out, centre


def _setup(scene: str, sets, runs: list[Run], out, figures, target_texts):
    """The studies (one per run, {label: Study}) and the targets; every run's scene checked first."""
    bases = {}
    for run in runs:
        try:
            bases[run.label] = load_base(run.scene or scene, [*sets, *run.overrides])
        except api.SceneError as exc:
            if run.label is None:
                raise
            shown = run.label + (f"@{run.scene}" if run.scene else "")
            raise StudyError(f"--run {shown}:{','.join(run.overrides)}: {exc}") from None
    targets = parse_targets(target_texts, bases)
    studies = {}
    for run in runs:
        measures = standard_columns(bases[run.label]) + [t.measure for t in targets if t.run == run.label]
        studies[run.label] = Study(run.scene or scene, [*sets, *run.overrides], out, list(dict.fromkeys(measures)), figures)
    return bases, studies, targets


def run_fit(scene: str, free_texts, target_texts, *, runs=(), sets=(), out=None, execution: Execution = Execution(),
            max_evaluations=100, argv=None) -> dict:
    """The ``fit`` command (module docstring); returns what ``fit.json`` holds. ``execution``: where its
    points run (:class:`~rftstatic.study.runner.Execution`)."""
    t0 = time.perf_counter()
    base = load_base(scene, sets)
    free = parse_free(free_texts)
    run_list = parse_runs(runs, free)
    out = Path(out) if out else Path("out") / f"fit-{base.name}"
    bases, studies, targets = _setup(scene, list(sets), run_list, out, execution.figures, target_texts)
    for r in free:  # each key alone first, so that the error names its --free argument
        for study in studies.values():
            study.spec({r.key: r.lo}, arg="--free")
    measures = list(dict.fromkeys(m for s in studies.values() for m in s.measures))
    store = Store(out, (["run"] if run_list[0].label else []) + [r.key for r in free] + measures)
    engine = execution.engine()
    ev = Evaluator(studies, store, engine, free, targets)
    try:
        res = minimise(ev, max_evaluations=max_evaluations)
        fitted = ev.values(np.clip(res.x, 0.0, 1.0))
        sens, achieved = sensitivities(ev, fitted)  # the centre is the optimum
        info = engine.info()
    finally:
        engine.close()
    analysis = identify.analyse(sens, [r.key for r in free])
    result = {"scene": base.name, "sets": list(sets),
              "runs": {r.label: {"scene": bases[r.label].name, "overrides": list(r.overrides)} for r in run_list}
              if run_list[0].label else None,
              "free": {r.key: [r.lo, r.hi] for r in free},
              "targets": {t.name: t.value for t in targets}, "fitted": fitted, "achieved": achieved,
              "relative_mismatch": {t.name: (achieved[t.name] - t.value) / abs(t.value) if t.value
                                    else achieved[t.name] - t.value for t in targets},
              "success": bool(res.success), "message": res.message, "objective": 0.5 * float(res.fun @ res.fun),
              "evaluations": len(ev.history), "points": len(store.rows), "points_run": ev.points_run,
              "sensitivity": sens, "identifiability": analysis, "warnings": identify.warnings(analysis),
              "history": ev.history, "engine": info, "wall_time_s": time.perf_counter() - t0}
    write_json(out / "fit.json", result)
    record_run(out, {"kind": "fit", "command": argv, "scene": base.name, "sets": list(sets), "runs": result["runs"],
                     "free": result["free"], "targets": result["targets"]},
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
    amp = result["identifiability"].get("amplification")
    if amp and len(amp) > 1:
        print("  a 1 % measurement error moves at most: " + ", ".join(f"{k} ~{a:.3g} %" for k, a in amp.items()))
    print(f"{result['evaluations']} evaluations, {result['points_run']} points run ({result['points']} kept) in "
          f"{result['wall_time_s']:.1f} s; {out}/fit.json", flush=True)
    for line in result["warnings"]:
        print(f"warning: {line}", file=sys.stderr)
