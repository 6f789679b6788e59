"""Benchmark of the static drape scenes of §4.2-4.5: wall time and peak memory, end to end.

``python -m rftstatic.bench.drape [LABEL ...]`` runs each scene of :data:`SCENES` as
``python -m rftstatic case NAME --set ...`` would (build, load-scaled Newton, summary.json,
deformed.vtu, PNG views with the obstacle), each in a fresh interpreter
(:func:`rftstatic.bench.harness.run_child`) so that the peak resident memory (``ru_maxrss`` of that
process) is the scene's own.

Targets on the 2-core reference machine, by mesh size: 33 x 33 nodes under 10 s, 61 x 61 under 60 s,
81 x 81 under 3 min (build + solve + outputs). Scenes larger than 81 x 81 are reported without a target.

The same child process is what the drape validation reports use (:func:`run_cached`): besides the
summary it saves ``state.npz`` (deformed and reference positions in the scene's units, triangles,
relative curvature |kappa| h and the dihedral angles) so that reports can be redrawn without solving.
Its folder is keyed on the scene, its overrides and the code's fingerprint
(:func:`rftstatic.provenance.code_fingerprint`), so that a run by other code is never reused.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

# label -> (scene, overrides)
SCENES = {
    "pedestal-square-20 33x33": ("pedestal-square-20", []),
    "pedestal-square-20 61x61": ("pedestal-square-20", ["mesh.nodes=[61,61]"]),
    "pedestal-square-40 81x81": ("pedestal-square-40", []),
    "pedestal-square-80 81x81": ("pedestal-square-80", []),
    "pedestal-round-50 21x160": ("pedestal-round-50", []),
    "sphere-30 61x61": ("sphere-30", []),
}

# (largest node count, target [s]) by mesh size: 33 x 33, 61 x 61, 81 x 81
TARGETS = ((33 * 33, 10.0), (61 * 61, 60.0), (81 * 81, 180.0))
TIMEOUT_S = 3600.0  # a run's child is killed after this long [s] (20 x the largest target)


def target_for(nodes: int) -> float | None:
    """The wall-time target [s] of a mesh with ``nodes`` nodes (None above 81 x 81)."""
    for n, t in TARGETS:
        if nodes <= n:
            return t
    return None


def extra_indicators(x, tri) -> dict:
    """Distribution of the dihedral angles [deg]: percentiles 50/90/99/99.9 and the count above 90 deg."""
    from rftstatic.post.measures.sharp import dihedral_angles

    _, ang = dihedral_angles(x, tri)
    deg = np.degrees(ang)
    return {"dihedral_p50_deg": float(np.percentile(deg, 50)), "dihedral_p90_deg": float(np.percentile(deg, 90)),
            "dihedral_p99_deg": float(np.percentile(deg, 99)), "dihedral_p999_deg": float(np.percentile(deg, 99.9)),
            "edges_over_90deg": int(np.sum(deg > 90.0)), "edges_over_45deg": int(np.sum(deg > 45.0)),
            "interior_edges": int(deg.size)}


def child(name: str, out: str, overrides: list[str], figures: bool) -> dict:
    """Run one static scene in this process; save ``state.npz`` and ``record.json``; return the record.

    The record: scene, overrides, element, nodes, elements, converged, error (the solver's message),
    load_factor, load_steps, newton_iterations, linear_solver, perturbation_seed, build_s, solve_s,
    outputs_s, wall_s [s] (in this process, imports excluded), peak_rss_mb [MB] (this process),
    max_penetration, h_mean [scene length unit], curvature and dihedral indicators (:func:`extra_indicators`),
    drape (the summary's drape measures) and software (:func:`rftstatic.provenance.software`).
    """
    import resource

    from rftstatic.app.levels import solve_levels
    from rftstatic.app.static import static_summary
    from rftstatic.errors import ConvergenceError
    from rftstatic.io.results import write_outputs
    from rftstatic.provenance import software
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.options import run_options, static_options
    from rftstatic.scenes.schema import load_scene
    from rftstatic.solvers.static import solve_static

    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    scene = load_scene(name, overrides)
    model, extras = build_model(scene)
    build = time.perf_counter() - t0
    error = ""
    opts = static_options(scene, progress=False)
    try:  # a scene with solver.levels > 1 is solved by mesh sequencing, as `python -m rftstatic case` does
        single = run_options(scene).levels == 1
        result = solve_static(model, options=opts) if single else solve_levels(scene, model, opts)
    except ConvergenceError as exc:
        if exc.result is None:  # no state to write (a coarser level failed): the solver's error, as the CLI does
            raise
        error, result = str(exc), exc.result
    solved = time.perf_counter() - t0
    summary = static_summary(scene, model, extras, result, build)
    write_outputs(scene, model, extras, result.U, out_dir, summary, figures=figures)
    wall = time.perf_counter() - t0
    u = scene.units.length
    x = model.positions(result.U) / u
    rel = model.relative_curvature(result.U)
    np.savez_compressed(out_dir / "state.npz", x=x, X=model.X3 / u, tri=model.mesh.tri, relative_curvature=rel)
    drape = summary.get("drape", {})
    rec = {"scene": name, "overrides": overrides, "element": model.element, "nodes": model.mesh.n_nodes,
           "elements": model.mesh.n_elements, "converged": bool(result.converged), "error": error,
           "load_factor": float(result.lam), "load_steps": len(result.load_steps),
           "newton_iterations": result.iterations, "linear_solver": result.linear_solver,
           "perturbation_seed": result.seed, "build_s": build, "solve_s": solved - build, "outputs_s": wall - solved,
           "wall_s": wall, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
           "max_penetration": summary.get("max_penetration"), "h_mean": float(model.mesh.element_size.mean()) / u,
           "max_relative_curvature": float(rel.max()), "rel_curvature_p99": float(np.percentile(rel, 99)),
           "drape": drape, **extra_indicators(x, model.mesh.tri), "software": software()}
    (out_dir / "record.json").write_text(json.dumps(rec, indent=1, default=float), encoding="utf-8")
    return rec


def run_one(name: str, overrides=(), out=None, *, figures: bool = True, timeout: float = TIMEOUT_S) -> dict:
    """Run one static scene in a fresh interpreter; return its record (see :func:`child`).

    The record adds ``process_s`` [s] (the whole child process, interpreter start-up and imports
    included), ``cpu_s`` [s] (its user + system time), ``target_s`` and ``within_target``; its
    ``peak_rss_mb`` [MB] is the child's peak to its exit. A solve that does not converge returns
    ``converged = False`` and the solver's message in ``error``; a crash, or a solve that failed with no
    state to write (a coarser level of ``solver.levels``), raises :class:`rftstatic.bench.harness.ChildError`
    (a ``RuntimeError``) naming the scene, with the child's stderr; a child still running after ``timeout``
    [s] is killed (:class:`~rftstatic.bench.harness.ChildTimeout`).
    """
    from rftstatic.bench.harness import run_child

    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(out) if out else Path(tmp) / "run"
        run = run_child("rftstatic.bench.drape:child",
                        {"name": name, "out": str(out_dir), "overrides": list(overrides), "figures": figures},
                        name=f"drape run of {name} {list(overrides)}", timeout=timeout)
    rec = run.result
    rec["process_s"] = run.wall_s
    rec["cpu_s"] = run.cpu_s  # user + system time of the child: what the run costs on a machine shared with others
    rec["peak_rss_mb"] = run.peak_rss_mb  # the child's, to its exit (the child's own figure is its peak so far)
    rec["target_s"] = target_for(rec["nodes"])
    rec["within_target"] = rec["target_s"] is None or run.wall_s < rec["target_s"]
    if out:
        (Path(out) / "record.json").write_text(json.dumps(rec, indent=1, default=float), encoding="utf-8")
    return rec


def run_label(name: str, overrides=()) -> str:
    """The scene and its overrides as a file-system safe name (no code version: see :func:`run_key`)."""
    parts = [name] + [o.replace("mesh.nodes=", "n").replace("element=", "") for o in overrides]
    return "_".join(parts).replace("[", "").replace("]", "").replace(",", "x").replace(" ", "").replace("=", "-")


def code_version() -> str:
    """The code's fingerprint as recorded with a run (12 hex digits of :func:`rftstatic.provenance.code_fingerprint`)."""
    from rftstatic import provenance

    return provenance.code_fingerprint()[:12]


def run_key(name: str, overrides=()) -> str:
    """Cache folder name of a run: :func:`run_label` and the code version (``..._code-<12 hex>``).

    Any edit of the package's sources changes the key, so a run made by other code is never reused.
    """
    return f"{run_label(name, overrides)}_code-{code_version()}"


def cached_dir(name: str, overrides=(), *, root: Path) -> Path | None:
    """``root/<key>/`` when it holds a finished run by this code (record, state, same fingerprint), else None."""
    d = Path(root) / run_key(name, overrides)
    if not ((d / "record.json").exists() and (d / "state.npz").exists()):
        return None
    try:
        code = json.loads((d / "record.json").read_text(encoding="utf-8")).get("software", {}).get("code")
    except (OSError, ValueError):
        return None
    return d if code == code_version() else None  # the child ran other code than the key says: stale


def run_cached(name: str, overrides=(), *, root: Path, refresh: bool = False, figures: bool = True,
               timeout: float = TIMEOUT_S) -> dict:
    """:func:`run_one` into ``root/<key>/`` (:func:`run_key`), reusing a finished run there unless ``refresh``.

    ``timeout`` [s]: the child is killed after this long.
    Returns the record with ``state`` (the arrays of ``state.npz``) and ``dir``.
    """
    d = Path(root) / run_key(name, overrides)
    if refresh or cached_dir(name, overrides, root=root) is None:
        run_one(name, list(overrides), d, figures=figures, timeout=timeout)
    rec = json.loads((d / "record.json").read_text(encoding="utf-8"))
    if "process_s" not in rec:  # the child finished but its parent was stopped: in-process time only
        rec["process_s"] = rec["wall_s"]
        rec["target_s"] = target_for(rec["nodes"])
        rec["within_target"] = rec["target_s"] is None or rec["wall_s"] < rec["target_s"]
    with np.load(d / "state.npz") as z:
        rec["state"] = {k: z[k] for k in z.files}
    rec["dir"] = str(d)
    return rec


def bench_drape_scenes(labels=None, *, out_root=None, verbose=True) -> list[dict]:
    """Run each labelled scene of :data:`SCENES` end to end in a fresh interpreter; return the records."""
    labels = list(labels or SCENES)
    unknown = [lb for lb in labels if lb not in SCENES]
    if unknown:
        raise ValueError(f"unknown scene label(s) {unknown}; use {list(SCENES)}")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(out_root) if out_root else Path(tmp)
        for lb in labels:
            name, ov = SCENES[lb]
            r = run_one(name, ov, root / run_label(name, ov))
            r["label"] = lb
            results.append(r)
            if verbose:
                t = r["target_s"]
                verdict = "" if t is None else (f" (target {t:g} s: {'met' if r['within_target'] else 'MISSED'})")
                conv = "" if r["converged"] else f"  NOT CONVERGED: {r['error']}"
                print(f"{lb:26s} {r['element']} {r['nodes']:6d} nodes  end to end {r['process_s']:7.1f} s{verdict} "
                      f"[CPU {r['cpu_s']:.1f} s]; "
                      f"build {r['build_s']:.1f} s, solve {r['solve_s']:.1f} s ({r['newton_iterations']} Newton "
                      f"iterations, {r['load_steps']} load steps), outputs {r['outputs_s']:.1f} s; "
                      f"peak {r['peak_rss_mb']:.0f} MB{conv}", flush=True)
    return results


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("labels", nargs="*", help=f"scene labels (default all): {', '.join(SCENES)}")
    ap.add_argument("--out", default=None, help="keep the outputs in this folder")
    ap.add_argument("--json", default=None, help="also write the records to this JSON file")
    args = ap.parse_args(argv)
    results = bench_drape_scenes(args.labels, out_root=args.out)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=float), encoding="utf-8")
    return 0 if all(r["within_target"] and r["converged"] for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
