"""Where a scene's run spends its time: ``python -m rftstatic bench profile SCENE [--set KEY=VALUE ...]``.

Runs the scene's whole process as ``python -m rftstatic case SCENE --no-figures`` does (``--figures``: with the
figures) in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`) under the phase timers of
:mod:`rftstatic.bench.phases`, and prints a table of the phases (wall seconds, share of the total, entries),
the counts (Newton iterations, factorisations, back-substitutions, explicit steps, ...) and the peak memory.
The phases add up to the child's total (from before its first import of the package's solvers to the end
of the outputs; the interpreter's start-up is the difference to the process time, printed apart).

Profiler overhead: the same scene runs once more, in another fresh interpreter, without the timers
(before the profiled run, so that a cold numba cache is filled by that run, not by the profiled one);
both wall times are printed (``--no-compare`` skips it). The machine's load average is printed with
them: on a shared machine compare the shares of one run, not seconds across runs.

``--format markdown`` prints the same as Markdown (for an issue note), ``--format json`` the raw record.
An unknown scene or a bad ``--set`` is an input error (exit status 2) naming it.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

TIMEOUT_S = 3600.0
INPUT_ERRORS = ("SceneError", "ParameterError", "MeshError", "MeshingError", "PatchError")
"""Exceptions of the child that are the scene's fault (found only when it is built): exit status 2."""
IMPORTS_SHOWN = 8  # the packages slowest to import, listed under the table


def _maxrss_mb() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / 1024**2 if sys.platform == "darwin" else r / 1024  # bytes on macOS, KiB on Linux


def run_scene(name: str, overrides: list, figures: bool = False, profiled: bool = True) -> dict:
    """Child: run scene ``name`` with ``overrides`` as ``case NAME`` does (outputs into a temporary folder);
    return its wall time [s], counts and (``profiled``) its phases.

    Returns a JSON-ready dict: scene, overrides, figures, profiled, total_s (the run, imports included),
    phases (list of phase, seconds, calls; summing to total_s), events (counts of calls: numeric
    factorisations, back-substitutions, ...), summary counts (nodes, analysis, route, converged, message,
    newton_iterations, factorisations, load_steps, explicit_steps), maxrss_mb.
    """
    from rftstatic.bench.phases import PhaseClock

    clock = PhaseClock()
    if profiled:
        clock.install()
        clock.start()
    t0 = time.perf_counter()
    error = None
    try:
        from rftstatic.api import ConvergenceError, InstabilityError, run

        with tempfile.TemporaryDirectory(prefix="rftstatic-profile-") as tmp:
            try:
                summary = run(name, f"{tmp}/out", overrides=list(overrides), figures=figures).summary
            except (ConvergenceError, InstabilityError) as exc:  # the run ended short of its goal: still profiled
                error = f"{type(exc).__name__}: {exc}"
                path = f"{tmp}/out/summary.json"
                summary = json.loads(Path(path).read_text()) if os.path.exists(path) else {}
    finally:
        total = time.perf_counter() - t0
        if profiled:
            total = clock.stop()
            clock.uninstall()
    out = {"scene": name, "overrides": list(overrides), "figures": figures, "profiled": profiled, "total_s": total,
           "error": error, "maxrss_mb": _maxrss_mb(), **summary_counts(summary)}
    if profiled:
        out["phases"] = clock.table()
        out["events"] = dict(clock.events)
        out["imports"] = dict(sorted(clock.imports.items(), key=lambda kv: -kv[1])[:IMPORTS_SHOWN])
        out["timer_entries"] = clock.entries
        out["timer_cost_s"] = clock.entries * clock.entry_cost()
    return out


