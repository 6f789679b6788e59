"""Property: any scene a user may write ends, within a time bound, in one of three ways.

* done (exit 0): ``summary.json`` is written, every number in it is finite and it says converged;
* an input error (exit 2): one line ``error: <scene file>: <key>: ...`` naming the scene key;
* a reported goal not reached (exit 3): no convergence, an instability, no rest by ``t_end``.

An internal error (exit 1), a traceback, another exit status or a run longer than :data:`BOUND_S` fails,
with the scene printed as TOML (save it and run ``python -m rftstatic case scene.toml`` to reproduce).

The scenes (:func:`scenes`) start from a case file of ``cases/`` (read with the project's own loader)
shrunk to a tiny mesh (under 200 nodes) and short dynamics, then take a few random mutations of keys
drawn from the scene schema itself (:data:`rftstatic.scenes.schema.SCHEMA`, the obstacle keys of every
registered type included): deleted or misspelt keys, values of a wrong type, NaN, +-inf, 0, negative,
huge, tiny, random strings, empty or wrong-length lists, points off the sheet, swapped values, unknown
keys; and valid but extreme values (a number scaled by up to 10^+-12, another value of an enum, a key
added with a plausible value) that reach the solvers; and a few explicit runs far beyond the default step
cap, which must be refused before they start. A mutation that would only make a valid scene big (more mesh
nodes, more explicit steps) rather than wrong is undone (:func:`keep_tiny`). Each scene is run the way a
user runs it: written to a TOML file and passed to the command line (``case FILE --out DIR
--no-figures``), in-process, under a SIGALRM time bound (a run stuck outside the interpreter ends the
process after three times the bound, its tracebacks in ``hung.txt`` beside ``scene.toml``).

Environment: ``RFTSTATIC_PROPERTY_EXAMPLES`` (default :data:`EXAMPLES`), ``RFTSTATIC_PROPERTY_BOUND_S``
(default 20 s), ``RFTSTATIC_PROPERTY_SHRINK=1`` lets hypothesis shrink a failing scene (each try may
take the whole bound, so it is off by default).
"""

from __future__ import annotations

import contextlib
import copy
import faulthandler
import functools
import io
import itertools
import json
import math
import os
import re
import shutil
import signal
import time
import tomllib
import traceback
from collections.abc import Mapping
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, Verbosity, event, given, settings
from hypothesis import strategies as st

from rftstatic.cli import main
from rftstatic.scenes.build import MAX_MESH_NODES
from rftstatic.scenes.schema import CASES_DIR, SCHEMA, ListOf, load_scene

EXAMPLES = int(os.environ.get("RFTSTATIC_PROPERTY_EXAMPLES", "300"))
"""Generated scenes per run (measured: 46-75 s on a busy 2-core machine, 20 % of them reach a solver)."""

BOUND_S = float(os.environ.get("RFTSTATIC_PROPERTY_BOUND_S", "45"))
"""Longest a tiny scene may take, whatever its values [s]: a hang detector, not a speed target. The slowest
generated scene took 12.7-23 s on a 2-core machine shared with four other solvers (load 5), which a 20 s
bound failed; an unloaded machine runs it in a few seconds."""

MAX_NODES = 200
"""Nodes of the tiny meshes the scenes start from (fewer than this)."""

MAX_STEPS = 4000
"""``dynamics.max_steps`` of the generated dynamic scenes: their explicit runs stay within a few seconds
(a tiny sheet steps at 3000-5000 steps/s here), and a mutation that needs more steps meets the cap."""

EXTREME_EVERY = 5
"""One scene in this many takes only valid-but-extreme mutations."""

STEP_CAP_EVERY = 40
"""One scene in this many asks for an explicit run beyond the default step cap (:func:`beyond_the_step_cap`)."""

CASES = tuple(sorted(p.stem for p in CASES_DIR.glob("*.toml") if 'analysis = "garment' not in p.read_text()))
"""The case files with a ``[mesh]`` to shrink (a garment scene's mesh comes from its pattern: tests/garment)."""


# --------------------------------------------------------------------------------------------- schema
def schema_entry(path):
    """The schema entry ``(spec, help)`` of the scene key ``path`` (a tuple of keys and array indices),
    or None when the schema has no such key."""
    table, entry = SCHEMA, None
    for part in path:
        if isinstance(part, int):
            if entry is None or not isinstance(entry[0], list):
                return None
            table = entry[0][0]
            continue
        if not isinstance(table, Mapping) or part not in table:
            return None
        entry = table[part]
        table = entry[0] if isinstance(entry[0], dict) else None
    return entry


