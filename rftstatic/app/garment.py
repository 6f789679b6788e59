"""The ``garment`` analysis: a garment pattern dressed on a parametric dress form, solved to static equilibrium.

A scene of this kind names a pattern file and a dress form::

    analysis = "garment"
    [garment]
    pattern = "patterns/skirt-circle-ring.toml"   # GarmentCode JSON or rftstatic TOML, relative to the scene
    h = 1.5                                       # target element size [length]
    [body]
    kind = "dress-form"                           # rftstatic.garment.body.DressForm, measurements in scene units
    waist_girth = 66.0 ...

Frames. Patterns are placed in GarmentCode's frame (y up, z to the front); the form stands on the floor with
z up (heights above the floor, :mod:`rftstatic.garment.body`). A placed point ``(x, y, z)`` of the pattern
is the point ``(x, -z, y)`` here (a rotation by +90 deg about x, so the pattern's height is the form's).

What runs. The pattern is meshed with matching seam nodes (:func:`rftstatic.garment.meshing.mesh_pattern`, size
``garment.h``), placed (and checked: no two panels may cross or overlap at the start), and sewn in the two stages of
:mod:`rftstatic.garment.sewing`: the seams are pulled shut by seam springs in damped explicit runs on the form
without gravity (each run up to :data:`CLOSING_TIME`; a pattern whose seams do not close is an error naming the
gap), then each seam's two sides are merged into one node, so that the bending patches reach across the seams. Every
element keeps its panel's flat shape with the warp along the panel's grain line. The form is written as
``body-m.obj`` [m] in the run folder and acts as a ``type = "mesh"`` obstacle
(:class:`rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`) by penalty contact; the contact surface is the
form grown by :data:`CLEARANCE` times the sag of the garment's mean element edge on the form's most curved section,
so that the garment's flat triangles, whose corners rest on it, do not dip into the form between them, its facet
edges and its concave valleys smoothed (the implicit surface of its facets, :func:`contact_surface`). The static
solve is the ``static`` analysis's (:func:`rftstatic.app.static.run`) on the sewn mesh, from the closed state, so
the scene's ``[solver]``, ``[contact]``, ``[[supports]]`` and ``[loads]`` apply unchanged; a support's ``at = [x,
y]`` is a point of the plan view of the placed panels (the mesh's chart ``X``: its nearest node there). A pattern
without seams (the one-ring circle skirt) skips the closing. ``[contact] friction`` (Coulomb, garment on form)
acts in the closing's explicit runs (impulses) and in the static solve (lagged from the last state, stick anchors:
:mod:`rftstatic.contact.friction`); the scenes are frictionless: a skirt hangs on the form's waist-to-hip flare, and
a circle skirt's rotation about the vertical axis (a zero-energy mode on a frictionless body of revolution) is held
by a ``fixed`` ``[[supports]]`` component at one waist node.

Measures added to ``summary.json`` (``garment``): the pattern's panels and seams, the largest seam gap at the
start of the closing and when the seams were merged, the closing's simulated time, explicit steps and wall time,
the nodes removed by merging, hem nodes (the lowest boundary loop of the garment without the panels turned back at
``fold`` seams, so a turned-up hem's crease), the creases' distance from their rest angle (``crease_edges``,
``crease_off_rest_mean_deg``, ``crease_off_rest_max_deg``: :mod:`rftstatic.element.hinge`), the hem's folds (the
node count of :func:`rftstatic.post.measures.boundary.fold_count` on the outline seen from above, about the form's
axis, as for a Cusick specimen), the hem's drape coefficient
``A_shadow / A_flat``: the area of the draped skirt's vertical projection (:func:`rftstatic.post.measures.shadow.shadow_area`,
the waist opening not counted) over the flat skirt's area (the opening left out too). It is Cusick's
``(A_shadow - A_disc) / (A_sheet - A_disc)`` with the waist opening as the disc, when the draped skirt does
not overlap the projection of its own waist opening (it flares outwards from the waist); mean element size.
The independent crossing check of the garment against the form itself (``body.obj``, not the contact surface):
at the start of the static solve (an error if any pair crosses) and at its end, ``body_crossing_pairs`` and
``body_smallest_distance``, with ``contact_clearance`` and ``contact_smoothing`` (the smooth surface's support,
:func:`contact_surface`; the summary's ``obstacle_crossings`` are against the contact surface's triangles, whose
implicit surface the garment rests on: its flat triangles cut them by their sag).
Outputs: ``deformed.vtu`` (cell data ``panel``), ``garment.obj`` with UVs (each node's flat pattern
coordinates, scene units), ``body.obj`` and ``body.vtu`` (scene units).
"""

