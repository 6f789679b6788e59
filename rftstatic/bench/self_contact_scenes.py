"""What self-contact costs a whole run: each scene with ``contact.self = false`` and ``= true``, in fresh
interpreters, alternately, and the ratio of the two (issue "Self-contact", "Done when": at most 1.5 x on
scenes whose layers never touch, at most 3 x on pedestal-square-80).

``python -m rftstatic bench self-contact`` runs the scenes whose layers never touch
(:data:`APART`); ``python -m rftstatic.bench.self_contact_scenes [NAME ...] [--repeat R]`` any scene.
The runs of one scene alternate off, on, off, on, ... so that a change in the machine's load falls on
both; the ratio is that of the medians. Wall time is what the target is about; the CPU time of the
child (user + system) is printed beside it, since on a shared machine it moves less with the load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

APART = ("pedestal-square-20", "sphere-30", "hang-20")
"""Paper scenes whose layers never touch, at their default meshes (33 x 33, 61 x 61, 41 x 41)."""

TIMEOUT_S = 1800.0


def child(name: str, overrides: list, out: str) -> dict:
    """One run as ``python -m rftstatic case NAME --set ... --no-figures`` would do it; its measures."""
    from rftstatic.api import run

    t0 = time.perf_counter()
    s = run(name, out, overrides=overrides, figures=False).summary
    sc = s.get("self_contact") or {}
    return {"run_s": time.perf_counter() - t0, "converged": s.get("converged"), "nodes": s.get("nodes"),
            "rebuilds": sc.get("rebuilds"), "broad_phase_s": sc.get("broad_phase_s"),
            "filter_s": sc.get("filter_s"), "force_s": sc.get("force_s"),
            "pairs": (s.get("self_intersections") or {}).get("pairs")}


def scene_ratio(name: str, *, overrides=(), repeat: int = 2, verbose: bool = True) -> dict:
    """Median wall and CPU time of ``repeat`` runs each without and with self-contact; their ratios."""
    from rftstatic.bench.harness import run_child

    runs = {False: [], True: []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            for on in (False, True):
                r = run_child("rftstatic.bench.self_contact_scenes:child",
                              {"name": name, "overrides": list(overrides) + [f"contact.self={str(on).lower()}"],
                               "out": f"{tmp}/{i}-{on}"},
                              name=f"self-contact ratio {name} self={on}", timeout=TIMEOUT_S)
                runs[on].append((r.wall_s, r.cpu_s, r.result))
    med = {on: (statistics.median(w for w, _, _ in v), statistics.median(c for _, c, _ in v)) for on, v in runs.items()}
    last = runs[True][-1][2]
    out = {"scene": name, "overrides": list(overrides), "repeat": repeat, "off_wall_s": med[False][0],
           "on_wall_s": med[True][0], "off_cpu_s": med[False][1], "on_cpu_s": med[True][1],
           "wall_ratio": med[True][0] / med[False][0], "cpu_ratio": med[True][1] / med[False][1],
           "on": last, "load": os.getloadavg()[0]}
    if verbose:
        print(f"{name:22s} {' '.join(overrides):24s} off {out['off_wall_s']:7.1f} s  on {out['on_wall_s']:7.1f} s  "
              f"ratio {out['wall_ratio']:.2f} (CPU {out['off_cpu_s']:.1f} -> {out['on_cpu_s']:.1f} s, "
              f"{out['cpu_ratio']:.2f})  rebuilds {last['rebuilds']}, broad phase {last['broad_phase_s']:.2f} s, "
              f"filter {last['filter_s']:.2f} s, crossings {last['pairs']}, load {out['load']:.1f}", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", default=list(APART))
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override for every scene")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args(argv)
    for name in args.names:
        scene_ratio(name, overrides=args.set, repeat=args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
