"""The one step that turns a scene's ``[solver]``, ``[dynamics]`` and ``[remesh]`` tables into SI options.

Every key, default and range is declared once (:mod:`rftstatic.optionspec`): the static solver's in
:mod:`rftstatic.solvers.options` (the app's ``[solver]`` keys in :mod:`rftstatic.scenes.run_options`), the
explicit and relaxation runs' in :mod:`rftstatic.scenes.dynamics_options` (with the few defaults that depend on the
analysis type), the remeshing drivers' in :class:`~rftstatic.remesh.options.RemeshOptions`. A bad value
raises :class:`~rftstatic.errors.SceneError` naming the file, the key and the value (:func:`scene_keys`).
"""

from __future__ import annotations

import logging
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from rftstatic.errors import ParameterError, SceneError
from rftstatic.optionspec import from_table
from rftstatic.remesh.options import RemeshOptions
from rftstatic.scenes.contact_options import ContactOptions
from rftstatic.scenes.dynamics_options import DYNAMICS_DEFAULTS, DynamicsOptions
from rftstatic.scenes.run_options import SOLVER_GROUPS, CantileverOptions, RunOptions
from rftstatic.solvers.options import IncrementOptions, NewtonOptions, RouteOptions, StaticOptions

log = logging.getLogger(__name__)

_UNREAD_WARNED = set()  # scene files whose unread [dynamics] table has been named (static_options)


@contextmanager
def scene_keys(scene):
    """A :class:`~rftstatic.errors.ParameterError` raised inside (a declaration's check names ``section.key``) as
    the :class:`~rftstatic.errors.SceneError` of ``scene``: file, key, value."""
    try:
        yield
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


def _declared(scene, section: str, cls):
    """The scene's table ``section`` as its one declared options class ``cls``, in SI."""
    with scene_keys(scene):
        return cls(**from_table((cls,), dict(scene.get(section, {})), section, scene.units)[cls])


def _solver_table(scene) -> dict:
    """The scene's ``[solver]`` table split over its declared groups, in SI
    (:func:`rftstatic.optionspec.from_table`)."""
    with scene_keys(scene):
        return from_table(SOLVER_GROUPS, dict(scene.get("solver", {})), "solver", scene.units)


def static_options(scene, *, progress=True) -> StaticOptions:
    """The scene's ``[solver]`` table as :class:`StaticOptions` (lengths in SI [m]); the app's keys (mesh
    sequence, seeds, membrane switch) are :func:`run_options`'. A ``[dynamics]`` table, which no static drape reads
    (a scene switched from ``relax`` keeps its own), is named in a warning."""
    if "dynamics" in scene.data and scene.analysis not in DYNAMICS_DEFAULTS and scene.path not in _UNREAD_WARNED:
        _UNREAD_WARNED.add(scene.path)
        log.warning("%s: [dynamics] is not read by a static drape (the static route's dynamic relaxation plans its "
                    "own damping and time from the sheet, rftstatic.solvers.static; a garment-motion scene's explicit "
                    'run is set by [motion]): it is ignored; remove it, or use analysis = "dynamic" or "relax"',
                    scene.path)
    table = _solver_table(scene)
    with scene_keys(scene):
        return StaticOptions(newton=NewtonOptions(**table[NewtonOptions]),
                             increments=IncrementOptions(**table[IncrementOptions]),
                             route=RouteOptions(**table[RouteOptions]), progress=progress)


def declared_run_options(scene) -> RunOptions:
    """The app's ``[solver]`` keys as the scene gives them (``levels`` None when ``"auto"``)."""
    table = _solver_table(scene)
    with scene_keys(scene):
        return RunOptions(**table[RunOptions])


def run_options(scene) -> RunOptions:
    """The app's ``[solver]`` keys as :class:`~rftstatic.scenes.run_options.RunOptions`, ``levels = "auto"`` (the
    default) resolved to a number of meshes by the mesh's size (:func:`rftstatic.scenes.levels.auto_levels`)."""
    from rftstatic.scenes.levels import auto_levels

    run = declared_run_options(scene)
    if run.levels is None:
        run = replace(run, levels=auto_levels(scene))
    return run


