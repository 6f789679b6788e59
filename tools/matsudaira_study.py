"""cusick-30 on the four fabrics of Matsudaira et al. (2015) as a third party transcribed them (issue 35).

The fabrics (:func:`rftstatic.references.drape_literature.secondary_table`: KES-FB B and 2HB, W, T, the measured DC
and node count; one B per fabric, so B_warp = B_weft) are given to ``cusick-30`` by their KES values alone
(``material = {kes_B_warp, kes_B_weft, kes_W, kes_T}``, every other quantity filled by the stated rules:
``python -m rftstatic fabrics --explain``), the 30 cm specimen on the 18 cm disc (the transcription does not give
the tester's diameters). Variants: ``compare`` (the relaxation and the load steps, the lower stable minimum kept:
``solver.compare = "load-steps"``; both drapes are in each run's summary), and with bending hysteresis (the
fabric's 2HB; path dependent, so no comparison) on the relaxation and on the load steps. Each run is one process
(``python -m rftstatic case cusick-30 --no-figures --set ...``), kept in ``--out`` (a finished run is read, not
solved again). Prints a Markdown table.

    PYTHONPATH=$PWD python tools/matsudaira_study.py [--seeds 3] [--out /tmp/matsudaira-runs]

``--starts``: instead, the lowest-energy drape found per fabric (no hysteresis: energies compare): the relaxation and
the load steps from the scene's start (seed 1), and the load steps from an n-fold lift of one element size
(``solver.perturbation_folds = n``, n = 3 ... 8); one row per run and the lowest energy per fabric.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

VARIANTS = {"compare": ["solver.compare=load-steps"], "relax, 2HB": ["solver.start=relax"],
            "load steps, 2HB": ["solver.start=load-steps"]}
"""Route keys of each variant; the 2HB variants add the fabric's bending hysteresis."""

STARTS = {"relax": ["solver.start=relax"], "load steps": ["solver.start=load-steps"],
          **{f"load steps, {n}-fold lift": ["solver.start=load-steps", "solver.perturbation=1",
                                            f"solver.perturbation_folds={n}"] for n in range(3, 9)}}
"""Starts of ``--starts``: the scene's two routes, and the load steps from n-fold lifts of one element size."""


