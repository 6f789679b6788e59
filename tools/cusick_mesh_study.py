"""Mesh study of a Cusick scene: the drape coefficient, fold count and node count against the diagonal
pattern, the rings and the sectors (nodes per ring), and the element. Prints a Markdown table
(validation/fabric_rules.md, "Meshes").

Usage::

    PYTHONPATH=$PWD python tools/cusick_mesh_study.py [SCENE] [--set KEY=VALUE ...] [--out DIR] [--study NAME ...]

Each row is ``python -m rftstatic case SCENE --set mesh.pattern=... --set mesh.nodes=[rings,sectors] ...
--no-figures`` (seed 1, the scene's route), with its locking number (C/B) h^2 from the run's log.
"""

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

STUDIES = {
    "pattern": [["mesh.pattern=alternate"], ["mesh.pattern=right"], ["mesh.pattern=left"]],
    "rings": [["mesh.pattern=right", f"mesh.nodes=[{n},160]"] for n in (7, 10, 13, 19, 25)],
    "sectors": [["mesh.pattern=right", f"mesh.nodes=[13,{n}]"] for n in (80, 120, 160, 240, 320)],
    "alternate-rings": [["mesh.pattern=alternate", f"mesh.nodes=[{n},160]"] for n in (7, 13, 19, 25)],
    "element": [["mesh.pattern=right", "element=RFT3", "solver.start=load-steps"],
                ["mesh.pattern=right", "solver.start=load-steps"]],
}
"""Study name -> the ``--set`` lists of its rows."""


def _run(scene: str, sets: list, out: Path) -> dict:
    argv = [sys.executable, "-m", "rftstatic", "case", scene, *(a for s in sets for a in ("--set", s)),
            "--no-figures", "--out", str(out)]
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    lock = next((line.split("(C/B) h^2 = ")[1].split(" ")[0] for line in proc.stderr.splitlines()
                 if "(C/B) h^2 = " in line), "")
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["?"])[-1]
        return {"status": f"exit {proc.returncode}: {last[:160]}", "wall": wall, "lock_warning": lock}
    s = json.loads((out / "summary.json").read_text())
    d = s.get("drape") or {}
    return {"status": "ok", "nodes": s["nodes"], "dc": d.get("drape_coefficient_percent"),
            "folds": d.get("fold_count"), "wall": wall, "lock_warning": lock}


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("scene", nargs="?", default="cusick-30")
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--study", action="append", default=None, choices=list(STUDIES))
    p.add_argument("--out", default="out/cusick_mesh")
    args = p.parse_args()
    print("| study | --set | nodes | DC [%] | folds | RFT6 locking warning (C/B) h^2 | wall [s] |")
    print("|---|---|---|---|---|---|---|")
    results = []
    for name in args.study or list(STUDIES):
        for i, sets in enumerate(STUDIES[name]):
            r = _run(args.scene, [*args.set, *sets], Path(args.out) / f"{name}-{i}")
            results.append({"study": name, "sets": sets, **r})
            shown = " ".join(sets)
            if r["status"] != "ok":
                print(f"| {name} | {shown} | - | - | {r['status']} | {r['lock_warning'] or '-'} | {r['wall']:.0f} |",
                      flush=True)
                continue
            print(f"| {name} | {shown} | {r['nodes']} | {r['dc']:.2f} | {r['folds']} | {r['lock_warning'] or '-'} | "
                  f"{r['wall']:.0f} |", flush=True)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "results.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