from __future__ import annotations

import copy
import logging
from pathlib import Path

import numpy as np

from rftstatic.app import static
from rftstatic.contact.obstacles.surface_mesh import SurfaceObstacle
from rftstatic.garment.body import DressForm
from rftstatic.garment.meshing import check_placement, mesh_pattern, place
from rftstatic.garment.sewing import (SEAM_STIFFNESS, ClosingResult, carry_closed, close_seams, fold_chains,
                                     panel_mesh, seam_pairs, sew, turned_back)
from rftstatic.garment.readers import read_pattern
from rftstatic.io.files import to_jsonable, write_json, write_vtu
from rftstatic.mesh.topology import edge_topology
from rftstatic.post.measures.boundary import boundary_loop, fold_count
from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
from rftstatic.post.measures.shadow import shadow_area

__all__ = ["run", "resume_scene", "dressed_mesh", "dress_form", "write_obj", "read_obj_uv", "BODY_KEYS"]

log = logging.getLogger(__name__)

BODY_KEYS = ("bust_girth", "waist_girth", "hip_girth", "bust_height", "waist_height", "hip_height",
             "shoulder_breadth", "shoulder_height", "neck_girth", "neck_height", "neck_length", "bottom_height")
"""Length keys of ``[body]`` (scene units), passed to :class:`~rftstatic.garment.body.DressForm` in metres;
its depth / width ratios (``*_depth``) are passed as given."""
DEPTH_KEYS = ("bust_depth", "waist_depth", "hip_depth", "shoulder_depth", "neck_depth")
CLOSING_TIME = 0.5
"""Longest run of the seam-closing stage [s] of simulated time, at each spring stiffness
(:func:`rftstatic.garment.sewing.close_seams`); a run stops as soon as the seams are closed."""
CLEARANCE = 1.5
"""The contact surface's distance outside the form over the sag of the garment's mean element edge on the
form's most curved section below the garment's highest point as placed (the shoulders for a dress,
:meth:`rftstatic.garment.body.DressForm.chord_clearance`) [-]: the garment's nodes
rest on that surface, so its flat triangles stay off the form itself (0 crossing pairs with ``body.obj``,
``garment.body_crossing_pairs``)."""
BODY_FEATURE_ANGLE = 100.0
"""The form's ``feature_angle`` [deg] as a mesh obstacle: above its sharpest edge (46 deg between the facets at the
shoulder points, where the sections stop widening), so the form has no sharp features (a body has none). With
edges as features, the feature contact (obstacle edges against garment edges, :mod:`rftstatic.contact.features`)
pumped energy into the closing runs: on a collar round the neck, with the rims of the form's former flat caps as
features, total energy 0.130 -> 1.12 J in 0.3 s undamped, against 0.130 -> 0.128 J without them."""
FORM_TESSELLATION = {"sections": 160, "around": 128}
"""The contact surface's rings and points per ring (:meth:`rftstatic.garment.body.DressForm.surface`): facets of
about 0.5 cm, so that the smooth surface's support (:data:`SMOOTH`) stays small against the form's curvature."""
SMOOTH = 2.5
"""Support radius of the contact surface's smooth implicit surface (``smooth`` of
:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`, :mod:`rftstatic.contact.obstacles.surface_smooth`)
in facet radii of :data:`FORM_TESSELLATION` [-] (the least the smooth surface takes). The triangles' own distance has a crease at every concave facet
edge (the waist's profile, the neck's fillet), where the contact normal jumps: a node resting in such a valley keeps
a force that no position balances, and Newton stalled on the garment meshes of 1.5 cm (the dress at 1.45 cm held a
neckline node on a jump of 1e-3 N, 30 times the tolerance); the smooth surface has none and an exact tangent."""
CLOSING_DAMPING = 8.0
"""Mass damping of the seam-closing stage [1/s], about critical for a garment's swing on a body
(2 sqrt(g / 0.5 m) = 8.9 /s)."""


