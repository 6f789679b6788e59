"""Validation reports against published and exact solutions: ``python -m rftstatic validate``.

Every benchmark is a module here with ``run(quick, *, out=None) -> BenchmarkResult``:

- ``strip``: the clamped wool strip of §4.1 against the heavy elastica (RFT3, RFT6, warp/weft,
  rigidity ratios, diagonal patterns);
- ``plates``: square Kirchhoff plates against Timoshenko/Navier (bending only, small load);
- ``sze2004``: the large-deflection cantilevers and slit annular plate of Sze, Liu & Lo (2004);
- ``hang20``: the explicit dynamics of §4.6 against fine-mesh and small-step runs;
- ``textile_tests``: the cantilever tester recovers the given bending rigidity; the Cusick tester's DC and folds
  against the mesh, the seed and the disc radius / bending length;
- ``measured_drape``: Cusick DC and node count of published measured fabrics (none readable: the sources
  searched are listed), the trends of the readable abstracts instead, and what bending hysteresis (KES 2HB)
  changes;
- ``peers``: the plates with scikit-fem's Morley and Argyris triangles (optional extra ``peers``) and
  the published ABAQUS S4R meshes of Sze et al. (2004), error and time side by side.

:func:`main` writes, into ``out`` (default: the repository's ``validation/``), ``NAME.md``,
``NAME.json`` and PNG plots per benchmark and the index ``README.md``; it returns 1 when a
benchmark misses its tolerance.
"""

from __future__ import annotations

import importlib
import logging
import re
import time
from pathlib import Path

from rftstatic.validate.report import BenchmarkResult, fmt_err, fmt_time, write_report

__all__ = ["BENCHMARKS", "BenchmarkResult", "main", "run_benchmark", "default_out"]

log = logging.getLogger(__name__)

BENCHMARKS = {
    "strip": "clamped wool strip (§4.1) vs heavy elastica",
    "plates": "square plates vs Timoshenko/Navier",
    "sze2004": "Sze, Liu & Lo (2004) large-deflection shells",
    "stability": "stability matrix: stiffness, mesh, load and time-step extremes",
    "hang20": "explicit dynamics of §4.6 vs fine-mesh / small-step runs",
    "remesh_scenes": "adaptive remeshing (§6) vs dense structured static drapes; RFT3/RFT6 at 371 nodes",
    "drape_sq20": "square sheet on a square pedestal (§4.2, Fig. 6): boundary and DC mesh convergence",
    "drape_sharp": "RFT3 vs RFT6 sharp-fold indicators on coarse meshes (§4.3, §4.5)",
    "drape_folds": "fold count on the round pedestal (§4.4, Fig. 10)",
    "path_following": "the load-scaled route alone (arc-length, levels) from the flat sheet on the §4 drapes",
    "self_contact": "self-contact: crossing pairs and smallest distance with and without it",
    "textile_tests": "cantilever bending tester and Cusick drape tester (ASTM D1388, BS 3356, BS 5058)",
    "measured_drape": "Cusick DC: published measured fabrics (none readable), trends, bending hysteresis 2HB",
    "peers": "a general FE code (scikit-fem Morley/Argyris plates; cited ABAQUS S4R) next to RF triangles",
}


TOOL_REPORTS = {
    "fabric_rules": "a fabric from KES-F B, W, T alone: the fill rules, the Cusick DC's sensitivity to each, the "
                    "Cusick mesh (pattern, rings, sectors, element) and RFT6 locking numbers (tools/"
                    "fabric_rule_sensitivity.py, tools/cusick_mesh_study.py)",
    "mesh_obstacles": "obstacles from triangle-mesh files: sphere-30 on icospheres against the analytic sphere "
                      "(convergence with the facet size, wall time), the crossing check and the penalty onset "
                      "that clears it, the box under the sheet, the rounded square pedestal as a mesh, sheet edges "
                      "against sharp edges in explicit steps, ipctk against the project's distance kernels "
                      "(tools/icosphere.py, tools/rounded_box.py, tools/mesh_obstacle_runs.py, "
                      "tools/ipctk_compare.py)",
    "cusick_route": "the Cusick tester's route: which drape the load steps and the dynamic relaxation find on "
                    "cusick-30, their energies, fold counts over seeds, lift amplitudes, fabrics and model changes "
                    "(tools/cusick_route_study.py)",
    "friction_obstacles": "Coulomb friction against the exact incline (static lag, relaxation and explicit "
                          "impulses), the drag tests on the floor and between layers (self_friction), its cost on "
                          "pedestal-square-20 and the Cusick friction scene (tools/friction_report.py)",
    "bench_profile": "where the paper scenes' time goes: bench profile by phase and the bench scenes table, the "
                     "three biggest cost centres (python -m rftstatic bench profile / bench scenes)",
    "garments": "skirts and a four-panel dress sewn on the dress form: convergence, stability, seam gaps, crossings "
                "against the form itself, the hem's drape coefficient and folds on two meshes, friction, the cost of "
                "each stage, the circle skirt's node count beside its fabric's Cusick test (tools/garment_report.py)",
}
"""Hand-made reports in ``validation/`` that the index lists below its table."""


