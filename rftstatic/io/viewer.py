"""An interactive 3-D view of a run, ``view.html``: :func:`write_view` (``python -m rftstatic view RUN_DIR``).

One self-contained HTML file (plotly.js inline: it opens without a network) drawn from the run folder's files
alone, so it works on any past run:

* the sheet from ``deformed.vtu`` (a static, cantilever or remeshed run's final state), or every saved state
  of ``series.pvd`` (dynamic and relax runs) or ``meshes.pvd`` (remeshed runs: one state per mesh), with a
  slider over the states (at most :data:`MAX_FRAMES`, evenly picked, the last always);
* what the sheet rests on (:func:`rftstatic.io.solids.run_solids`: the obstacles and a tester's clamping disc
  of ``summary.json``'s ``resolved_scene``), translucent;
* coloured by a field (:data:`FIELDS`, on one colour scale over all states), with a colour bar that names the
  field and its unit, equal scales on the three axes (``aspectmode = "data"``), rotatable and zoomable.

Fields: ``relative_curvature`` (|kappa| h [-], the default), ``curvature`` (|kappa| [1/length]),
``displacement`` (|u| [length]), ``membrane_strain`` (the largest principal Green strain [-]), ``height``
(z [length]) and, with obstacles, ``gap`` (the distance to the nearest obstacle, its signed distance [length]);
only those the run's files hold are offered. A folder that is missing, has no ``summary.json`` or no VTU, or a
field it does not have, is a :class:`ViewError` that names it (the command's exit 2).

Lengths are in the scene's units, as in the files. plotly is imported when a view is built.
"""

from __future__ import annotations

import json
import logging
import os
import textwrap
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rftstatic.io.figure import LENGTH_UNITS

log = logging.getLogger(__name__)

__all__ = ["FIELDS", "MAX_FRAMES", "VIEW_FILE", "ViewError", "available_fields", "read_states", "write_view"]

VIEW_FILE = "view.html"
MAX_FRAMES = 40
"""Most states on the slider: each adds the sheet's positions and colours (about 40 kB for 2000 nodes)."""

DEFAULT_FIELD = "relative_curvature"


class ViewError(ValueError):
    """A run folder the viewer cannot draw: missing, without ``summary.json`` or VTU, or an unknown field."""


@dataclass(frozen=True)
class SavedState:
    """One state of the sheet as a VTU holds it [scene units]: ``label`` for the slider, deformed positions
    ``x (N, 3)``, triangles ``tri (E, 3)``, and the file's ``point_data`` and ``cell_data`` fields."""

    label: str
    x: np.ndarray
    tri: np.ndarray
    point_data: dict
    cell_data: dict


def _read_vtu(path: Path, label: str) -> SavedState:
    import meshio

    mesh = meshio.read(path)
    tri = np.concatenate([c.data for c in mesh.cells if c.type == "triangle"]).astype(np.int64)
    cells = {k: np.concatenate(v) for k, v in mesh.cell_data.items()}
    return SavedState(label, np.asarray(mesh.points, float), tri, dict(mesh.point_data), cells)


