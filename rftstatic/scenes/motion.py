"""The ``motion`` table of an ``[[obstacles]]`` entry: a rigid body moved by keyframes in a dynamic run.

A scene moves an obstacle with (TOML: the table right after its ``[[obstacles]]`` entry)::

    [[obstacles]]
    type = "round-pedestal"
    ...
    [obstacles.motion]
    times = [0.0, 1.0]            # keyframe times [time], strictly increasing
    angles = [0.0, 60.0]          # rotation at each key [deg] about `axis` through `centre` (default all 0)
    axis = [0.0, 0.0, 1.0]        # rotation axis (default z, up)
    centre = [0.0, 0.0, 0.0]      # a point of the axis [length] (default the origin)
    translations = [[0, 0, 0], [5, 0, 0]]   # translation at each key [length] (default all 0)
    interpolation = "smooth"      # "smooth" (3u^2 - 2u^3: at rest at every key) or "linear"

The pose between the keys is :class:`rftstatic.contact.motion.Keyframes`'; before the first key and after the
last the body holds still. A moving obstacle acts by the penalty contact (:mod:`rftstatic.contact.penalty`, in
its body frame) also in a ``dynamic`` run, whose other obstacles then act by the penalty too (one contact law per
run); friction (``contact.friction`` or the obstacle's ``friction``) acts on the velocity relative to its surface.
Only ``interpolation`` is a declared option (:class:`MotionOptions`, ``python -m rftstatic options
obstacles.motion``); the lists are checked here (:func:`obstacle_motion`), a bad one a scene error naming
``obstacles.<i>.motion.<key>``, its value and the fix.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.contact.motion import INTERPOLATIONS, Keyframes, ObstacleMotion, ShapeClock
from rftstatic.errors import ParameterError
from rftstatic.optionspec import check, option

__all__ = ["GarmentMotionOptions", "MotionOptions", "MOTION_LISTS", "has_motion", "list_rows", "obstacle_motion"]

MOTION_LISTS = {
    "times": "keyframe times [time], strictly increasing (required)",
    "angles": "rotation angle at each key [deg], right-handed about axis (default all 0)",
    "axis": "rotation axis [x, y, z], nonzero (default [0, 0, 1])",
    "centre": "a point of the rotation axis [x, y, z] (length; default the origin)",
    "translations": "translation at each key, one [x, y, z] per time (length; default all 0)",
}
"""The list keys of ``obstacles.motion`` (not declared options: each checked by :func:`obstacle_motion`)."""

LIST_ROWS = (("times", "time", "required"), ("angles", "deg", "all 0"), ("axis", "-", "[0, 0, 1]"),
             ("centre", "length", "[0, 0, 0]"), ("translations", "length", "all 0"))
"""Unit and default of each list key, for the ``options obstacles.motion`` listing (:func:`list_rows`)."""


def list_rows(section: str) -> list[dict]:
    """The rows of the list keys (:data:`MOTION_LISTS`) in the form of :func:`rftstatic.optionspec.describe`."""
    return [{"key": f"{section}.{k}", "type": "list", "unit": unit, "range": "", "default": default,
             "help": MOTION_LISTS[k], "group": "keyframes"} for k, unit, default in LIST_ROWS]


@dataclass(frozen=True, kw_only=True)
class MotionOptions:
    """The scalar keys of ``[obstacles.motion]``."""

    interpolation: str = option("smooth", "how the pose goes between keys: smooth (3u^2 - 2u^3, at rest at every "
                                "key) or linear (constant speed, velocity jumps at the keys)", choices=INTERPOLATIONS)

    def __post_init__(__dataclass_self__):
        check(__dataclass_self__, "obstacles.motion")


@dataclass(frozen=True, kw_only=True)
class GarmentMotionOptions:
    """``[motion]`` of an ``analysis = "garment-motion"`` scene (:mod:`rftstatic.app.garment_motion`): the explicit
    run on the moving form after the static drape, in SI. The form's keyframes are ``[body.motion]`` (the keys of
    ``obstacles.motion``)."""

    t_end: float = option(5.0, "simulated time of the run on the moving form, from the draped state", unit="time",
                          low=0.0, open_low=True)
    alpha: float = option(3.0, "mass damping of the run (air drag on the absolute velocity; the skirt's swing is "
                          "critically damped near 2 sqrt(g / L) = 9 /s for L = 0.5 m)", unit="rate", low=0.0,
                          high=1e6)
    friction: float = option(0.4, "Coulomb coefficient mu of the garment on the form, static and kinetic", low=0.0)
    samples: int = option(50, "regular states saved (VTU, GIF frame, crossing checks)", low=1, high=1000)
    rest_tolerance: float = option(1e-3, "kinetic / peak kinetic energy at which the garment has settled", low=0.0,
                                   high=1.0, open_low=True)

    def __post_init__(__dataclass_self__):
        check(__dataclass_self__, "motion")


SEQUENCE = "mesh-sequence"
"""The obstacle type whose shape follows time (:class:`rftstatic.contact.obstacles.surface_sequence.SurfaceSequence`)."""


def _moves(spec) -> bool:
    """An ``[[obstacles]]`` entry with a ``motion`` table, or a surface sequence."""
    return isinstance(spec, dict) and ("motion" in spec or str(spec.get("type", "")).replace("_", "-") == SEQUENCE)


def has_motion(scene) -> bool:
    """True if some ``[[obstacles]]`` entry of ``scene`` moves: a ``motion`` table or a ``mesh-sequence``."""
    return any(_moves(spec) for spec in scene.get("obstacles", []))


def _numbers(scene, key, value, shape):
    arr = None
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        pass
    if arr is None or arr.shape != shape or not np.isfinite(arr).all():
        want = {1: "a list of numbers", 2: "a list of [x, y, z]"}.get(len(shape), "numbers")
        raise scene.error(key, f"{value!r}: give {want} of shape {shape} ({MOTION_LISTS[key.rsplit('.', 1)[1]]})")
    return arr


def _keyframes(scene, i, table) -> Keyframes:
    where = f"obstacles.{i}.motion"
    if not isinstance(table, dict):
        raise scene.error(where, f"{table!r}: give a table with the keys {', '.join(MOTION_LISTS)}, interpolation")
    unknown = sorted(set(table) - set(MOTION_LISTS) - {"interpolation"})
    if unknown:
        raise scene.error(f"{where}.{unknown[0]}", f"unknown key (value {table[unknown[0]]!r}); known: "
                          f"{', '.join(MOTION_LISTS)}, interpolation")
    if "times" not in table:
        raise scene.error(f"{where}.times", f"is required: {MOTION_LISTS['times']}")
    try:
        opts = MotionOptions(interpolation=table.get("interpolation", "smooth"))
    except ParameterError as exc:
        raise scene.error(f"{where}.interpolation", str(exc)) from None
    u = scene.units
    raw = table["times"]
    k = len(raw) if isinstance(raw, list) else -1
    if k < 1:
        raise scene.error(f"{where}.times", f"{raw!r}: give a list of one or more times ({MOTION_LISTS['times']})")
    times = _numbers(scene, f"{where}.times", raw, (k,))
    if np.any(np.diff(times) <= 0):
        j = int(np.flatnonzero(np.diff(times) <= 0)[0])
        raise scene.error(f"{where}.times", f"{raw!r}: times[{j}] = {times[j]:g} is not below times[{j + 1}] = "
                          f"{times[j + 1]:g}; give strictly increasing times")
    angles = _numbers(scene, f"{where}.angles", table.get("angles", [0.0] * k), (k,))
    axis = _numbers(scene, f"{where}.axis", table.get("axis", [0.0, 0.0, 1.0]), (3,))
    if not np.linalg.norm(axis) > 0:
        raise scene.error(f"{where}.axis", f"{table['axis']!r} is the zero vector; give the direction of the "
                          "rotation axis, e.g. [0, 0, 1]")
    centre = _numbers(scene, f"{where}.centre", table.get("centre", [0.0, 0.0, 0.0]), (3,))
    shifts = _numbers(scene, f"{where}.translations", table.get("translations", [[0.0] * 3] * k), (k, 3))
    return Keyframes(times * u.time, np.radians(angles), axis, centre * u.length, shifts * u.length,
                     interpolation=opts.interpolation)


def obstacle_motion(scene, n_obstacles: int) -> ObstacleMotion | None:
    """The keyframed motions of the first ``n_obstacles`` contact obstacles of ``scene`` (the scene's
    ``[[obstacles]]`` in order, then any the route adds, which stay put), or None if none moves. A motion in an
    analysis other than ``dynamic`` is a scene error."""
    specs = scene.get("obstacles", [])
    if not has_motion(scene):
        return None
    if scene.analysis != "dynamic":
        i = next(i for i, s in enumerate(specs) if _moves(s))
        key = f"obstacles.{i}.motion" if "motion" in specs[i] else f"obstacles.{i}.type"
        raise scene.error(key, f'moves the obstacle in time: it needs analysis = "dynamic" (this scene is '
                          f'"{scene.analysis}"); remove the motion table or make the scene dynamic')
    motions = [None] * n_obstacles
    for i, spec in enumerate(specs[:n_obstacles]):
        if isinstance(spec, dict) and "motion" in spec:
            if not _moves({k: v for k, v in spec.items() if k != "motion"}):
                motions[i] = _keyframes(scene, i, spec["motion"])
                continue
            raise scene.error(f"obstacles.{i}.motion", f"a {SEQUENCE} moves by its frames: give the frames in their "
                              "pose, or remove the motion table")
        if _moves(spec):  # a surface sequence: its shape follows the run's time (built and checked by from_spec)
            times = spec.get("times")
            end = max(times) if isinstance(times, list) and times and all(
                isinstance(t, (int, float)) for t in times) else 0.0
            motions[i] = ShapeClock(float(end) * scene.units.time)
    return ObstacleMotion(motions)
