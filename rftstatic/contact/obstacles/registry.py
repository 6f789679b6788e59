"""The obstacle types scenes can name: registration, :func:`from_spec`, and the keys the scene schema checks.

A type is registered with :func:`register` (a class decorator) under its ``type_name``; its
``scene_keys`` (scene key -> :class:`~rftstatic.contact.obstacles.base.SceneKey`) say how a scene table
becomes constructor arguments. Nothing else names the types: :func:`obstacle_types`, :func:`from_spec`
and :func:`scene_schema` (read by :mod:`rftstatic.scenes.schema` when it checks a scene) all read the
registry.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

import numpy as np

from rftstatic.contact.obstacles.base import Obstacle, SceneKey

__all__ = ["from_spec", "obstacle_class", "obstacle_types", "register", "scene_schema", "unregister"]

_TYPES: dict[str, type[Obstacle]] = {}


def register(cls: type[Obstacle]) -> type[Obstacle]:
    """Make the obstacle class ``cls`` buildable from scene tables; usable as a class decorator.

    ``cls`` must subclass :class:`Obstacle` and define, in its own body, ``type_name`` (lower case,
    words joined by dashes, e.g. ``"round-pedestal"``) and ``scene_keys`` (scene key -> ``SceneKey``,
    each naming an argument of ``cls``). Registering the same class again is a no-op.

    Returns
    -------
    ``cls`` unchanged.

    Raises
    ------
    TypeError
        If ``cls`` is not an :class:`Obstacle` class.
    ValueError
        For a bad declaration or a name already taken by another class.
    """
    if not (isinstance(cls, type) and issubclass(cls, Obstacle)):
        raise TypeError(f"register: {cls!r} is not a subclass of Obstacle")
    own = vars(cls)
    name = own.get("type_name")
    if not isinstance(name, str) or not name or name != name.strip().lower().replace("_", "-"):
        raise ValueError(f"register: {cls.__name__}.type_name must be a lower-case name with dashes "
                         f"(e.g. 'round-pedestal') set in the class body, got {name!r}")
    keys = own.get("scene_keys")
    if not isinstance(keys, Mapping) or not all(isinstance(k, str) and isinstance(v, SceneKey)
                                                for k, v in keys.items()):
        raise ValueError(f"register: {cls.__name__}.scene_keys must be a dict of scene key -> SceneKey "
                         f"set in the class body, got {keys!r}")
    if "type" in keys:
        raise ValueError(f"register: {cls.__name__}.scene_keys must not declare 'type'")
    params = inspect.signature(cls).parameters
    if not any(p.kind is p.VAR_KEYWORD for p in params.values()):
        bad = sorted(k for k, v in keys.items() if v.arg not in params)
        if bad:
            raise ValueError(f"register: {cls.__name__}.scene_keys {bad} name no argument of {cls.__name__}")
    if _TYPES.get(name, cls) is not cls:
        raise ValueError(f"register: obstacle type {name!r} is already {_TYPES[name].__name__}")
    _TYPES[name] = cls
    return cls


def unregister(name: str) -> None:
    """Forget the obstacle type ``name`` (e.g. one a test registered); unknown names are ignored."""
    _TYPES.pop(name, None)


def obstacle_types() -> list[str]:
    """Type names accepted by :func:`from_spec`, sorted."""
    return sorted(_TYPES)


def obstacle_class(name: str) -> type[Obstacle]:
    """The class registered as ``name`` (underscores accepted for dashes); ``KeyError`` if none."""
    return _TYPES[str(name).strip().lower().replace("_", "-")]


CONTACT_KEYS = {"friction": ((int, float), "Coulomb friction coefficient of the sheet on this obstacle, static and "
                                           "kinetic, instead of contact.friction"),
                "motion": ({"times": ((list,), "keyframe times [time], strictly increasing"),
                            "angles": ((list,), "rotation angle at each key [deg] about axis (default all 0)"),
                            "axis": ((list,), "rotation axis [x, y, z] (default [0, 0, 1])"),
                            "centre": ((list,), "a point of the rotation axis [x, y, z] (default the origin)"),
                            "translations": ((list,), "translation [x, y, z] at each key (default all 0)"),
                            "interpolation": ((str,), "smooth (default) or linear between keys")},
                           "keyframed rigid motion of this obstacle in a dynamic run (rftstatic.scenes.motion)")}
"""Keys every ``[[obstacles]]`` table may have that belong to the contact with it, not to its shape (read by the
scene's contact, :func:`rftstatic.scenes.build.contact_friction`; not passed to the obstacle)."""


def scene_schema() -> dict[str, tuple[tuple[type, ...], str]]:
    """Keys of an ``[[obstacles]]`` table over all registered types, for the scene schema.

    Returns
    -------
    ``{key: (accepted value types, help)}``, ``type`` first; a key several types declare accepts the
    union of their value types and joins their help texts.
    """
    table = {"type": ((str,), "obstacle type: " + ", ".join(obstacle_types()))}
    kinds: dict[str, list[type]] = {}
    helps: dict[str, list[str]] = {}
    for name in obstacle_types():
        for key, sk in _TYPES[name].scene_keys.items():
            kinds.setdefault(key, [])
            kinds[key] += [t for t in sk.kinds if t not in kinds[key]]
            helps.setdefault(key, [])
            if sk.help and sk.help not in helps[key]:
                helps[key].append(sk.help)
    for key, types in kinds.items():
        table[key] = (tuple(types), "; ".join(helps[key]))
    table.update(CONTACT_KEYS)
    return table


def _scale(key: str, value: Any, factor: float, where: str) -> Any:
    """A scene length (number or list of numbers) times ``factor`` [m / scene unit]."""
    if value is None:
        return None
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"{where}: key {key!r} must be a number or a list of numbers, got {value!r}"
        ) from None
    scaled = arr * factor
    return float(scaled) if scaled.ndim == 0 else scaled


