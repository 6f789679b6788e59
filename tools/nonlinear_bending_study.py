"""cusick-30 with nonlinear (softening) bending, Feng et al.'s k2 (issue 35 item 4): what it changes in DC and nodes.

The law (:mod:`rftstatic.element.nonlinear_bending`): M = B kappa + k2 kappa |kappa| per unit width, the slope
floored at 0.2 B. k2 is set per fabric and direction from a ratio r = k2 kappa / B at the bending length's
curvature kappa = 1/c, c = (B/W)^(1/3): k2 = r B c. r = -0.13 is the median of Feng et al.'s 618 fabrics, -0.41
their 5th percentile (:mod:`rftstatic.fabrics.lab`). Fabrics: the wool preset (linear, median, 5th percentile) and
the four fabrics of :func:`rftstatic.references.drape_literature.secondary_table` by their KES values alone
(``material = {kes_B_warp, kes_B_weft, kes_W, kes_T}``, as ``tools/matsudaira_study.py``; linear and median).
Routes: the scene's default (relaxation, then Newton) and ``solver.start = "load-steps"``; seed 1. Each run is one
process (``python -m rftstatic case cusick-30 --no-figures --set ...``), kept in ``--out`` (a finished run is read,
not solved again). Prints a Markdown table.

    PYTHONPATH=$PWD python tools/nonlinear_bending_study.py [--out /tmp/nlb-runs]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from matsudaira_study import run_case  # tools/: the same cached one-process run of cusick-30

WOOL = {"id": "wool", "name": "(preset wool-kang-yu)", "B_warp": 0.083, "B_weft": 0.063, "W": 0.019, "DC": None,
        "nodes": None}
"""The preset's bending rigidities [gf cm] and weight [gf/cm^2] (rftstatic.material.WOOL_KANG_YU_CM_GF)."""

RATIOS = {"wool": (0.0, -0.13, -0.41), "kes": (0.0, -0.13)}
"""k2 kappa / B at kappa = 1/c per fabric kind: linear, the data set's median, its 5th percentile."""

ROUTES = {"relax": [], "load steps": ["solver.start=load-steps"]}
"""The scene's default route and the load steps."""

FLOORS = (0.1, 0.4)
"""Floors phi besides the default 0.2 run on the wool at the 5th percentile, the scene's route (how much the floor's
choice matters where the drape goes past kappa_f)."""


def k2_of(B: float, W: float, r: float) -> float:
    """k2 [gf cm^2] with k2 kappa / B = r at kappa = 1/c, c = (B/W)^(1/3) [cm] (B [gf cm], W [gf/cm^2])."""
    return r * B * (B / W) ** (1.0 / 3.0)


def _material(f: dict, r: float, floor: float | None = None) -> list[str]:
    k2 = [k2_of(f["B_warp"], f["W"], r), k2_of(f["B_weft"], f["W"], r)]
    nl = [f"bending_k2_warp={k2[0]:.6g}", f"bending_k2_weft={k2[1]:.6g}"] if r else []
    nl += [f"bending_floor={floor}"] if floor is not None else []
    if f["id"] == "wool":
        return [f"material.{k}" for k in nl]
    lab = [f"kes_B_warp={f['B_warp']}", f"kes_B_weft={f['B_weft']}", f"kes_W={f['W'] * 1000:g}", f"kes_T={f['T']}"]
    return ["material={" + ", ".join(lab + nl) + "}"]


def _run(f: dict, r: float, route: str, out: Path, floor: float | None = None) -> dict | None:
    sets = _material(f, r, floor) + ["solver.seed=1"] + ROUTES[route]
    return run_case(sets, out, f"{f['id']} r={r} {route}")


def main(argv=None):
    from rftstatic.references.drape_literature import secondary_table

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/nlb-runs")
    a = ap.parse_args(argv)
    root = Path(a.out)
    fabrics = [WOOL] + [{"id": r["id"], "name": r["name"], "B_warp": float(r["B_gf*cm^2/cm"]),
                         "B_weft": float(r["B_gf*cm^2/cm"]), "W": float(r["W_mg/cm^2"]) / 1000, "T": float(r["T_mm"]),
                         "DC": float(r["DC_pub_%"]), "nodes": int(r["nodes_pub"])} for r in secondary_table()]
    lines = ["| fabric | measured DC [%], nodes | route | k2 kappa / B at 1/c | k2 warp, weft [gf cm^2] | DC [%] | "
             "nodes | energy [gf cm] | stable | crossing pairs | past kappa_f: share (warp, weft), max kappa / "
             "kappa_f | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    runs = [(f, route, r, None) for f in fabrics for route in ROUTES for r in RATIOS["wool" if f["id"] == "wool"
                                                                                   else "kes"]]
    runs += [(WOOL, "relax", RATIOS["wool"][-1], phi) for phi in FLOORS]
    for f, route, r, phi in runs:
        tag = f"{f['id']}-{route.replace(' ', '_')}-r{abs(r):g}" + ("" if phi is None else f"-floor{phi:g}")
        s = _run(f, r, route, root / tag, phi)
        if s is not None:
            lines.append(_row(f, route, r, phi, s))
            print(lines[-1], flush=True)
    print("\n".join(lines))


def _row(f: dict, route: str, r: float, phi: float | None, s: dict) -> str:
    """One table row of a run's summary ``s``."""
    measured = "-" if f["DC"] is None else f"{f['DC']:g}, {f['nodes']}"
    nb = s.get("nonlinear_bending")
    past = ("-" if nb is None else f"{nb['floor_share_warp']:.3f}, {nb['floor_share_weft']:.3f}, "
            f"{max(nb['max_over_floor_curvature_warp'], nb['max_over_floor_curvature_weft']):.2f}")
    k2 = "-" if not r else f"{k2_of(f['B_warp'], f['W'], r):.4g}, {k2_of(f['B_weft'], f['W'], r):.4g}"
    ratio = f"{r:g}" + ("" if phi is None else f", floor {phi:g}")
    d = s.get("drape") or {}
    return (f"| {f['id']} {f['name']} | {measured} | {route} | {ratio} | {k2} | "
            f"{d.get('drape_coefficient_percent', float('nan')):.1f} | {d.get('fold_count')} | "
            f"{s['energies']['total']:.4f} | {s['stable_minimum']} | {s['self_intersections'].get('pairs')} | {past} | "
            f"{s['wall_s']:.0f} |")


if __name__ == "__main__":
    main()
