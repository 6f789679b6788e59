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

What runs. The pattern is meshed with matching seam nodes (:func:`rftstatic.garment.meshing.mesh_pattern`,
size ``garment.h``) and placed; the form is written as ``body-m.obj`` [m] in the run folder and acts as a
``type = "mesh"`` obstacle (:class:`rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle`) with penalty
contact. The model's reference mesh must be flat: this version dresses patterns whose panels are placed in
one horizontal plane and carry no seams (the one-ring circle skirt, ``cases/skirt-circle.toml``), which
need no sewing stage; a pattern with seams, or panels out of that plane, is refused naming the pattern
(the sewing stage, issue 37 item 3, is not built yet). The static solve is the ``static`` analysis's
(:func:`rftstatic.app.static.run`) on this mesh, so the scene's ``[solver]``, ``[contact]``,
``[[supports]]`` (reference coordinates are the placed plane's x, y) and ``[loads]`` apply unchanged.
Contact is frictionless: the skirt hangs on the form's waist-to-hip flare, and its rotation about the
vertical axis (a zero-energy mode on a frictionless body of revolution) is held by a ``fixed``
``[[supports]]`` component at one waist node.

Measures added to ``summary.json`` (``garment``): the pattern's panels, seams (0 here, so the largest seam
gap before merging is 0 by construction), hem nodes (the outer boundary loop), the hem's drape coefficient
``A_shadow / A_flat``: the area of the draped skirt's vertical projection (:func:`rftstatic.post.measures.shadow.shadow_area`,
the waist opening not counted) over the flat skirt's area (the opening left out too). It is Cusick's
``(A_shadow - A_disc) / (A_sheet - A_disc)`` with the waist opening as the disc, when the draped skirt does
not overlap the projection of its own waist opening (it flares outwards from the waist); mean element size.
Outputs: ``deformed.vtu`` (cell data ``panel``), ``garment.obj`` with UVs (each node's flat pattern
coordinates, scene units), ``body.obj`` and ``body.vtu`` (scene units).
"""

from __future__ import annotations

import copy
import logging
from pathlib import Path

import numpy as np

from rftstatic.app import static
from rftstatic.garment.body import DressForm
from rftstatic.garment.meshing import mesh_pattern, place
from rftstatic.garment.readers import read_pattern
from rftstatic.io.files import to_jsonable, write_json, write_vtu
from rftstatic.mesh.trimesh import TriMesh
from rftstatic.post.measures.shadow import shadow_area

__all__ = ["run", "dressed_mesh", "dress_form", "write_obj", "read_obj_uv", "BODY_KEYS"]

log = logging.getLogger(__name__)

BODY_KEYS = ("bust_girth", "waist_girth", "hip_girth", "bust_height", "waist_height", "hip_height",
             "shoulder_breadth", "shoulder_height", "neck_girth", "neck_height", "neck_length", "bottom_height")
"""Length keys of ``[body]`` (scene units), passed to :class:`~rftstatic.garment.body.DressForm` in metres;
its depth / width ratios (``*_depth``) are passed as given."""
DEPTH_KEYS = ("bust_depth", "waist_depth", "hip_depth", "shoulder_depth", "neck_depth")
_PLANE_TOL = 1e-9  # [m]: panels placed in one horizontal plane


def dress_form(scene) -> DressForm:
    """The scene's ``[body]`` as a :class:`~rftstatic.garment.body.DressForm` (lengths in metres)."""
    body = scene.get("body")
    if not isinstance(body, dict) or body.get("kind", "dress-form") != "dress-form":
        raise scene.error("body", 'a garment scene needs [body] with kind = "dress-form" and its measurements')
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


def dressed_mesh(scene):
    """``(pmesh, mesh, uv)``: the meshed pattern, the flat reference mesh of the placed garment [m] (one
    horizontal plane, :class:`~rftstatic.mesh.trimesh.TriMesh` at its height) and the nodes' flat pattern
    coordinates ``uv (N, 2)`` [m]."""
    path = _pattern_path(scene)
    h = scene.get("garment.h")
    if not isinstance(h, (int, float)) or not h > 0:
        raise scene.error("garment.h", f"{h!r}: give the target element size (> 0, scene units)")
    pmesh = mesh_pattern(read_pattern(path), float(h) * scene.units.length)
    if pmesh.pattern.seams:
        raise scene.error("garment.pattern", f"{path.name} has {len(pmesh.pattern.seams)} seams; the sewing stage "
                          "is not built yet: this version dresses seamless one-plane patterns (a circle skirt's ring)")
    P = place(pmesh)
    world = np.stack([P[:, 0], -P[:, 2], P[:, 1]], axis=1)
    if np.ptp(world[:, 2]) > _PLANE_TOL:
        raise scene.error("garment.pattern", f"{path.name}: the panels are not placed in one horizontal plane "
                          f"(heights {world[:, 2].min():.4g} to {world[:, 2].max():.4g} m); place them flat "
                          "(e.g. rotate = [-90, 0, 0]) until the sewing stage is built")
    tri = np.concatenate([m.tri + pmesh.offsets[p] for p, m in enumerate(pmesh.meshes)])
    mesh = TriMesh(X=world[:, :2], tri=tri, z0=float(world[0, 2]), name=f"garment {path.stem}")
    uv = np.concatenate([m.X for m in pmesh.meshes])
    return pmesh, mesh, uv