def _pvd_entries(pvd: Path) -> list[tuple[float, Path]]:
    """``(time, file)`` of every data set a PVD index lists."""
    root = ET.parse(pvd).getroot()
    return [(float(d.get("timestep", 0.0)), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def _pick(n: int, most: int) -> list[int]:
    """At most ``most`` indices of ``n`` states, evenly spread, the first and last included."""
    if n <= most:
        return list(range(n))
    return sorted(set(np.linspace(0, n - 1, most).round().astype(int).tolist()))


def read_states(run_dir: Path, *, most: int = MAX_FRAMES) -> list[SavedState]:
    """The sheet's saved states in ``run_dir``: a series (dynamic ``series.pvd``, remeshed ``meshes.pvd``) or the
    final ``deformed.vtu``; :class:`ViewError` when there is none."""
    for pvd, kind in (("series.pvd", "time"), ("meshes.pvd", "mesh")):
        if (run_dir / pvd).is_file():
            entries = _pvd_entries(run_dir / pvd)
            missing = [str(f) for _, f in entries if not f.is_file()]
            if missing:
                raise ViewError(f"{run_dir / pvd} lists files that are not there: {missing[:3]}")
            if kind == "mesh" and (run_dir / "deformed.vtu").is_file():
                entries[-1] = (entries[-1][0], run_dir / "deformed.vtu")   # the final state, with all its fields
            states = []
            for k in _pick(len(entries), most):
                t, f = entries[k]
                label = f"{t:.4g}" if kind == "time" else f"{k}"
                states.append(_read_vtu(f, label))
            if kind == "mesh":                                   # name each mesh by its node count
                states = [SavedState(f"{s.label} ({len(s.x)} nodes)", s.x, s.tri, s.point_data, s.cell_data)
                          for s in states]
            return states
    if (run_dir / "deformed.vtu").is_file():
        return [_read_vtu(run_dir / "deformed.vtu", "final")]
    raise ViewError(f"{run_dir} has no deformed.vtu, series.pvd or meshes.pvd: the run wrote no VTU "
                    "(output.vtu = false?); run it again with VTU output to view it")


def _obstacles(summary: dict) -> list:
    """The run's obstacles [scene units]; none when its summary's scene cannot be read back (a foreign version)."""
    from rftstatic.contact.obstacles import from_spec

    try:
        return [from_spec(spec, 1.0) for spec in (summary.get("resolved_scene") or {}).get("obstacles", []) or []]
    except (ValueError, TypeError, AttributeError) as exc:
        log.warning("the obstacles of summary.json's resolved_scene cannot be rebuilt (%s): they are not drawn", exc)
        return []


@dataclass(frozen=True)
class Field:
    """A colouring of the sheet: its label, unit (``"-"``, ``"L"`` a length, ``"1/L"``), where it lives
    (``"cell"`` or ``"point"``), what it needs (a ``point_data``/``cell_data`` name of the VTU, or ``"obstacles"``)
    and ``values(state, obstacles)``, (E,) or (N,)."""

    label: str
    unit: str
    where: str
    needs: str | None
    values: Callable[[SavedState, list], np.ndarray]


def _curvature_norm(state, _):
    from rftstatic.element.curvature import curvature_norm

    return curvature_norm(np.asarray(state.cell_data["curvature"], float))


def _largest_principal_strain(state, _):
    e = np.asarray(state.cell_data["membrane_strain"], float)      # (e_xx, e_yy, 2 e_xy)
    return 0.5 * (e[:, 0] + e[:, 1]) + np.hypot(0.5 * (e[:, 0] - e[:, 1]), 0.5 * e[:, 2])


FIELDS = {
    "relative_curvature": Field("relative curvature |kappa| h", "-", "cell", "relative_curvature",
                                lambda s, _: np.asarray(s.cell_data["relative_curvature"], float).ravel()),
    "curvature": Field("curvature |kappa|", "1/L", "cell", "curvature", _curvature_norm),
    "displacement": Field("displacement |u|", "L", "point", "displacement",
                          lambda s, _: np.linalg.norm(np.asarray(s.point_data["displacement"], float), axis=1)),
    "membrane_strain": Field("membrane strain (largest principal)", "-", "cell", "membrane_strain",
                             _largest_principal_strain),
    "height": Field("height z", "L", "point", None, lambda s, _: s.x[:, 2].copy()),
    "gap": Field("gap to the nearest obstacle", "L", "point", "obstacles",
                 lambda s, obs: np.min([ob.signed_distance(s.x)[0] for ob in obs], axis=0)),
}
"""The fields the view can colour the sheet by (``--field``), in the order the error lists them."""


def available_fields(state: SavedState, obstacles) -> list[str]:
    """The names of :data:`FIELDS` that ``state`` (and the run's ``obstacles``) can colour the sheet by."""
    have = {None, *state.point_data, *state.cell_data, *(["obstacles"] if obstacles else [])}
    return [name for name, f in FIELDS.items() if f.needs in have]


def _title(summary: dict) -> str:
    material = (summary.get("material") or {}).get("name", "")
    what = ", ".join(p for p in (f"fabric {material}" if material else "", summary.get("element", ""),
                                 f"{summary.get('nodes')} nodes" if summary.get("nodes") else "") if p)
    status = "" if summary.get("converged", True) else "NOT CONVERGED; "
    title = "<br>".join(textwrap.wrap(summary.get("title") or summary.get("scene", ""), 90)[:2])
    return f"{title}<br><sub>{status}{what}</sub>"


def _mesh_trace(state: SavedState, values: np.ndarray, field: Field, unit: str, clim, *, topology=True) -> dict:
    """A plotly ``mesh3d`` of ``state`` coloured by ``values`` (per triangle or per node) in ``clim``."""
    trace = {"type": "mesh3d", "x": state.x[:, 0].astype(np.float32), "y": state.x[:, 1].astype(np.float32),
             "z": state.x[:, 2].astype(np.float32), "intensity": values.astype(np.float32),
             "intensitymode": "cell" if field.where == "cell" else "vertex", "cmin": clim[0], "cmax": clim[1]}
    if topology:
        trace.update(i=state.tri[:, 0].astype(np.int32), j=state.tri[:, 1].astype(np.int32),
                     k=state.tri[:, 2].astype(np.int32), name="sheet", colorscale="Viridis", flatshading=True,
                     lighting={"ambient": 0.45, "diffuse": 0.75, "specular": 0.05, "roughness": 0.9},
                     colorbar={"title": {"text": f"{field.label} [{unit}]", "side": "right"}, "len": 0.8},
                     hovertemplate=f"{field.label}: %{{intensity:.4g}} {unit}<extra></extra>")
    return trace


def _unit(field: Field, length: str) -> str:
    return {"-": "-", "L": length or "length", "1/L": f"1/{length or 'length'}"}[field.unit]


def build_figure(run_dir: Path, summary: dict, field: str = DEFAULT_FIELD, *, most: int = MAX_FRAMES):
    """The plotly figure of the run in ``run_dir`` (:func:`write_view`)."""
    import plotly.graph_objects as go

    from rftstatic.io.solids import run_solids

    states = read_states(run_dir, most=most)
    obstacles = _obstacles(summary)
    fields = [f for f in available_fields(states[-1], obstacles)
              if all(f in available_fields(s, obstacles) for s in states[:-1])]
    if field not in fields:
        raise ViewError(f"field {field!r} is not in the run {run_dir}; its fields are {', '.join(fields)}")
    spec = FIELDS[field]
    unit = _unit(spec, LENGTH_UNITS.get(summary.get("units", ""), ""))
    values = [spec.values(s, obstacles) for s in states]
    finite = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(0)])
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    clim = (lo, hi if hi > lo else lo + 1.0)
    last = states[-1]
    x_ref = last.x - np.asarray(last.point_data.get("displacement", np.zeros_like(last.x)), float)
    every = np.concatenate([s.x for s in states])
    solids = run_solids(summary.get("resolved_scene"), x_ref, every, obstacles=obstacles)
    data = [_mesh_trace(last, values[-1], spec, unit, clim)]    # the final state first; the slider goes back
    for solid in solids:
        v, t = solid.vertices.astype(np.float32), solid.triangles.astype(np.int32)
        data.append({"type": "mesh3d", "x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "i": t[:, 0], "j": t[:, 1],
                     "k": t[:, 2], "color": "rgb(158,168,189)", "opacity": 0.35, "name": solid.name,
                     "hoverinfo": "name", "showscale": False, "flatshading": False})
    length = LENGTH_UNITS.get(summary.get("units", ""), "")
    axis = {f"{a}axis": {"title": {"text": f"{a} [{length}]" if length else a}} for a in "xyz"}
    layout = {"title": {"text": _title(summary), "x": 0.5}, "margin": {"l": 0, "r": 0, "t": 60, "b": 0},
              "scene": {"aspectmode": "data", "camera": {"eye": {"x": 1.1, "y": -1.95, "z": 1.3}}, **axis},
              "paper_bgcolor": "white", "showlegend": False}
    fig = go.Figure(data=data, layout=layout)
    if len(states) > 1:
        same = all(len(s.tri) == len(states[0].tri) and np.array_equal(s.tri, states[0].tri) for s in states)
        frames = [go.Frame(name=str(k), data=[_mesh_trace(s, v, spec, unit, clim, topology=not same)],
                           traces=[0]) for k, (s, v) in enumerate(zip(states, values))]
        fig.frames = frames
        animate = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}, "transition": {"duration": 0}}
        fig.update_layout(sliders=[{
            "active": len(states) - 1, "pad": {"t": 10},
            "currentvalue": {"prefix": "t = ", "suffix": " s"} if (run_dir / "series.pvd").is_file() else
                            {"prefix": "mesh "},
            "steps": [{"label": s.label, "method": "animate", "args": [[str(k)], animate]}
                      for k, s in enumerate(states)]}])
    return fig