GARMENT_KEYS = ("garment", "body")
"""Tables of a garment scene only (analysis = "garment", tests/garment), left out of the mutations."""


def schema_paths(table=SCHEMA, prefix=()):
    """``(path, spec, help)`` of every key the schema declares (arrays of tables at item 0)."""
    for key in table:
        if not prefix and key in GARMENT_KEYS:
            continue
        spec, text = table[key]
        path = (*prefix, key)
        yield path, spec, text
        if isinstance(spec, dict):
            yield from schema_paths(spec, path)
        elif isinstance(spec, list):
            yield from schema_paths(spec[0], (*path, 0))


def scalar_types(spec) -> tuple:
    """The python types of a scalar schema spec (() for tables, arrays and lists)."""
    if isinstance(spec, type):
        return (spec,)
    if isinstance(spec, tuple):
        return spec
    return ()


@functools.cache
def enum_candidates() -> dict:
    """Strings seen at each string key: the values in the case files and the words of the key's help."""
    seen = {}
    for name in CASES:
        for path, value in walk(load_scene(name).data):
            if isinstance(value, str):
                seen.setdefault(generic(path), set()).add(value)
    out = {}
    for path, spec, text in schema_paths():
        if str in scalar_types(spec):
            words = set(re.findall(r"[A-Za-z][A-Za-z0-9_-]*[A-Za-z0-9]", text))
            out[path] = tuple(sorted(seen.get(path, set()) | words))
    return out


def generic(path):
    """``path`` with every array index as 0 (the schema's item)."""
    return tuple(0 if isinstance(p, int) else p for p in path)


