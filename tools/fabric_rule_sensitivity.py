"""The Cusick drape coefficient's sensitivity to each rule that fills a lab fabric's missing values
(:mod:`rftstatic.fabrics.rules`): each filled value x0.5 and x2 (given explicitly, so the rule no longer
applies), the Poisson rule (C12 = B12 = 0) against a Poisson coupling of 0.2, and the tensile rule against
the KES-FB1 secant at Fm = 500 gf/cm of a typical EMT of 5 %. Prints a Markdown table (validation/fabric_rules.md).

Usage::

    PYTHONPATH=$PWD python tools/fabric_rule_sensitivity.py [SCENE] [--seeds N] [--set KEY=VALUE ...] [--out DIR]

Each run is ``python -m rftstatic case SCENE --set "material={...}" --set solver.seeds=N --no-figures``;
the table gives the mean DC over the seeds, its range, the fold counts and the wall time.
"""

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

FABRICS = {
    "wool-like": {"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_W": 19.0, "kes_T": 0.5},
    "limp": {"kes_B_warp": 0.019, "kes_B_weft": 0.019, "kes_W": 10.43, "kes_T": 0.3},
}
"""Lab fabrics: Kang & Yu's wool as B and W with a suiting's thickness (assumed); the issue's limp fabric
(B 0.019 gf cm^2/cm, W 10.43 mg/cm^2) with an assumed T of 0.3 mm."""


def _toml(table: dict) -> str:
    return "material={" + ", ".join(f"{k}={v!r}" for k, v in table.items()) + "}"


def _variants(fabric: dict) -> list:
    """(label, table) of the base lab fabric and of each rule's value scaled (cm-gf-s model keys)."""
    from rftstatic.scenes.material import build_material, material_summary
    from rftstatic.scenes.schema import scene_from_dict

    scene = scene_from_dict({"units": "cm-gf-s", "material": fabric})
    filled = {q: r["value"] for q, r in material_summary(scene, build_material(scene))["filled"].items()}
    out = [("rules (base)", dict(fabric))]
    for label, keys in (("tensile C_warp, C_weft", ("C_warp", "C_weft")), ("shear C_shear", ("C_shear",)),
                        ("twist B_twist", ("B_twist",))):
        for f in (0.5, 2.0):
            out.append((f"{label} x{f:g}", {**fabric, **{k: filled[k] * f for k in keys}}))
    bw, bf = fabric["kes_B_warp"], fabric["kes_B_weft"]
    out.append(("Poisson 0.2: C12 = 0.2 sqrt(Cw Cf), B12 = 0.2 sqrt(Bw Bf)",
                {**fabric, "C12": 0.2 * math.sqrt(filled["C_warp"] * filled["C_weft"]), "B12": 0.2 * math.sqrt(bw * bf)}))
    out.append(("tensile: KES secant, EMT 5 % at Fm 500 gf/cm (C = 10000 gf/cm)",
                {**fabric, "kes_EMT_warp": 5.0, "kes_EMT_weft": 5.0}))
    return out


def _run(scene: str, table: dict, seeds: int, sets: list, out: Path) -> dict:
    argv = [sys.executable, "-m", "rftstatic", "case", scene, "--set", _toml(table), "--set", f"solver.seeds={seeds}",
            *(a for s in sets for a in ("--set", s)), "--no-figures", "--out", str(out)]
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        return {"status": f"exit {proc.returncode}: {proc.stderr.strip().splitlines()[-1][:160]}", "wall": wall}
    s = json.loads((out / "summary.json").read_text())
    if seeds > 1:
        g = s["seeds"]
        return {"status": "ok", "dc": g["drape_coefficient_percent_mean"], "dc_min": g["drape_coefficient_percent_min"],
                "dc_max": g["drape_coefficient_percent_max"], "folds": g["fold_counts"], "wall": wall}
    d = s["drape"]
    return {"status": "ok", "dc": d["drape_coefficient_percent"], "dc_min": d["drape_coefficient_percent"],
            "dc_max": d["drape_coefficient_percent"], "folds": [d["fold_count"]], "wall": wall}


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("scene", nargs="?", default="cusick-30")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--fabric", action="append", default=None, choices=list(FABRICS))
    p.add_argument("--out", default="out/fabric_rules")
    args = p.parse_args()
    results = {}
    for name in args.fabric or list(FABRICS):
        rows = []
        base = None
        for i, (label, table) in enumerate(_variants(FABRICS[name])):
            r = _run(args.scene, table, args.seeds, args.set, Path(args.out) / f"{name}-{i}")
            base = r if base is None else base
            rows.append((label, r))
            print(f"{name:10s} {label:70s} {json.dumps(r)}", file=sys.stderr, flush=True)
        results[name] = rows
        print(f"\n{name}: {FABRICS[name]}\n")
        print("| variant | DC mean [%] | DC range [%] | change of mean [points] | fold counts | wall [s] |")
        print("|---|---|---|---|---|---|")
        for label, r in rows:
            if r["status"] != "ok":
                print(f"| {label} | - | - | - | {r['status']} | {r['wall']:.0f} |")
                continue
            change = r["dc"] - base["dc"] if base["status"] == "ok" else float("nan")
            print(f"| {label} | {r['dc']:.2f} | {r['dc_min']:.2f}-{r['dc_max']:.2f} | {change:+.2f} | "
                  f"{', '.join(map(str, r['folds']))} | {r['wall']:.0f} |")
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "results.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
