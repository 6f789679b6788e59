"""Write a solved state: ``summary.json``, ``deformed.vtu`` (displacement, curvature, relative
curvature |kappa| h, membrane strain) and the PNG views, all in the scene's units."""

from __future__ import annotations

from pathlib import Path

from rftstatic.io.files import write_json, write_vtu


def write_outputs(scene, model, extras, U, out: Path, summary: dict, *, figures=True) -> None:
    """Write the deformed state ``U (N, 3)`` [m] of ``model`` (VTU, PNG views) and then ``summary`` into ``out``:
    ``summary.json`` is written once, last, so a run folder with one is complete."""
    u = scene.units.length
    cell = {"curvature": model.curvature(U) * u, "relative_curvature": model.relative_curvature(U),
            "membrane_strain": model.membrane_strain(U)}
    if scene.get("output.vtu", True):
        write_vtu(out / "deformed.vtu", model.X3, U, model.mesh.tri, length_unit_scale=u, cell_data=cell)
    if figures:
        from rftstatic.io.drape_figures import obstacle_drawers
        from rftstatic.io.views import plot_views

        views = tuple(scene.get("output.views", ["side", "top", "iso"]))
        status = "" if summary.get("converged", True) else "NOT CONVERGED; "
        title = f"{scene.get('title', scene.name)}\n{status}{run_label(model)}"
        plot_views(str(out / "view"), model.positions(U) / u, model.mesh.tri, views=views, title=title,
                   color_by=cell["relative_curvature"], color_label="|kappa| h",
                   obstacles_draw=obstacle_drawers(extras.get("obstacles", ()), u))
        drape = summary.get("drape") or {}
        if extras.get("disc") is not None and drape.get("drape_coefficient") is not None:
            _shadow(scene, model, extras["disc"], U, out, drape)
    write_json(out / "summary.json", summary)


def run_label(model) -> str:
    """What was run, for a figure's title: the fabric that was used (the material's name, "(modified)" when a
    scene changed a preset's values), the element and the mesh size. A scene's title names the fabric it was
    written for; after ``--set material...`` this line says which one the figure shows."""
    return f"fabric {model.material.name}, {model.element}, {model.mesh.n_nodes} nodes"


def _shadow(scene, model, disc, U, out: Path, drape: dict) -> None:
    """``shadow_top.png``: the Cusick tester's view of the draped specimen (its shadow from above)."""
    import numpy as np

    from rftstatic.io.drape_figures import plot_shadow

    u = scene.units.length
    r = np.hypot(*(model.mesh.X - disc.centre).T)
    title = (f"{scene.get('title', scene.name)}\n{model.material.name}: DC {drape['drape_coefficient_percent']:.1f}%, "
             f"{drape['fold_count']} folds ({model.element}, {model.mesh.n_nodes} nodes)")
    plot_shadow(out / "shadow_top.png", model.positions(U) / u, model.mesh.tri, fill=disc.fill / u,
                centre=disc.centre / u, specimen_radius=float(r.max()) / u,
                disc_radius=float(np.sqrt(disc.area / np.pi)) / u, title=title, unit=scene.units.name.split("-")[0])
