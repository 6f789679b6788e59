"""Benchmark results, convergence measures and the Markdown/JSON/PNG report of one benchmark.

A benchmark is a list of *studies* (one per case and element: a mesh sequence with its errors and
wall times). From each study we measure

- the finest error (on the finest mesh run),
- the observed rate p of ``error ~ h^p`` (least-squares slope of log error on log h, h the typical
  element size; on uniform 2-D meshes ``h ~ nodes^(-1/2)``, so the slope against the node count is
  ``-p/2``),
- the wall time (model construction + solve) to reach 1 % and 0.1 % error, interpolated log-log on
  the error-against-time curve between the first mesh below the target and the one before it
  ("not reached" when no mesh is below, "<= t" when the coarsest already is).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class Study:
    """One convergence study: a case with one element on a sequence of meshes.

    Attributes
    ----------
    case, element : labels
    h : (M,) typical element size of each mesh [length]
    nodes : (M,) node counts
    error : (M,) error against the reference, in the benchmark's error measure [-]
    wall_time : (M,) model construction + solve [s]
    tolerance : pass threshold on the finest mesh's error [-] (``None``: reported, not checked)
    """

    case: str
    element: str
    h: list
    nodes: list
    error: list
    wall_time: list
    tolerance: float | None = None

    @property
    def finest_error(self) -> float:
        return float(self.error[int(np.argmax(self.nodes))])

    @property
    def rate(self) -> float:
        return observed_rate(self.h, self.error)

    def time_to(self, target: float) -> float | None:
        return time_to_error(self.wall_time, self.error, target)

    @property
    def passed(self) -> bool:
        return self.tolerance is None or (math.isfinite(self.finest_error) and self.finest_error <= self.tolerance)

    def summary(self) -> dict:
        return {"case": self.case, "element": self.element, "finest_error": self.finest_error,
                "observed_rate": self.rate, "time_to_1pct": self.time_to(0.01),
                "time_to_0p1pct": self.time_to(0.001), "tolerance": self.tolerance, "passed": self.passed}


@dataclass
class BenchmarkResult:
    """What one benchmark measured (see module docstring).

    ``rows`` hold every solve: element, mesh, nodes, value, error, wall_time_s, iterations (and
    the case and reference value). ``finest_error``, ``observed_rate``, ``time_to_1pct``,
    ``time_to_0p1pct`` are those of the governing study (largest finest error among the checked
    ones); ``passed`` needs every checked study within its tolerance.
    """

    name: str
    title: str
    reference: str
    citation: str = ""  # short form for the index
    rows: list = field(default_factory=list)
    tolerance: str = ""
    finest_error: float = float("nan")
    observed_rate: float = float("nan")
    time_to_1pct: float | None = None
    time_to_0p1pct: float | None = None
    passed: bool = True
    discrepancy: str = ""  # where the result differs from the paper's without failing the tolerance
    figures: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    studies: list = field(default_factory=list)
    sections: list = field(default_factory=list)  # (heading, markdown) added to the report

    def finish(self) -> "BenchmarkResult":
        """Fill the governing figures and the pass flag from ``studies``."""
        checked = [s for s in self.studies if s.tolerance is not None] or self.studies
        if checked:
            worst = max(checked, key=lambda s: s.finest_error / (s.tolerance or 1.0)
                        if math.isfinite(s.finest_error) else math.inf)
            self.finest_error, self.observed_rate = worst.finest_error, worst.rate
            self.time_to_1pct, self.time_to_0p1pct = worst.time_to(0.01), worst.time_to(0.001)
        self.passed = all(s.passed for s in self.studies)
        return self


def observed_rate(h, err) -> float:
    """Slope p of log|err| against log h (least squares); NaN with fewer than two usable points."""
    h, err = np.asarray(h, float), np.abs(np.asarray(err, float))
    ok = np.isfinite(h) & np.isfinite(err) & (h > 0) & (err > 0)
    if len(np.unique(h[ok])) < 2:
        return float("nan")
    return float(np.polyfit(np.log(h[ok]), np.log(err[ok]), 1)[0])


def time_to_error(times, err, target) -> float | None:
    """Wall time at which the error first falls to ``target``, log-log interpolated; None if never.

    A negative value ``-t`` means "already below on the first (cheapest) mesh, which took t".
    """
    order = np.argsort(times)
    t, e = np.asarray(times, float)[order], np.abs(np.asarray(err, float))[order]
    below = np.flatnonzero(np.isfinite(e) & (e <= target))
    if not len(below):
        return None
    i = int(below[0])
    if i == 0:
        return -float(t[0])
    t0, t1, e0, e1 = t[i - 1], t[i], e[i - 1], e[i]
    if not (e0 > 0 and e1 > 0 and e0 != e1):
        return float(t1)
    f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return float(math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))))


def fmt_time(t: float | None) -> str:
    if t is None:
        return "not reached"
    if t < 0:
        return f"<= {-t:.2g} s"
    return f"{t:.2g} s"


def fmt_err(e: float) -> str:
    if e is None or not math.isfinite(e):
        return "n/a"
    return f"{100 * e:.3g} %"


def convergence_figures(result: BenchmarkResult, out: Path, *, studies=None, stem=None, title=None) -> list[str]:
    """Error against node count and against wall time, every element of every case on one plot each."""
    from rftstatic.io.charts import plot_convergence

    studies = result.studies if studies is None else studies
    stem = stem or result.name
    title = title or result.title
    if not studies:
        return []
    nodes = {f"{s.case} {s.element}": (np.asarray(s.nodes, float), np.asarray(s.error, float)) for s in studies}
    times = {f"{s.case} {s.element}": (np.asarray(s.wall_time, float), np.asarray(s.error, float)) for s in studies}
    names = []
    for suffix, series, xlabel in (("nodes", nodes, "nodes"), ("time", times, "wall time [s]")):
        path = out / f"{stem}_error_vs_{suffix}.png"
        plot_convergence(path, series, xlabel=xlabel, ylabel="error", title=f"{title}: error vs {xlabel}",
                         reference_slopes=(0.5, 1) if suffix == "nodes" else (1,))
        names.append(path.name)
    return names


def write_report(result: BenchmarkResult, out: Path, *, quick: bool) -> Path:
    """Write ``NAME.md`` and ``NAME.json`` into ``out`` (figures are already there)."""
    from rftstatic.io.files import write_json

    lines = [f"# {result.title}", "",
             f"Benchmark `{result.name}`{' (quick: coarse meshes only)' if quick else ''}; regenerate with "
             f"`python -m rftstatic validate {result.name}{' --quick' if quick else ''}`.", "",
             f"**Reference.** {result.reference}", "",
             f"**Tolerance.** {result.tolerance}", "",
             f"**Result: {'PASS' if result.passed else 'FAIL'}.** Governing study: finest error "
             f"{fmt_err(result.finest_error)}, observed rate {result.observed_rate:.2f} (error ~ h^p), "
             f"time to 1 %: {fmt_time(result.time_to_1pct)}, to 0.1 %: {fmt_time(result.time_to_0p1pct)}.", ""]
    if result.discrepancy:
        lines += [f"**Differs from the paper.** {result.discrepancy}", ""]
    if result.studies:
        lines += ["## Convergence studies", "",
                  "Rate p: least-squares slope of log(error) on log(h). Times are model construction + solve "
                  "on this machine, interpolated log-log on the error-vs-time curve.", "",
                  "| case | element | finest error | rate p | time to 1 % | time to 0.1 % | tolerance | pass |",
                  "|---|---|---|---|---|---|---|---|"]
        for s in result.studies:
            d = s.summary()
            tol = fmt_err(s.tolerance) if s.tolerance is not None else "reported only"
            case = s.case.replace("|", "\\|")  # a pipe in the case would split the table cell
            lines.append(f"| {case} | {s.element} | {fmt_err(d['finest_error'])} | {d['observed_rate']:.2f} | "
                         f"{fmt_time(d['time_to_1pct'])} | {fmt_time(d['time_to_0p1pct'])} | {tol} | "
                         f"{'yes' if s.passed else 'NO'} |")
        lines.append("")
    for heading, text in result.sections:
        lines += [f"## {heading}", "", text.rstrip(), ""]
    if result.notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in result.notes] + [""]
    if result.figures:
        lines += ["## Figures", ""] + [f"![{f}]({f})" for f in result.figures] + [""]
    lines += ["## All solves", "", "| case | element | mesh | nodes | value | reference | error | wall time [s] | "
              "Newton iterations |", "|---|---|---|---|---|---|---|---|---|"]
    for r in result.rows:
        lines.append(f"| {r.get('case', '')} | {r['element']} | {r['mesh']} | {r['nodes']} | {_num(r['value'])} | "
                     f"{_num(r.get('reference'))} | {fmt_err(r['error'])} | {r['wall_time_s']:.3g} | "
                     f"{r['iterations']} |")
    path = out / f"{result.name}.md"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    data = {k: v for k, v in asdict(result).items() if k not in ("studies", "sections")}
    data["quick"] = quick
    data["studies"] = [dict(asdict(s), **s.summary()) for s in result.studies]
    write_json(out / f"{result.name}.json", data)
    return path


def _num(v) -> str:
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):
        return ", ".join(_num(x) for x in v)
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)