# ---------------------------------------------------------------------------------------- scene paths
def walk(node, path=()):
    """``(path, value)`` of every key of a scene, depth first; arrays of tables by item index."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*path, key), value
            yield from walk(value, (*path, key))
    elif isinstance(node, list) and node and all(isinstance(v, dict) for v in node):
        for i, value in enumerate(node):
            yield (*path, i), value
            yield from walk(value, (*path, i))


def parent_of(data, path):
    """The table or array that holds the key ``path``."""
    node = data
    for part in path[:-1]:
        node = node[part]
    return node


def get(data, path, default=None):
    """The value at ``path`` (``default`` when there is none)."""
    node = data
    for part in path:
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            return default
    return node


def put(data, path, value) -> bool:
    """Set ``path`` to ``value``, creating the missing tables and arrays of tables on the way (False when
    a value is in the way)."""
    node = data
    for part, nxt in itertools.pairwise(path):
        if isinstance(node, dict) and isinstance(part, int):
            return False  # an array index where a table stands (e.g. after a swap): TOML has no int keys
        if isinstance(node, dict):
            node = node.setdefault(part, [{}] if isinstance(nxt, int) else {})
        elif isinstance(node, list) and isinstance(part, int):
            if not node:
                node.append({})
            if part >= len(node):
                return False
            node = node[part]
        else:
            return False
    if isinstance(node, dict) and isinstance(path[-1], str):
        node[path[-1]] = value
        return True
    return False


# ------------------------------------------------------------------------------------------ the base
def extent(mesh: dict) -> float:
    """The smaller side (or the diameter) of a scene mesh, in its units."""
    if "radius" in mesh:
        return 2.0 * float(mesh["radius"])
    return float(min(mesh.get("size", [1.0, 1.0])))


MESH_COUNTS = {
    "rectangle": ((2, 14), lambda a: (2, min(14, (MAX_NODES - 1) // a))),
    "polar": ((2, 8), lambda a: (3, min(24, (MAX_NODES - 2) // a))),
    "square-polar": ((2, 5), lambda a: (8, min(24, 100 // a))),
    "unstructured": ((3, 9), lambda a: (0, 0)),
}
"""Mesh kind -> range of its first count (nodes along x or the radius; elements across the sheet) and the
range of the second (nodes along y or around) given the first: under :data:`MAX_NODES` nodes in all."""


def tiny_mesh(m: dict, a: int, b: int) -> None:
    """Make the ``[mesh]`` table ``m`` tiny: ``nodes = [a, b]``, or ``h`` = the sheet's extent / ``a``; coarse on
    purpose, so not refined against membrane locking (``locking = "refine"`` of the Cusick scenes)."""
    m.pop("locking", None)
    if m.get("kind", "rectangle") == "unstructured":
        m["h"] = extent(m) / a
    elif "nodes" in m or m.get("kind", "rectangle") in MESH_COUNTS:
        m["nodes"] = [a, b]


@st.composite
def tiny_case(draw):
    """``(name, data)``: a case file's scene with a tiny mesh (:data:`MESH_COUNTS`), short dynamics capped
    at :data:`MAX_STEPS` steps and remeshing bounds of a few elements across the sheet."""
    name = draw(st.sampled_from(CASES))
    data = copy.deepcopy(load_scene(name).data)
    m = data.setdefault("mesh", {})
    first, second = MESH_COUNTS.get(m.get("kind", "rectangle"), ((2, 2), lambda a: (2, 2)))
    a = draw(st.integers(*first))
    tiny_mesh(m, a, draw(st.integers(*second(a))))
    if "dynamics" in data:
        d = data["dynamics"]
        d["t_end"] = draw(st.sampled_from([0.001, 0.01, 0.03, 0.1]))
        d["frames"] = sorted({f for f in d.get("frames", []) if f <= d["t_end"]} | {d["t_end"]})
        d["samples"] = draw(st.integers(0, 4))
        d["max_steps"] = MAX_STEPS
    if "remesh" in data:
        r = data["remesh"]
        r["h_upper"] = extent(m) / draw(st.integers(3, 5))
        r["h_lower"] = r["h_upper"] / draw(st.sampled_from([1.0, 1.5, 2.0]))
        r["const"] = r["h_lower"]
        r["kappa_h2_max"] = 3 * r["const"]
        r["every"] = draw(st.sampled_from([50, 200, 1000]))
    return name, data


# ------------------------------------------------------------------------------------------ mutations
SPECIAL_NUMBERS = (math.nan, math.inf, -math.inf, 0, 0.0, -0.0, -1, -1.0, 1e300, -1e300, 1e-300, -1e-300,
                   5e-324, 2**63 - 1, -(2**63), 1.5, 7)
TEXT = st.text(st.characters(exclude_categories=("Cs",)), max_size=8)
JUNK = st.one_of(
    st.sampled_from(SPECIAL_NUMBERS), st.booleans(), TEXT, st.just([]), st.just({}),
    st.floats(), st.integers(-10**6, 10**6),
    st.lists(st.one_of(st.floats(), st.integers(-5, 5), TEXT), max_size=5),
    st.dictionaries(st.sampled_from(["x", "kind", "at", "box", "type", "radius"]),
                    st.one_of(st.integers(-3, 3), st.floats(-10, 10), TEXT), max_size=2),
)


def typo(draw, word: str) -> str:
    """A misspelling of ``word``: a letter dropped, doubled, swapped or changed, or the case changed."""
    if not word:
        return "x"
    i = draw(st.integers(0, len(word) - 1))
    how = draw(st.sampled_from(["drop", "double", "swap", "change", "upper", "space", "dash"]))
    if how == "drop" and len(word) > 1:
        return word[:i] + word[i + 1:]
    if how == "swap" and i + 1 < len(word):
        return word[:i] + word[i + 1] + word[i] + word[i + 2:]
    if how == "change":
        return word[:i] + draw(st.sampled_from("aeiouxz_-")) + word[i + 1:]
    if how == "upper":
        return word.upper() if word != word.upper() else word.lower()
    if how == "space":
        return word + " "
    if how == "dash":
        return word.replace("_", "-") if "_" in word else word.replace("-", "_") if "-" in word else word + "_"
    return word[:i] + word[i] + word[i:]


def bad_list(draw, value):
    """A list value broken: empty, an item dropped or added, an item of a wrong type or a
    special number, nested, or its points moved off the sheet."""
    items = list(value) if isinstance(value, list) else []
    how = draw(st.sampled_from(["empty", "drop", "append", "item", "nest", "off-sheet", "invert", "scalar"]))
    if how == "empty":
        return []
    if how == "drop" and items:
        return items[:-1]
    if how == "append":
        return [*items, draw(st.one_of(st.sampled_from(SPECIAL_NUMBERS), st.floats(-50, 50)))]
    if how == "item" and items:
        i = draw(st.integers(0, len(items) - 1))
        items[i] = draw(JUNK)
        return items
    if how == "nest":
        return [items]
    if how == "off-sheet" and items:
        offset = draw(st.sampled_from([1e3, -1e3, 1e9, 0.51]))
        return [shift(v, offset) for v in items]
    if how == "invert" and len(items) == 4 and all(isinstance(v, (int, float)) for v in items):
        return [items[1], items[0], items[3], items[2]]
    return draw(JUNK)


def shift(v, offset):
    """A coordinate (or a list of them) moved by ``offset`` times its size plus ``offset``."""
    if isinstance(v, list):
        return [shift(x, offset) for x in v]
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return v + offset * (1.0 + abs(v))
    return v


def wrong_value(draw, path, value):
    """A value for ``path`` that the schema or the scene's meaning should refuse (or that sits at the edge
    of what it accepts)."""
    entry = schema_entry(generic(path))
    spec = entry[0] if entry else None
    types = scalar_types(spec)
    if isinstance(spec, (ListOf, list)) or (types == (list,)) or isinstance(value, list):
        return bad_list(draw, value)
    if str in types and draw(st.booleans()):
        word = value if isinstance(value, str) else draw(st.sampled_from(enum_candidates()[generic(path)] or ("x",)))
        return draw(st.sampled_from([typo(draw, word), word.upper(), "", f" {word}", word + "s"]))
    if (int in types or float in types) and draw(st.booleans()):
        return draw(st.sampled_from(SPECIAL_NUMBERS))
    if bool in types and draw(st.booleans()):
        return draw(st.sampled_from([0, 1, "true", "yes", [True]]))
    return draw(JUNK)


def extreme_value(draw, path, value):
    """A value for ``path`` of the type the schema accepts, far from the usual one: a number scaled by
    10^k (|k| <= 12, also negated or integral), another word of an enum, a flipped bool."""
    entry = schema_entry(generic(path))
    types = scalar_types(entry[0]) if entry else ()
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)):
        k = draw(st.integers(-12, 12))
        scaled = value * 10.0**k if value else 10.0**k
        if draw(st.integers(0, 5)) == 0:
            scaled = -scaled
        return int(scaled) if isinstance(value, int) and abs(scaled) < 2**62 else float(scaled)
    if isinstance(value, str) and str in types:
        choices = enum_candidates().get(generic(path), ())
        return draw(st.sampled_from(choices)) if choices else value
    if isinstance(value, list) and value and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                 for v in value):
        k = draw(st.integers(-6, 6))
        if all(isinstance(v, int) for v in value):
            return [int(v * 10**k) if k >= 0 else v // 10**-k for v in value]
        return [v * 10.0**k for v in value]
    return value


def plausible_value(draw, path, spec):
    """A value of the type the schema declares for ``path`` (to add a key the scene lacks)."""
    types = scalar_types(spec)
    if isinstance(spec, dict):
        return {}
    if isinstance(spec, list):
        return [{}]
    if isinstance(spec, ListOf):
        n = spec.length or draw(st.integers(max(spec.min_length, 1), 4))
        if spec.choices:
            return [draw(st.sampled_from(spec.choices)) for _ in range(n)]
        if spec.item is int:
            return [draw(st.integers(-2, 30)) for _ in range(n)]
        return [draw(st.floats(-30, 30)) for _ in range(n)]
    if bool in types:
        return draw(st.booleans())
    if str in types:
        choices = enum_candidates().get(generic(path), ()) or ("x",)
        return draw(st.sampled_from(choices))
    if types == (list,):
        return [draw(st.floats(-20, 20)) for _ in range(draw(st.integers(2, 3)))]
    if float in types:  # ordinary, or a power of ten from very soft to very stiff
        return draw(st.one_of(st.sampled_from([0.0, 1.0, 0.5, 2.0, -1.0]), st.floats(-100, 100),
                              st.integers(-12, 12).map(lambda k: 10.0**k)))
    if int in types:
        return draw(st.integers(-2, 50))
    return draw(JUNK)


INPUT_MUTATIONS = ("wrong", "wrong", "wrong", "delete", "rename", "unknown", "swap", "copy")
"""Mutations that (mostly) make a scene invalid."""

EXTREME_MUTATIONS = ("extreme", "extreme", "extreme", "add", "delete")
"""Mutations that (mostly) keep a scene valid and reach the solvers with unusual values."""


def mutate(draw, data, kinds) -> str:
    """Apply one random mutation of ``kinds`` to ``data`` (in place); return what it did, for the report."""
    how = draw(st.sampled_from(kinds))
    paths = [p for p, _ in walk(data)]
    if how == "add":
        absent = [(p, spec) for p, spec, _ in schema_paths() if get(data, p) is None]
        path, spec = draw(st.sampled_from(absent))
        value = plausible_value(draw, path, spec)
        return f"add {'.'.join(map(str, path))} = {value!r}" if put(data, path, value) else "add: blocked"
    if how == "extreme":  # a value, not a table or an array of tables
        paths = [p for p, v in walk(data) if not isinstance(v, dict) and not (
            isinstance(v, list) and v and all(isinstance(item, dict) for item in v))]
    if not paths:
        return "no keys"
    path = draw(st.sampled_from(paths))
    key = ".".join(map(str, path))
    parent, last = parent_of(data, path), path[-1]
    value = parent[last]
    if how == "delete":
        del parent[last]
        return f"delete {key}"
    if how == "wrong":
        parent[last] = wrong_value(draw, path, value)
        return f"wrong {key} = {parent[last]!r}"
    if how == "extreme":
        parent[last] = extreme_value(draw, path, value)
        return f"extreme {key} = {parent[last]!r}"
    if how == "rename" and isinstance(last, str):
        parent[typo(draw, last)] = parent.pop(last)
        return f"rename {key}"
    if how == "unknown" and isinstance(value, dict):
        value[typo(draw, draw(st.sampled_from([*value, "kind", "size"])))] = draw(JUNK)
        return f"unknown key in {key}"
    others = [p for p in paths if p[:len(path)] != path and path[:len(p)] != p]
    if how in ("swap", "copy") and others:
        other = draw(st.sampled_from(others))
        oparent, olast = parent_of(data, other), other[-1]
        if how == "swap":
            parent[last], oparent[olast] = oparent[olast], value
            return f"swap {key} <-> {'.'.join(map(str, other))}"
        parent[last] = copy.deepcopy(oparent[olast])
        return f"copy {'.'.join(map(str, other))} -> {key}"
    parent[last] = wrong_value(draw, path, value)  # what the drawn mutation cannot do here
    return f"wrong {key} = {parent[last]!r}"


def keep_tiny(data, base) -> None:
    """Undo the mutations that would make a valid scene big rather than wrong: a mesh (or a ``remesh.h_lower``
    that allows a remeshed sheet) of more than :data:`MAX_NODES` nodes (but not one ten times over the scenes'
    limit ``MAX_MESH_NODES``, which must be refused), a higher or missing ``dynamics.max_steps``."""
    d, b = data.get("dynamics"), base.get("dynamics")
    if isinstance(d, dict) and isinstance(b, dict):
        steps = d.get("max_steps")
        if steps is None or (isinstance(steps, int) and not isinstance(steps, bool) and steps > MAX_STEPS):
            d["max_steps"] = MAX_STEPS
    r, br = data.get("remesh"), base.get("remesh")
    if isinstance(r, dict) and isinstance(br, dict) and isinstance(data.get("mesh"), dict):
        fine = {**data["mesh"], "kind": "unstructured", "h": r.get("h_lower")}  # the finest remeshed sheet
        n = estimated_nodes(fine) if "size" in fine or "radius" in fine else None
        if n is not None and MAX_NODES <= n <= 10 * MAX_MESH_NODES:
            r["h_lower"] = br["h_lower"]
    m, bm = data.get("mesh"), base.get("mesh")
    if isinstance(m, dict) and isinstance(bm, dict):
        n = estimated_nodes(m)
        if n is not None and MAX_NODES <= n <= 10 * MAX_MESH_NODES:
            for key in ("nodes", "h", "size", "radius"):
                if key in bm:
                    m[key] = copy.deepcopy(bm[key])


def estimated_nodes(m: dict) -> float | None:
    """About how many nodes the ``[mesh]`` table ``m`` makes, if it is valid (None: not a valid size)."""
    num = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)  # noqa: E731
    nodes = m.get("nodes")
    if m.get("kind", "rectangle") != "unstructured":
        if isinstance(nodes, list) and len(nodes) == 2 and all(isinstance(v, int) and v > 0 for v in nodes):
            return 2.0 * nodes[0] * nodes[1]  # square-polar: its core too
        return None
    h = m.get("h")
    if not (num(h) and h > 0):
        return None
    if "radius" in m:
        r = m["radius"]
        return 4.0 * r / h * r / h if num(r) else None
    size = m.get("size", [1.0, 1.0])
    if isinstance(size, list) and len(size) == 2 and all(num(v) for v in size):
        return 1.2 * (abs(size[0]) / h + 1) * (abs(size[1]) / h + 1)
    return None


def beyond_the_step_cap(draw, data) -> str:
    """Make ``data`` a dynamic run of far more steps than the default ``dynamics.max_steps``, which must be
    refused before it starts (its own ``max_steps`` removed, a long ``t_end`` or a tiny ``dt``). Always
    ``dynamic``: a ``relax`` run is not refused but stops at the cap (10^4 sqrt(nodes) steps: 31 s of a tiny
    scene's CPU time, over the hang bound on a loaded machine), which ``tests/cli/test_scene_errors.py`` checks."""
    data["analysis"] = "dynamic"
    d = data.setdefault("dynamics", {"t_end": 0.01})
    d.pop("max_steps", None)
    d.pop("frames", None)
    if draw(st.booleans()):
        d["t_end"] = draw(st.sampled_from([1e7, 1e12, 1e300]))
        return f"step cap: analysis = {data['analysis']}, t_end = {d['t_end']!r}"
    d["dt"] = draw(st.sampled_from([1e-12, 1e-300, 5e-324]))
    return f"step cap: analysis = {data['analysis']}, dt = {d['dt']!r}"


@st.composite
def scenes(draw):
    """``(case, mutations, data)``: a tiny case scene (:func:`tiny_case`) after 1-4 mutations: most scenes
    get at least one of :data:`INPUT_MUTATIONS` (then any), one in :data:`EXTREME_EVERY` only
    :data:`EXTREME_MUTATIONS`, so that the solvers run (their runs take most of the test's time)."""
    name, base = draw(tiny_case())
    data = copy.deepcopy(base)
    if draw(st.sampled_from(range(STEP_CAP_EVERY))) == STEP_CAP_EVERY - 1:
        return name, [beyond_the_step_cap(draw, data)], data
    extreme = draw(st.sampled_from(range(EXTREME_EVERY))) == EXTREME_EVERY - 1
    first = EXTREME_MUTATIONS if extreme else INPUT_MUTATIONS
    rest = EXTREME_MUTATIONS if extreme else INPUT_MUTATIONS + EXTREME_MUTATIONS
    n = draw(st.integers(1, 4))
    done = [mutate(draw, data, first if i == 0 else rest) for i in range(n)]
    event(f"mutations: {'valid-but-extreme' if extreme else 'input'}")
    keep_tiny(data, base)
    return name, done, data


# ------------------------------------------------------------------------------------------ TOML out
def toml_key(key) -> str:
    """A TOML key: bare when it can be, else quoted."""
    return str(key) if re.fullmatch(r"[A-Za-z0-9_-]+", str(key)) else toml_string(str(key))


def toml_string(s: str) -> str:
    """A TOML basic string (quotes, backslashes and control characters escaped)."""
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_value(v) -> str:
    """A TOML value, inline (nan and +-inf as TOML writes them)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"no TOML for {v!r}")


def to_toml(table: dict, prefix=()) -> str:
    """``table`` as a TOML document (tables and arrays of tables as sections)."""
    lines, sections = [], []
    for key, value in table.items():
        path = (*prefix, key)
        head = ".".join(toml_key(k) for k in path)
        if isinstance(value, dict):
            sections.append(f"\n[{head}]\n" + to_toml(value, path))
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            sections += [f"\n[[{head}]]\n" + to_toml(item, path) for item in value]
        else:
            lines.append(f"{toml_key(key)} = {toml_value(value)}\n")
    return "".join(lines) + "".join(sections)


def same(a, b) -> bool:
    """Equal, NaN equal to NaN and types alike (1 is not 1.0)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


# -------------------------------------------------------------------------------------------- running
class SceneTimeout(BaseException):
    """The time bound ran out (a BaseException: no ``except Exception`` of the code under test swallows it)."""


@contextlib.contextmanager
def time_bound(seconds: float, hung: Path):
    """Raise :class:`SceneTimeout` in the main thread after ``seconds``. As a last resort, for code that
    never returns to the interpreter, write the tracebacks to the file ``hung`` and end the process after
    three times as long (the scene is beside it)."""
    def alarm(signum, frame):
        raise SceneTimeout(f"still running after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    with open(hung, "w") as fh:
        faulthandler.dump_traceback_later(3 * seconds + 30, exit=True, file=fh)
        try:
            yield
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
            faulthandler.cancel_dump_traceback_later()
    hung.unlink()


def run_cli(scene_file: Path, out: Path, *, verbose=False) -> tuple[int, str, str]:
    """``python -m rftstatic case FILE --out OUT --no-figures`` in-process: (status, stdout, stderr)."""
    argv = ["case", str(scene_file), "--out", str(out), "--no-figures", *(["-v"] if verbose else [])]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(argv)
    return code, stdout.getvalue(), stderr.getvalue()


def input_error_problem(err: str, scene_file: Path, data: dict) -> str | None:
    """What is wrong with the stderr of an exit-2 run (None: one line ``error: FILE: KEY: ...``, the key a
    schema key or one of the scene's own)."""
    lines = err.strip().splitlines()
    if len(lines) != 1:
        return f"the input error is {len(lines)} lines, not one"
    head = f"error: {scene_file}: "
    if not lines[0].startswith(head):
        return f"the input error does not start with {head!r}"
    key = lines[0][len(head):].split(": ", 1)[0]
    if key.split(".")[0] not in {*SCHEMA, *data}:
        return f"the input error does not name a scene key after the file (it names {key!r})"
    return None


def non_finite(value, path="summary"):
    """The path of the first NaN or infinite number in a JSON value, else None."""
    if isinstance(value, float) and not math.isfinite(value):
        return path
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        bad = non_finite(v, f"{path}.{k}")
        if bad:
            return bad
    return None


def read_summary(out: Path):
    """The run's ``summary.json`` (None when it wrote none)."""
    path = out / "summary.json"
    return json.loads(path.read_text()) if path.exists() else None


def outcome_problem(code: int, out_text: str, err: str, out: Path, scene_file: Path, data: dict) -> str | None:
    """Why the outcome of a run is not one of the three allowed (None: it is)."""
    if "Traceback" in err or "Traceback" in out_text:
        return "a traceback was printed"
    if code == 0:
        summary = read_summary(out)
        if summary is None:
            return "exit 0 without summary.json"
        bad = non_finite(summary)
        if bad:
            return f"exit 0 with a non-finite number in summary.json at {bad}"
        if summary.get("converged") is not True:
            return f"exit 0 but summary.json says converged = {summary.get('converged')!r}"
        return None
    if code == 2:
        return input_error_problem(err, scene_file, data)
    if code == 3:
        if not err.startswith("error: "):
            return "exit 3 without an error message"
        summary = read_summary(out)
        if summary is not None and summary.get("converged") is not False:
            return f"exit 3 but summary.json says converged = {summary.get('converged')!r}"
        return None
    return f"exit status {code}"


def check_scene(data: dict, workdir: Path, label: str = "") -> tuple[str, float]:
    """Run the scene ``data`` as a user does; fail with the scene when its outcome is not allowed.

    Returns the outcome (``"done"``, ``"input"``, ``"goal"``) and the wall time [s].
    """
    text = to_toml(data)
    assert same(tomllib.loads(text), data), f"the test's TOML writer lost something:\n{text}"
    scene_file = workdir / "scene.toml"
    scene_file.write_text(text, encoding="utf-8")
    out = workdir / "out"
    t0 = time.perf_counter()
    try:
        with time_bound(BOUND_S, workdir / "hung.txt"):
            code, out_text, err = run_cli(scene_file, out)
    except SceneTimeout:
        pytest.fail(f"the scene did not end within {BOUND_S:g} s {label}\n--- scene.toml\n{text}", pytrace=False)
    wall = time.perf_counter() - t0
    problem = outcome_problem(code, out_text, err, out, scene_file, data)
    if problem is not None:
        detail = err.strip()
        if code == 1:  # the one-line internal error: run again with -v for the traceback
            try:
                with time_bound(BOUND_S, workdir / "hung.txt"):
                    run_cli(scene_file, workdir / "again", verbose=True)
            except BaseException:  # noqa: BLE001 - whatever it raises is the report
                detail += "\n" + traceback.format_exc()
        pytest.fail(f"{problem} {label}\n--- stderr\n{detail}\n--- scene.toml\n{text}", pytrace=False)
    return {0: "done", 2: "input", 3: "goal"}[code], wall


# ----------------------------------------------------------------------------------------------- tests
@pytest.fixture(scope="module")
def workdirs(tmp_path_factory):
    """A fresh folder per example; the first use loads (or compiles) the kernels outside the bound."""
    root = tmp_path_factory.mktemp("scenes")
    from rftstatic.contact.self_contact.law_kernels import load_compiled

    load_compiled()  # the self-contact twins that a long tiny run switches to (their first compile: ~30 s)
    for name in ("hang-20", "strip", "pedestal-square-20"):  # the explicit, static and relax routes
        extra = ["dynamics.t_end=0.01", "dynamics.frames=[0.01]"] if name == "hang-20" else []
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["case", name, *(a for kv in ("mesh.nodes=[5,5]", *extra) for a in ("--set", kv)),
                  "--out", str(root / f"warm-{name}"), "--no-figures"])
    counter = iter(range(10**9))

    def fresh() -> Path:
        path = root / f"s{next(counter)}"
        path.mkdir()
        return path

    yield fresh
    shutil.rmtree(root, ignore_errors=True)


SHRINK = os.environ.get("RFTSTATIC_PROPERTY_SHRINK") == "1"
LOG = os.environ.get("RFTSTATIC_PROPERTY_LOG")  # a file: one JSON line per scene (case, mutations, outcome, wall)


@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None, verbosity=Verbosity.quiet,
          phases=(Phase.explicit, Phase.generate, *((Phase.shrink,) if SHRINK else ())),
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                 HealthCheck.function_scoped_fixture])
@given(scenes())
def test_any_scene_ends_in_success_a_scene_error_or_a_reported_failure(workdirs, scene):
    name, mutations, data = scene
    workdir = workdirs()
    outcome, wall = check_scene(data, workdir, f"(from {name}; mutations: {'; '.join(mutations) or 'none'})")
    event(f"outcome: {outcome}")
    if LOG:
        with open(LOG, "a") as fh:
            fh.write(json.dumps({"case": name, "mutations": mutations, "outcome": outcome, "wall": wall,
                                "mesh": data.get("mesh")}, default=repr) + "\n")
    event(f"wall: {'<0.1 s' if wall < 0.1 else '<1 s' if wall < 1 else '<5 s' if wall < 5 else '>=5 s'}")
    shutil.rmtree(workdir, ignore_errors=True)


