"""Why the Cusick node count does not follow the fabric (issue 35, item 3): one variant of the wool at a time.

Each run is ``python -m rftstatic case SCENE --set ... --set solver.seed=K --no-figures --out OUT/<variant>-s<K>``
(one process per seed, so every specimen keeps its own ``summary.json`` with its hem profile r(theta) and its energy);
a run whose ``summary.json`` exists is read, not solved again. The tables (Markdown, printed) give per variant: the
DC mean and range over the seeds, the node counts of the fold counter as the run made them
(:func:`rftstatic.post.measures.boundary.fold_count`), the same outlines counted with a threshold from the hem's depth
(``--depth-fraction``: a crest counts when its prominence is at least that fraction of r_max - r_min of its own
outline, the nodes a lab sees in the shadow), the hem depth, the energies (total, and the membrane's share of the
elastic energy), how many specimens ended on a stable minimum (the exact tangent factorises) and the solve time.

Usage::

    PYTHONPATH=$PWD python tools/node_count_study.py [--group G ...] [--seeds 3] [--jobs 2] [--out DIR]
        [--json FILE] [--plot FILE.png --plot-variants NAME ...]
    PYTHONPATH=$PWD python tools/node_count_study.py --plot-only FILE.png --plot-variants NAME ...
    PYTHONPATH=$PWD python tools/node_count_study.py --probe-release FACTOR

Groups (``--group``; all by default): ``base`` (the wool with its bending rigidities x 0.25, 1, 4), ``membrane``
(in-plane shear and tensile rigidity scaled down to and below KES-typical values), ``anisotropy`` (B_warp / B_weft at
fixed sqrt(B_warp B_weft) and fixed B_twist), ``mesh`` (sector counts that 8 does not divide), ``hysteresis``
(bending hysteresis 2HB), ``route`` (the stiff wools on the quasi-static release and on the load steps),
``imperfection`` (the release from a 4-fold lift), ``isotropic`` (an isotropic sheet: no 4-fold anisotropy in bending
or membrane).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

GF_CM_TO_MJ = 9.80665e-5 * 1e3
"""1 gf cm in mJ (the scene's energy unit in cm-gf-s)."""

WOOL = {"B_warp": 0.083, "B_weft": 0.063, "B_twist": 0.027, "C_warp": 1118.2, "C_weft": 759.5, "C_shear": 41.8}
"""Kang & Yu's wool in cm-gf-s (rftstatic.material.WOOL_KANG_YU_CM_GF)."""


def _bending(factor: float, ratio: float | None = None, twist: float | None = None) -> list[str]:
    """``--set`` values of the wool's bending rigidities x ``factor``; with ``ratio``, B_warp / B_weft = ratio at the
    wool's sqrt(B_warp B_weft) x factor; ``twist``: B_twist [gf cm] (default: the wool's x factor)."""
    if ratio is None:
        bw, bf = WOOL["B_warp"] * factor, WOOL["B_weft"] * factor
    else:
        g = math.sqrt(WOOL["B_warp"] * WOOL["B_weft"]) * factor
        bw, bf = g * math.sqrt(ratio), g / math.sqrt(ratio)
    bt = WOOL["B_twist"] * factor if twist is None else twist
    return [f"material.B_warp={bw:.6g}", f"material.B_weft={bf:.6g}", f"material.B_twist={bt:.6g}"]


def _scaled(keys: tuple, factor: float) -> list[str]:
    return [f"material.{k}={WOOL[k] * factor:.6g}" for k in keys]


def _hysteresis(hb_warp: float, factor: float = 1.0) -> list[str]:
    """The wool (bending x ``factor``) as a whole table (lab keys may not sit next to a preset) with 2HB along the warp
    [gf cm/cm], the weft's scaled by B_weft / B_warp (as rftstatic.validate.measured_drape)."""
    t = {**WOOL, **{k: WOOL[k] * factor for k in ("B_warp", "B_weft", "B_twist")}, "weight": 0.019,
         "kes_2HB_warp": hb_warp, "kes_2HB_weft": hb_warp * WOOL["B_weft"] / WOOL["B_warp"]}
    return ["material={" + ", ".join(f"{k}={v:.6g}" for k, v in t.items()) + "}"]


G_MEAN = math.sqrt(WOOL["B_warp"] * WOOL["B_weft"])
C_MEAN = math.sqrt(WOOL["C_warp"] * WOOL["C_weft"])


def _isotropic(factor: float, tensile: float = C_MEAN) -> list[str]:
    """An isotropic sheet with zero Poisson ratio: B = sqrt(B_warp B_weft) x ``factor`` of the wool, B_twist = B / 2,
    C_warp = C_weft = ``tensile`` [gf/cm] (default the wool's sqrt(C_warp C_weft)), C_shear = C / 2."""
    return _bending(factor, 1.0, G_MEAN * factor / 2) + [
        f"material.C_warp={tensile:.6g}", f"material.C_weft={tensile:.6g}", f"material.C_shear={tensile / 2:.6g}"]


GROUPS = {
    "base": [
        ("wool B x 0.25", _bending(0.25)),
        ("wool", []),
        ("wool B x 4", _bending(4.0)),
    ],
    "membrane": [
        ("wool C_shear x 0.4 (G 0.29 gf/cm/deg)", _scaled(("C_shear",), 0.4)),
        ("wool C_shear x 0.1 (G 0.073 gf/cm/deg)", _scaled(("C_shear",), 0.1)),
        ("wool C_warp, C_weft x 0.1", _scaled(("C_warp", "C_weft"), 0.1)),
        ("wool C x 0.1, C_shear x 0.1", _scaled(("C_warp", "C_weft", "C_shear"), 0.1)),
        ("wool B x 4, C_shear x 0.4", _bending(4.0) + _scaled(("C_shear",), 0.4)),
        ("wool B x 4, C_shear x 0.1", _bending(4.0) + _scaled(("C_shear",), 0.1)),
        ("wool B x 4, C_warp, C_weft x 0.1", _bending(4.0) + _scaled(("C_warp", "C_weft"), 0.1)),
    ],
    "anisotropy": [
        ("isotropic (ratio 1, B_twist = B / 2)", _bending(1.0, 1.0, G_MEAN / 2)),
        ("ratio 1, wool B_twist", _bending(1.0, 1.0)),
        ("ratio 2, wool B_twist", _bending(1.0, 2.0)),
        ("ratio 3, wool B_twist", _bending(1.0, 3.0)),
        ("B x 4 isotropic (ratio 1, B_twist = B / 2)", _bending(4.0, 1.0, 4 * G_MEAN / 2)),
        ("B x 4 ratio 3, wool B_twist x 4", _bending(4.0, 3.0)),
        ("B x 0.25 isotropic (ratio 1, B_twist = B / 2)", _bending(0.25, 1.0, 0.25 * G_MEAN / 2)),
        ("B x 2 isotropic (ratio 1, B_twist = B / 2)", _bending(2.0, 1.0, 2 * G_MEAN / 2)),
    ],
    "isotropic": [
        ("isotropic sheet, B x 0.25", _isotropic(0.25)),
        ("isotropic sheet, B x 1", _isotropic(1.0)),
        ("isotropic sheet, B x 2", _isotropic(2.0)),
        ("isotropic sheet, B x 4", _isotropic(4.0)),
        ("isotropic sheet, C = 2 C_shear of the wool, B x 1", _isotropic(1.0, 2 * WOOL["C_shear"])),
        ("isotropic sheet, C = 2 C_shear of the wool, B x 4", _isotropic(4.0, 2 * WOOL["C_shear"])),
    ],
    "route": [
        ("wool B x 2, release", _bending(2.0) + ["solver.start=release"]),
        ("wool B x 4, release", _bending(4.0) + ["solver.start=release"]),
        ("wool B x 2, load steps", _bending(2.0) + ["solver.start=load-steps"]),
        ("wool B x 4, load steps", _bending(4.0) + ["solver.start=load-steps"]),
        ("wool B x 2", _bending(2.0)),
        ("wool B x 0.5", _bending(0.5)),
        ("wool B x 0.5, load steps", _bending(0.5) + ["solver.start=load-steps"]),
        ("wool B x 0.5, release", _bending(0.5) + ["solver.start=release"]),
        ("wool B x 4, C_shear x 0.1, load steps", _bending(4.0) + _scaled(("C_shear",), 0.1)
         + ["solver.start=load-steps"]),
        ("wool B x 4, lift 0.3 element sizes", _bending(4.0) + ["solver.perturbation=0.3"]),
        ("wool B x 4, release, first lowering step 1 element size", _bending(4.0) + ["solver.start=release",
                                                                                  "solver.release_step=1.0"]),
        ("wool B x 4, load steps, 13 x 150 sectors",
         _bending(4.0) + ["solver.start=load-steps", "mesh.nodes=[13, 150]"]),
    ],
    "imperfection": [
        ("wool B x 4, release, 4-fold lift 0.3", _bending(4.0) + ["solver.start=release", "solver.perturbation=0.3",
                                                              "solver.perturbation_folds=4"]),
        ("wool B x 4, release, 4-fold lift 1", _bending(4.0) + ["solver.start=release", "solver.perturbation=1.0",
                                                            "solver.perturbation_folds=4"]),
        ("wool, release, 4-fold lift 1", ["solver.start=release", "solver.perturbation=1.0",
                                          "solver.perturbation_folds=4"]),
    ],
    "mesh": [
        ("wool, 13 x 150 sectors", ["mesh.nodes=[13, 150]"]),
        ("wool, 13 x 162 sectors", ["mesh.nodes=[13, 162]"]),
        ("wool B x 4, 13 x 150 sectors", _bending(4.0) + ["mesh.nodes=[13, 150]"]),
        ("wool B x 4, 13 x 162 sectors", _bending(4.0) + ["mesh.nodes=[13, 162]"]),
        ("wool B x 4 isotropic, 13 x 150 sectors", _bending(4.0, 1.0, 4 * G_MEAN / 2) + ["mesh.nodes=[13, 150]"]),
    ],
    "hysteresis": [
        ("wool, 2HB 0.04", _hysteresis(0.04)),
        ("wool, 2HB 0.08", _hysteresis(0.08)),
        ("wool B x 4, 2HB 0.16", _hysteresis(0.16, 4.0)),
        ("wool B x 4, 2HB 0.32", _hysteresis(0.32, 4.0)),
    ],
}
"""Group -> [(variant, --set values)] on cusick-30 (the wool preset; B x f: B_warp, B_weft, B_twist all x f)."""


def slug(label: str) -> str:
    keep = "".join(c if c.isalnum() else "-" for c in label.lower())
    return "-".join(p for p in keep.split("-") if p)


def run_one(scene: str, label: str, sets: list, seed: int, out: Path, figures: bool = False) -> dict:
    """Solve (or read) one specimen; returns its row (status, DC, folds, hem profile, energies, wall)."""
    d = out / f"{slug(label)}-s{seed}"
    summary = d / "summary.json"
    wall = None
    if not summary.exists():
        argv = [sys.executable, "-m", "rftstatic", "case", scene, *(a for s in sets for a in ("--set", s)),
                "--set", f"solver.seed={seed}", "--out", str(d)] + ([] if figures else ["--no-figures"])
        t0 = time.perf_counter()
        proc = subprocess.run(argv, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            tail = (proc.stderr.strip().splitlines() or ["?"])[-1][:200]
            return {"label": label, "seed": seed, "status": f"exit {proc.returncode}: {tail}", "wall": wall}
    s = json.loads(summary.read_text())
    dr, en = s["drape"], s["energies"]
    r = np.asarray(dr["hem_profile"]["r"])
    return {"label": label, "seed": seed, "status": "ok" if s["converged"] else "not converged",
            "dc": dr["drape_coefficient_percent"], "folds": dr["fold_count"], "angles": dr["fold_angles_deg"],
            "r": r.tolist(), "hem_depth": float(r.max() - r.min()), "r_mean": float(r.mean()),
            "energy_mJ": en["total"] * GF_CM_TO_MJ, "bending_mJ": en["bending"] * GF_CM_TO_MJ,
            "membrane_mJ": en["membrane"] * GF_CM_TO_MJ, "stable": s.get("stable_minimum"),
            "warnings": s.get("warnings", []), "solve_s": s.get("wall_time_s"), "wall": wall,
            "relax_steps": (s.get("relax") or {}).get("steps")}


def peaks(r: np.ndarray, threshold: float) -> int:
    """Crests of the periodic hem radius ``r`` (1 deg samples) whose prominence is at least ``threshold``."""
    from rftstatic.post.measures.boundary import _prominent_peaks

    return int(_prominent_peaks(np.asarray(r), threshold).size)


def depth_count(row: dict, fraction: float) -> int:
    """Nodes with prominence >= ``fraction`` x the hem depth (r_max - r_min) of the specimen's own outline."""
    return peaks(np.asarray(row["r"]), fraction * row["hem_depth"])


def table(rows: list, fractions: list) -> str:
    """Markdown rows, one per variant (the order of ``rows``)."""
    head = ("| variant | seeds | DC [%] mean (range) | nodes (counter) | nodes mean | "
            + " | ".join(f"nodes, prominence >= {f:g} depth" for f in fractions)
            + " | hem depth [cm] mean | energy [mJ] (range) | membrane / elastic | stable | solve [s] per seed |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    by = {}
    for row in rows:
        by.setdefault(row["label"], []).append(row)
    for label, rs in by.items():
        ok = [r for r in rs if r["status"] == "ok"]
        bad = [f"seed {r['seed']}: {r['status']}" for r in rs if r["status"] != "ok"]
        if not ok:
            lines.append(f"| {label} | {len(rs)} | {'; '.join(bad)} |" + " |" * (9 + len(fractions)))
            continue
        dc = np.array([r["dc"] for r in ok])
        en = np.array([r["energy_mJ"] for r in ok])
        folds = [r["folds"] for r in ok]
        share = np.mean([r["membrane_mJ"] / (r["membrane_mJ"] + r["bending_mJ"]) for r in ok])
        dcounts = [", ".join(str(depth_count(r, f)) for r in ok) for f in fractions]
        solve = np.mean([r["solve_s"] for r in ok])
        note = f" ({'; '.join(bad)})" if bad else ""
        lines.append(f"| {label}{note} | {len(ok)} | {dc.mean():.2f} ({dc.min():.2f}-{dc.max():.2f}) | "
                     f"{', '.join(map(str, folds))} | {np.mean(folds):.2f} | " + " | ".join(dcounts)
                     + f" | {np.mean([r['hem_depth'] for r in ok]):.2f} | {en.mean():.4f} ({en.min():.4f} .. "
                     f"{en.max():.4f}) | {share:.3f} | {sum(bool(r['stable']) for r in ok)}/{len(ok)} | {solve:.0f} |")
    return "\n".join(lines)


def plot(rows: list, labels: list, path: str) -> None:
    """Top views of the hem outlines r(theta) of the first seed of each variant in ``labels``, crests marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rftstatic.post.measures.boundary import _prominent_peaks

    pick = [next(r for r in rows if r["label"] == lb and r["status"] == "ok") for lb in labels]
    cols = min(len(pick), 4)
    rows_n = -(-len(pick) // cols)
    fig, axes = plt.subplots(rows_n, cols, figsize=(3.4 * cols, 3.7 * rows_n), squeeze=False)
    for ax in axes.ravel()[len(pick):]:
        ax.set_axis_off()
    th = np.radians(np.arange(360.0))
    for ax, row in zip(axes.ravel(), pick):
        r = np.asarray(row["r"])
        ax.fill(r * np.cos(th), r * np.sin(th), color="0.15")
        ax.add_patch(plt.Circle((0, 0), 9.0, color="0.6"))
        ax.add_patch(plt.Circle((0, 0), 15.0, fill=False, ls="--", color="r"))
        counter = _prominent_peaks(r, max(0.1 * (r.max() - r.min()), 0.01 * r.mean()))
        deep = _prominent_peaks(r, 0.25 * (r.max() - r.min()))
        ax.plot(r[counter] * np.cos(th[counter]), r[counter] * np.sin(th[counter]), "o", mfc="none", mec="c", ms=10)
        ax.plot(r[deep] * np.cos(th[deep]), r[deep] * np.sin(th[deep]), "y*", ms=8)
        ax.set_title(f"{row['label']}\nDC {row['dc']:.1f} %, counter {counter.size}, >= 0.25 depth {deep.size}",
                     fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlim(-15.5, 15.5)
        ax.set_ylim(-15.5, 15.5)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def probe_release(factor: float, scene_name: str = "cusick-30") -> None:
    """Print the fold count, hem depth [cm] and hem drop [cm] at every pause of the release route of the wool with
    its bending rigidities x ``factor`` (seed 1): where the route chooses its count."""
    from rftstatic import api
    from rftstatic.post.measures.boundary import boundary_loop, fold_count
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.options import static_options
    from rftstatic.solvers.drive import drive
    from rftstatic.solvers.newton import start_state
    from rftstatic.solvers.static import static_route

    scene = api.load_scene(scene_name, _bending(factor) + ["solver.start=release", "solver.seed=1"])
    model, _ = build_model(scene)
    opts = static_options(scene, progress=False)
    state = start_state(model, opts.newton.linear_solver)
    u = scene.units.length

    def on_pause(pause):
        x = model.positions(state.U) / u
        prof = fold_count(x, boundary_loop(model.mesh.tri, x))
        print(f"{pause.what}: nodes {prof.count}, hem depth {prof.r.max() - prof.r.min():.3f}, "
              f"hem drop {-x[:, 2].min():.3f}", flush=True)

    res = drive(static_route(model, state, opts), on_pause)
    print(f"converged {res.converged}, stable {res.stable}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="cusick-30")
    p.add_argument("--group", action="append", choices=list(GROUPS))
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--out", default="/tmp/nodes35-runs")
    p.add_argument("--json")
    p.add_argument("--depth-fraction", type=float, action="append")
    p.add_argument("--plot")
    p.add_argument("--plot-variants", nargs="*", default=[])
    p.add_argument("--plot-only", help="only draw the outlines of seed 1 of --plot-variants into this file")
    p.add_argument("--probe-release", type=float, metavar="FACTOR",
                   help="only print the fold count along the release route of the wool with B x FACTOR")
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.probe_release is not None:
        probe_release(args.probe_release, args.scene)
        return
    if args.plot_only:
        sets = {label: s for g in GROUPS.values() for label, s in g}
        plot([run_one(args.scene, label, sets[label], 1, out) for label in args.plot_variants], args.plot_variants,
             args.plot_only)
        return
    groups = args.group or list(GROUPS)
    jobs = [(g, label, sets, k) for g in groups for label, sets in GROUPS[g] for k in range(1, args.seeds + 1)]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(lambda j: {"group": j[0], **run_one(args.scene, j[1], j[2], j[3], out)}, jobs))
    fractions = args.depth_fraction or [0.25, 0.5]
    for g in groups:
        print(f"\n### {g}\n")
        print(table([r for r in results if r["group"] == g], fractions))
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    if args.plot:
        plot(results, args.plot_variants, args.plot)


if __name__ == "__main__":
    main()
