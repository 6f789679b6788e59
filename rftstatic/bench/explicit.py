"""Benchmark of the explicit loop: element-steps per second on the §4.6 sheets (41 x 41, 51 x 51).

``python -m rftstatic.bench.explicit [--steps N] [--backend numpy numba]`` runs the hanging-sheet
set-up of §4.6 (two adjacent corners pinned, gravity, alpha = 5/s) for a fixed number of steps per
back end and prints E * steps / wall time. The target is >= 5e6 element-steps/s on one core.

``python -m rftstatic.bench.explicit --threads SCENE [KEY=VALUE ...]`` times the compiled force kernel on a
scene's mesh with one thread and with all (:func:`thread_calls`: blocks of calls alternating in one process, so
both see the same machine load), the measurement behind :data:`rftstatic.compiled.PARALLEL_MIN_ELEMENTS`.
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


def thread_calls(scene: str, overrides=(), *, blocks: int = 40, calls: int = 25, seed: int = 0) -> dict:
    """Seconds per call of the compiled force kernel (:class:`rftstatic.element.explicit_force.ForceKernel`) on
    the mesh of ``scene`` (with ``overrides``) at random displacements (1 mm rms), one thread against all
    (``numba.config.NUMBA_NUM_THREADS``, no tuner), in ``blocks`` alternating blocks of ``calls`` calls.

    Returns ``{"elements", "threads", "same_force", "one": {...}, "all": {...}}``, each timing the fastest,
    tenth-percentile and median call [s]; ``same_force``: whether both give the same force to the bit."""
    import numba
    import numpy as np

    from rftstatic.element.explicit_force import ForceKernel
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene

    model, _ = build_model(load_scene(scene, list(overrides)), quiet=True)
    U = 1e-3 * np.random.default_rng(seed).standard_normal((model.mesh.n_nodes, 3))
    most = max(1, int(numba.config.NUMBA_NUM_THREADS))
    kernels = {"one": ForceKernel(model, backend="numba", threads=1),
               "all": ForceKernel(model, backend="numba", threads=most)}
    same = bool(np.array_equal(kernels["one"](U), kernels["all"](U)))  # also the compilation / cache load
    times = {k: [] for k in kernels}
    for _ in range(blocks):
        for key, kernel in kernels.items():
            for _ in range(calls):
                t0 = time.perf_counter()
                kernel(U)
                times[key].append(time.perf_counter() - t0)
    out = {"elements": model.mesh.n_elements, "threads": most, "same_force": same}
    for key, t in times.items():
        out[key] = {"min": float(np.min(t)), "p10": float(np.percentile(t, 10)), "median": float(np.median(t))}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--backend", nargs="+", default=["numpy", "numba"])
    ap.add_argument("--element", default="RFT6")
    ap.add_argument("--threads", nargs="+", metavar="SCENE [KEY=VALUE]",
                    help="time the force kernel on one thread and on all on this scene's mesh instead")
    args = ap.parse_args(argv)
    if args.threads:
        import os

        m = thread_calls(args.threads[0], args.threads[1:])
        print(f"{' '.join(args.threads)}: {m['elements']} elements, same force bits {m['same_force']}, "
              f"load {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        for key, label in (("one", "1 thread"), ("all", f"{m['threads']} threads")):
            t = m[key]
            print(f"  {label:10s} fastest {t['min'] * 1e3:.3f} ms  p10 {t['p10'] * 1e3:.3f} ms  "
                  f"median {t['median'] * 1e3:.3f} ms")
        return 0
    for side, n in ((0.2, 41), (1.0, 51)):
        model = sheet_model(side, n, args.element)
        for be in args.backend:
            m = measure(model, steps=args.steps, backend=be)
            print(f"{n}x{n} {args.element} E={m['elements']:5d} {be:6s} {m['steps']} steps "
                  f"{m['wall_s']:.2f} s  {m['element_steps_per_s'] / 1e6:.2f} M element-steps/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
