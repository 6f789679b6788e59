"""The ``static`` analysis: build the scene's model, solve the static drape, write the outputs.

The route (load-scaled Newton, dynamic relaxation, or both) is :func:`rftstatic.solvers.static.solve_static`.
Every number written is in the scene's units. A solve that fails still writes its last equilibrium,
labelled ``"converged": false``, before the :class:`~rftstatic.errors.ConvergenceError` is raised again
(the command line exits with status 3).
"""

from __future__ import annotations

import time
from pathlib import Path

from rftstatic.app.result import RunResult
from rftstatic.errors import ConvergenceError
from rftstatic.io.files import to_jsonable
from rftstatic.io.results import write_outputs
from rftstatic.io.summary import drape_summary, probe_summary, summary_header
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import static_options
from rftstatic.solvers.static import solve_static


def run(scene, out: Path, *, progress=True, figures=True) -> RunResult:
    """Build and solve ``scene``; write the outputs into ``out``; return the result."""
    t0 = time.perf_counter()
    model, extras = build_model(scene)
    build_time = time.perf_counter() - t0
    error = None
    try:
        result = solve_static(model, options=static_options(scene, progress=progress))
    except ConvergenceError as exc:
        error, result = exc, exc.result
        if result is None:
            raise
    summary = static_summary(scene, model, extras, result, build_time)
    write_outputs(scene, model, extras, result.U, out, summary, figures=figures)
    if error is not None:
        raise error
    return RunResult(to_jsonable(summary), model, result.U, extras, out)


def static_summary(scene, model, extras, result, build_time) -> dict:
    """The summary (scene units) of a :class:`~rftstatic.solvers.newton.StaticResult` of ``model``."""
    u = scene.units
    U = result.U
    summary = summary_header(scene, model, "static")
    summary.update({
        "linear_solver": result.linear_solver,
        "converged": bool(result.converged),
        "message": result.message,
        "load_factor": result.lam,
        "load_steps": len(result.load_steps),
        "newton_iterations": result.iterations,
        "cutbacks": result.cutbacks,
        "factorisations": result.factorisations,
        "iteration_retries": result.retries,
        "solver_path": [{"lam": s["lam"], "iterations": s["iterations"], "scheme": s.get("scheme", "")}
                        for s in result.load_steps],
        "tangent_modes": result.tangent_modes,
        "route": result.route,
        "relax": result.relax,
        "stable_minimum": result.stable,
        "perturbation_seed": result.seed,
        "residual": result.residual / u.force,
        "wall_time_s": result.wall_time,
        "build_time_s": build_time,
        "energies": {k: v / u.energy for k, v in result.energies.items()},
        "probes": probe_summary(scene, model, extras["probes"], U),
        "max_relative_curvature": float(model.relative_curvature(U).max()),
    })
    if model.contact is not None:
        x = model.positions(U)
        summary["max_penetration"] = model.contact.max_penetration(x) / u.length
        summary["contact_nodes"] = int(model.contact.active(x).sum())
        summary["drape"] = drape_summary(scene, model, extras, U)
    return summary