def load_summary(run_dir) -> tuple[Path, dict]:
    """``(run_dir, summary)`` of a run folder; :class:`ViewError` naming what is missing."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ViewError(f"run folder {str(run_dir)!r} does not exist" if not run_dir.exists() else
                        f"{str(run_dir)!r} is not a folder: give a run's output folder")
    path = run_dir / "summary.json"
    if not path.is_file():
        raise ViewError(f"{str(run_dir)!r} has no summary.json: it is not a finished rftstatic run")
    try:
        return run_dir, json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ViewError(f"{path} is not valid JSON ({exc})") from None


def write_view(run_dir: str | os.PathLike, *, field: str | None = None, summary: dict | None = None,
               path: str | os.PathLike | None = None, most: int = MAX_FRAMES) -> Path:
    """Write the interactive view of the run in ``run_dir`` (module notes) and return its path.

    Parameters
    ----------
    run_dir : a run's output folder (``summary.json`` and its VTU files)
    field : the colouring, one of :data:`FIELDS` the run has (default ``relative_curvature``)
    summary : the run's summary when it is not yet written (a run writes ``summary.json`` last)
    path : the file to write (default ``run_dir/view.html``)
    most : the most states on the slider
    """
    from rftstatic.io.files import atomic_write

    if summary is None:
        run_dir, summary = load_summary(run_dir)
    run_dir = Path(run_dir)
    fig = build_figure(run_dir, summary, field or DEFAULT_FIELD, most=most)
    out = Path(path) if path is not None else run_dir / VIEW_FILE
    html = fig.to_html(include_plotlyjs=True, full_html=True, auto_play=False, default_height="96vh",
                       config={"displaylogo": False, "responsive": True})
    with atomic_write(out) as tmp:
        tmp.write_text(html, encoding="utf-8")
    return out