def _sized(scene, body: dict) -> dict:
    """``[body]`` with the measurements of its ``size`` (:func:`rftstatic.references.body_sizes.size_chart`, converted
    to scene units) under the keys it does not give."""
    from rftstatic.references.body_sizes import size_chart

    size = body.get("size")
    chart = size_chart()
    if isinstance(size, bool) or not isinstance(size, (int, float)) or size not in chart:
        raise scene.error("body.size", f"{size!r}: not a size of the chart (the bust girth in cm: "
                          f"{', '.join(map(str, chart))}; rftstatic.references.body_sizes), or give the measurements")
    cm = 0.01 / scene.units.length
    row = {k: v * cm for k, v in chart[int(size)].items() if k in BODY_KEYS}
    row.update({k: v for k, v in chart[int(size)].items() if k in DEPTH_KEYS})
    return {**row, **{k: v for k, v in body.items() if k != "size"}}


def dress_form(scene) -> DressForm:
    """The scene's ``[body]`` as a :class:`~rftstatic.garment.body.DressForm` (lengths in metres): its measurements,
    or a ``size`` of the chart (:mod:`rftstatic.references.body_sizes`) with any measurement given overriding."""
    body = scene.get("body")
    if not isinstance(body, dict) or body.get("kind", "dress-form") != "dress-form":
        raise scene.error("body", 'a garment scene needs [body] with kind = "dress-form" and its measurements '
                          "(or a size)")
    if "size" in body:
        body = _sized(scene, body)
    u = scene.units.length
    args = {k: float(body[k]) * u for k in BODY_KEYS if k in body}
    args.update({k: float(body[k]) for k in DEPTH_KEYS if k in body})
    try:
        return DressForm(**args)
    except (TypeError, ValueError) as exc:
        raise scene.error("body", f"{exc}; give the measurements {', '.join(BODY_KEYS[:10])} in scene units") from None


def _pattern_path(scene) -> Path:
    name = scene.get("garment.pattern")
    if not isinstance(name, str):
        raise scene.error("garment.pattern", "give the pattern file (GarmentCode JSON or TOML), relative to the scene")
    path = Path(name) if scene.path is None else scene.path.parent / name
    if not path.is_file():
        raise scene.error("garment.pattern", f'"{name}" is not a file ({path})')
    return path


def _size(scene, key, default=None) -> float:
    h = scene.get(key, default)
    if not isinstance(h, (int, float)) or isinstance(h, bool) or not h > 0:
        raise scene.error(key, f"{h!r}: give an element size (> 0, scene units)")
    return float(h)


def dressed_mesh(scene, h=None):
    """``(pmesh, mesh, uv)``: the meshed pattern (element size ``h`` [scene units], default ``garment.h``), its
    panels placed around the form as one mesh with the panels apart (:func:`rftstatic.garment.sewing.panel_mesh`:
    each element flat in its panel with the warp along the grain, the placed positions its reference [m], the plan
    view its chart ``X``) and every node's flat pattern coordinates ``uv (N, 2)`` [m]."""
    path = _pattern_path(scene)
    h = _size(scene, "garment.h") if h is None else h
    pmesh = mesh_pattern(read_pattern(path), float(h) * scene.units.length)
    P = place(pmesh)
    world = np.stack([P[:, 0], -P[:, 2], P[:, 1]], axis=1)
    check_placement(pmesh, world)
    uv = np.concatenate([m.X for m in pmesh.meshes])
    return pmesh, panel_mesh(pmesh, world), uv