def summary_counts(summary: dict) -> dict:
    """The counts of a run's summary: nodes, analysis, route, converged, message, newton_iterations,
    factorisations, load_steps, explicit_steps (a dynamic run's steps, or the relaxation route's), tangent_modes
    (Newton steps by the tangent that gave them: exact, modified, psd, shift)."""
    relax = summary.get("relax") if isinstance(summary.get("relax"), dict) else {}
    steps = summary.get("steps") if summary.get("analysis") in ("dynamic", "relax") else relax.get("steps")
    return {"nodes": summary.get("nodes"), "analysis": summary.get("analysis"), "route": summary.get("route"),
            "converged": summary.get("converged"), "message": summary.get("message"),
            "newton_iterations": summary.get("newton_iterations"), "factorisations": summary.get("factorisations"),
            "load_steps": summary.get("load_steps"), "explicit_steps": steps,
            "tangent_modes": summary.get("tangent_modes")}


def profile(name: str, overrides=(), *, figures: bool = False, compare: bool = True,
            timeout: float = TIMEOUT_S) -> dict:
    """Profile ``name`` in a fresh interpreter (and, ``compare``, run it once unprofiled before); the record.

    The record is :func:`run_scene`'s with ``process_s`` (the child's whole wall time), ``cpu_s``,
    ``peak_rss_mb`` (the child's peak resident memory), ``load`` (load averages before and after), ``date``
    and, with ``compare``, ``unprofiled`` (the plain run's total_s, process_s, peak_rss_mb).
    """
    from rftstatic.bench.harness import run_child

    load0 = os.getloadavg()
    kwargs = {"name": name, "overrides": list(overrides), "figures": figures}
    label = " ".join([name, *(f"--set {o}" for o in overrides)])
    plain = None
    if compare:
        plain = run_child("rftstatic.bench.profile:run_scene", {**kwargs, "profiled": False},
                          name=f"unprofiled run of {label}", timeout=timeout)
    run = run_child("rftstatic.bench.profile:run_scene", {**kwargs, "profiled": True}, name=f"profile of {label}",
                    timeout=timeout)
    record = dict(run.result)
    record.update(process_s=run.wall_s, cpu_s=run.cpu_s, peak_rss_mb=run.peak_rss_mb,
                  load=[list(load0), list(os.getloadavg())], date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    if plain is not None:
        same = all(plain.result.get(k) == record.get(k) for k in SAME)
        record["unprofiled"] = {"total_s": plain.result["total_s"], "process_s": plain.wall_s,
                                "peak_rss_mb": plain.peak_rss_mb, "same_counts": same}
    return record


SAME = ("converged", "newton_iterations", "factorisations", "load_steps", "explicit_steps")
"""Counts the unprofiled run must repeat: the timers change no result."""

SAME_WORDS = {True: "yes", False: "NO", None: "not compared"}

COUNTS = (("Newton iterations", "newton_iterations"), ("factorisations (the solver's count)", "factorisations"),
          ("load steps", "load_steps"), ("explicit steps", "explicit_steps"),
          ("Newton steps by tangent mode", "tangent_modes"))


def _count_lines(r: dict) -> list[tuple[str, object]]:
    def shown(v):
        return ", ".join(f"{k} {n}" for k, n in v.items() if n) if isinstance(v, dict) else v

    rows = [(label, shown(r.get(key))) for label, key in COUNTS if r.get(key) is not None]
    rows += sorted(r.get("events", {}).items())
    return rows


def _heading(r: dict) -> str:
    sets = "".join(f" --set {o}" for o in r["overrides"])
    state = "converged" if r.get("converged") else f"NOT converged ({r.get('error') or r.get('message')})"
    load = " / ".join(" ".join(f"{x:.2f}" for x in la) for la in r["load"])
    route = f", route {r['route']}" if r.get("route") else ""
    return (f"profile of `{r['scene']}{sets}`{' with figures' if r['figures'] else ' --no-figures'}: "
            f"{r.get('nodes')} nodes, {r.get('analysis')} analysis{route}, {state}; {r['date']}, "
            f"{os.cpu_count()} cores, load average before / after {load}")


def _imports(r: dict) -> str:
    top = r.get("imports") or {}
    return "import time by package (each module without what it imports): " + (", ".join(f"{m} {t:.2f} s" for m, t in top.items())
                                                            or "none")


def _overhead(r: dict) -> str:
    p = r.get("unprofiled")
    cost = (f"profiler overhead: the timers' own cost {r['timer_cost_s']:.3f} s ({r['timer_entries']} timed calls, "
            f"{100 * r['timer_cost_s'] / r['total_s']:.1f} % of the total; measured in the child by timing a wrapped "
            "no-op)")
    if not p:
        return cost + "; no unprofiled run (--no-compare)"
    return (f"{cost}; run {p['total_s']:.2f} s without the timers, {r['total_s']:.2f} s with them "
            f"({100 * (r['total_s'] / p['total_s'] - 1):+.1f} %); whole process {p['process_s']:.2f} s / "
            f"{r['process_s']:.2f} s (two fresh interpreters one after the other, the unprofiled first); same "
            f"iterations, factorisations and steps: {SAME_WORDS[p.get('same_counts')]}")


def format_record(r: dict, fmt: str = "text") -> str:
    """The profile ``r`` (:func:`profile`) as a text table, Markdown, or JSON."""
    if fmt == "json":
        return json.dumps(r, indent=1)
    total = r["total_s"]
    rows = [(p["phase"], p["seconds"], 100 * p["seconds"] / total if total else 0.0, p["calls"]) for p in r["phases"]]
    memory = f"peak memory (ru_maxrss of the child): {r['peak_rss_mb']:.0f} MB"
    startup = r["process_s"] - total
    if fmt == "markdown":
        lines = [_heading(r), "", "| phase | wall [s] | share | entries |", "|---|---:|---:|---:|"]
        lines += [f"| {p} | {s:.3f} | {f:.1f} % | {c} |" for p, s, f, c in rows]
        lines += [f"| **total** (the run in the child) | **{total:.3f}** | 100.0 % | |",
                  f"| interpreter start-up (outside the total) | {startup:.3f} | | |", "",
                  "| count | value |", "|---|---:|"]
        lines += [f"| {k} | {v} |" for k, v in _count_lines(r)]
        lines += ["", memory + "; " + _imports(r) + "; " + _overhead(r)]
        return "\n".join(lines)
    lines = [_heading(r).replace("`", ""), f"{'phase':48s} {'wall [s]':>9s} {'share':>7s} {'entries':>8s}"]
    lines += [f"{p:48s} {s:9.3f} {f:6.1f}% {c:8d}" for p, s, f, c in rows]
    lines += [f"{'total (the run in the child)':48s} {total:9.3f} {100.0:6.1f}%",
              f"{'interpreter start-up (outside the total)':48s} {startup:9.3f}",
              "counts: " + ", ".join(f"{k} {v}" for k, v in _count_lines(r)), memory, _imports(r), _overhead(r)]
    return "\n".join(lines)


def check_scene(name: str, overrides) -> str | None:
    """None if the scene reads with its overrides, else the error message."""
    from rftstatic.errors import SceneError
    from rftstatic.scenes.schema import load_scene

    try:
        load_scene(name, list(overrides))
    except (SceneError, ValueError) as exc:
        return str(exc)
    return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="rftstatic bench profile", description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="cases/NAME.toml or a path to a .toml file")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a scene key, as for case")
    ap.add_argument("--figures", action="store_true", help="write the figures too (default: as --no-figures)")
    ap.add_argument("--no-compare", action="store_true", help="skip the unprofiled run (no overhead measured)")
    ap.add_argument("--format", default="text", choices=("text", "markdown", "json"))
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S, help=f"seconds per run (default {TIMEOUT_S:g})")
    args = ap.parse_args(argv)
    problem = check_scene(args.scene, args.set)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    from rftstatic.bench.harness import ChildError

    try:
        record = profile(args.scene, args.set, figures=args.figures, compare=not args.no_compare, timeout=args.timeout)
    except ChildError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2 if exc.exception in INPUT_ERRORS else 1
    print(format_record(record, args.format), flush=True)
    return 0 if record.get("error") is None else 3


if __name__ == "__main__":
    raise SystemExit(main())
