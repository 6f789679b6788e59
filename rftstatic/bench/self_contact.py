"""Timings of self-contact (issue 15): broad phase, distances, law and step bound on the sheets the
module docstrings quote. ``python -m rftstatic.bench.self_contact [--n 81 161]``; prints seconds (best
of ``--repeat``) and the machine's load average."""

from __future__ import annotations

import argparse
import os
from time import perf_counter

import numpy as np

from rftstatic.mesh.trimesh import rectangle


def crumpled(n: int, seed: int = 0):
    """The 0.8 m sheet of n x n nodes crumpled by random waves of 2 cm: ``(mesh, X (N, 3) [m])``."""
    mesh = rectangle(0.8, 0.8, n, n, pattern="alternate")
    rng = np.random.default_rng(seed)
    X = mesh.X3.copy()
    for _ in range(6):
        k = rng.normal(0, 8, 2)
        X[:, 2] += 0.02 / 6 * np.sin(X[:, :2] @ k + rng.uniform(0, 6.3))
    return mesh, X


def folded(n: int, d: float = 5e-4):
    """The 0.8 m sheet of n x n nodes, its right half folded onto its left half ``0.6 d`` above it."""
    mesh = rectangle(0.8, 0.8, n, n, pattern="alternate")
    X = mesh.X3.copy()
    right = X[:, 0] > 0.4 + 1e-9
    X[right, 0] = 0.8 - X[right, 0] + 0.0033
    X[right, 1] += 0.0021
    X[right, 2] = 0.6 * d
    return mesh, X


def smooth_step(X, size: float, seed: int = 1):
    """A smooth step of the nodes (waves over the sheet) whose largest motion is ``size`` [m]."""
    rng = np.random.default_rng(seed)
    dx = np.zeros_like(X)
    for i in range(3):
        for _ in range(3):
            k = rng.normal(0, 6, 2)
            dx[:, i] += np.sin(X[:, :2] @ k + rng.uniform(0, 6.3))
    return dx * (size / np.max(np.linalg.norm(dx, axis=1)))


def best(f, repeat):
    t = []
    for _ in range(repeat):
        t0 = perf_counter()
        out = f()
        t.append(perf_counter() - t0)
    return min(t), out


def main(argv=None):
    from rftstatic.contact.self_contact.broad_phase import SheetPrimitives, find_pairs
    from rftstatic.contact.self_contact.law import SelfContact

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, nargs="+", default=[81, 161])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--skip", nargs="*", default=[], help="parts to skip: build swept law ccd")
    ap.add_argument("--numpy", action="store_true", help="the numpy path only (no compiled twins)")
    a = ap.parse_args(argv)
    from rftstatic.contact.self_contact import distance, law_kernels

    if a.numpy:
        distance.compiled_for = lambda n, compiled=None: False
    print(f"load average {os.getloadavg()}, {'numpy' if a.numpy else 'compiled where numba is installed'}"
          )
    for n in a.n:
        mesh, X = crumpled(n)
        prims = SheetPrimitives.of_mesh(mesh)
        if "build" not in a.skip:
            t, p = best(lambda: find_pairs(prims, X, 3e-3), a.repeat)
            print(f"{n}x{n} crumpled build r = 3 mm: {t:.3f} s, {len(p.pt)} PT, {len(p.ee)} EE")
        if "swept" not in a.skip:
            X1 = X + smooth_step(X, 0.07)
            t, p = best(lambda: find_pairs(prims, X, 5e-4, X1), 1 if n > 81 else a.repeat)
            print(f"{n}x{n} crumpled swept 7 cm step r = 0.5 mm: {t:.3f} s, {len(p.pt)} PT, {len(p.ee)} EE")
        if n > 81:
            continue
        mesh, X = folded(n)
        d = 5e-4
        sc = SelfContact(mesh, d, 1.0)
        t, p = best(lambda: sc.pairs(X), a.repeat)
        print(f"{n}x{n} folded build: {t:.3f} s, {len(p.pt)} PT, {len(p.ee)} EE")
        if "law" not in a.skip:
            t, st = best(lambda: sc.evaluate(X, tangent=False), a.repeat)
            print(f"{n}x{n} folded energy+force: {t:.3f} s, {st.n_active} active, min {st.min_distance / d:.3f} d")
            t, st = best(lambda: sc.evaluate(X, tangent=True), a.repeat)
            print(f"{n}x{n} folded with PSD tangent (law_kernels.psd_project): {t:.3f} s")
            cache = sc.new_pairs()
            sc.pairs(X, cache)
            t, st = best(lambda: sc.evaluate(X, tangent=False, cache=cache), a.repeat)
            print(f"{n}x{n} folded energy+force, cached pairs: {t:.3f} s")
            t, st = best(lambda: sc.evaluate(X, tangent=True, cache=cache, project=False), a.repeat)
            print(f"{n}x{n} folded with unprojected tangent, cached pairs: {t:.3f} s")
            t, _ = best(lambda: law_kernels.psd_project(st.blocks), a.repeat)
            print(f"{n}x{n} law_kernels.psd_project of {len(st.blocks)} blocks: {t:.3f} s")
        if "ccd" not in a.skip:
            cache = sc.new_pairs()
            sc.pairs(X, cache)
            dx = 1e-4 * np.random.default_rng(2).standard_normal(X.shape)
            t, al = best(lambda: sc.max_step_fraction(X, dx, cache=cache), a.repeat)
            print(f"{n}x{n} folded step bound, random 0.1 mm step: {t:.3f} s, alpha {al:.4f}")
            dx = 1e-2 * np.random.default_rng(3).standard_normal(X.shape)
            t, al = best(lambda: sc.max_step_fraction(X, dx, cache=cache), 1)
            print(f"{n}x{n} folded step bound, random 1 cm step: {t:.3f} s, alpha {al:.4f}")
            npt, nee = sc._x4(X, cache.pairs(sc.prims, X, d))
            for step in (1e-4, 1e-2):
                dx = step * np.random.default_rng(2).standard_normal(X.shape)
                t, al = best(lambda: min(law_kernels.additive_ccd(X[npt], dx[npt], 0, 0.2, 200),
                                         law_kernels.additive_ccd(X[nee], dx[nee], 1, 0.2, 200)), a.repeat)
                print(f"{n}x{n} law_kernels.additive_ccd, listed pairs, random {step * 1e3:g} mm step: "
                      f"{t:.3f} s, alpha {al:.4f}")


if __name__ == "__main__":
    main()