def write_obj(path, x, tri, uv=None, header="") -> None:
    """Triangles ``tri (E, 3)`` on points ``x (N, 3)`` as an OBJ file; with ``uv (N, 2)`` one texture
    coordinate per node (``vt``, faces ``a/a``). Numbers with 9 significant digits."""
    with open(path, "w", encoding="utf-8") as fh:
        if header:
            fh.write(f"# {header}\n")
        fh.writelines(f"v {a:.9g} {b:.9g} {c:.9g}\n" for a, b, c in x)
        if uv is None:
            fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tri)
            return
        fh.writelines(f"vt {a:.9g} {b:.9g}\n" for a, b in uv)
        fh.writelines(f"f {a + 1}/{a + 1} {b + 1}/{b + 1} {c + 1}/{c + 1}\n" for a, b, c in tri)


def read_obj_uv(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x (N, 3), uv (N, 2), tri (E, 3))`` of an OBJ written by :func:`write_obj` with UVs."""
    v, vt, f = [], [], []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        part = line.split()
        if part and part[0] == "v":
            v.append([float(s) for s in part[1:4]])
        elif part and part[0] == "vt":
            vt.append([float(s) for s in part[1:3]])
        elif part and part[0] == "f":
            f.append([int(s.split("/")[0]) - 1 for s in part[1:4]])
    return np.array(v), np.array(vt), np.array(f, dtype=np.int64)


def _hem(mesh) -> np.ndarray:
    """Nodes of the longest boundary loop (the hem of a skirt) of ``mesh``."""
    edges = np.sort(np.concatenate([mesh.tri[:, [0, 1]], mesh.tri[:, [1, 2]], mesh.tri[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    boundary = uniq[count == 1]
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = mesh.n_nodes
    g = coo_matrix((np.ones(len(boundary)), (boundary[:, 0], boundary[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    nodes = np.unique(boundary)
    loops, sizes = np.unique(label[nodes], return_counts=True)
    r = np.linalg.norm(mesh.X[nodes] - mesh.X.mean(axis=0), axis=1)
    radius = {lab: r[label[nodes] == lab].mean() for lab in loops}
    outer = max(loops, key=lambda lab: radius[lab])
    return nodes[label[nodes] == outer]


def _garment_measures(scene, model, U, pmesh, hem) -> dict:
    """The ``garment`` table of the summary (scene units; module docstring)."""
    u = scene.units.length
    x = model.positions(U)
    flat = float(model.mesh.area.sum())
    shadow = shadow_area(x, model.mesh.tri)
    return {"pattern": Path(pmesh.pattern.source).name, "panels": len(pmesh.meshes),
            "seams": len(pmesh.pattern.seams), "largest_seam_gap": 0.0, "hem_nodes": int(len(hem)),
            "mean_element_size": float(model.mesh.element_size.mean()) / u, "flat_area": flat / u**2,
            "shadow_area": shadow / u**2, "hem_drape_coefficient": shadow / flat,
            "hem_lowest": float(x[hem, 2].min()) / u, "hem_highest": float(x[hem, 2].max()) / u}


def run(scene, out: Path, *, progress=True, figures=True):
    """Dress the scene's form with its garment (module docstring); write the outputs; return the
    :class:`~rftstatic.app.result.RunResult` (its summary with the ``garment`` measures)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    u = scene.units.length
    form = dress_form(scene)
    form.write_obj(out / "body-m.obj")  # the obstacle's surface [m]; body.obj is written in scene units
    pmesh, mesh, uv = dressed_mesh(scene)
    data = copy.deepcopy(scene.data)
    data.pop("garment")
    data.pop("body")
    data["analysis"] = "static"
    data.setdefault("obstacles", []).append({"type": "mesh", "path": str((out / "body-m.obj").resolve()),
                                              "units": "m"})
    solved = type(scene)(data, scene.path, scene.name, scene.overrides)
    result = static.run(solved, out, progress=progress, figures=figures, mesh=mesh)
    model, U = result.model, result.U
    hem = _hem(model.mesh)
    garment = _garment_measures(scene, model, U, pmesh, hem)
    summary = dict(result.summary)
    summary["analysis"] = "garment"
    summary["garment"] = to_jsonable(garment)
    panel = np.repeat(np.arange(len(pmesh.meshes)), [len(m.tri) for m in pmesh.meshes])
    write_vtu(out / "deformed.vtu", model.X3, U, model.mesh.tri, length_unit_scale=u,
              cell_data={"panel": panel.astype(float), "relative_curvature": model.relative_curvature(U)})
    write_obj(out / "garment.obj", model.positions(U) / u, model.mesh.tri, uv / u,
              header=f"dressed garment, {scene.units.name} lengths, vt = flat pattern coordinates")
    P, T = form.surface()
    write_obj(out / "body.obj", P / u, T, header=f"dress form, {scene.units.name} lengths")
    write_vtu(out / "body.vtu", P, np.zeros_like(P), T, length_unit_scale=u)
    write_json(out / "summary.json", summary)
    result.summary = summary
    log.info("garment: hem drape coefficient %.3f, %d hem nodes", garment["hem_drape_coefficient"], len(hem))
    return result
