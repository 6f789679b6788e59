"""Scene files: TOML data that say which paper figure they reproduce, in the units they state.

A scene is parsed into plain dictionaries, validated against :data:`SCHEMA` (an unknown key or a
value of the wrong type is a :class:`SceneError` naming the file, the key and the value), and
``--set key=value`` overrides are applied before validation. :func:`build_model` turns a scene
into a :class:`rftstatic.model.model.Model` in SI units; the documentation's scene-key reference is generated from it.
"""

from __future__ import annotations

import copy
import difflib
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from rftstatic.compiled import KERNELS
from rftstatic.contact.obstacles import scene_schema as obstacle_schema
from rftstatic.errors import SceneError
from rftstatic.fabrics.lab import LAB_KEYS
from rftstatic.optionspec import schema_entries
from rftstatic.remesh.options import RemeshOptions
from rftstatic.scenes.contact_options import ContactOptions
from rftstatic.scenes.dynamics_options import FRAMES_HELP, DynamicsOptions
from rftstatic.scenes.analyses import SCENE_ANALYSES
from rftstatic.scenes.motion import GarmentMotionOptions
from rftstatic.scenes.run_options import SOLVER_GROUPS, CantileverOptions
from rftstatic.units import UNIT_SYSTEMS, UnitSystem, unit_system

CASES_DIR = Path(__file__).resolve().parents[2] / "cases"

NUM = (int, float)
MESH_NODES = {"rectangle": [11, 11], "polar": [11, 40], "square-polar": [21, 160]}
"""``mesh.nodes`` of a generated mesh whose scene gives none (the mesh builder and the mesh sequence read it)."""
LIST = (list,)


@dataclass(frozen=True)
class ListOf:
    """A TOML array whose items are ``item`` (python types, or a nested :class:`ListOf`), ``length`` of
    them (None: any number, at least ``min_length``), optionally from ``choices``."""

    item: object
    length: int | None = None
    min_length: int = 0
    choices: tuple = ()

    def problem(self, value) -> str | None:
        """What is wrong with ``value`` (None: nothing)."""
        if not isinstance(value, list):
            return f"expected an array, got {value!r} ({type(value).__name__})"
        if self.length is not None and len(value) != self.length:
            return f"expected {self.length} items, got {len(value)} ({value!r})"
        if len(value) < self.min_length:
            return f"expected at least {self.min_length} items, got {value!r}"
        for i, item in enumerate(value):
            if isinstance(self.item, ListOf):
                inner = self.item.problem(item)
                if inner is not None:
                    return f"item {i}: {inner}"
                continue
            types = self.item if isinstance(self.item, tuple) else (self.item,)
            if not isinstance(item, types) or (isinstance(item, bool) and bool not in types):
                names = "number" if set(types) == {int, float} else "/".join(t.__name__ for t in types)
                return f"item {i} = {item!r} is not {'an ' if names == 'int' else 'a '}{names}"
            if self.choices and item not in self.choices:
                close = difflib.get_close_matches(str(item), self.choices, n=1)
                hint = f' (did you mean "{close[0]}"?)' if close else ""
                return f'item {i} = "{item}" is not one of {", ".join(self.choices)}{hint}'
        return None


XY = ListOf(NUM, 2)
XYZ = ListOf(NUM, 3)
BOX = ListOf(NUM, 4)


class PointsXY(ListOf):
    """One reference point ``[x, y]`` or several ``[[x, y], ...]``."""

    def __init__(self):
        super().__init__(NUM, None, 1)

    def problem(self, value) -> str | None:
        if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
            return ListOf(XY, None, 1).problem(value)
        return XY.problem(value)


class _ObstacleKeys(Mapping):
    """Schema of an ``[[obstacles]]`` table: ``type`` and the keys of every registered obstacle type
    (:func:`rftstatic.contact.obstacles.scene_schema`), read when a scene is checked, so that a type
    registered after this module was imported is known too."""

    def __getitem__(self, key):
        return obstacle_schema()[key]

    def __iter__(self):
        return iter(obstacle_schema())

    def __len__(self):
        return len(obstacle_schema())