CONTEXT = ("scene_length", "base_dir")
"""Keyword arguments :func:`from_spec` passes to a constructor that declares them: the scene's length unit
[m] (a file's coordinates are in it unless said otherwise) and the directory of the scene file (a relative
file path is taken from it)."""


def from_spec(spec: Mapping[str, Any], length_scale: float = 1.0, base_dir=None) -> Obstacle:
    """Build an obstacle from a scene table.

    Parameters
    ----------
    spec : table such as ``{"type": "round-pedestal", "centre": [0, 0], "radius": 10, "top": 0,
        "edge_radius": 0.5}``; lengths in scene units. The keys of each type are its ``scene_keys``;
        the built-in types:

        - ``floor``: ``height`` (default 0);
        - ``sphere``: ``centre`` (3 numbers), ``radius``;
        - ``square-pedestal``: ``centre`` (2 numbers, default origin), ``half_width`` or ``size``
          (number or 2 numbers), ``top`` (default 0), ``edge_radius`` (default 0), ``height``
          (default infinitely tall);
        - ``round-pedestal``: ``centre``, ``radius``, ``top``, ``edge_radius``, ``height`` as above;
        - ``mesh``: ``path`` of a surface file, ``units``, ``scale``, ``rotate``, ``translate``, ``side`` or
          ``thickness`` (an open surface), ``feature_angle``
          (:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`).

        Underscores in the type name are accepted for dashes (``round_pedestal``).
    length_scale : metres per scene length unit [m] (0.01 for ``cm-gf-s``); multiplies the length keys
    base_dir : the scene file's directory (relative file paths, :data:`CONTEXT`); None: the working directory

    Returns
    -------
    Obstacle with all lengths in metres.

    Raises
    ------
    ValueError
        Naming the type and the offending key (missing, unknown or invalid value).
    """
    if not isinstance(spec, Mapping):
        raise ValueError(f"obstacle spec must be a table, got {spec!r}")  # noqa: TRY004 (callers catch ValueError)
    factor = float(length_scale)
    if not np.isfinite(factor) or factor <= 0:
        raise ValueError(f"length_scale must be a finite number > 0, got {length_scale!r}")
    if "type" not in spec:
        raise ValueError(f"obstacle spec {dict(spec)!r} has no key 'type'; use one of {obstacle_types()}")
    kind = str(spec["type"]).strip().lower().replace("_", "-")
    if kind not in _TYPES:
        raise ValueError(f"obstacle key 'type' = {spec['type']!r} is unknown; use one of {obstacle_types()}")
    cls = _TYPES[kind]
    keys = cls.scene_keys
    where = f"obstacle {kind!r}"
    unknown = sorted(set(spec) - set(keys) - {"type"} - set(CONTACT_KEYS))
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {unknown}; allowed keys are {sorted(keys)}")
    missing = [key for key, sk in keys.items() if sk.required and key not in spec]
    if missing:
        raise ValueError(f"{where}: missing key(s) {missing}")
    kwargs = {}
    for key, sk in keys.items():
        if key in spec:
            kwargs[sk.arg] = _scale(key, spec[key], factor, where) if sk.length else spec[key]
        elif sk.default is not None:
            kwargs[sk.arg] = sk.default
    params = inspect.signature(cls).parameters
    context = {"scene_length": factor, "base_dir": base_dir}
    kwargs.update({k: v for k, v in context.items() if k in params})
    try:
        return cls(**kwargs)
    except ValueError as err:
        raise _named(err, keys, spec, where, factor) from None


def _named(err: ValueError, keys: Mapping[str, SceneKey], spec: Mapping[str, Any], where: str,
           factor: float) -> ValueError:
    """The constructor's error restated with the scene key it comes from (its first word is the argument)."""
    message = str(err)
    first = message.split(" ", 1)[0]
    for key, sk in keys.items():
        if first == sk.arg and key in spec:
            return ValueError(f"{where}: key {key!r} = {spec[key]!r} is invalid: {message} "
                              f"(in metres, after length_scale = {factor:g})")
    return ValueError(f"{where}: {message}")
