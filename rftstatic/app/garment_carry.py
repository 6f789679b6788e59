"""A garment's drape carried to another mesh of its pattern and solved there: does that mesh hold the drape?

A garment on a frictionless form can rest in several stable equilibria that differ in their hem folds and hardly
in energy (a full circle skirt: 12 or 14 folds). Which one the route finds depends on the fall from the flat
start, so comparing the fold counts of two meshes' own runs mixes the mesh with the route. :func:`carry_drape`
separates them: it takes a finished run's drape (``garment.obj``) of one mesh size, carries it to the mesh of
another size of the same pattern through the flat pattern (every node at its panel coordinates on the source's
curved RF patches, :func:`rftstatic.garment.sewing.carry_closed`) and solves the static equilibrium there by
Newton at full load from that state (:meth:`rftstatic.solvers.options.StaticOptions.from_state`), with the scene's
contact surface of that mesh size. If the drape is a stable minimum on both meshes with the same folds, the mesh
resolves it; the energies of two drapes on one mesh tell which is lower there.

Seamed patterns are carried too: the source's sewn nodes are spread back to their panels' nodes (the same merge
as the source run's, :func:`rftstatic.garment.sewing.sew`), and the carried panels are merged again on the target
mesh. Lengths in scene units in the returned table.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from rftstatic.app import garment as G
from rftstatic.garment.sewing import carry_closed, panel_mesh, seam_pairs, sew

__all__ = ["carry_drape"]


def _panel_positions(pmesh, x_sewn: np.ndarray, source) -> np.ndarray:
    """(N_panel, 3) [m]: the positions of the panel nodes of ``pmesh`` from the sewn garment's ``x_sewn`` (the same
    merge as the run's: :func:`rftstatic.garment.sewing.sew`); ``ValueError`` when the node counts differ."""
    pairs = seam_pairs(pmesh)
    node_of = np.arange(pmesh.n_nodes)
    if len(pairs):
        flat = np.concatenate([m.X for m in pmesh.meshes])  # any positions: only the node map is used
        _, node_of = sew(panel_mesh(pmesh, np.c_[flat, np.zeros(len(flat))]), pairs, np.zeros((pmesh.n_nodes, 3)))
    if len(x_sewn) != node_of.max() + 1:
        raise ValueError(f"{source}: garment.obj has {len(x_sewn)} nodes, the pattern meshed and sewn at that size "
                         f"has {node_of.max() + 1}: give the source run's garment.h")
    return x_sewn[node_of]


def carry_drape(scene, source: str | Path, source_h: float, *, out: str | Path, h: float | None = None,
                progress: bool = False) -> dict:
    """Carry the drape of the finished garment run in folder ``source`` (its ``garment.obj``; the run's mesh size
    ``source_h`` [scene length]) to the scene's mesh of size ``h`` (default ``garment.h``) and solve it there.

    Returns a table (scene units): ``folds_carried`` (the carried start's hem folds), ``hem_folds``,
    ``hem_drape_coefficient``, ``converged``, ``stable_minimum``, ``newton_iterations``, ``energies``, ``nodes``,
    ``wall_time_s``. ``out``: the folder for the contact surface's OBJ. Raises ``ValueError`` when the source's
    node count does not match the pattern meshed at ``source_h``."""
    from rftstatic.post.measures.shadow import shadow_area
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.options import static_options
    from rftstatic.solvers.static import solve_static

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    u = scene.units.length
    t0 = time.perf_counter()
    src_pmesh, _, _ = G.dressed_mesh(scene, source_h)
    x_panels = _panel_positions(src_pmesh, G.read_obj_uv(Path(source) / "garment.obj")[0] * u, source)
    pmesh, mesh, _ = G.dressed_mesh(scene, h)
    x = carry_closed(src_pmesh, x_panels, pmesh)
    pairs = seam_pairs(pmesh)
    if len(pairs):  # the reference: the placed panels merged at their seams' midpoints (U's origin only)
        where = Path(pmesh.pattern.source).name
        x = sew(mesh, pairs, x, where=where)[0].X3  # the carried panels merged the same way
        mesh, _ = sew(mesh, pairs, mesh.X3, where=where)
    table = G.contact_surface(G.dress_form(scene), out / "body-m.obj", mesh, u)
    solved = type(scene)(G.static_data(scene, table), scene.path, scene.name, scene.overrides)
    model, _ = build_model(solved, mesh=mesh, start_check=False)
    U0 = x - model.X3
    folds0 = G.hem_folds(model.mesh, x)
    result = solve_static(model, U0=U0, options=static_options(solved, progress=progress).from_state())
    x1 = model.positions(result.U)
    flat = float(model.mesh.area.sum())
    return {"source": str(source), "source_h": float(source_h), "h": float(G.garment_h(scene) if h is None else h),
            "nodes": int(model.mesh.n_nodes), "folds_carried": folds0, "hem_folds": G.hem_folds(model.mesh, x1),
            "hem_drape_coefficient": shadow_area(x1, model.mesh.tri) / flat, "converged": bool(result.converged),
            "stable_minimum": result.stable, "newton_iterations": int(result.iterations),
            "energies": {k: float(v) / scene.units.energy for k, v in result.energies.items()},
            "wall_time_s": time.perf_counter() - t0}
