"""Property: any number a scene file may hold builds a model with finite numbers, or is an input error.

For each scene of ``cases/`` (shrunk to a tiny mesh), and an isotropic shell beside them, every numeric key
the scene holds (scalars and the numbers of its lists) and the numeric keys of the schema that the scene's
own tables may add (``contact.smoothing``, ``loads.pressure``, the keys of its obstacles' types...) is set
to an extreme value: ``1e300``, ``-1e300``, ``-1``, ``0``, ``1e-300``, ``10^400`` (an integer Python's TOML
reader takes) and, for integers, ``2^63 - 1`` and ``-2^63``. The scene layer then builds the model
(:func:`rftstatic.scenes.build.build_model`) and the options of its analysis, and evaluates the energies
and the residual at the flat state. Either every number is finite, or a
:class:`~rftstatic.errors.SceneError` names the key (``scene: KEY: ...``, the key's name in the message of
its table, or another value of the scene that the mutation moved: :func:`names_a_key`); anything else (an
``OverflowError``, an ``IndexError``, a NaN, a RuntimeWarning of numpy) fails. Nothing is solved: 400
sampled mutations of the ~5,800 take a few seconds (all of them ~40 s on a busy machine).

The ``[solver]`` keys are checked by their declarations (:mod:`rftstatic.solvers.options`,
:mod:`rftstatic.scenes.run_options`) when the scene's options are made, here too.
:mod:`tests.app.test_scene_property` runs whole scenes through the CLI.
"""

from __future__ import annotations

import copy
import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rftstatic.contact.obstacles import obstacle_class
from rftstatic.errors import SceneError
from rftstatic.material import _FABRIC_KINDS as FABRIC_KINDS
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import cantilever_options, dynamics_options, remesh_options, run_options, static_options
from rftstatic.scenes.schema import CASES_DIR, SCHEMA, load_scene, scene_from_dict

FLOATS = (1e300, -1e300, -1.0, 0.0, 1e-300, 10**400)
"""Values for every numeric key; ``10**400``: an integer that Python's TOML reader takes, beyond a float's range."""
INTS = (2**63 - 1, -(2**63), -1, 0)
SKIPPED = ("title", "figure", "units", "element", "analysis", "output")
"""Top-level keys whose numbers are not mutated here (they hold none)."""

TINY_NODES = {"rectangle": [5, 5], "polar": [3, 12], "square-polar": [2, 16]}

ISOTROPIC = {
    "units": "SI", "analysis": "static",
    "mesh": {"kind": "rectangle", "size": [1.0, 0.2], "nodes": [5, 3], "origin": [0.0, -0.1]},
    "material": {"kind": "isotropic", "E": 1e6, "nu": 0.3, "thickness": 1e-3, "weight": 1.0},
    "supports": [{"kind": "clamped", "box": [0.0, 0.0, -0.1, 0.1]}],
    "loads": {"gravity": True, "pressure": 1.0},
}
"""An isotropic shell cantilever (no case file is one): its E, nu, thickness and weight get mutated too."""


def tiny(data: dict) -> dict:
    """``data`` with a mesh of a few dozen nodes, its obstacles' file paths taken from cases/ (the data is read
    without its scene file)."""
    data = copy.deepcopy(data)
    for ob in data.get("obstacles", []):
        if "path" in ob:
            ob["path"] = str(CASES_DIR / ob["path"])
        if isinstance(ob.get("paths"), list):  # a mesh-sequence's frames
            ob["paths"] = [str(CASES_DIR / p) for p in ob["paths"]]
    m = data.setdefault("mesh", {})
    kind = m.get("kind", "rectangle")
    if kind in TINY_NODES:
        m["nodes"] = list(TINY_NODES[kind])
    elif kind == "unstructured":
        m["h"] = (2.0 * m["radius"] if "radius" in m else min(m.get("size", [1.0, 1.0]))) / 4.0
    return data


BASES = {**{p.stem: tiny(load_scene(p.stem).data) for p in sorted(CASES_DIR.glob("*.toml"))},
         "isotropic-shell": ISOTROPIC}