# key -> (allowed python types, help). Nested tables are dicts; arrays of tables are [dict] (or [mapping]).
SCHEMA = {
    "title": (str, "one line saying what the scene is"),
    "figure": (str, "the paper figure or section it reproduces"),
    "units": (str, "unit system: " + ", ".join(UNIT_SYSTEMS)),
    "element": (str, "RFT3 or RFT6"),
    "analysis": (str, "static (Newton), dynamic (explicit) or relax (dynamic relaxation): "
                      "rftstatic.scenes.analyses"),
    "kernels": (str, "kernel back end of the run: auto (compiled with numba from 3,000 elements, with "
                     "self-contact or on a long route; else numpy), numpy or compiled"),
    "mesh": ({
        "kind": (str, "rectangle, polar, square-polar, file or unstructured"),
        "size": (XY, "[lx, ly] of a rectangle"),
        "nodes": (ListOf(int, 2), "[nx, ny] (rectangle) or [n_radial, n_circ] (polar), integers"),
        "origin": (XY, "lower-left corner of a rectangle"),
        "centre": (XY, "centre of a polar mesh"),
        "pattern": (str, "diagonal pattern: right, left, alternate, union-jack"),
        "radius": (NUM, "outer radius (polar) or half side (square-polar)"),
        "inner_radius": (NUM, "inner radius of an annulus"),
        "grading": (NUM, "polar: outermost ring spacing / innermost (1: uniform)"),
        "locking": (str, 'RFT6 membrane locking, (C/B) h^2 > 1e4: "warn" (default) or "refine" (rectangle, polar, '
                         'square-polar: more nodes until below; rftstatic.scenes.locking)'),
        "path": (str, "mesh file read with meshio (relative to the scene file)"),
        "h": (NUM, "target element size of an unstructured mesh"),
        "z": (NUM, "height of the flat reference plane"),
    }, "the flat reference mesh"),
    "material": ({
        "preset": (str, "named fabric, e.g. wool-kang-yu"),
        "kind": (str, "fabric (rigidities) or isotropic (E, nu, thickness)"),
        "warp_angle": (NUM, "angle of the warp from the x axis [deg]"),
        **{k: (NUM, "fabric rigidity in scene units") for k in
           ("C_warp", "C_weft", "C_shear", "C12", "B_warp", "B_weft", "B_twist", "B12")},
        "weight": (NUM, "areal weight [force/area]"),
        "E": (NUM, "Young's modulus [force/area]"),
        "nu": (NUM, "Poisson ratio"),
        "thickness": (NUM, "shell thickness, or a fabric's (self-contact default) [length]"),
        "hysteresis_ratio": (NUM, "bending hysteresis: stick stiffness / B (default 10; with kes_2HB_*)"),
        "shear_hysteresis_ratio": (NUM, "shear hysteresis: stick stiffness / G (default 10; with kes_2HG; "
                                        "rftstatic.element.shear_friction)"),
        **{f"bending_k2_{d}": (NUM, f"nonlinear bending: Feng et al.'s k2, {d} [force length^2], <= 0 "
                                   "(rftstatic.element.nonlinear_bending)") for d in ("warp", "weft")},
        "bending_floor": (NUM, "nonlinear bending: least slope / B, in (0, 1) (default 0.2)"),
        "nonlinear_bending": (bool, "true: a ctd-* preset's published k2 (opt-in nonlinear bending)"),
        **{k: (NUM, f"{meaning} [{unit}], lab units whatever the scene's (rftstatic.fabrics.lab)")
           for k, (unit, meaning) in LAB_KEYS.items()},
    }, "fabric or shell rigidities; fabric lab data (KES-F kes_*, FAST fast_*)"),
    "supports": ([{
        "kind": (str, "clamped, pinned or fixed"),
        "box": (BOX, "[xmin, xmax, ymin, ymax] in reference coordinates"),
        "at": (PointsXY(), "[x, y] or [[x, y], ...] reference points (nearest nodes)"),
        "radius": (NUM, "the nodes within this distance of centre (a tester's clamping disc) [length]"),
        "centre": (XY, "centre of the radius selector (default [0, 0])"),
        "components": (str, "for kind = fixed: which of x, y, z are held, e.g. 'xy'"),
        "velocity": (XYZ, "[vx, vy, vz] the held components move at in a dynamic run (a dragged edge, "
                          "rftstatic.scenes.drive) [length/time]"),
    }], "prescribed displacements: zero, or moving at a velocity (dynamic runs)"),
    "loads": ({
        "gravity": (bool, "the material's weight, along -z"),
        "gravity_tilt": (NUM, "tilt of the weight about the y axis [deg], towards +x: the sheet on a plane "
                              "inclined by this angle, in the plane's frame (the incline scene)"),
        "pressure": (NUM, "uniform transverse load along -z [force/area]"),
        "point": ([{"at": (PointsXY(), "[x, y]"), "force": (XYZ, "[fx, fy, fz]")}], "nodal forces"),
        "edge": ([{"box": (BOX, "[xmin, xmax, ymin, ymax]"),
                   "force_per_length": (XYZ, "[fx, fy, fz] per unit length")}], "boundary line loads"),
    }, "external loads at load factor 1"),
    "obstacles": ([_ObstacleKeys()], "rigid obstacles (the keys every registered obstacle type declares)"),
    "contact": (schema_entries(ContactOptions), "penalty contact and self-contact: python -m rftstatic options "
                "contact"),
    "solver": (schema_entries(*SOLVER_GROUPS), "static solver options (rftstatic.solvers.options) and the app's "
               "(rftstatic.scenes.run_options): python -m rftstatic options solver"),
    "dynamics": ({**schema_entries(DynamicsOptions), "frames": (ListOf(NUM), FRAMES_HELP)},
                 "explicit dynamics and dynamic relaxation: python -m rftstatic options dynamics"),
    "remesh": (schema_entries(RemeshOptions), "global adaptive remeshing (§5): python -m rftstatic options remesh"),
    "cantilever": (schema_entries(CantileverOptions), "cantilever bending tester (analysis = \"cantilever\"): the "
                   "strip's mesh.size[0] is the first overhang; python -m rftstatic options cantilever"),
    "garment": ({"pattern": (str, "pattern file, GarmentCode JSON or TOML (relative to the scene)"),
                 "h": (NUM, "target element size of the garment mesh [length]"),
                 "closing_h": (NUM, "element size of the mesh the seams are closed on, if coarser than h [length]: "
                               "the closed shape is carried to the garment mesh (rftstatic.garment.sewing)")},
                "the garment of analysis = \"garment\" (rftstatic.app.garment)"),
    "body": ({"kind": (str, "dress-form (rftstatic.garment.body.DressForm)"),
              "size": (NUM, "a size of the chart, by bust girth in cm (rftstatic.references.body_sizes; ANSUR II "
                       "medians): the measurements not given"),
              **{k: (NUM, "dress form measurement [length]") for k in
                 ("bust_girth", "waist_girth", "hip_girth", "bust_height", "waist_height", "hip_height",
                  "shoulder_breadth", "shoulder_height", "neck_girth", "neck_height", "neck_length",
                  "bottom_height")},
              **{k: (NUM, "depth / width ratio of the section [-]") for k in
                 ("bust_depth", "waist_depth", "hip_depth", "shoulder_depth", "neck_depth")},
              "motion": (obstacle_schema()["motion"][0], "the form's keyframes (analysis = \"garment-motion\"; the "
                         "keys of obstacles.motion, rftstatic.scenes.motion)")},
             "the dress form of analysis = \"garment\""),
    "motion": (schema_entries(GarmentMotionOptions), "the run on the moving form of analysis = \"garment-motion\" "
               "(rftstatic.app.garment_motion): python -m rftstatic options motion"),
    "probes": ([{"name": (str, "probe name"), "at": (XY, "[x, y] reference point")}], "tracked points"),
    "output": ({
        "views": (ListOf(str, choices=("side", "top", "iso")), "PNG views: side, top, iso"),
        "vtu": (bool, "write the deformed mesh as VTU"),
    }, "what a run writes"),
}



