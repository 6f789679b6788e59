"""The paper scenes' cost, one table: ``python -m rftstatic bench scenes [NAME ...] [--quick]``.

Each scene of :data:`SCENES` runs as ``python -m rftstatic case NAME --no-figures`` would (``--figures``: with
them) in a fresh interpreter (:func:`rftstatic.bench.harness.run_child`: a new ``sys.executable``, never a fork,
what the "spawn" start method does), one after the other, and the table gives per scene: nodes, analysis and
route, whether it converged (or came to rest), the run's wall time (the child's, imports included) and the
whole process's, Newton iterations, factorisations, explicit steps and the child's peak resident memory.

``--quick`` runs every scene on a coarse mesh (and the dynamic ones over a short time), :data:`QUICK`: a
smoke test of the table in about a minute, not a measurement. The machine's load average is printed: on a
shared machine compare rows of one table.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

SCENES = ("strip", "pedestal-square-20", "pedestal-square-40", "pedestal-square-80", "pedestal-round-50", "sphere-30",
          "cusick-30", "hang-20", "hang-100", "drop-floor")
"""The scenes of the paper (§4.1-4.6) and the Cusick and self-contact scenes the issues measure."""

QUICK = {
    "strip": ["mesh.nodes=[21,5]"],
    "pedestal-square-20": ["mesh.nodes=[17,17]"],
    "pedestal-square-40": ["mesh.nodes=[13,13]"],
    "pedestal-square-80": ["mesh.nodes=[13,13]"],
    "pedestal-round-50": ["mesh.nodes=[7,48]"],
    "sphere-30": ["mesh.nodes=[17,17]"],
    "cusick-30": ["mesh.nodes=[5,48]"],
    "hang-20": ["mesh.nodes=[11,11]", "dynamics.t_end=0.05", "dynamics.frames=[0.0,0.05]"],
    "hang-100": ["mesh.nodes=[11,11]", "dynamics.t_end=0.05", "dynamics.frames=[0.0,0.05]"],
    "drop-floor": ["mesh.nodes=[11,11]", "dynamics.t_end=0.05", "dynamics.frames=[0.0,0.05]"],
}
"""Overrides of ``--quick``: coarse meshes, and 0.05 s of the dynamic scenes."""

TIMEOUT_S = 3600.0
COLUMNS = (("scene", "scene"), ("nodes", "nodes"), ("analysis / route", "route"), ("done", "converged"),
           ("run [s]", "total_s"), ("process [s]", "process_s"), ("Newton its", "newton_iterations"),
           ("factorisations", "factorisations"), ("explicit steps", "explicit_steps"), ("peak [MB]", "peak_rss_mb"))


def bench_scene(name: str, overrides=(), *, figures: bool = False, timeout: float = TIMEOUT_S) -> dict:
    """Run ``name`` (with ``overrides``) in a fresh interpreter, unprofiled; its row, or a row with ``failed``.

    The row: the record of :func:`rftstatic.bench.profile.run_scene` with the child's process_s, cpu_s [s] and
    peak_rss_mb [MB]."""
    from rftstatic.bench.harness import ChildError, run_child

    label = " ".join([name, *(f"--set {o}" for o in overrides)])
    try:
        run = run_child("rftstatic.bench.profile:run_scene", {"name": name, "overrides": list(overrides),
                                                               "figures": figures, "profiled": False},
                        name=f"scene bench of {label}", timeout=timeout)
    except ChildError as exc:
        return {"scene": name, "overrides": list(overrides), "failed": str(exc).splitlines()[0]}
    row = dict(run.result)
    row.update(process_s=run.wall_s, cpu_s=run.cpu_s, peak_rss_mb=run.peak_rss_mb)
    return row


def _cell(row, key):
    v = row.get(key)
    if key == "route":
        return f"{row.get('analysis')} / {v}" if v else str(row.get("analysis"))
    if key == "scene":
        sets = [o for o in row.get("overrides", [])]
        return f"{v} ({', '.join(sets)})" if sets else v
    if key == "converged":
        return "yes" if v else ("no" if v is not None else "-")
    if isinstance(v, float):
        return f"{v:.0f}" if key == "peak_rss_mb" else f"{v:.2f}"
    return "-" if v is None else str(v)


def format_table(rows, fmt: str = "text") -> str:
    """The rows (:func:`bench_scene`) as a text or Markdown table; failed rows say why."""
    heads = [h for h, _ in COLUMNS]
    cells = [[_cell(r, k) for _, k in COLUMNS] if "failed" not in r else [_cell(r, "scene"), r["failed"]]
             for r in rows]
    if fmt == "markdown":
        lines = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        lines += ["| " + " | ".join(c) + " |" * (len(heads) - len(c) + 1) for c in cells]
        return "\n".join(lines)
    width = [max([len(h)] + [len(c[i]) for c in cells if i < len(c) and len(c) == len(heads)])
             for i, h in enumerate(heads)]
    lines = ["  ".join(h.rjust(w) if i else h.ljust(w) for i, (h, w) in enumerate(zip(heads, width)))]
    for c in cells:
        if len(c) != len(heads):
            lines.append(f"{c[0].ljust(width[0])}  FAILED: {c[1]}")
        else:
            lines.append("  ".join(x.rjust(w) if i else x.ljust(w) for i, (x, w) in enumerate(zip(c, width))))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="rftstatic bench scenes", description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help=f"scenes (default: {', '.join(SCENES)})")
    ap.add_argument("--quick", action="store_true", help="coarse meshes and short dynamic runs (a smoke test)")
    ap.add_argument("--figures", action="store_true", help="write the figures too (default: as --no-figures)")
    ap.add_argument("--format", default="text", choices=("text", "markdown"))
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S, help=f"seconds per scene (default {TIMEOUT_S:g})")
    args = ap.parse_args(argv)
    names = args.names or list(SCENES)
    from rftstatic.bench.profile import check_scene

    for name in names:
        problem = check_scene(name, QUICK.get(name, []) if args.quick else [])
        if problem:
            print(f"error: {problem}", file=sys.stderr)
            return 2
    load0 = " ".join(f"{x:.2f}" for x in os.getloadavg())
    t0 = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    rows = []
    for name in names:
        rows.append(bench_scene(name, QUICK.get(name, []) if args.quick else [], figures=args.figures,
                                timeout=args.timeout))
        print(f"  {name}: done", file=sys.stderr, flush=True)
    load1 = " ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"paper scenes{' (--quick: coarse meshes, not a measurement)' if args.quick else ''}, "
          f"{'with' if args.figures else 'no'} figures, each in a fresh interpreter; {t0}, {os.cpu_count()} cores, "
          f"load average before / after {load0} / {load1}")
    print(format_table(rows, args.format), flush=True)
    return 1 if any("failed" in r for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
