"""Run the mesh-obstacle comparisons of validation/mesh_obstacles.md ("Third session") and print their tables.

    PYTHONPATH=$PWD python tools/mesh_obstacle_runs.py [--out /tmp/mesh-obstacle-runs] [--rounds 2]

Each row runs the mesh scene and its analytic twin back to back as whole processes (``python -m rftstatic case
... --no-figures``, file reading and checks included), ``--rounds`` times, and reports the smaller wall time of
each; the drape numbers come from the runs' ``summary.json``, the analytic obstacle's node distance and deepest
chord from its own signed distance at the sheet's nodes, triangle centroids and edge midpoints. Obstacle files
are written by ``tools/icosphere.py`` and ``tools/rounded_box.py``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _case(scene, out, sets):
    cmd = [sys.executable, "-m", "rftstatic", "case", str(scene), "--no-figures", "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def _chord(out, ob, u=0.01):
    """Smallest node distance and deepest chord [scene units] of the run in ``out`` to the obstacle ``ob``."""
    import meshio

    m = meshio.read(out / "deformed.vtu")
    x, tri = m.points * u, m.cells_dict["triangle"]
    e = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    mids = np.concatenate([x[tri].mean(axis=1), 0.5 * x[e].sum(axis=1)])
    return ob.signed_distance(x)[0].min() / u, min(0.0, ob.signed_distance(mids)[0].min()) / u


def _pair(name, mesh, analytic, ob, rounds, out):
    """Run the two scenes ``(scene, sets)`` back to back ``rounds`` times; one table row."""
    tm, ta = [], []
    om, oa = out / (name.replace(" ", "-") + "-mesh"), out / (name.replace(" ", "-") + "-analytic")
    for r in range(rounds):
        tm.append(_case(mesh[0], om, mesh[1]))
        ta.append(_case(analytic[0], oa, analytic[1]))
    sm = json.loads((om / "summary.json").read_text())
    sa = json.loads((oa / "summary.json").read_text())
    oc = sm["obstacle_crossings"][0]
    node_a, chord_a = _chord(oa, ob)
    dm, da = sm["drape"]["drape_coefficient_percent"], sa["drape"]["drape_coefficient_percent"]
    em, ea = sm["energies"]["total"], sa["energies"]["total"]
    return (f"| {name} | {dm:.3f} / {da:.3f} | {100 * (dm / da - 1):+.2f}% | {em:.3f} / {ea:.3f} | "
            f"{100 * (em / ea - 1):+.2f}% | {oc['pairs']} | {10 * oc['smallest_node_distance']:.3f} / "
            f"{10 * node_a:.3f} | {10 * oc['deepest_chord']:.3f} / {10 * chord_a:.3f} | "
            f"{sm['newton_iterations']} / {sa['newton_iterations']} | {min(tm):.1f} / {min(ta):.1f} | "
            f"{min(tm) / min(ta):.2f} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/mesh-obstacle-runs")
    ap.add_argument("--rounds", type=int, default=2)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    from rftstatic.contact.obstacles import Sphere, SquarePedestal

    for level in (3, 4):
        subprocess.run([sys.executable, "tools/icosphere.py", str(level), str(out / f"ico{level}.obj")], check=True,
                       cwd=ROOT, stdout=subprocess.DEVNULL)
    subprocess.run([sys.executable, "tools/rounded_box.py", str(out / "pedestal.obj")], check=True, cwd=ROOT,
                   stdout=subprocess.DEVNULL)
    scene = (ROOT / "cases" / "pedestal-square-20.toml").read_text()
    head, rest = scene.split("[[obstacles]]", 1)
    ped = head + (f'[[obstacles]]\ntype = "mesh"\npath = "{out / "pedestal.obj"}"\nunits = "cm"\n\n[contact]'
                  + rest.split("[contact]", 1)[1])
    (out / "pedestal-mesh.toml").write_text(ped)
    sphere = Sphere([0.0, 0.0, -0.05], 0.05)
    pedestal = SquarePedestal([0.0, 0.0], half_width=0.05, top_z=0.0, edge_radius=0.002)
    print("| run | DC mesh / analytic [%] | rel. diff | total energy mesh / analytic [gf cm] | rel. diff | "
          "crossing pairs (mesh) | smallest node distance mesh / analytic [mm] | deepest chord mesh / analytic [mm] "
          "| Newton its | wall mesh / analytic [s] | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for level in (3, 4):
        for s in ("0.07", "0.05"):
            sets = [f"contact.smoothing={s}"]
            row = _pair(f"sphere L{level} smoothing {s}",
                        ("sphere-mesh", [f"obstacles.0.path={out / f'ico{level}.obj'}"] + sets),
                        ("sphere-30", ["mesh.nodes=[33,33]"] + sets), sphere, a.rounds, out)
            print(row, flush=True)
    print(_pair("pedestal-square-20", (out / "pedestal-mesh.toml", []), ("pedestal-square-20", []), pedestal,
                a.rounds, out), flush=True)


if __name__ == "__main__":
    main()