def run_case(sets: list[str], out: Path, label: str) -> dict | None:
    """``python -m rftstatic case cusick-30 --no-figures --out OUT --set ...`` in its own process, unless ``out``
    already holds a finished run; its summary.json with the whole process's ``wall_s``, or None (and the last
    error line, after ``label``, on stderr) when it exits with an error."""
    if not (out / "summary.json").is_file():
        t = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "rftstatic", "case", "cusick-30", "--no-figures", "--out", str(out)]
                           + [a for k in sets for a in ("--set", k)], capture_output=True, text=True)
        if p.returncode:
            print(f"{label}: exit {p.returncode}: {p.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
            return None
        (out / "wall.json").write_text(json.dumps({"wall_s": time.perf_counter() - t}))
    s = json.loads((out / "summary.json").read_text())
    s["wall_s"] = json.loads((out / "wall.json").read_text())["wall_s"]
    return s


def _run(fabric, variant, seed, out: Path) -> dict | None:
    keys = [f"kes_B_warp={fabric['B']}", f"kes_B_weft={fabric['B']}", f"kes_W={fabric['W']}", f"kes_T={fabric['T']}"]
    if "2HB" in variant:
        keys += [f"kes_2HB_warp={fabric['2HB']}", f"kes_2HB_weft={fabric['2HB']}"]
    sets = ["material={" + ", ".join(keys) + "}", f"solver.seed={seed}", *{**VARIANTS, **STARTS}[variant]]
    return run_case(sets, out, f"{fabric['id']} {variant} seed {seed}")


def main(argv=None):
    from rftstatic.references.drape_literature import secondary_table

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--out", default="/tmp/matsudaira-runs")
    ap.add_argument("--starts", action="store_true", help="the lowest-energy drape found per fabric (see above)")
    a = ap.parse_args(argv)
    root = Path(a.out)
    fabrics = [{"id": r["id"], "name": r["name"], "B": float(r["B_gf*cm^2/cm"]), "2HB": float(r["2HB_gf*cm/cm"]),
                "W": float(r["W_mg/cm^2"]), "T": float(r["T_mm"]), "DC": float(r["DC_pub_%"]),
                "nodes": int(r["nodes_pub"])} for r in secondary_table()]
    if a.starts:
        return _starts(fabrics, root)
    lines = ["| fabric | B [gf cm^2/cm], 2HB [gf cm/cm], W [mg/cm^2] | measured DC [%], nodes | variant | DC [%] mean "
             "(seeds) | nodes mean (seeds) | DC error [points] | nodes error | route kept (compare) | stable | wall [s] "
             "per seed |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for f in fabrics:
        for variant in VARIANTS:
            runs = [_run(f, variant, k, root / f"{f['id']}-{variant.replace(', ', '-').replace(' ', '_')}-s{k}")
                    for k in range(1, a.seeds + 1)]
            runs = [s for s in runs if s is not None]
            if not runs:
                continue
            dc = [s["drape"]["drape_coefficient_percent"] for s in runs]
            nodes = [s["drape"]["fold_count"] for s in runs]
            kept = ", ".join(s["starts"]["kept"] for s in runs) if "starts" in runs[0] else "-"
            lines.append(f"| {f['id']} {f['name']} | {f['B']:g}, {f['2HB']:g}, {f['W']:g} | {f['DC']:g}, {f['nodes']} | "
                         f"{variant} | {np.mean(dc):.1f} ({', '.join(f'{v:.1f}' for v in dc)}) | {np.mean(nodes):.1f} "
                         f"({', '.join(map(str, nodes))}) | {np.mean(dc) - f['DC']:+.1f} | {np.mean(nodes) - f['nodes']:+.1f} | "
                         f"{kept} | {sum(bool(s['stable_minimum']) for s in runs)}/{len(runs)} | "
                         f"{np.mean([s['wall_s'] for s in runs]):.0f} |")
            print(lines[-1], flush=True)
    print("\n".join(lines))


def _starts(fabrics, root: Path) -> None:
    """Print the ``--starts`` table: every start's drape, and the lowest stable one per fabric."""
    lines = ["| fabric | measured DC [%], nodes | start | energy [gf cm] | nodes | DC [%] | stable | crossing pairs | "
             "wall [s] |", "|---|---|---|---|---|---|---|---|---|"]
    lowest = []
    for f in fabrics:
        runs = {}
        for start in STARTS:
            s = _run(f, start, 1, root / f"{f['id']}-starts-{start.replace(', ', '-').replace(' ', '_')}")
            if s is None:
                continue
            runs[start] = s
            lines.append(f"| {f['id']} {f['name']} | {f['DC']:g}, {f['nodes']} | {start} | {s['energies']['total']:.4f} | "
                         f"{s['drape']['fold_count']} | {s['drape']['drape_coefficient_percent']:.1f} | "
                         f"{s['stable_minimum']} | {s['self_intersections'].get('pairs')} | {s['wall_s']:.0f} |")
            print(lines[-1], flush=True)
        stable = {k: s for k, s in runs.items() if s["stable_minimum"] and not s["self_intersections"].get("pairs")}
        if stable:
            k = min(stable, key=lambda k: stable[k]["energies"]["total"])
            s = stable[k]
            lowest.append(f"| {f['id']} {f['name']} | {f['DC']:g}, {f['nodes']} | {k} | {s['energies']['total']:.4f} | "
                          f"{s['drape']['fold_count']} | {s['drape']['drape_coefficient_percent']:.1f} | "
                          f"{s['drape']['drape_coefficient_percent'] - f['DC']:+.1f} | "
                          f"{s['drape']['fold_count'] - f['nodes']:+d} |")
    print("\n".join(lines))
    print("\n| fabric | measured DC [%], nodes | lowest-energy start | energy [gf cm] | nodes | DC [%] | DC error "
          "[points] | nodes error |\n|---|---|---|---|---|---|---|---|")
    print("\n".join(lowest))


if __name__ == "__main__":
    main()