def dynamics_options(scene) -> DynamicsOptions:
    """The scene's ``[dynamics]`` table checked against its declarations
    (:class:`~rftstatic.scenes.dynamics_options.DynamicsOptions`), with the analysis type's defaults
    (:data:`~rftstatic.scenes.dynamics_options.DYNAMICS_DEFAULTS`), converted to SI
    (:func:`rftstatic.optionspec.from_table`); ``frames``, a list bounded by ``t_end``, is checked here."""
    analysis = scene.analysis
    if analysis not in DYNAMICS_DEFAULTS:
        raise scene.error("analysis", f'"{analysis}" has no [dynamics]; use "dynamic" or "relax"')
    d = {**DYNAMICS_DEFAULTS[analysis], **scene.get("dynamics", {})}
    frames = d.pop("frames", [])
    try:
        table = from_table((DynamicsOptions,), d, "dynamics", scene.units)[DynamicsOptions]
    except ParameterError as exc:
        if exc.key == "dynamics.t_end" and "t_end" not in d:
            raise scene.error(exc.key, f'an analysis = "{analysis}" scene needs its end time (dynamics.t_end, the '
                              "longest simulated time for relax)") from None
        raise scene.error(exc.key, exc.detail) from None
    t_end = d["t_end"]
    if not all(isinstance(f, (int, float)) and not isinstance(f, bool) and 0 <= f <= t_end for f in frames):
        raise scene.error("dynamics.frames", f"expected times in [0, t_end = {t_end}], got {frames!r}")
    t = scene.units.time
    with scene_keys(scene):
        return DynamicsOptions(**table, frames=np.array(sorted(set(float(f) * t for f in frames))))


def remesh_options(scene) -> RemeshOptions:
    """The scene's ``[remesh]`` table checked against its declarations (:class:`~rftstatic.remesh.options.RemeshOptions`)
    and converted to SI (:func:`rftstatic.optionspec.from_table`)."""
    return _declared(scene, "remesh", RemeshOptions)


def contact_options(scene) -> ContactOptions:
    """The scene's ``[contact]`` table checked against its declarations
    (:class:`~rftstatic.scenes.contact_options.ContactOptions`) and converted to SI
    (:func:`rftstatic.optionspec.from_table`)."""
    return _declared(scene, "contact", ContactOptions)


def seed_count(scene) -> int:
    """``solver.seeds``: how many seeded starts a static drape runs (a lab's specimens), checked; 1 by default.
    More than one needs a seeded start (``solver.perturbation`` > 0)."""
    n = declared_run_options(scene).seeds
    if n > 1 and not static_options(scene).route.perturbation > 0:
        raise scene.error("solver.seeds", f"{n} seeded starts need a seeded lift: give solver.perturbation > 0 "
                          "(e.g. 0.01 element sizes), or every start is the same")
    if n > 1 and scene.analysis != "static":
        raise scene.error("solver.seeds", f"{n!r}: seeded starts are run by the static analysis only")
    return n


def compare_start(scene) -> str | None:
    """``solver.compare``: the second start a static drape is solved from (:mod:`rftstatic.app.starts`), checked;
    None for ``"none"``."""
    other = declared_run_options(scene).compare
    if other == "none":
        return None
    if scene.analysis != "static":
        raise scene.error("solver.compare", f"{other!r}: a second start is run by the static analysis only")
    if other == static_options(scene).route.start:  # e.g. a scene with compare = "load-steps" run --set start=...
        log.warning("%s: solver.compare = %r is the scene's own solver.start: nothing to compare", scene.path, other)
        return None
    return other


def cantilever_options(scene) -> CantileverOptions:
    """The scene's ``[cantilever]`` table checked (:class:`~rftstatic.scenes.run_options.CantileverOptions`), the
    angle in radians."""
    return _declared(scene, "cantilever", CantileverOptions)


__all__ = ["run_options", "declared_run_options", "seed_count", "cantilever_options", "CantileverOptions",
           "static_options", "dynamics_options", "contact_options", "remesh_options", "scene_keys", "DynamicsOptions",
           "DYNAMICS_DEFAULTS", "SceneError"]
