"""Rows of validation/friction_obstacles.md that tools/friction_report.py imports: the mesh obstacle's cost against
the analytic sphere it approximates."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def sphere_cost_rows(tmp, case, rounds=2):
    """sphere-30 at 33 x 33 on the analytic sphere and on the level-4 icosphere (5,120 triangles, written by
    tools/icosphere.py and given to ``cases/sphere-mesh.toml`` by its absolute path; the same smoothing 0.07), whole
    processes back to back by ``case`` (friction_report's: ``(args, out) -> (exit, summary, wall, error)``), ``rounds``
    times: rows, the ratio of the smaller walls and the DC's relative difference."""
    ico = Path(tmp).resolve() / "icosphere-4.obj"
    subprocess.run([sys.executable, "tools/icosphere.py", "4", str(ico)], check=True, cwd=ROOT, capture_output=True)
    runs = {"analytic": ["sphere-30", "--set", "mesh.nodes=[33,33]", "--set", "contact.smoothing=0.07"],
            "mesh (icosphere-4)": ["sphere-mesh", "--set", f"obstacles.0.path={ico}"]}
    walls, rows, dc = {k: [] for k in runs}, [], {}
    for r in range(rounds):
        for name, args in runs.items():
            rc, s, wall, _ = case(args, tmp / f"sphere-{r}-{name.split()[0]}")
            walls[name].append(wall)
            d = s.get("drape") or {}
            dc[name] = d.get("drape_coefficient_percent", float("nan"))
            rows.append(f"| {r + 1} | {name} | {rc} | {s.get('converged')} | {s.get('stable_minimum')} | "
                        f"{s.get('newton_iterations')} | {dc[name]:.3f} | {wall:.1f} |")
    ratio = min(walls["mesh (icosphere-4)"]) / min(walls["analytic"])
    diff = dc["mesh (icosphere-4)"] / dc["analytic"] - 1.0
    return rows, ratio, diff
