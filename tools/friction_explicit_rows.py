"""Rows of validation/friction_obstacles.md for the explicit route (tools/friction_report.py): the drag on the floor
(kinematic and penalty impulses) and between layers with a moving support, the drag scene, and the energy of the
sharp-feature contact in undamped explicit runs."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def explicit_drag_rows():
    sys.path.insert(0, str(ROOT / "tests" / "contact"))
    from test_friction import drag_explicit

    rows = []
    for route in ("kinematic", "penalty"):
        for mu in (0.2, 0.5):
            r, moved = drag_explicit(mu=mu, route=route)
            rows.append(f"| {route} | {mu:g} | {1000 * moved:.1f} | {r:.5f} | {100 * abs(r - 1):.2f} % | "
                        f"{'PASS' if abs(r - 1) < 0.02 else 'FAIL'} |")
    return rows


def layer_drag_explicit_rows():
    sys.path.insert(0, str(ROOT))
    from tests.contact.self_contact.test_self_friction import drag_layers_explicit

    free = drag_layers_explicit(0.0)
    rows = []
    for mu in (0.3, 0.5):
        held = drag_layers_explicit(mu)
        r = (free - held) / mu
        rows.append(f"| {mu:g} | {free:+.4f} | {held:+.4f} | {r:.4f} | {100 * abs(r - 1):.2f} % | "
                    f"{'PASS' if abs(r - 1) < 0.02 else 'FAIL'} |")
    return rows


def drag_scene_row(tmp):
    out = tmp / "drag-floor"
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "rftstatic", "case", "drag-floor", "--no-figures", "--out", str(out)],
                       capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - t
    s = json.loads((out / "summary.json").read_text())
    d = s["drive"]
    r = d["reaction_over_mu_weight"]
    return (f"| {p.returncode} | {s['steps']} | {d['mu']:g} | {d['reaction_along_motion']:.4f} | "
            f"{d['weight_pulled']:.4f} | {r:.5f} | {100 * abs(r - 1):.2f} % | {wall:.1f} | "
            f"{'PASS' if abs(r - 1) < 0.02 else 'FAIL'} |")


BOX = (np.array([[x, y, z] for z in (-4, 0) for y in (-5.3, 4.7) for x in (-5.4, 4.6)], float),
       np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                 [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]))


def _slide(tmp, features: bool, t_end=0.3):
    """A 20 cm wool sheet (13 x 13) 1 mm above a 10 x 10 x 4 cm box (its rims off the rows of nodes), thrown along
    x at 0.5 m/s, undamped, under the penalty contact with the box's rims as features (or the box with
    feature_angle 179 deg: none): total energy at the start, at the end and its largest change [J]."""
    import meshio

    from rftstatic.garment.sewing import _closing_step
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import scene_from_dict
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    meshio.write(tmp / "box.obj", meshio.Mesh(BOX[0], [("triangle", BOX[1])]))
    ob = {"type": "mesh", "path": str(tmp / "box.obj")}
    if not features:
        ob["feature_angle"] = 179.0
    model, _ = build_model(scene_from_dict({
        "units": "cm-gf-s", "analysis": "static",
        "mesh": {"kind": "rectangle", "size": [20.0, 20.0], "nodes": [13, 13], "origin": [-10.0, -10.0]},
        "material": {"preset": "wool-kang-yu"}, "loads": {"gravity": True}, "obstacles": [ob]}))
    U0, V0 = np.zeros_like(model.X3), np.zeros_like(model.X3)
    U0[:, 2], V0[:, 0] = 0.001, 0.5
    dt = _closing_step(model, U0, 0.0)  # the garment closing's step: elements and the penalty
    res = run_explicit(model, ExplicitOptions(t_end=t_end, dt=dt, alpha=0.0, energy_check=False, progress=False),
                       U0=U0, V0=V0)
    tot = np.asarray(res.history["total"])
    return tot[0], tot[-1], float(np.abs(tot - tot[0]).max()), res.steps


def feature_energy_rows(tmp):
    sys.path.insert(0, str(ROOT / "tests" / "contact"))
    import meshio
    from test_feature_energy import BOX_F, BOX_V, _bounce

    from rftstatic.contact.obstacles import SurfaceObstacle

    meshio.write(tmp / "unit-box.obj", meshio.Mesh(BOX_V, [("triangle", BOX_F)]))
    worst, lowest = _bounce(SurfaceObstacle(tmp / "unit-box.obj", scene_length=0.01), 600)
    rows = [f"| 4-node square pressed into the face beside a rim, sliding past it (600 steps) | features | "
            f"{lowest:.2f} | | | {100 * worst:.3f} % |"]
    for features in (True, False):
        e0, e1, worst, steps = _slide(tmp, features)
        rows.append(f"| 13 x 13 sheet sliding over a box's rims (0.3 s, {steps} steps) | "
                    f"{'features' if features else 'none'} | | {e0:.5e} | {e1:.5e} | {100 * worst / e0:.2f} % |")
    return rows