@dataclass
class Scene:
    """A validated scene: its data (scene units), file and unit system."""

    data: dict
    path: Path | None = None
    name: str = "scene"
    overrides: dict = field(default_factory=dict)

    @property
    def units(self) -> UnitSystem:
        return unit_system(self.data.get("units", "cm-gf-s"))

    @property
    def analysis(self) -> str:
        """The scene's ``analysis`` key; a scene without one is static (the one place this default is written)."""
        return self.data.get("analysis", "static")

    def get(self, dotted: str, default=None):
        node = self.data
        for part in dotted.split("."):
            if not isinstance(node, dict) or part not in node:
                return default
            node = node[part]
        return node

    def error(self, key: str, message: str) -> SceneError:
        where = str(self.path) if self.path else self.name
        return SceneError(f"{where}: {key}: {message}")


def find_scene(name: str) -> Path:
    """``name`` as a path to a .toml file, or a scene in ``cases/``."""
    p = Path(name)
    if p.suffix == ".toml":
        if not p.exists():
            raise SceneError(f"{p}: no such scene file")
        return p
    candidate = CASES_DIR / f"{name}.toml"
    if candidate.exists():
        return candidate
    names = sorted(q.stem for q in CASES_DIR.glob("*.toml"))
    near = difflib.get_close_matches(name, names, n=1)
    hint = f'did you mean "{near[0]}"? ' if near else ""
    raise SceneError(f'no scene "{name}" in {CASES_DIR}; {hint}known scenes: {", ".join(names)}')


