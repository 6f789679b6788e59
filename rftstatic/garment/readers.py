"""Pattern files: GarmentCode's JSON specification and a small TOML form for hand-written patterns.

Both give a :class:`rftstatic.garment.pattern.Pattern` in SI; :func:`read_pattern` picks the reader
by the file's suffix (``.json`` or ``.toml``).

GarmentCode JSON (``*_specification.json`` of GarmentCode / pygarment, read with :mod:`json`)
------------------------------------------------------------------------------------------
``properties.units_in_meter`` (100 = cm, 1000 = mm, 1 = m; any positive number; default 100)
scales every length to m. ``properties.curvature_coords`` must be ``"relative"`` (the default;
``"absolute"``, an older form, is refused: load and save it with pygarment first).
``pattern.panels.<name>``: ``vertices`` [[x, y], ...], ``edges`` [{``endpoints``: [i, j],
optional ``curvature``}, ...] as one closed chain, ``translation`` [x, y, z], ``rotation``
[alpha, beta, gamma] (deg, :mod:`rftstatic.garment.pattern` for the order), optional ``grain``
[deg] (not in the schema: default :data:`~rftstatic.garment.pattern.GRAIN_DEFAULT`).
Edge curvature, as GarmentCode writes it:

- ``{"type": "circle", "params": [radius, large_arc, right]}``: a circular arc (radius in the
  file's units; the flags of :mod:`rftstatic.garment.curves`);
- ``{"type": "quadratic", "params": [[u, v]]}`` and ``{"type": "cubic", "params": [[u, v],
  [u, v]]}``: Bézier control points relative to the edge: u along the chord a -> b, v along the
  chord turned +90 deg, both in chord lengths (point = a + u (b - a) + v perp(b - a));
- ``[u, v]`` (Garment-Pattern-Generator's older form): a quadratic Bézier as above.

Any other curvature type is refused with the panel and edge named.
``pattern.stitches``: [[{``panel``, ``edge``}, {``panel``, ``edge``}], ...]; an optional third
entry ``"right_wrong"`` pairs start with start (``aligned``), otherwise start meets end
(``reversed``, GarmentCode's default). Other keys (``parameters``, ``panel_order``, ``label``...)
are ignored.

TOML form
---------
::

    units = "cm"                      # "m", "cm" or "mm"; every length below is in it
    name = "a-line skirt"             # optional

    [[panels]]
    name = "front"
    vertices = [[-30, 0], [30, 0], [18, 60], [-18, 60]]   # edge k runs from vertex k to k+1 (closing)
    holes = []                        # optional: loops of vertices inside, their edges numbered on
    arcs = [{edge = 2, radius = 91.8, side = "left", large = false}]  # optional; side of the chord
    grain = 90                        # warp direction from the panel's x axis [deg] (default 90)
    translate = [0, 0.4, 0.15]        # placement, in `units` (default 0)
    rotate = [0, 0, 0]                # Euler angles [deg] (default 0)

    [[seams]]
    a = "front:1"                     # panel:edge
    b = "back:3"
    orientation = "reversed"          # or "aligned" (default "reversed")
    kind = "sew"                      # "sew", "fold" or "open" (default "sew")
    angle = 180                       # fold seams: the crease's rest angle [deg] (default 180: turned back)
    width = 0.5                       # fold seams: the crease's width, in `units` (default: the elements' height)

An arc's ``side`` says on which side of its chord (vertex k -> k+1) the arc's midpoint lies;
``large = true`` takes the arc longer than half the circle. A loop of two vertices whose two edges
are arcs is a circle (a ring panel: ``vertices = [[R, 0], [-R, 0]]``, ``holes = [[[r, 0], [-r, 0]]]``,
four arcs). Hole edges are numbered after the outline's (and after earlier holes'), each hole closing
on itself; ``arcs`` and ``seams`` use these numbers. Unknown keys are errors.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np

from rftstatic.garment.pattern import GRAIN_DEFAULT, SEAM_LENGTH_TOLERANCE, Edge, Panel, Pattern, PatternError, Seam

__all__ = ["LENGTH_UNITS", "read_pattern", "read_garmentcode", "parse_garmentcode", "read_toml", "parse_toml"]

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
"""Length units of the TOML form -> metres."""

_UNITS_IN_METER_DEFAULT = 100.0     # GarmentCode's default (cm)


def read_pattern(path, *, seam_tolerance=SEAM_LENGTH_TOLERANCE):
    """Read a ``.json`` (GarmentCode) or ``.toml`` pattern file into a checked :class:`Pattern` [SI].

    ``seam_tolerance``: largest relative length difference of a seam's edges [-]
    (:class:`~rftstatic.garment.pattern.Pattern`).
    """
    path = Path(path)
    readers = {".json": read_garmentcode, ".toml": read_toml}
    if path.suffix.lower() not in readers:
        raise PatternError(f"{path}: unknown pattern format {path.suffix!r}; give a .json (GarmentCode) "
                           "or a .toml pattern file")
    return readers[path.suffix.lower()](path, seam_tolerance=seam_tolerance)


def _load(path, loader, what):
    try:
        with open(path, "rb") as fh:
            return loader(fh)
    except FileNotFoundError:
        raise PatternError(f"{path}: no such pattern file; check the path") from None
    except (ValueError, tomllib.TOMLDecodeError) as err:
        raise PatternError(f"{path}: not valid {what}: {err}; fix the syntax") from None


# ------------------------------------------------------------------------------------- GarmentCode
def read_garmentcode(path, *, seam_tolerance=SEAM_LENGTH_TOLERANCE):
    """Read a GarmentCode JSON specification (module docstring) into a :class:`Pattern` [SI]."""
    return parse_garmentcode(_load(path, json.load, "JSON"), source=str(path), seam_tolerance=seam_tolerance)


def _number(value, where, key):
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise PatternError(f"{where}: {key} = {value!r} is not numeric; give numbers") from None
    return out


def _vector(value, where, key):
    """A placement 3-vector (translation, rotation) read as floats."""
    out = _number(value, where, key)
    if out.shape != (3,):
        raise PatternError(f"{where}: {key} = {value!r}; give three numbers [x, y, z]")
    return out


def _grain(spec, where):
    grain = spec.get("grain", GRAIN_DEFAULT)
    if isinstance(grain, bool) or not isinstance(grain, (int, float)):
        raise PatternError(f"{where}: grain = {grain!r}; give the warp direction's angle from the panel's x axis [deg]")
    return float(grain)


def parse_garmentcode(data, *, source="<json>", seam_tolerance=SEAM_LENGTH_TOLERANCE):
    """GarmentCode specification ``data`` (the parsed JSON) -> :class:`Pattern` [SI]."""
    if not isinstance(data, dict) or not isinstance(data.get("pattern"), dict) \
            or not isinstance(data["pattern"].get("panels"), dict):
        raise PatternError(f"{source}: no pattern.panels table; a GarmentCode specification has "
                           "{\"pattern\": {\"panels\": {...}, \"stitches\": [...]}, \"properties\": {...}}")
    props = data.get("properties") or {}
    uim = props.get("units_in_meter", _UNITS_IN_METER_DEFAULT)
    if not (isinstance(uim, (int, float)) and not isinstance(uim, bool) and np.isfinite(uim) and uim > 0):
        raise PatternError(f"{source}: properties.units_in_meter = {uim!r}; give a positive number "
                           "(100 for cm, 1000 for mm, 1 for m)")
    coords = props.get("curvature_coords", "relative")
    if coords != "relative":
        raise PatternError(f"{source}: properties.curvature_coords = {coords!r}; only 'relative' (GarmentCode's "
                           "current form) is read: load and save the pattern with pygarment to convert it")
    scale = 1.0 / float(uim)
    panels = [_gc_panel(name, spec, scale, f"{source}: panel {name!r}")
              for name, spec in data["pattern"]["panels"].items()]
    seams = [_gc_stitch(s, k, f"{source}: stitch {k}") for k, s in enumerate(data["pattern"].get("stitches", []))]
    units = {1.0: "m", 100.0: "cm", 1000.0: "mm"}.get(float(uim), f"1/{uim:g} m")
    return Pattern(panels=panels, seams=seams, units=units, source=source, seam_tolerance=seam_tolerance)


def _gc_panel(name, spec, scale, where):
    if not isinstance(spec, dict) or "vertices" not in spec or "edges" not in spec:
        raise PatternError(f"{where}: needs 'vertices' and 'edges'; add them")
    v = _number(spec["vertices"], where, "vertices")
    if v.ndim != 2 or v.shape[1] != 2:
        raise PatternError(f"{where}: vertices must be a list of [x, y] pairs, got shape {v.shape}")
    v = v * scale
    if not isinstance(spec["edges"], list):
        raise PatternError(f"{where}: edges must be a list of {{\"endpoints\": [i, j]}} tables")
    edges = [_gc_edge(e, v, scale, f"{where}, edge {k}") for k, e in enumerate(spec["edges"])]
    return Panel(name=name, vertices=v, edges=edges, grain=_grain(spec, where),
                 translation=_vector(spec.get("translation", [0, 0, 0]), where, "translation") * scale,
                 rotation=_vector(spec.get("rotation", [0, 0, 0]), where, "rotation"))


def _gc_edge(spec, v, scale, where):
    ends = spec.get("endpoints") if isinstance(spec, dict) else None
    if not (isinstance(ends, list) and len(ends) == 2 and all(isinstance(i, int) for i in ends)):
        raise PatternError(f"{where}: 'endpoints' must be two vertex indices, got {ends!r}")
    i, j = ends
    if not (0 <= i < len(v) and 0 <= j < len(v)):
        raise PatternError(f"{where}: endpoints {ends} outside the {len(v)} vertices; fix the indices")
    curv = spec.get("curvature")
    if curv is None:
        return Edge(i, j)
    if isinstance(curv, list):                          # Garment-Pattern-Generator: quadratic [u, v]
        curv = {"type": "quadratic", "params": [curv]}
    kind, params = (curv.get("type"), curv.get("params")) if isinstance(curv, dict) else (None, None)
    if kind == "circle":
        if not (isinstance(params, list) and len(params) == 3):
            raise PatternError(f"{where}: circle curvature params must be [radius, large_arc, right], got {params!r}")
        return Edge(i, j, "arc", radius=float(params[0]) * scale, large=bool(params[1]), right=bool(params[2]))
    if kind in ("quadratic", "cubic"):
        uv = _number(params, where, "curvature.params").reshape(-1, 2) if params else np.zeros((0, 2))
        if len(uv) != (1 if kind == "quadratic" else 2):
            raise PatternError(f"{where}: a {kind} curvature needs {1 if kind == 'quadratic' else 2} "
                               f"[u, v] control point(s), got {params!r}")
        a, b = v[i], v[j]
        d = b - a
        pts = a + uv[:, :1] * d + uv[:, 1:] * np.array([-d[1], d[0]])
        return Edge(i, j, "bezier", controls=tuple(map(tuple, pts.tolist())))
    raise PatternError(f"{where}: curvature {curv!r} is not supported; use a circle "
                       "({\"type\": \"circle\", \"params\": [radius, large_arc, right]}), a quadratic or a cubic "
                       "Bézier in relative coordinates, or a straight edge")


def _gc_stitch(spec, k, where):
    if not (isinstance(spec, list) and len(spec) in (2, 3)
            and all(isinstance(s, dict) and "panel" in s and "edge" in s for s in spec[:2])):
        raise PatternError(f"{where}: a stitch is [{{\"panel\": name, \"edge\": index}}, {{...}}] "
                           f"(optionally \"right_wrong\" third), got {spec!r}")
    if len(spec) == 3 and spec[2] != "right_wrong":
        raise PatternError(f"{where}: third entry {spec[2]!r}; only \"right_wrong\" is known")
    a, b = spec[0], spec[1]
    return Seam(str(a["panel"]), a["edge"], str(b["panel"]), b["edge"],
                orientation="aligned" if len(spec) == 3 else "reversed")


# -------------------------------------------------------------------------------------------- TOML
_TOP = {"units", "name", "panels", "seams"}
_PANEL = {"name", "vertices", "holes", "arcs", "grain", "translate", "rotate"}
_ARC = {"edge", "radius", "side", "large"}
_SEAM = {"a", "b", "orientation", "kind", "angle", "width"}


def read_toml(path, *, seam_tolerance=SEAM_LENGTH_TOLERANCE):
    """Read a TOML pattern (module docstring) into a :class:`Pattern` [SI]."""
    return parse_toml(_load(path, tomllib.load, "TOML"), source=str(path), seam_tolerance=seam_tolerance)


def _unknown(table, known, where):
    if not isinstance(table, dict):
        raise PatternError(f"{where}: expected a table with keys {', '.join(sorted(known))}, got {table!r}")
    extra = sorted(set(table) - known)
    if extra:
        raise PatternError(f"{where}: unknown key {extra[0]!r}; known keys: {', '.join(sorted(known))}")


def parse_toml(data, *, source="<toml>", seam_tolerance=SEAM_LENGTH_TOLERANCE):
    """A parsed TOML pattern ``data`` -> :class:`Pattern` [SI]."""
    _unknown(data, _TOP, source)
    units = data.get("units")
    if units not in LENGTH_UNITS:
        raise PatternError(f"{source}: units = {units!r}; give one of {', '.join(LENGTH_UNITS)}")
    scale = LENGTH_UNITS[units]
    panels = [_toml_panel(p, k, scale, source) for k, p in enumerate(data.get("panels", []))]
    seams = [_toml_seam(s, f"{source}: seams[{k}]", scale) for k, s in enumerate(data.get("seams", []))]
    return Pattern(panels=panels, seams=seams, units=units, source=source, seam_tolerance=seam_tolerance)


def _toml_panel(spec, k, scale, source):
    if not isinstance(spec, dict):
        raise PatternError(f"{source}: panels[{k}] = {spec!r}; each panel is a [[panels]] table")
    name = spec.get("name")
    where = f"{source}: panel {name!r}" if name else f"{source}: panels[{k}]"
    if not isinstance(name, str) or not name or ":" in name:
        raise PatternError(f"{where}: needs a name (a string without ':')")
    _unknown(spec, _PANEL, where)
    loops = [spec.get("vertices")] + list(spec.get("holes", []))
    verts, edges = [], []
    for j, raw in enumerate(loops):
        v = _number(raw, where, "vertices" if j == 0 else f"holes[{j - 1}]")
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 2:
            raise PatternError(f"{where}: {'vertices' if j == 0 else f'holes[{j - 1}]'} must be 2 or more [x, y] "
                               f"pairs (2 when both edges are arcs), got {raw!r}")
        first = sum(len(q) for q in verts)
        edges += [Edge(first + q, first + (q + 1) % len(v)) for q in range(len(v))]
        verts.append(v * scale)
    v = np.concatenate(verts)
    n = len(edges)
    for arc in spec.get("arcs", []):
        _unknown(arc, _ARC, f"{where}, arcs")
        j = arc.get("edge")
        if not (isinstance(j, int) and 0 <= j < n):
            raise PatternError(f"{where}, arcs: edge = {j!r}; give an edge index 0..{n - 1} "
                               "(edge k runs from vertex k to vertex k+1 of its loop)")
        side = arc.get("side")
        if side not in ("left", "right"):
            raise PatternError(f"{where}, edge {j}: arc side = {side!r}; give 'left' or 'right' "
                               "(the side of the chord vertex k -> k+1 the arc bulges to)")
        radius = arc.get("radius")
        if not (isinstance(radius, (int, float)) and radius > 0):
            raise PatternError(f"{where}, edge {j}: arc radius = {radius!r}; give a positive length "
                               "in the file's units")
        edges[j] = Edge(edges[j].start, edges[j].end, "arc", radius=float(radius) * scale,
                        large=bool(arc.get("large", False)), right=side == "right")
    return Panel(name=name, vertices=v, edges=edges, loops=[len(q) for q in verts], grain=_grain(spec, where),
                 translation=_vector(spec.get("translate", [0, 0, 0]), where, "translate") * scale,
                 rotation=_vector(spec.get("rotate", [0, 0, 0]), where, "rotate"))


def _toml_seam(spec, where, scale):
    _unknown(spec, _SEAM, where)
    refs = []
    for key in ("a", "b"):
        ref = spec.get(key)
        panel, _, edge = ref.rpartition(":") if isinstance(ref, str) else ("", "", "")
        if not panel or not edge.strip().isdigit():
            raise PatternError(f"{where}: {key} = {ref!r}; give \"panel:edge\", e.g. \"front:2\"")
        refs += [panel.strip(), int(edge)]
    kind = spec.get("kind", "sew")
    if kind != "fold" and ("angle" in spec or "width" in spec):
        raise PatternError(f"{where}: angle and width belong to a fold seam (kind = \"fold\"), not to kind {kind!r}; "
                           "remove them or make the seam a fold")
    width = spec.get("width")
    return Seam(*refs, orientation=spec.get("orientation", "reversed"), kind=kind, angle=spec.get("angle", 180.0),
                width=None if width is None else float(_number(width, where, "width")) * scale)
