"""Benchmark of the explicit loop: element-steps per second on the §4.6 sheets (41 x 41, 51 x 51).

``python -m rftstatic.bench.explicit [--steps N] [--backend numpy numba]`` runs the hanging-sheet
set-up of §4.6 (two adjacent corners pinned, gravity, alpha = 5/s) for a fixed number of steps per
back end and prints E * steps / wall time. The target is >= 5e6 element-steps/s on one core.
"""

from __future__ import annotations

import argparse
import time

from rftstatic.bench.problems import sheet_model


def measure(model, *, steps: int, backend: str) -> dict:
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions
    from rftstatic.solvers.timestep import stable_time_step

    dt = stable_time_step(model).dt
    run_explicit(model, ExplicitOptions(t_end=5 * dt, dt=dt, alpha=5.0, backend=backend, progress=False))  # warm up
    t0 = time.perf_counter()
    r = run_explicit(model, ExplicitOptions(t_end=steps * dt, dt=dt, alpha=5.0, backend=backend, progress=False,
                                            energy_check=False, sample_every=max(1, steps // 20)))
    wall = time.perf_counter() - t0
    return {"elements": model.mesh.n_elements, "steps": r.steps, "wall_s": wall,
            "element_steps_per_s": model.mesh.n_elements * r.steps / wall, "dt": dt}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--backend", nargs="+", default=["numpy", "numba"])
    ap.add_argument("--element", default="RFT6")
    args = ap.parse_args(argv)
    for side, n in ((0.2, 41), (1.0, 51)):
        model = sheet_model(side, n, args.element)
        for be in args.backend:
            m = measure(model, steps=args.steps, backend=be)
            print(f"{n}x{n} {args.element} E={m['elements']:5d} {be:6s} {m['steps']} steps "
                  f"{m['wall_s']:.2f} s  {m['element_steps_per_s'] / 1e6:.2f} M element-steps/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
