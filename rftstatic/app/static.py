"""Run a scene and write what users look at: summary.json, the deformed mesh (VTU) and PNG views.

Every number written is in the scene's units. A static solve that fails still writes its last
equilibrium, labelled ``"converged": false``, before the error is raised again.
"""

from __future__ import annotations

import logging
import platform
import time
from pathlib import Path

import numpy as np

from rftstatic.provenance import __version__
from rftstatic.errors import ConvergenceError
from rftstatic.scenes.build import build_model, probe_positions
from rftstatic.scenes.schema import Scene
from rftstatic.solvers.static import StaticOptions, solve_static

log = logging.getLogger(__name__)

_STATIC_KEYS = set(StaticOptions.__dataclass_fields__) - {"progress"}


def static_options(scene: Scene, *, progress=True) -> StaticOptions:
    s = dict(scene.get("solver", {}))
    s.pop("membrane", None)
    u = scene.units.length
    for key in ("max_step", "increment_displacement"):
        if key in s:
            s[key] = s[key] * u
    unknown = set(s) - _STATIC_KEYS
    if unknown:
        raise scene.error("solver", f"unknown option(s) {sorted(unknown)}")
    try:
        return StaticOptions(**s, progress=progress)
    except (TypeError, ValueError) as exc:
        raise scene.error("solver", str(exc)) from None


def run_scene(scene: Scene, out_dir, *, progress=True, figures=True) -> dict:
    """Build and solve ``scene``; write the outputs into ``out_dir``; return the summary."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if scene.get("remesh") is not None:
        from rftstatic.app.remeshed import run_remesh_scene

        return run_remesh_scene(scene, out, progress=progress, figures=figures)
    t0 = time.perf_counter()
    model, extras = build_model(scene)
    build_time = time.perf_counter() - t0
    analysis = scene.get("analysis", "static")
    if analysis != "static":
        from rftstatic.app.dynamic import run_dynamic_scene

        return run_dynamic_scene(scene, model, extras, out, progress=progress, figures=figures)
    error = None
    try:
        result = solve_static(model, options=static_options(scene, progress=progress))
    except ConvergenceError as exc:
        error, result = exc, exc.result
    summary = static_summary(scene, model, extras, result, build_time)
    write_outputs(scene, model, extras, result.U, out, summary, figures=figures)
    if error is not None:
        raise error
    return summary


def static_summary(scene, model, extras, result, build_time) -> dict:
    u = scene.units
    U = result.U
    probes = {name: {"reference": (p["reference"] / u.length).tolist(), "deformed": (p["deformed"] / u.length).tolist()}
              for name, p in probe_positions(model, extras["probes"], U).items()}
    rel_k = model.relative_curvature(U)
    summary = {
        "scene": scene.name,
        "title": scene.get("title", ""),
        "figure": scene.get("figure", ""),
        "units": u.name,
        "overrides": scene.overrides,
        "element": model.element,
        "analysis": "static",
        "nodes": model.mesh.n_nodes,
        "elements": model.mesh.n_elements,
        "mesh": model.mesh.summary(),
        "linear_solver": result.linear_solver,
        "converged": bool(result.converged),
        "message": result.message,
        "load_factor": result.lam,
        "load_steps": len(result.load_steps),
        "newton_iterations": result.iterations,
        "cutbacks": result.cutbacks,
        "solver_path": [{"lam": s["lam"], "iterations": s["iterations"]} for s in result.load_steps],
        "tangent_modes": result.tangent_modes,
        "route": result.route,
        "relax": result.relax,
        "stable_minimum": result.stable,
        "perturbation_seed": result.seed,
        "residual": result.residual / u.force,
        "wall_time_s": result.wall_time,
        "build_time_s": build_time,
        "energies": {k: v / u.energy for k, v in result.energies.items()},
        "probes": probes,
        "max_relative_curvature": float(rel_k.max()),
        "software": {"rftstatic": __version__, "python": platform.python_version()},
        "warnings": list(model.warnings),
    }
    if model.contact is not None:
        x = model.positions(U)
        summary["max_penetration"] = model.contact.max_penetration(x) / u.length
        summary["contact_nodes"] = int(model.contact.active(x).sum())
        summary["drape"] = drape_summary(scene, model, extras, U)
    return summary


def drape_summary(scene, model, extras, U) -> dict:
    """Drape coefficient, fold count and sharp-fold indicator (method.md), scene units."""
    from rftstatic.post.measures.summary import drape_measures

    u = scene.units.length
    x = model.positions(U)
    obstacles = extras["obstacles"]
    disc_area, centre = obstacles[0].footprint() if obstacles else (None, np.zeros(2))
    m = drape_measures(x, model.mesh.tri, sheet_area=float(model.mesh.area.sum()), disc_area=disc_area,
                       centre=centre, curvature=model.curvature(U), h=model.mesh.element_size)
    return _scale_lengths(m, u)


_LENGTH_KEYS = ("boundary_radius_min", "boundary_radius_mean", "boundary_radius_max", "max_dihedral_at",
                "max_relative_curvature_at")


def _scale_lengths(m: dict, u: float) -> dict:
    """Drape measures from SI to the scene's length unit."""
    out = dict(m)
    if "shadow_area" in out:
        out["shadow_area"] = out["shadow_area"] / u**2
    for key in _LENGTH_KEYS:
        if key in out and out[key] is not None:
            out[key] = (np.asarray(out[key], float) / u).tolist()
    return out


def write_outputs(scene, model, extras, U, out: Path, summary: dict, *, figures=True) -> None:
    from rftstatic.io.files import write_json, write_vtu

    u = scene.units.length
    write_json(out / "summary.json", summary)
    cell = {"curvature": model.curvature(U) * u, "relative_curvature": model.relative_curvature(U),
            "membrane_strain": model.membrane_strain(U)}
    if scene.get("output.vtu", True):
        write_vtu(out / "deformed.vtu", model.X3, U, model.mesh.tri, length_unit_scale=u, cell_data=cell)
    if figures:
        from rftstatic.io.views import plot_views

        views = tuple(scene.get("output.views", ["side", "top", "iso"]))
        status = "" if summary.get("converged", True) else " (NOT CONVERGED)"
        title = f"{scene.get('title', scene.name)} - {model.element}, {model.mesh.n_nodes} nodes{status}"
        from rftstatic.io.drape_figures import obstacle_drawers

        plot_views(str(out / "view"), model.positions(U) / u, model.mesh.tri, views=views, title=title,
                   color_by=cell["relative_curvature"], color_label="|kappa| h",
                   obstacles_draw=obstacle_drawers(extras.get("obstacles", ()), u))
