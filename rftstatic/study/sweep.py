"""``python -m rftstatic sweep SCENE --vary KEY=... [--samples N] [--out DIR] [--scheduler ADDRESS]``.

Resolves every point's scene (the study's ``--set`` overrides, then the point's values, through the
same :func:`rftstatic.api.load_scene` as ``case --set``: an unknown key or a bad value is refused
before anything runs), keys it (:func:`rftstatic.study.store.point_key`), skips the points
``results.csv`` (or a point's own ``point.json``) already holds, and runs the rest on Dask
(:class:`rftstatic.study.runner.Engine`). A study with nothing left to run starts no cluster and does
not import Dask. Then it draws each measure against each varied key (:mod:`rftstatic.study.plots`).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

from rftstatic import api
from rftstatic.provenance import code_fingerprint
from rftstatic.study.measures import standard_columns
from rftstatic.study.runner import Execution
from rftstatic.study.space import StudyError, format_override, parse_vary
from rftstatic.study.store import Store, point_key, record_run


@dataclass
class Study:
    """What the points of a study share: the scene (name or path), its ``--set`` overrides, the folder,
    the measures each row records, whether points draw their PNG views."""

    scene: str
    sets: list
    out: Path
    measures: list
    figures: bool = False

    def spec(self, values: dict, *, arg: str = "--vary") -> dict:
        """The point with ``values`` ({key: value}): resolved and keyed (a :class:`StudyError` naming ``arg``
        and the values when the scene refuses them)."""
        overrides = [*self.sets, *(format_override(k, v) for k, v in values.items())]
        try:
            scene = api.load_scene(self.scene, overrides)
        except api.SceneError as exc:
            shown = " ".join(format_override(k, v) for k, v in values.items())
            raise StudyError(f"{arg} {shown}: {exc}") from None
        key = point_key(scene)
        return {"scene": self.scene, "overrides": overrides, "key": key, "values": dict(values),
                "folder": str((self.out / "points" / key).resolve()), "measures": list(self.measures),
                "figures": self.figures, "code": code_fingerprint()}


def load_base(scene: str, sets) -> object:
    """The study's scene with its ``--set`` overrides (a SceneError: exit 2)."""
    return api.load_scene(scene, list(sets))


def run_sweep(scene: str, vary, *, samples=None, seed=0, sets=(), out=None, execution: Execution = Execution(),
              plots=True, retry_failed=False, argv=None) -> list[dict]:
    """The ``sweep`` command (module docstring); returns the rows of its points, in their order.

    ``vary``: the ``--vary`` texts; ``samples``, ``seed``: a Latin hypercube of their ranges; ``sets``: the
    ``--set`` overrides of every point; ``out``: the study folder (default ``out/sweep-NAME``);
    ``execution``: where the points run; ``plots``: draw each measure against each key; ``retry_failed``:
    run the failed points again; ``argv``: the command line recorded in ``study.json``."""
    t0 = time.perf_counter()
    base = load_base(scene, sets)
    space = parse_vary(vary, samples)
    for key, values in space.grid.items():  # each key alone first: the error names its --vary argument
        _check_key(scene, sets, key, values[0])
    for r in space.ranges:
        _check_key(scene, sets, r.key, r.lo)
    out = Path(out) if out else Path("out") / f"sweep-{base.name}"
    study = Study(scene, list(sets), out, standard_columns(base), execution.figures)
    specs = [study.spec(values) for values in space.points(samples, seed)]
    store = Store(out, space.keys + study.measures)
    store.recover([s["key"] for s in specs])
    todo = [s for s in specs if not store.done(s["key"], retry_failed=retry_failed)]
    print(f"sweep {base.name}: {len(specs)} points, {len(specs) - len(todo)} done"
          f"{f' ({store.recovered} recovered from their folders)' if store.recovered else ''}, {len(todo)} to run; "
          f"results in {out}/results.csv", flush=True)
    engine = execution.engine()
    try:
        engine.run(todo, store.add, label="sweep")
        info = engine.info()
    finally:
        engine.close()
    record_run(out, {"kind": "sweep", "command": argv, "scene": base.name, "sets": list(sets),
                     "varied": space.keys, "samples": samples, "seed": seed, "points": len(specs),
                     "measures": study.measures},
               {**info, "points_run": len(todo), "wall_time_s": time.perf_counter() - t0})
    rows = [store.rows[s["key"]] for s in specs]  # this study's points (the table may hold earlier code's rows)
    if plots:
        from rftstatic.study.plots import plot_study

        plot_study(rows, space.keys, study.measures, out / "plots")
    _report(rows, store.path)
    return rows


def _check_key(scene, sets, key, value) -> None:
    try:
        api.load_scene(scene, [*sets, format_override(key, value)])
    except api.SceneError as exc:
        raise StudyError(f"--vary {format_override(key, value)}: {exc}") from None


def _report(rows: list[dict], path: Path) -> None:
    counts = {s: sum(r.get("status") == s for r in rows) for s in ("ok", "not converged", "failed")}
    print(f"{len(rows)} points: {counts['ok']} converged, {counts['not converged']} not converged, "
          f"{counts['failed']} failed; {path}", flush=True)
    for r in rows:
        if r.get("status") == "failed":
            print(f"  failed {r['key']}: {r.get('error')}", file=sys.stderr)