def is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def present_numbers(node, path=()):
    """``path`` of every number of a scene (an array item's index at the end of its path)."""
    if isinstance(node, dict):
        for key, value in node.items():
            if not path and key in SKIPPED:
                continue
            yield from present_numbers(value, (*path, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from present_numbers(value, (*path, i))
    elif is_number(node):
        yield path


def added_numbers(data: dict):
    """Paths of the numeric schema keys a scene's own tables may take and do not hold."""
    tables = {"contact": SCHEMA["contact"][0], "loads": {"pressure": SCHEMA["loads"][0]["pressure"]},
              "solver": SCHEMA["solver"][0]}
    for name in ("dynamics", "remesh", "cantilever"):
        if name in data:
            tables[name] = SCHEMA[name][0]
    material = data.get("material", {})
    own = ("E", "nu", "thickness", "weight") if material.get("kind") == "isotropic" else (*FABRIC_KINDS, "thickness")
    tables["material"] = {k: SCHEMA["material"][0][k] for k in own}
    for table, keys in tables.items():
        for key, (spec, _) in keys.items():
            types = spec if isinstance(spec, tuple) else (spec,)
            if (int in types or float in types) and key not in data.get(table, {}):
                yield (table, key)
    for i, obstacle in enumerate(data.get("obstacles", [])):
        for key, sk in obstacle_class(obstacle["type"]).scene_keys.items():
            if key not in obstacle and int in sk.kinds:
                yield ("obstacles", i, key)


def mutations(name: str) -> list[tuple[tuple, object]]:
    """``(path, value)`` of every extreme mutation of the base scene ``name``."""
    data = BASES[name]
    out = []
    for path in [*present_numbers(data), *added_numbers(data)]:
        old = get(data, path)
        values = FLOATS + (INTS if isinstance(old, int) or old is None else ())
        out += [(path, v) for v in values]
    return out


def get(data, path):
    node = data
    for part in path:
        try:
            node = node[part]
        except (KeyError, IndexError):
            return None
    return node


def put(data: dict, path: tuple, value) -> dict:
    """A copy of ``data`` with ``path`` set to ``value`` (missing tables created)."""
    data = copy.deepcopy(data)
    node = data
    for part in path[:-1]:
        node = node.setdefault(part, {}) if isinstance(node, dict) else node[part]
    node[path[-1]] = value
    return data


def dotted(path: tuple) -> str:
    """The scene key of ``path``: its parts joined by dots, without the index of an array's number."""
    while isinstance(path[-1], int):
        path = path[:-1]
    return ".".join(str(p) for p in path)


def all_finite(values) -> bool:
    return all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in values)


def evaluate(data: dict) -> list:
    """Build the scene's model and its analysis options; the energies and residual at the flat state."""
    scene = scene_from_dict(data, name="scene")
    model, _ = build_model(scene)
    analysis = scene.get("analysis", "static")
    if analysis in ("dynamic", "relax"):
        dynamics_options(scene)
    if "remesh" in scene.data:
        remesh_options(scene)
    if analysis == "cantilever":
        cantilever_options(scene)
    static_options(scene, progress=False)
    run_options(scene)
    U = np.zeros_like(model.X3)
    return [*model.energies(U).values(), model.residual(U), model.material.Dm, model.material.Db]


def names_a_key(text: str, data: dict, key: str) -> bool:
    """Whether the scene error ``text`` names ``key``: as its key, in the message of the key's table, or
    another value of the scene that the mutation affected (``mesh.origin = 0`` moves the sheet away from
    ``supports.0.at``); not a bare table (``scene: mesh: 16 degenerate triangles``)."""
    if not text.startswith("scene: "):
        return False
    named = text[len("scene: "):].split(": ", 1)[0]
    table, _, last = key.rpartition(".")
    if named == key or key in text or (named == table and last in text):
        return True
    value = get(data, tuple(int(p) if p.isdigit() else p for p in named.split(".")))
    return value is not None and not isinstance(value, dict)


def problem(name: str, path: tuple, value) -> str | None:
    """What is wrong with the outcome of the base scene ``name`` with ``path`` set to ``value`` (None: a model
    with finite numbers, or a scene error that names the key)."""
    data = put(BASES[name], path, value)
    key = dotted(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            numbers = evaluate(data)
    except SceneError as exc:
        return None if names_a_key(str(exc), data, key) else f"the scene error does not name {key}: {exc}"
    except Exception as exc:  # noqa: BLE001 - any other exception is the finding
        return f"{type(exc).__name__}: {exc}"
    return None if all_finite(numbers) else "a non-finite energy, residual or rigidity"


CASES = [(name, path, value) for name in BASES for path, value in mutations(name)]


@settings(max_examples=400, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(CASES))
def test_an_extreme_number_builds_a_finite_model_or_is_a_scene_error_naming_its_key(case):
    name, path, value = case
    bad = problem(name, path, value)
    assert bad is None, f"{name} with {dotted(path)} ({'.'.join(map(str, path))}) = {value!r}: {bad}"


def test_the_mutations_reach_every_table_and_value():
    """The sample space holds what the issue reported: the shell's thickness, the smoothing, a mesh radius and
    an obstacle's radius, each at 1e300; and it is large (every base, dozens of keys)."""
    seen = {(name, ".".join(map(str, path)), value) for name, path, value in CASES}
    for expected in [("isotropic-shell", "material.thickness", 1e300),
                     ("pedestal-square-20", "contact.smoothing", 1e300),
                     ("pedestal-square-20", "contact.smoothing", -1.0),
                     ("pedestal-round-50", "mesh.radius", 1e300), ("sphere-30", "obstacles.0.radius", 1e300)]:
        assert expected in seen
    assert len(BASES) == len(list(CASES_DIR.glob("*.toml"))) + 1 and len(CASES) > 1000


@pytest.mark.parametrize("name, path, value", [
    ("isotropic-shell", ("material", "thickness"), 1e300),
    ("pedestal-square-20", ("contact", "smoothing"), 1e300),
    ("pedestal-square-20", ("contact", "smoothing"), -1.0),
    ("pedestal-round-50", ("mesh", "radius"), 1e300),
    ("sphere-30", ("obstacles", 0, "radius"), 1e300),
])
def test_the_reported_inputs_are_scene_errors_naming_their_key(name, path, value):
    with pytest.raises(SceneError, match=rf"^scene: {re.escape(dotted(path))}: .*{re.escape(repr(value))}"):
        evaluate(put(BASES[name], path, value))
