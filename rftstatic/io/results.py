"""Write a solved state: ``summary.json``, ``deformed.vtu`` (displacement, curvature, relative
curvature |kappa| h, membrane strain), the PNG views and the interactive ``view.html``
(:mod:`rftstatic.io.viewer`), all in the scene's units; :func:`write_mesh_series`: a remeshed run's meshes."""

from __future__ import annotations

import logging
from pathlib import Path

from rftstatic.io.figure import LENGTH_UNITS
from rftstatic.io.files import write_json, write_vtu

log = logging.getLogger(__name__)


def write_outputs(scene, model, extras, U, out: Path, summary: dict, *, figures=True) -> None:
    """Write the deformed state ``U (N, 3)`` [m] of ``model`` (VTU, PNG views, ``view.html``) and then ``summary``
    into ``out``: ``summary.json`` is written once, last, so a run folder with one is complete.

    The views draw what the sheet rests on (:func:`rftstatic.io.solids.run_solids`: the obstacles and a tester's
    clamping disc of the scene) and are coloured by the relative curvature |kappa| h.
    ``view.html`` (with ``figures`` and the VTU) is built from the files just written, as
    ``python -m rftstatic view`` builds it later."""
    u = scene.units.length
    cell = {"curvature": model.curvature(U) * u, "relative_curvature": model.relative_curvature(U),
            "membrane_strain": model.membrane_strain(U)}
    if scene.get("output.vtu", True):
        write_vtu(out / "deformed.vtu", model.X3, U, model.mesh.tri, length_unit_scale=u, cell_data=cell)
    if figures:
        from rftstatic.io.solids import run_solids
        from rftstatic.io.views import plot_views

        views = tuple(scene.get("output.views", ["side", "top", "iso"]))
        status = "" if summary.get("converged", True) else "NOT CONVERGED; "
        title = f"{scene.get('title', scene.name)}\n{status}{run_label(model)}"
        x = model.positions(U) / u
        plot_views(str(out / "view"), x, model.mesh.tri, views=views, title=title,
                   color_by=cell["relative_curvature"], color_label=CURVATURE_LABEL,
                   length_unit=LENGTH_UNITS.get(scene.units.name, ""), solids=run_solids(scene.data, model.X3 / u, x))
        drape = summary.get("drape") or {}
        if extras.get("disc") is not None and drape.get("drape_coefficient") is not None:
            _shadow(scene, model, extras["disc"], U, out, drape)
        if scene.get("output.vtu", True):
            write_run_view(out, summary)
    write_json(out / "summary.json", summary)


CURVATURE_LABEL = "relative curvature |kappa| h [-]"
"""The colour bar of the views: the field and its unit."""


def write_run_view(out: Path, summary: dict) -> None:
    """``view.html`` of the run being written in ``out`` (its VTU files are there, ``summary`` not yet written);
    entered in ``summary["view"]``."""
    from rftstatic.io.viewer import VIEW_FILE, write_view

    try:
        write_view(out, summary=summary)
    except Exception as exc:  # noqa: BLE001 - a picture must not cost the run's results
        log.warning("view.html was not written (%s: %s); the other outputs are complete: try "
                    "'python -m rftstatic view RUN_DIR' on the run folder", type(exc).__name__, exc)
        return
    summary["view"] = VIEW_FILE


def write_mesh_series(scene, meshes, out: Path) -> None:
    """A remeshed run's meshes as ``meshes/mesh_<k>.vtu`` indexed by ``meshes.pvd`` (the time of a relaxation's
    remesh, else the cycle k), for the viewer's slider; ``meshes``: dicts with ``mesh``, ``U (N, 3)`` [m] (None:
    drawn flat), ``t`` [s] and ``model`` (its curvature and strain fields; without one a flat mesh has none, zeros)."""
    import numpy as np

    from rftstatic.io.files import write_pvd, write_vtu

    if not scene.get("output.vtu", True):
        return
    (out / "meshes").mkdir(exist_ok=True)
    entries = []
    for k, m in enumerate(meshes):
        mesh = m["mesh"]
        U = m["U"] if m["U"] is not None else np.zeros_like(mesh.X3)
        name = f"meshes/mesh_{k:02d}.vtu"
        model, e = m.get("model"), mesh.n_elements
        if model is not None:
            cell = {"curvature": model.curvature(U) * scene.units.length,
                    "relative_curvature": model.relative_curvature(U), "membrane_strain": model.membrane_strain(U)}
        elif m["U"] is None:                                        # the flat reference: no curvature, no strain
            cell = {"curvature": np.zeros((e, 3)), "relative_curvature": np.zeros(e),
                    "membrane_strain": np.zeros((e, 3))}
        else:
            cell = {}
        write_vtu(out / name, mesh.X3, U, mesh.tri, length_unit_scale=scene.units.length, cell_data=cell)
        t = m.get("t")
        entries.append((k if t is None else t / scene.units.time, name))
    if len({t for t, _ in entries}) < len(entries):               # a static route: no times, the cycles
        entries = [(k, name) for k, (_, name) in enumerate(entries)]
    write_pvd(out / "meshes.pvd", entries)


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
