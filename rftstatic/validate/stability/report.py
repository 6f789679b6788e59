"""The stability matrix's report: every cell run in turn, its outcome printed, tables by group."""

from __future__ import annotations

from rftstatic.validate.report import BenchmarkResult, fmt_err
from rftstatic.validate.stability.matrix import cells, short
from rftstatic.validate.stability.runner import run_cell


def _modes(rec) -> str:
    m = rec.get("tangent_modes") or {}
    return ", ".join(f"{k} {v}" for k, v in m.items() if v) or ""


def run(quick: bool = False, *, out=None) -> BenchmarkResult:
    """Run every cell of :func:`~rftstatic.validate.stability.matrix.cells` (each in its own child
    process, :func:`~rftstatic.validate.stability.runner.run_cell`) and build the report.

    ``out`` is unused (no figures). Passed when no cell is a FAIL.
    """
    import logging

    log = logging.getLogger(__name__)
    records = []
    for cell in cells(quick):
        rec = run_cell(cell)
        log.info("%s | %s: %s (%s) %.1f s", cell.group, cell.name, rec["verdict"], rec["reason"], rec["wall_time_s"])
        print(f"  {rec['verdict']:13s} {cell.group}: {cell.name} ({rec['wall_time_s']:.1f} s) {rec['reason']}",
              flush=True)
        records.append(rec)
    fails = [r for r in records if r["verdict"] == "FAIL"]
    result = BenchmarkResult(
        name="stability", title="Stability matrix: extremes of stiffness, mesh, load and time step",
        citation="heavy elastica, Timoshenko, exact circle, half-step runs",
        reference="Per cell: the extensible heavy elastica (strips), Timoshenko's clamped plate (sheets), the "
                  "exact circle of the end-moment roll-up (Sze et al. 2004), the same explicit run at half the "
                  "step, and dt ~ sqrt(s) for mass scaling; pedestal drapes have none.",
        tolerance="No FAIL cell: no hang (each cell has a wall-time budget in a child process), no crash "
                  "(unexpected exception type), no wrong answer reported as converged (error above the cell's "
                  "tolerance: 3 x the measured O(h^2) discretisation error of the mesh, >= 0.5 % of L for "
                  "strips). ConvergenceError where a solution exists is a reported limitation.")
    result.rows = [_row(r) for r in records]
    result.passed = not fails
    counts = {v: sum(r["verdict"] == v for r in records)
              for v in ("pass", "converged", "expected stop", "limitation", "FAIL")}
    result.sections.append(("Summary", ", ".join(f"{v}: {k}" for v, k in counts.items())
                            + f" ({len(records)} cells, {sum(r['wall_time_s'] for r in records):.0f} s)."))
    for g in dict.fromkeys(r["group"] for r in records):
        result.sections.append((g, _group_table([r for r in records if r["group"] == g])))
    for r in fails:
        result.notes.append(f"FAIL {r['group']} / {r['case']}: {r['reason']}"
                            + (f"; {r.get('exception')}: {short(r.get('message', ''), 300)}"
                               if r.get("exception") else ""))
        if r.get("traceback"):
            result.notes.append("traceback: `" + r["traceback"].strip().replace("\n", " / ")[-600:] + "`")
    locking = [r for r in records if r["group"] == "stiffness ratio: strip" and r.get("membrane_energy_share")]
    if locking:
        result.notes.append("Membrane / bending energy at equilibrium (strip, by C/B): " + "; ".join(
            f"{r['case'].split(', ')[1]} {r['case'].split(',')[0][6:]}: {r['membrane_energy_share']:.2g}"
            for r in locking) + ". The physical share falls as B/C (RFT3); a share that grows with C/B is "
                            "parasitic membrane strain in bending (membrane locking), which makes the strip too "
                            "stiff: a wrong answer on this mesh that disappears only with refinement.")
    result.notes.append("Mass scaling: with the mass damping alpha = 5/s of hang-20 the critical step is "
                        "(sqrt(alpha^2 + 4 w^2) - alpha) / w^2, which is sqrt(s) x the unscaled one only at "
                        "alpha = 0; the reference is that formula at w = w_max / sqrt(s) (value: dt(s) / dt(1)).")
    result.notes.append("Tangent modes: exact (Hessian), psd (compressive stress dropped from the geometric "
                        "stiffness), shift (Levenberg-Marquardt shift), reused (modified Newton step on the last "
                        "factorisation). Explicit cells: iterations = time steps.")
    result.notes.append("Each cell runs in a fresh child interpreter (never a fork of the report's process); its "
                        "budget is the child's wall time, start-up included; wall [s]: the cell's function in the "
                        "child.")
    return result


def _group_table(records) -> str:
    """The markdown table of one group's cells."""
    lines = [("| cell | outcome | why | value (reference) | error (tolerance) | iterations / steps | load steps | "
              "cutbacks | tangent modes | wall [s] |"), "|---|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        tol = f" ({fmt_err(r['tolerance'])})" if r.get("tolerance") is not None else ""
        err = fmt_err(r.get("error")) + tol if r.get("error") is not None else ""
        outcome = "**FAIL**" if r["verdict"] == "FAIL" else r["verdict"]
        why = r["reason"]
        if r.get("exception") and r["exception"] not in ("timeout",):
            why += f": `{short(r['message'])}`"
        if r.get("stopped"):
            why += f": `{short(r['message'])}`"
        val = _val(r.get("value")) + (f" ({_val(r.get('reference'))})" if r.get("reference") is not None else "")
        lines.append(f"| {r['case']} | {outcome} | {why} | {val} | {err} | {r.get('iterations', '')} | "
                     f"{r.get('load_steps', '')} | {r.get('cutbacks', '')} | {_modes(r)} | "
                     f"{r['wall_time_s']:.1f} |")
    return "\n".join(lines)


def _val(v) -> str:
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):
        return ", ".join(_val(x) for x in v)
    return f"{v:.5g}" if isinstance(v, float) else str(v)


def _row(r) -> dict:
    """A row for the generic report table (and the JSON, which keeps every field)."""
    return dict(r, element=r["group"], mesh=r["verdict"], nodes=r.get("nodes", ""), value=r.get("value"),
                reference=r.get("reference"), error=r.get("error") if r.get("error") is not None else float("nan"),
                iterations=r.get("iterations", ""))