def write_obj(path, x, tri, uv=None, header="", uv_tri=None) -> None:
    """Triangles ``tri (E, 3)`` on points ``x (N, 3)`` as an OBJ file; with ``uv (M, 2)`` texture coordinates
    (``vt``), one per node (faces ``a/a``) or, with ``uv_tri (E, 3)``, the texture coordinate of each face corner
    (faces ``a/t``: a sewn node has one per panel). Numbers with 9 significant digits."""
    with open(path, "w", encoding="utf-8") as fh:
        if header:
            fh.write(f"# {header}\n")
        fh.writelines(f"v {a:.9g} {b:.9g} {c:.9g}\n" for a, b, c in x)
        if uv is None:
            fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tri)
            return
        fh.writelines(f"vt {a:.9g} {b:.9g}\n" for a, b in uv)
        corners = tri if uv_tri is None else uv_tri
        fh.writelines(f"f {a + 1}/{ta + 1} {b + 1}/{tb + 1} {c + 1}/{tc + 1}\n"
                      for (a, b, c), (ta, tb, tc) in zip(tri, corners))


def read_obj_uv(path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(x (N, 3), uv (M, 2), tri (E, 3), uv_tri (E, 3))`` of an OBJ written by :func:`write_obj` with UVs."""
    v, vt, f, ft = [], [], [], []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        part = line.split()
        if part and part[0] == "v":
            v.append([float(s) for s in part[1:4]])
        elif part and part[0] == "vt":
            vt.append([float(s) for s in part[1:3]])
        elif part and part[0] == "f":
            f.append([int(s.split("/")[0]) - 1 for s in part[1:4]])
            ft.append([int(s.split("/")[1]) - 1 for s in part[1:4]])
    return np.array(v), np.array(vt), np.array(f, dtype=np.int64), np.array(ft, dtype=np.int64)


def _hem(tri, x) -> np.ndarray:
    """Nodes of the hem of a skirt of triangles ``tri (E, 3)`` hanging at positions ``x (N, 3)`` [m]: the boundary
    loop lowest on average (a folded hem's crease, when ``tri`` leaves out the facing turned back,
    :func:`rftstatic.garment.sewing.turned_back`)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(x)
    topo = edge_topology(tri, n)
    e, k = np.nonzero(topo.is_boundary)
    boundary = np.stack([tri[e, (k + 1) % 3], tri[e, (k + 2) % 3]], axis=1)
    g = coo_matrix((np.ones(len(boundary)), (boundary[:, 0], boundary[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    nodes = np.unique(boundary)
    loops = np.unique(label[nodes])
    height = {lab: x[nodes[label[nodes] == lab], 2].mean() for lab in loops}
    lowest = min(loops, key=lambda lab: height[lab])
    return nodes[label[nodes] == lowest]


def hem_folds(mesh, x, tri=None) -> int | None:
    """The hem's folds of the garment ``mesh`` at positions ``x (N, 3)`` [m]: the node count of its outer boundary
    seen from above, about the form's axis (as a Cusick specimen's); None when it does not surround the axis.
    ``tri``: the garment's outer triangles (default all; :func:`_hem`)."""
    try:
        return fold_count(x, boundary_loop(mesh.tri if tri is None else tri, x), (0.0, 0.0)).count
    except ValueError:
        return None


def garment_h(scene) -> float:
    """The scene's ``garment.h`` [scene length]: the garment's target element size."""
    return _size(scene, "garment.h")


def _garment_measures(scene, model, U, pmesh, hem, closing, outer) -> dict:
    """The ``garment`` table of the summary (scene units; module docstring)."""
    u = scene.units.length
    x = model.positions(U)
    flat = float(model.mesh.area.sum())
    shadow = shadow_area(x, model.mesh.tri)
    sewing = {"largest_seam_gap": 0.0, "largest_seam_gap_start": 0.0, "closing_time": 0.0, "closing_steps": 0,
              "closing_wall_time": 0.0}
    if closing is not None:
        sewing = {"largest_seam_gap": closing.largest_gap / u, "largest_seam_gap_start": closing.largest_gap_start / u,
                  "closing_time": closing.time, "closing_steps": closing.steps, "closing_wall_time": closing.wall_time}
    folds = hem_folds(model.mesh, x, outer)
    creases = {}
    if model.hinges is not None:  # fold seams: how far the creases sit from their rest angle
        off = np.degrees(np.abs(model.hinges.excess(x)))
        creases = {"crease_edges": len(model.hinges), "crease_off_rest_mean_deg": float(off.mean()),
                   "crease_off_rest_max_deg": float(off.max())}
    return {"pattern": Path(pmesh.pattern.source).name, "panels": len(pmesh.meshes), "hem_folds": folds,
            "seams": len(pmesh.pattern.seams), **sewing, "hem_nodes": int(len(hem)),
            "nodes_sewn": int(model.mesh.info.get("sewn_from_nodes", model.mesh.n_nodes) - model.mesh.n_nodes),
            "mean_element_size": float(model.mesh.element_size.mean()) / u, "flat_area": flat / u**2,
            "shadow_area": shadow / u**2, "hem_drape_coefficient": shadow / flat,
            "hem_lowest": float(x[hem, 2].min()) / u, "hem_highest": float(x[hem, 2].max()) / u, **creases}


def _closing_scene(scene, data):
    """The seam-closing stage's scene: a dynamic run of the same garment on the same body, no gravity."""
    stage = copy.deepcopy(data)
    stage["analysis"] = "dynamic"
    stage["loads"] = {"gravity": False}
    stage.pop("solver", None)
    stage["dynamics"] = {"t_end": CLOSING_TIME, "alpha": CLOSING_DAMPING}
    return type(scene)(stage, scene.path, scene.name, scene.overrides)


def close(scene, data, mesh, pairs, *, progress=True, start_check=True):
    """Close the seams ``pairs (S, 2)`` of the panel ``mesh`` on the scene's body (stage 1 of
    :mod:`rftstatic.garment.sewing`): :class:`~rftstatic.garment.sewing.ClosingResult`. ``start_check``: refuse
    a start that cuts the contact surface (:func:`rftstatic.scenes.build.build_contact`)."""
    from rftstatic.model.model import Model
    from rftstatic.scenes.build import build_model

    stage = _closing_scene(scene, data)
    base, _ = build_model(stage, mesh=mesh, contact="penalty", quiet=True, start_check=start_check)
    Dm = base.material.Dm

    def build(springs):
        return Model(mesh, base.material, element=base.element, supports=base.supports, contact=base.contact,
                     load_terms=(springs,), self_contact=base.self_contact, kernels=base.kernels, quiet=True)

    weight = base.material.weight * float(mesh.area.sum())
    return close_seams(build, pairs, (), weight=weight,
                       stiffest=SEAM_STIFFNESS * min(Dm[0, 0], Dm[1, 1]), t_stage=CLOSING_TIME,
                       alpha=CLOSING_DAMPING, progress=progress)


def contact_surface(form: DressForm, path, mesh, unit: float) -> dict:
    """Write the form's contact surface for the garment ``mesh`` (placed) to ``path`` (an OBJ in metres) and return
    its mesh-obstacle table (``smooth`` in scene lengths, ``unit`` [m] each): the form grown by the
    :data:`CLEARANCE` over the chord sag of the mesh's mean element on the form's most curved section below the
    garment's top, tessellated finely (:data:`FORM_TESSELLATION`), its smooth implicit surface (:data:`SMOOTH`);
    ``clearance`` and ``smooth_m`` [m] added for the summary."""
    clearance = CLEARANCE * form.chord_clearance(float(mesh.element_size.mean()), float(mesh.X3[:, 2].max()))
    P, T = form.surface(clearance=clearance, **FORM_TESSELLATION)
    smooth = SMOOTH * float(np.max(np.linalg.norm(P[T] - P[T].mean(axis=1, keepdims=True), axis=2)))  # facet radii
    write_obj(path, P, T, header="dress form grown by the contact clearance, metres (rftstatic.app.garment)")
    return {"type": "mesh", "path": str(Path(path).resolve()), "units": "m", "smooth": smooth / unit,
            "feature_angle": BODY_FEATURE_ANGLE, "clearance": clearance, "smooth_m": smooth}


def _with_body(data, body) -> dict:
    """A copy of the scene's table ``data`` with the form's contact surface ``body`` (:func:`contact_surface`) as a
    mesh obstacle."""
    data = copy.deepcopy(data)
    data.setdefault("obstacles", []).append({k: v for k, v in body.items() if k not in ("clearance", "smooth_m")})
    return data


def static_data(scene, body) -> dict:
    """The garment scene's table as a ``static`` drape's: without ``[garment]`` and ``[body]``, the form's contact
    surface ``body`` (:func:`contact_surface`) a mesh obstacle."""
    data = copy.deepcopy(scene.data)
    data.pop("garment")
    data.pop("body")
    data["analysis"] = "static"
    return _with_body(data, body)


def _closing_levels(scene, data, out, form, pmesh, mesh, pairs, *, progress=True):
    """The closing (stage 1 of :mod:`rftstatic.garment.sewing`), on a coarser mesh first when ``garment.closing_h``
    is larger than ``garment.h``: ``(mesh, closing, levels)``, the garment's panel mesh (placed at the carried
    closed positions after a coarse closing), the :class:`~rftstatic.garment.sewing.ClosingResult` of the whole
    closing (times and steps of both levels added) and one summary row per level."""
    h = _size(scene, "garment.h")
    h_close = _size(scene, "garment.closing_h", h)
    levels, coarse = [], None
    if h_close > h:
        cp, cmesh, _ = dressed_mesh(scene, h_close)
        coarse_body = contact_surface(form, out / "body-closing-m.obj", cmesh, scene.units.length)
        coarse = close(scene, _with_body(data, coarse_body), cmesh, seam_pairs(cp), progress=progress)
        levels.append(_level_row(scene, h_close, cmesh, coarse))
        # the carried nodes lie on the coarse patches, which may dip below the fine contact surface where the form
        # is most curved (a shoulder): such nodes are moved out onto it, then checked against the form itself
        body = data["obstacles"][-1]
        surface = SurfaceObstacle(body["path"], units="m", smooth=body["smooth"] * scene.units.length,
                                  feature_angle=BODY_FEATURE_ANGLE)
        mesh = panel_mesh(pmesh, surface.project(carry_closed(cp, coarse.x, pmesh)))
        _check_off_form(scene, form.surface(), mesh, f"carried from the closing on the {h_close:g} mesh (garment.closing_h)")
    # (a carried start's triangles cut the contact surface by their sag, as the static stage's do: start_check off)
    closing = close(scene, data, mesh, pairs, progress=progress, start_check=coarse is None)
    levels.append(_level_row(scene, h, mesh, closing))
    if coarse is not None:
        closing = ClosingResult(x=closing.x, largest_gap_start=coarse.largest_gap_start,
                                largest_gap=closing.largest_gap, time=coarse.time + closing.time,
                                steps=coarse.steps + closing.steps, wall_time=coarse.wall_time + closing.wall_time,
                                closed=closing.closed)
    return mesh, closing, levels


def _check_off_form(scene, surface, mesh, what) -> None:
    """Refuse a garment ``mesh`` whose placed positions cross the form itself (the independent triangle-pair test of
    :func:`rftstatic.post.measures.obstacle_crossings.obstacle_crossings` against the form's ``surface = (P, T)``)."""
    P, T = surface
    start = obstacle_crossings(mesh.X3, mesh.tri, P, T)
    if start["pairs"]:
        u = scene.units.length
        raise scene.error("garment.pattern", f"the garment {what} crosses the form ({start['pairs']} triangle pairs, "
                          f"the first at {np.round(np.asarray(start['first_at']) / u, 3).tolist()}): place the panels "
                          "off the form, or close on a finer mesh (garment.closing_h)")


def _level_row(scene, h, mesh, closing) -> dict:
    u = scene.units.length
    return {"h": h, "nodes": mesh.n_nodes, "elements": mesh.n_elements,
            "mean_element_size": float(mesh.element_size.mean()) / u,
            "largest_seam_gap_start": closing.largest_gap_start / u, "largest_seam_gap": closing.largest_gap / u,
            "time": closing.time, "steps": closing.steps, "wall_time": closing.wall_time}


def run(scene, out: Path, *, progress=True, figures=True, resume=False):
    """Dress the scene's form with its garment (module docstring); write the outputs; return the
    :class:`~rftstatic.app.result.RunResult` (its summary with the ``garment`` measures). ``resume``: the static
    solve continues from ``out/checkpoint.npz`` (:func:`rftstatic.app.static.run`); the mesh, the contact surface
    and the seams' closing before it are made again (they are the same for the same scene)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    u = scene.units.length
    form = dress_form(scene)
    pmesh, mesh, uv = dressed_mesh(scene)
    # the contact surface [m]: the form grown by the sag of the garment's mean edge (body.obj: the form itself)
    table = contact_surface(form, out / "body-m.obj", mesh, u)
    clearance = table["clearance"]
    data = static_data(scene, table)
    pairs = seam_pairs(pmesh)
    closing, corner_uv, levels = None, mesh.tri, []
    if len(pairs):
        mesh, closing, levels = _closing_levels(scene, data, out, form, pmesh, mesh, pairs, progress=progress)
        if not closing.closed:
            raise scene.error("garment.pattern", f"the seams did not close in {closing.time:.3g} s: the largest gap is "
                              f"{closing.largest_gap / u:.3g} {scene.units.name.split('-')[0]} (from "
                              f"{closing.largest_gap_start / u:.3g}); place the panels closer to their seams "
                              "or check that the body does not hold them apart (the contact surface lies "
                              f"{clearance / u:.3g} {scene.units.name.split('-')[0]} outside the form at this mesh "
                              "size: a finer garment.h brings it closer)")
        mesh, _ = sew(mesh, pairs, closing.x, where=Path(pmesh.pattern.source).name, folds=fold_chains(pmesh))
    P, T = form.surface()
    _check_off_form(scene, (P, T), mesh, "as placed and sewn")
    solved = type(scene)(data, scene.path, scene.name, scene.overrides)
    # the start is checked against the form itself above: the contact surface, grown by the clearance, is cut by
    # the garment's flat triangles between their nodes by up to their sag (which the clearance is for)
    result = static.run(solved, out, progress=progress, figures=figures, resume=resume, mesh=mesh, start_check=False)
    model, U = result.model, result.U
    outer = model.mesh.tri[~turned_back(pmesh)]  # a hem's facing turned back inside is not the garment's outline
    hem = _hem(outer, model.positions(U))
    garment = _garment_measures(scene, model, U, pmesh, hem, closing, outer)
    body = obstacle_crossings(model.positions(U), model.mesh.tri, P, T)
    garment.update({"contact_clearance": clearance / u, "contact_smoothing": table["smooth_m"] / u,
                    "body_crossing_pairs": body["pairs"], "closing_levels": levels,
                    "body_smallest_distance": body["smallest_distance"] / u})
    summary = dict(result.summary)
    summary["analysis"] = "garment"
    summary["garment"] = to_jsonable(garment)
    panel = np.repeat(np.arange(len(pmesh.meshes)), [len(m.tri) for m in pmesh.meshes])
    write_vtu(out / "deformed.vtu", model.X3, U, model.mesh.tri, length_unit_scale=u,
              cell_data={"panel": panel.astype(float), "relative_curvature": model.relative_curvature(U)})
    write_obj(out / "garment.obj", model.positions(U) / u, model.mesh.tri, uv / u, uv_tri=corner_uv,
              header=f"dressed garment, {scene.units.name} lengths, vt = flat pattern coordinates")
    write_obj(out / "body.obj", P / u, T, header=f"dress form, {scene.units.name} lengths")
    write_vtu(out / "body.vtu", P, np.zeros_like(P), T, length_unit_scale=u)
    write_json(out / "summary.json", summary)
    result.summary = summary
    log.info("garment: hem drape coefficient %.3f, %d hem nodes", garment["hem_drape_coefficient"], len(hem))
    return result


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Continue the garment run of ``scene`` from ``out_dir/checkpoint.npz`` (``case NAME --resume``): the sewing
    is done again, the static solve goes on from its checkpoint (:func:`run`)."""
    return run(scene, Path(out_dir), progress=progress, figures=figures, resume=True).summary