def default_out() -> Path:
    """The repository's ``validation/`` folder."""
    import rftstatic

    return Path(rftstatic.__file__).resolve().parent.parent / "validation"


def run_benchmark(name: str, *, quick: bool = False, out: Path | None = None) -> BenchmarkResult:
    """Run one benchmark; with ``out`` its figures are drawn there."""
    if name not in BENCHMARKS:
        raise ValueError(f'unknown benchmark "{name}"; use one of {", ".join(BENCHMARKS)}')
    module = importlib.import_module(f"{__name__}.{name}")
    return module.run(quick, out=out)


def main(names, *, quick: bool = False, out=None) -> int:
    """Run the named benchmarks (all when empty) and write their reports; 1 if any fails."""
    names = list(names) or list(BENCHMARKS)
    unknown = [n for n in names if n not in BENCHMARKS]
    if unknown:
        print(f'error: unknown benchmark(s) {", ".join(unknown)}; use {", ".join(BENCHMARKS)}')
        return 2
    out = Path(out) if out else default_out()
    out.mkdir(parents=True, exist_ok=True)
    results = []
    for name in names:
        t0 = time.perf_counter()
        res = run_benchmark(name, quick=quick, out=out)
        write_report(res, out, quick=quick)
        results.append(res)
        print(f"{name:10s} {'PASS' if res.passed else 'FAIL'}  finest error {fmt_err(res.finest_error)}  "
              f"rate {res.observed_rate:.2f}  ({time.perf_counter() - t0:.1f} s)  -> {out / (name + '.md')}")
    write_index(results, out, quick=quick)
    return 0 if all(r.passed for r in results) else 1


def rebuild_index(out=None) -> Path:
    """Rewrite the index from every ``NAME.json`` in ``out`` (the reports already on disk)."""
    import json
    from types import SimpleNamespace

    from rftstatic.validate.report import Study

    out = Path(out) if out else default_out()
    results = []
    for path in sorted(out.glob("*.json")):
        d = json.loads(path.read_text(encoding="utf-8"))
        if "studies" not in d or "name" not in d:
            continue
        studies = [Study(s["case"], s["element"], s["h"], s["nodes"], s["error"], s["wall_time"], s["tolerance"])
                   for s in d["studies"]]
        results.append(SimpleNamespace(name=d["name"], citation=d.get("citation", ""), reference=d["reference"],
                                       studies=studies, passed=d.get("passed", True), title=d.get("title", ""),
                                       discrepancy=d.get("discrepancy", "")))
    index = out / "README.md"
    if index.exists():
        index.unlink()
    return write_index(results, out, quick=False)


def write_index(results, out: Path, *, quick: bool) -> Path:
    """``README.md``: one row per convergence study of every benchmark (rows of earlier runs kept)."""
    path = out / "README.md"
    rows = {}
    if path.exists():  # keep the rows of benchmarks not rerun this time
        for line in path.read_text(encoding="utf-8").splitlines():
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]  # not at "\|"
            if line.startswith("| [") and len(cells) == 9:
                rows.setdefault(cells[0], []).append(line)
    for res in results:
        key = f"[{res.name}]({res.name}.md)"
        rows[key] = []
        if not res.studies:  # a benchmark of cells or tables: one row with its verdict
            verdict = "pass" if res.passed else "**FAIL**"
            if getattr(res, "discrepancy", ""):
                verdict += "; **differs from the paper** (see report)"
            rows[key].append(f"| {key} | {res.citation or res.reference.split('. ')[0]} | "
                             f"{getattr(res, 'title', '')} | - | - | - | - | see report | {verdict} |")
        for s in res.studies:
            d = s.summary()
            tol = fmt_err(s.tolerance) if s.tolerance is not None else "reported"
            verdict = "reported" if s.tolerance is None else ("pass" if s.passed else "**FAIL**")
            case = s.case.replace("|", "\\|")
            rows[key].append(f"| {key} | {res.citation or res.reference.split('. ')[0]} | {case} | {s.element} | "
                             f"{fmt_err(d['finest_error'])} | {d['observed_rate']:.2f} | "
                             f"{fmt_time(d['time_to_1pct'])} / {fmt_time(d['time_to_0p1pct'])} | {tol} | "
                             f"{verdict} |")
    lines = ["# Validation reports", "",
             "Generated by `python -m rftstatic validate [NAME ...] [--quick]`; each benchmark has a report "
             "(`NAME.md`), its raw numbers (`NAME.json`) and plots of the error against node count and wall "
             "time. Rate p: slope of log(error) on log(h). Times: model construction + solve, log-log "
             "interpolated on the error-vs-time curve (\"<= t\": the coarsest mesh, taking t, is already "
             "below). " + ("Quick run: coarse meshes only." if quick else ""), "",
             "| benchmark | reference | case | element | finest error | rate p | time to 1 % / 0.1 % | "
             "tolerance | result |",
             "|---|---|---|---|---|---|---|---|---|"]
    for key in sorted(rows):
        lines += rows[key]
    lines += ["", "Reports written from the runs of a tool (not by `validate`; each gives its commands):", ""]
    lines += [f"- [{name}]({name}.md): {what}" for name, what in TOOL_REPORTS.items()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