def list_scenes() -> list[tuple[str, str]]:
    """(name, title) of every scene in ``cases/``."""
    out = []
    for p in sorted(CASES_DIR.glob("*.toml")):
        with open(p, "rb") as fh:
            data = tomllib.load(fh)
        out.append((p.stem, data.get("title", "") + (f"  [{data['figure']}]" if "figure" in data else "")))
    return out


def parse_override(text: str) -> tuple[str, object]:
    """``key=value`` with a TOML value (``3``, ``[21, 101]``, ``"RFT3"``); bare words are strings."""
    if "=" not in text:
        raise SceneError(f'--set "{text}": expected key=value, e.g. --set element=RFT3')
    key, raw = text.split("=", 1)
    key, raw = key.strip(), raw.strip()
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except ValueError as exc:  # an integer of more than 4300 digits (Python's limit on int(str))
        raise SceneError(f"--set {key}: {exc}; TOML's integers are 64-bit") from None
    except RecursionError:
        raise SceneError(f'--set {key}: the value nests arrays or tables too deeply for the TOML reader; a scene '
                         f'nests at most {MAX_NESTING} levels') from None
    if _nesting(value) > MAX_NESTING:
        raise SceneError(f"--set {key}: the value nests arrays or tables more than {MAX_NESTING} levels deep; a "
                         "scene nests at most 5 (loads.point.0.at = [[x, y]])")
    return key, value


def apply_override(data: dict, key: str, value, source="--set") -> None:
    parts = key.split(".")
    node = data
    for i, part in enumerate(parts[:-1]):
        if isinstance(node, list):
            try:
                node = node[int(part)]
            except (ValueError, IndexError):
                raise SceneError(f'{source} {key}: "{part}" is not an index of the array {".".join(parts[:i])}') from None
            continue
        if not isinstance(node, dict):
            raise SceneError(f'{source} {key}: "{".".join(parts[:i])}" is a value, not a table; set '
                             f'{".".join(parts[:i])} itself')
        node = node.setdefault(part, {})
        if not isinstance(node, (dict, list)):
            raise SceneError(f'{source} {key}: "{".".join(parts[:i + 1])}" is a value ({node!r}), not a table; '
                             f'set {".".join(parts[:i + 1])} itself')
    last = parts[-1]
    if isinstance(node, list):
        try:
            node[int(last)] = value
        except (ValueError, IndexError):
            raise SceneError(f'{source} {key}: "{last}" is not an index of the array') from None
    else:
        node[last] = value


def load_scene(name_or_path: str, overrides=()) -> Scene:
    """Read, override and validate a scene (``overrides``: ``["key=value", ...]``)."""
    path = find_scene(name_or_path)
    if not path.is_file():
        raise SceneError(f"{path}: not a scene file (a directory or a special file); give a .toml file")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc})") from None
    except RecursionError:
        raise SceneError(f"{path}: {_deep_key(path)}nests tables or arrays too deeply for the TOML reader (it "
                         f"recurses once per level); a scene nests at most {MAX_NESTING} levels: flatten it") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not a text file in UTF-8 (byte {exc.start}: {exc.reason}); save the scene "
                         "as UTF-8 TOML") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot be read ({exc.strerror})") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's limit on int(str))
        raise SceneError(f"{path}: {exc}; TOML's integers are 64-bit") from None
    _check_nesting(data, str(path))
    applied = {}
    for text in overrides:
        key, value = parse_override(text)
        apply_override(data, key, value)
        applied[key] = value
    scene = Scene(data, path, path.stem, applied)
    validate(scene)
    return scene


def scene_from_dict(data: dict, name="scene") -> Scene:
    _check_nesting(data, name)
    scene = Scene(copy.deepcopy(data), None, name)
    validate(scene)
    return scene


MAX_NESTING = 16
"""Deepest nesting of tables and arrays in a scene: the schema's deepest value is 5 levels down
(``loads.point.0.at = [[x, y]]``); a deeper one is no scene, and a few thousand levels exhaust the
recursion of the TOML reader, of ``copy.deepcopy`` and of ``repr``."""


