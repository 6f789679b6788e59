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
import logging
import os
import shutil
from pathlib import Path

from rftstatic.errors import ConvergenceError, InstabilityError
from rftstatic.scenes.analyses import ANALYSES, SCENE_ANALYSES

__all__ = ["ANALYSES", "analysis_of", "run", "run_scene", "resume_scene"]

log = logging.getLogger(__name__)

def analysis_of(scene) -> str:
    """The registered analysis that runs ``scene``: ``remeshed`` when it has a ``[remesh]`` table, else its
    ``analysis`` key (default ``static``)."""
    if scene.get("remesh") is not None:
        return "remeshed"
    name = scene.analysis
    if name not in ANALYSES:
        raise scene.error("analysis", f'"{name}" is not an analysis; use one of {", ".join(SCENE_ANALYSES)}')
    return name


PARTIAL = ".partial"
"""Suffix of the folder a run writes into before it replaces ``--out`` as a whole."""


def _check_out(out: Path) -> None:
    """``out`` may be replaced: absent, empty, or an earlier run's folder (it holds ``summary.json``)."""
    if out.exists() and (not out.is_dir() or (any(out.iterdir()) and not (out / "summary.json").exists())):
        what = "a file" if not out.is_dir() else "a folder that is not an rftstatic output (no summary.json)"
        raise OSError(f"--out {out} is {what}; a run replaces its output folder as a whole: choose a new "
                      "or an earlier run's folder")


def _publish(partial: Path, out: Path) -> None:
    """Move the finished run ``partial`` into place as ``out``, replacing an earlier run as a whole."""
    old = None
    if out.exists():
        old = out.with_name(f"{out.name}.old-{os.getpid()}")
        out.rename(old)
    partial.rename(out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _resumable(folder: Path) -> bool:
    """Whether ``folder`` holds work a ``--resume`` continues: a checkpoint, or the saved levels of a mesh
    sequence (``level-K.npz``, :mod:`rftstatic.app.levels`)."""
    return (folder / "checkpoint.npz").exists() or any(folder.glob("level-*.npz"))


def run(scene, out_dir, *, progress=True, figures=True):
    """Run ``scene`` with its analysis (:func:`analysis_of`) and return the
    :class:`~rftstatic.app.result.RunResult`.

    The run writes into ``<out_dir>.partial`` and replaces ``out_dir`` as a whole when it ends (also when
    its goal was not reached: the last state is written, labelled ``converged = false``), so that a
    reader never sees two runs mixed. An interrupted or killed dynamic run leaves its checkpoint in
    ``<out_dir>.partial``, where ``--resume`` finds it.
    """
    out = Path(out_dir)
    _check_out(out)
    partial = out.with_name(out.name + PARTIAL)
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    module = importlib.import_module(ANALYSES[analysis_of(scene)])
    try:
        result = module.run(scene, partial, progress=progress, figures=figures)
    except (ConvergenceError, InstabilityError):
        if (partial / "summary.json").exists():  # the last state was written: it is the run's result
            _publish(partial, out)
        raise
    except Exception:
        if not _resumable(partial):  # nothing to resume: leave no partial folder
            shutil.rmtree(partial, ignore_errors=True)
        raise
    _publish(partial, out)
    result.out = out
    return result


def run_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """:func:`run`, returning the summary as written to ``summary.json`` (plain types, scene units)."""
    return run(scene, out_dir, progress=progress, figures=figures).summary


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue a run of ``scene`` (static, dynamic, relax or remeshed) from its checkpoint; return its summary.

    The checkpoint of an interrupted run is in ``<out_dir>.partial`` (:func:`run`); that run continues
    there and then replaces ``out_dir``. Without one, the run continues from ``out_dir/checkpoint.npz``
    in place; a static or remeshed scene with neither runs from the start (:func:`run`).
    """
    name = analysis_of(scene)
    static = name in ("static", "remeshed")  # these start afresh without a checkpoint
    resume = importlib.import_module(ANALYSES[name]).resume_scene
    out = Path(out_dir)
    partial = out.with_name(out.name + PARTIAL)
    if _resumable(partial):
        summary = resume(scene, partial, progress=progress, figures=figures)
        _publish(partial, out)
        return summary
    if static and not _resumable(out):
        log.warning("no checkpoint in %s or %s: running %s from the start", partial, out, scene.name)
        return run(scene, out, progress=progress, figures=figures).summary
    return resume(scene, out, progress=progress, figures=figures)