@pytest.mark.parametrize("name", CASES)
def test_the_tiny_bases_have_under_200_nodes(name):
    """The largest meshes :func:`tiny_case` makes of each case have fewer than :data:`MAX_NODES` nodes."""
    from rftstatic.scenes.build import build_mesh
    from rftstatic.scenes.schema import scene_from_dict

    data = load_scene(name).data
    first, second = MESH_COUNTS[data["mesh"].get("kind", "rectangle")]
    for a in range(first[0], first[1] + 1):
        tiny_mesh(data["mesh"], a, second(a)[1])
        assert build_mesh(scene_from_dict(data)).n_nodes < MAX_NODES, data["mesh"]


def test_the_time_bound_ends_a_run_that_does_not(tmp_path):
    t0 = time.perf_counter()
    with pytest.raises(SceneTimeout), time_bound(0.2, tmp_path / "hung.txt"):
        while True:
            pass
    assert time.perf_counter() - t0 < 5


def test_the_check_fails_an_internal_error_and_passes_an_input_error(tmp_path, monkeypatch):
    from rftstatic import api

    name, data = "strip", copy.deepcopy(load_scene("strip").data)
    data["mesh"]["nodes"] = [5, 3]
    (tmp_path / "a").mkdir()
    assert check_scene({**data, "element": "RFT9"}, tmp_path / "a")[0] == "input"

    def broken(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(api, "run", broken)
    (tmp_path / "b").mkdir()
    with pytest.raises(pytest.fail.Exception, match=r"(?s)exit status 1.*ZeroDivisionError: a bug.*\[mesh\]"):
        check_scene(data, tmp_path / "b", name)