def _nesting(value) -> int:
    """Levels of tables and arrays in ``value`` (0: a scalar), without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, (dict, list)):
            deepest = max(deepest, depth + 1)
            if depth + 1 <= MAX_NESTING:  # deeper is refused anyway: stop counting there
                stack.extend((v, depth + 1) for v in (node.values() if isinstance(node, dict) else node))
    return deepest


def _deep_key(path: Path) -> str:
    """``"KEY: "`` of the first line of a scene file that opens more than :data:`MAX_NESTING` arrays or inline
    tables (``""`` when no single line does)."""
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        if "=" in line and line.count("[") + line.count("{") > MAX_NESTING:
            return line.split("=", 1)[0].strip().strip('"') + ": "
    return ""


def _check_nesting(data, where: str) -> None:
    """Scene error naming the top-level key whose value nests tables or arrays deeper than :data:`MAX_NESTING`."""
    if not isinstance(data, dict):
        return
    for key, value in data.items():
        if _nesting(value) > MAX_NESTING:
            raise SceneError(f"{where}: {key}: nests tables or arrays more than {MAX_NESTING} levels deep; a scene "
                             "nests at most 5 (loads.point.0.at = [[x, y]]): flatten it")


def validate(scene: Scene) -> None:
    _check_table(scene, scene.data, SCHEMA, "")
    if scene.data.get("units", "cm-gf-s") not in UNIT_SYSTEMS:
        raise scene.error("units", f'unknown unit system "{scene.data["units"]}"; use one of {", ".join(UNIT_SYSTEMS)}')
    if scene.data.get("element", "RFT6") not in ("RFT3", "RFT6"):
        raise scene.error("element", f'"{scene.data["element"]}" is not an element; use RFT3 or RFT6')
    if scene.data.get("kernels", "auto") not in ("auto", *KERNELS):
        raise scene.error("kernels", f'"{scene.data["kernels"]}" is not a kernel back end; use auto, '
                          f'{", ".join(KERNELS)}')
    if scene.analysis not in SCENE_ANALYSES:
        raise scene.error("analysis", f'"{scene.data["analysis"]}" is not an analysis; use one of '
                          f'{", ".join(SCENE_ANALYSES)}')


INT64 = (-(2**63), 2**63 - 1)
"""TOML's integers are 64-bit (its specification); Python's reader takes any size, and an integer beyond a
float's range (``1`` followed by 400 zeros) overflows where a length or a count is computed from it."""


def _non_finite(value):
    """The first NaN or infinite number, or integer beyond :data:`INT64`, in ``value`` (a number or nested
    lists), else None."""
    if isinstance(value, float) and not math.isfinite(value):
        return value
    if isinstance(value, int) and not isinstance(value, bool) and not INT64[0] <= value <= INT64[1]:
        return value
    if isinstance(value, list):
        for item in value:
            bad = _non_finite(item)
            if bad is not None:
                return bad
    return None


def _check_table(scene, table, schema, prefix):
    if not isinstance(table, dict):
        raise scene.error(prefix.rstrip("."), f"expected a table, got {table!r}")
    for key, value in table.items():
        full = prefix + key
        if key not in schema:
            near = difflib.get_close_matches(key, list(schema), n=1)
            hint = f'did you mean "{prefix}{near[0]}"? ' if near else ""
            raise scene.error(full, f"unknown key (value {value!r}); {hint}known keys here: {', '.join(sorted(schema))}")
        spec, _ = schema[key]
        if isinstance(spec, dict):
            _check_table(scene, value, spec, full + ".")
        elif isinstance(spec, list):
            if not isinstance(value, list):
                raise scene.error(full, f"expected an array of tables ([[{full}]]), got {value!r}")
            for i, item in enumerate(value):
                _check_table(scene, item, spec[0], f"{full}.{i}.")
        elif isinstance(spec, ListOf):
            bad = spec.problem(value)
            if bad is not None:
                raise scene.error(full, bad)
        else:
            types = spec if isinstance(spec, tuple) else (spec,)
            ok = isinstance(value, types) and not (isinstance(value, bool) and bool not in types)
            if not ok:
                names = "/".join(t.__name__ for t in types)
                raise scene.error(full, f"expected {names}, got {value!r} ({type(value).__name__})")
        bad = _non_finite(value)
        if bad is not None:
            where = f" (in {value!r})" if isinstance(value, list) else ""
            if isinstance(bad, int):
                raise scene.error(full, f"an integer of {bad.bit_length()} bits is beyond TOML's 64-bit integers "
                                  "(at most 9223372036854775807 in magnitude); give a smaller value")
            raise scene.error(full, f"{bad!r} is not a finite number{where}; give a finite value")
