"""The analysis types, registered by name: each is one module of this package with a function
``run(scene, out, *, progress, figures) -> RunResult``.

=============  ============================================================  =========================
name           what it does                                                  module
=============  ============================================================  =========================
``static``     static drape: load-scaled Newton and/or relaxation + Newton    :mod:`rftstatic.app.static`
``dynamic``    explicit central differences with mass damping (§2.4, §4.6)   :mod:`rftstatic.app.dynamic`
``relax``      dynamic relaxation to rest (§6)                               :mod:`rftstatic.app.dynamic`
``remeshed``   a scene with ``[remesh]``: global adaptive remeshing (§5-6)   :mod:`rftstatic.app.remeshed`
=============  ============================================================  =========================

A new analysis type is one module with ``run`` and one line in
:data:`rftstatic.scenes.analyses.ANALYSES` (which the scene schema checks); the modules are imported
only when a scene asks for them, so a static drape does not pay for the explicit solver's or the
mesher's imports.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from rftstatic.scenes.analyses import ANALYSES, SCENE_ANALYSES

__all__ = ["ANALYSES", "analysis_of", "run", "run_scene", "resume_scene"]

def analysis_of(scene) -> str:
    """The registered analysis that runs ``scene``: ``remeshed`` when it has a ``[remesh]`` table, else its
    ``analysis`` key (default ``static``)."""
    if scene.get("remesh") is not None:
        return "remeshed"
    name = scene.get("analysis", "static")
    if name not in ANALYSES:
        raise scene.error("analysis", f'"{name}" is not an analysis; use one of {", ".join(SCENE_ANALYSES)}')
    return name


def run(scene, out_dir, *, progress=True, figures=True):
    """Run ``scene`` with its analysis (:func:`analysis_of`), writing into ``out_dir`` (created);
    return the :class:`~rftstatic.app.result.RunResult`."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    module = importlib.import_module(ANALYSES[analysis_of(scene)])
    return module.run(scene, out, progress=progress, figures=figures)


def run_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """:func:`run`, returning the summary as written to ``summary.json`` (plain types, scene units)."""
    return run(scene, out_dir, progress=progress, figures=figures).summary


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue a dynamic or relax run of ``scene`` from ``out_dir/checkpoint.npz``; return its summary."""
    from rftstatic.app.dynamic import resume_scene as resume

    return resume(scene, out_dir, progress=progress, figures=figures)
