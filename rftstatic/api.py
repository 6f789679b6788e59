"""The Python API: what ``python -m rftstatic case NAME`` does, step by step, for scripts and notebooks.

>>> from rftstatic import api
>>> scene = api.load_scene("pedestal-square-20", ["mesh.nodes=[17,17]"])   # cases/NAME.toml or a path
>>> model, extras = api.build_model(scene)                                 # the Model and its obstacles
>>> result = api.run(scene, "out/ps20", figures=False)                     # solve and write outputs
>>> result.converged, result.summary["drape"]["drape_coefficient"]
>>> result.U.shape                                                          # (N, 3) displacements [m]

Every quantity inside the package is SI; ``result.summary`` (as written to ``summary.json``) is in the
scene's units. Errors: :class:`~rftstatic.errors.SceneError` (bad scene: names file, key, value),
:class:`~rftstatic.errors.ConvergenceError` (the static solve failed; its last equilibrium was
written, labelled ``converged = false``).
"""

from __future__ import annotations

from pathlib import Path

from rftstatic.app.registry import ANALYSES, analysis_of, resume_scene
from rftstatic.app.registry import run as _run
from rftstatic.app.result import RunResult
from rftstatic.errors import ConvergenceError, InstabilityError, SceneError
from rftstatic.scenes.build import build_model
from rftstatic.scenes.material import list_fabrics
from rftstatic.scenes.schema import Scene, list_scenes, load_scene, scene_from_dict
from rftstatic.scenes.sections import format_rows, option_rows

__all__ = ["option_rows", "format_rows", "load_scene", "scene_from_dict", "list_scenes", "list_fabrics", "build_model",
           "run", "resume", "analysis_of",
           "ANALYSES", "RunResult", "Scene", "SceneError", "ConvergenceError", "InstabilityError"]


def run(scene: Scene | str, out: str | Path | None = None, *, overrides=(), progress: bool = False,
        figures: bool = True) -> RunResult:
    """Run a scene with its analysis and write its outputs.

    Parameters
    ----------
    scene : a :class:`Scene`, or a scene name / path (read with ``overrides``, ``["key=value", ...]``)
    out : output folder (default ``out/<scene name>``)
    progress : show progress bars
    figures : write the PNG views and animations

    Returns
    -------
    :class:`RunResult` (``summary``, ``model``, ``U`` [m], ``extras``, ``out``)
    """
    if not isinstance(scene, Scene):
        scene = load_scene(str(scene), overrides)
    elif overrides:
        raise ValueError("overrides apply when the scene is read: pass a scene name or path with them")
    out = Path(out) if out is not None else Path("out") / scene.name
    return _run(scene, out, progress=progress, figures=figures)


def resume(scene: Scene | str, out: str | Path | None = None, *, overrides=(), progress: bool = False,
           figures: bool = True) -> dict:
    """Continue a run (static, dynamic, relax or remeshed) from its checkpoint in ``out.partial`` or ``out``; return its
    summary (:func:`rftstatic.app.registry.resume_scene`)."""
    if not isinstance(scene, Scene):
        scene = load_scene(str(scene), overrides)
    out = Path(out) if out is not None else Path("out") / scene.name
    return resume_scene(scene, out, progress=progress, figures=figures)
