"""From a validated scene (scene units) to a :class:`~rftstatic.model.model.Model` (SI units).

Everything a scene names in reference coordinates -- supports, loads, probes, obstacles -- is
located on the mesh here, so that it carries over to any other mesh of the same sheet.
"""

from __future__ import annotations

import math

import numpy as np

from rftstatic.compiled import choose_kernels
from rftstatic.errors import PatchError
from rftstatic.model.model import Model, Supports, edge_load, gravity_load
from rftstatic.post.measures.disc import clamp_disc
from rftstatic.scenes.drive import support_velocities
from rftstatic.scenes.material import build_material
from rftstatic.scenes.friction import contact_friction
from rftstatic.scenes.obstacle_checks import check_surface_obstacles
from rftstatic.scenes.options import contact_options, declared_run_options, static_options
from rftstatic.scenes.ranges import (
    check_mesh_table,
    check_obstacle_sizes,
    check_position,
    check_thickness,
    check_weight,
    sheet_size,
)
from rftstatic.scenes.motion import has_motion, obstacle_motion
from rftstatic.scenes.mesh_build import MAX_MESH_NODES, MESH_KEYS, build_mesh  # noqa: F401 (re-exported)
from rftstatic.scenes.schema import Scene
from rftstatic.scenes.release import release_support
from rftstatic.scenes.self_contact import build_self_contact

def select_nodes(scene: Scene, mesh, spec: dict, key: str) -> np.ndarray:
    """Nodes named by a ``box`` or ``at`` entry of a scene table (reference coordinates)."""
    u = scene.units.length
    given = [k for k in ("box", "at", "radius") if k in spec]
    if len(given) > 1:
        raise scene.error(f"{key}.{given[1]}", f"give box, at or radius (one of them), not {' and '.join(given)}")
    if "radius" in spec:
        return _within_radius(scene, mesh, spec, key)
    if "box" in spec:
        box = spec["box"]
        if not (isinstance(box, list) and len(box) == 4):
            raise scene.error(f"{key}.box", f"expected [xmin, xmax, ymin, ymax], got {box!r}")
        nodes = mesh.nodes_in_box(*(b * u for b in box))
    elif "at" in spec:
        pts = np.atleast_2d(np.asarray(spec["at"], float))
        if pts.shape[1] != 2:
            raise scene.error(f"{key}.at", f"expected [[x, y], ...], got {spec['at']!r}")
        check_on_sheet(scene, mesh, pts * u, f"{key}.at")
        nodes = np.unique(mesh.nearest_node(pts * u))
    else:
        raise scene.error(key, "needs a box = [xmin, xmax, ymin, ymax] or at = [[x, y], ...]")
    if len(nodes) == 0:
        raise scene.error(f"{key}.box", f"{spec['box']} contains no node of the mesh; check the coordinates "
                          f"(scene units, reference configuration)")
    return nodes


def _within_radius(scene: Scene, mesh, spec: dict, key: str) -> np.ndarray:
    """Nodes within ``radius`` of ``centre`` (reference coordinates): a tester's clamping disc. Scene error
    when the radius is not positive, holds no node, or holds them all (the specimen is not larger than the
    disc)."""
    u = scene.units.length
    radius, centre = spec["radius"], spec.get("centre", [0.0, 0.0])
    if not radius > 0:
        raise scene.error(f"{key}.radius", f"{radius!r} must be > 0 (the clamping disc's radius, scene length units)")
    middle = 0.5 * (mesh.X.min(axis=0) + mesh.X.max(axis=0)) / u
    check_position(scene, f"{key}.centre", centre, [*middle, 0.0], sheet_size(mesh) / u, "the sheet's centre")
    r = np.linalg.norm(mesh.X - np.asarray(centre, float) * u, axis=1)
    nodes = np.flatnonzero(r <= radius * u * (1.0 + 1e-9))
    if len(nodes) == 0:
        raise scene.error(f"{key}.radius", f"{radius!r} holds no node of the mesh within it about centre {centre}")
    if len(nodes) == mesh.n_nodes:
        raise scene.error(f"{key}.radius", f"{radius!r} holds the whole specimen (it reaches {r.max() / u:g} from "
                          f"centre {centre}, scene length units): the specimen must be larger than the clamping disc")
    return nodes


def check_on_sheet(scene: Scene, mesh, pts: np.ndarray, key: str) -> None:
    """Scene error unless every reference point ``pts (P, 2)`` [m] lies on the sheet: inside an element,
    or within half the largest element size of a node (a boundary point the point location misses)."""
    margin = 0.5 * float(mesh.element_size.max())
    lo, hi = mesh.X.min(axis=0), mesh.X.max(axis=0)
    beyond = np.any((pts < lo - margin) | (pts > hi + margin), axis=1)  # before locate: 1e300 overflows there
    if beyond.any():
        far_points = pts[beyond]
    elif not mesh.chart_is_flat:  # a sewn garment: its chart is the panels' plan view; near a node there
        d = np.linalg.norm(mesh.X[mesh.nearest_node(pts)] - pts, axis=1)
        far_points = pts[d > margin]
    else:
        elem, _ = mesh.locate(pts)
        off = elem < 0
        d = np.linalg.norm(mesh.X[mesh.nearest_node(pts[off])] - pts[off], axis=1) if off.any() else np.zeros(0)
        far_points = pts[off][d > margin]
    if len(far_points):
        u = scene.units.length
        p, lo, hi = far_points[0] / u, lo / u, hi / u
        raise scene.error(key, f"[{p[0]:g}, {p[1]:g}] is not on the sheet (reference coordinates, scene "
                          f"units; the sheet spans x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g})")


def build_supports(scene: Scene, mesh) -> Supports:
    clamped, pinned = [], []
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    for i, spec in enumerate(scene.get("supports", [])):
        key = f"supports.{i}"
        nodes = select_nodes(scene, mesh, spec, key)
        kind = spec.get("kind", "pinned")
        if kind == "clamped":
            clamped.append(nodes)
        elif kind == "pinned":
            pinned.append(nodes)
        elif kind == "fixed":
            comps = spec.get("components", "xyz")
            if not comps or set(comps) - set("xyz"):
                raise scene.error(f"{key}.components", f'"{comps}" must be letters of "xyz"')
            for c in comps:
                fixed[nodes, "xyz".index(c)] = True
        else:
            raise scene.error(f"{key}.kind", f'"{kind}" is not a support kind; use clamped, pinned or fixed')
    cat = lambda a: np.unique(np.concatenate(a)) if a else np.zeros(0, dtype=np.int64)  # noqa: E731
    return Supports(cat(clamped), cat(pinned), fixed, support_velocities(scene, mesh, select_nodes))


def build_load(scene: Scene, mesh, material) -> np.ndarray:
    units = scene.units
    loads = scene.get("loads", {"gravity": True})
    P = np.zeros((mesh.n_nodes, 3))
    if loads.get("gravity", False):
        w = gravity_load(mesh, material.weight)
        tilt = float(loads.get("gravity_tilt", 0.0))
        if not (math.isfinite(tilt) and -90.0 < tilt < 90.0):
            raise scene.error("loads.gravity_tilt", f"must be an angle in (-90, 90) degrees, got {tilt!r}")
        th = math.radians(tilt)
        P[:, 0] -= w[:, 2] * math.sin(th)  # downhill along +x in the inclined plane's frame
        P[:, 2] += w[:, 2] * math.cos(th)
    if "pressure" in loads:
        P += gravity_load(mesh, units.to_si(loads["pressure"], "pressure"))
    for i, spec in enumerate(loads.get("point", [])):
        f = np.asarray(spec.get("force", [0, 0, 0]), float)
        if f.shape != (3,):
            raise scene.error(f"loads.point.{i}.force", f"expected [fx, fy, fz], got {spec.get('force')!r}")
        nodes = select_nodes(scene, mesh, spec, f"loads.point.{i}")
        P[nodes] += units.to_si(f, "force") / len(nodes)
    for i, spec in enumerate(loads.get("edge", [])):
        q = np.asarray(spec.get("force_per_length", [0, 0, 0]), float)
        if q.shape != (3,):
            raise scene.error(f"loads.edge.{i}.force_per_length", f"expected [fx, fy, fz], got {q!r}")
        nodes = select_nodes(scene, mesh, spec, f"loads.edge.{i}")
        inside = np.zeros(mesh.n_nodes, bool)
        inside[nodes] = True
        edges = mesh.boundary_edges[inside[mesh.boundary_edges].all(axis=1)]
        if len(edges) == 0:
            raise scene.error(f"loads.edge.{i}.box", "contains no boundary edge")
        P += edge_load(mesh, edges, units.to_si(q, "line_force"))
    return P


CONTACT_LAWS = ("penalty", "kinematic")
"""How obstacles act: the static solver's penalty (an energy) or the explicit solver's kinematic projection."""


def contact_law(scene: Scene) -> str:
    """The contact law the scene's analysis uses: ``"penalty"`` for static, ``"kinematic"`` for dynamic/relax; a
    dynamic scene with a moving obstacle (:mod:`rftstatic.scenes.motion`) uses the penalty, which evaluates it in
    its pose."""
    return "penalty" if scene.analysis == "static" or (scene.analysis == "dynamic" and has_motion(scene)) else \
        "kinematic"


def build_obstacles(scene: Scene) -> list:
    """The scene's obstacles in SI (:func:`rftstatic.contact.obstacles.from_spec`)."""
    from rftstatic.contact.obstacles import from_spec

    obstacles = []
    for i, spec in enumerate(scene.get("obstacles", [])):
        try:
            obstacles.append(from_spec(spec, scene.units.length,
                                       base_dir=None if scene.path is None else scene.path.parent))
        except ValueError as exc:
            raise scene.error(f"obstacles.{i}", str(exc)) from None
    return obstacles


def build_contact(scene: Scene, mesh, material, supports: Supports, *, law: str = "penalty", start_check: bool = True):
    """The obstacles and, for ``law = "penalty"``, the penalty contact (None without obstacles, or for the
    kinematic law); ``start_check``: refuse a surface obstacle that cuts the sheet at the start
    (:func:`~rftstatic.scenes.obstacle_checks.check_surface_obstacles`; off for a stage that starts where an
    earlier one of the same run ended, a sewn garment's). May add the in-plane holds of a sheet on a frictionless support to ``supports``:
    the static drape (penalty) and dynamic relaxation (a kinematic run of a ``relax`` scene) seek a rest
    state and keep them (unless ``contact.hold_inplane = false``), or a slightly asymmetric sheet creeps
    and spins on the support; a true dynamic run does not."""
    if law not in CONTACT_LAWS:
        raise ValueError(f'contact law "{law}" is unknown; use one of {", ".join(CONTACT_LAWS)}')
    check_obstacle_positions(scene, mesh)
    check_obstacle_sizes(scene, mesh, OBSTACLE_POSITION_KEYS)
    obstacles = build_obstacles(scene)
    support = release_support(scene, mesh, law)  # the release route's support: the law's last obstacle
    if not obstacles and not support:
        return None, []
    if start_check:
        check_surface_obstacles(scene, mesh, obstacles, law)
    motion = obstacle_motion(scene, len(obstacles) + len(support))  # keyframes: a scene error outside dynamic runs
    c = contact_options(scene)
    friction = contact_friction(scene, c, len(obstacles), mesh)
    hold = c.hold_inplane if c.hold_inplane is not None else friction is None
    if law == "kinematic":
        if hold and scene.analysis == "relax":
            hold_inplane_rigid_modes(mesh, supports)
        return None, obstacles
    from rftstatic.contact.penalty import PenaltyContact, auto_penalty

    h = float(mesh.element_size.mean())
    k = c.penalty
    if k is None:
        k = auto_penalty(membrane_rigidity=material.membrane_scale, bending_rigidity=material.bending_scale,
                         weight=max(material.weight, 1e-300), h=h, factor=c.factor)
    if hold and motion is None:  # a moving body drives the sheet: its rigid modes are the motion's to take
        hold_inplane_rigid_modes(mesh, supports)
    return PenaltyContact(obstacles + support, mesh.node_area, k, smoothing=c.smoothing * h, sheet=mesh,
                          friction=friction, motion=motion), obstacles


OBSTACLE_POSITION_KEYS = {"centre": "xyz", "top": "z", "height": "z", "translate": "xyz"}
"""``[[obstacles]]`` keys that place an obstacle, and the axes of their numbers."""

MAX_OBSTACLE_DISTANCE = 1000.0
"""Farthest an obstacle may be placed from the sheet, in sheet sizes: further away it cannot touch the sheet
in any run, and its distances overflow (``top = -1e300``: RuntimeWarnings in every contact evaluation)."""


def check_obstacle_positions(scene: Scene, mesh) -> None:
    """Scene error unless every obstacle's ``centre``, ``top`` and ``height`` lies within
    :data:`MAX_OBSTACLE_DISTANCE` sheet sizes (the largest side of its reference mesh) of the sheet's centre."""
    u = scene.units.length
    lo, hi = mesh.X3.min(axis=0) / u, mesh.X3.max(axis=0) / u
    centre, size = 0.5 * (lo + hi), max(float((hi - lo).max()), 1e-300)
    bound = MAX_OBSTACLE_DISTANCE * size
    for i, spec in enumerate(scene.get("obstacles", [])):
        for key, axes in OBSTACLE_POSITION_KEYS.items():
            value = spec.get(key) if isinstance(spec, dict) else None
            numbers = value if isinstance(value, list) else [value]
            for axis, v in zip(axes, numbers):
                if isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v - centre["xyz".index(axis)]) > bound:
                    raise scene.error(f"obstacles.{i}.{key}", f"{value!r} places the obstacle more than "
                                      f"{MAX_OBSTACLE_DISTANCE:g} sheet sizes ({bound:g} scene length units) from the "
                                      f"sheet (centre {axis} = {centre['xyz'.index(axis)]:g}); give a position near the "
                                      "sheet")


def hold_inplane_rigid_modes(mesh, supports: Supports) -> None:
    """Remove the in-plane rigid modes of a sheet on a frictionless support (docs/theory/contact.md).

    The node nearest the sheet's centre is held in x and y (translations) and the node nearest
    the point one quarter of the sheet's width along +x from it is held in y (spin about z).
    Nothing is added when the supports already hold the sheet in its plane.
    """
    if supports.fixed_mask()[:, :2].any():
        return
    centre = 0.5 * (mesh.X.min(axis=0) + mesh.X.max(axis=0))
    c = int(mesh.nearest_node([centre])[0])
    reach = 0.25 * float(np.ptp(mesh.X[:, 0]))
    a = int(mesh.nearest_node([centre + [reach, 0.0]])[0])
    supports.fixed[c, 0] = supports.fixed[c, 1] = True
    supports.fixed[a, 1] = True


def check_static_scene(scene: Scene, material, supports: Supports, load: np.ndarray, obstacles: list) -> None:
    """Scene error unless a static scene can have an equilibrium and its route can run: without obstacles,
    every direction its load ``(N, 3)`` [N] pushes the sheet along is held by a support; the relaxation
    start (``solver.start = "relax"``) needs the sheet's mass."""
    if scene.get("solver.start") == "relax" and not material.mass_per_area > 0:
        raise scene.error("solver.start", '"relax" (dynamic relaxation) moves the sheet\'s mass, and material.weight '
                          'is 0; give a positive weight or use start = "load-steps"')
    if obstacles:
        return
    held = supports.fixed_mask().any(axis=0)
    resultant = load.sum(axis=0)
    scale = float(np.abs(load).sum())
    for i, axis in enumerate("xyz"):
        if abs(resultant[i]) > 1e-9 * scale and not held[i]:
            force = resultant[i] / scene.units.force
            raise scene.error("supports", f"nothing holds the sheet along {axis}, and its load pushes it that way "
                              f"(resultant {force:.4g}, {scene.units.name} units): no static equilibrium; add "
                              f"[[supports]] that hold {axis} (clamped, pinned, or fixed with {axis} in "
                              "components) or an obstacle")


def run_kernels(scene: Scene, mesh) -> str:
    """The kernel back end of the scene's run on ``mesh`` (:func:`rftstatic.compiled.choose_kernels`): the
    scene's ``kernels`` when it is ``"numpy"`` or ``"compiled"``, else by the mesh's size, self-contact and
    the length of the route (an explicit or relaxation run, or arc-length path following, evaluates the
    model thousands of times). A function of the scene alone."""
    requested = scene.get("kernels", "auto")
    long_run = scene.analysis in ("dynamic", "relax") or (
        scene.analysis == "static" and static_options(scene, progress=False).increments.continuation == "arc-length")
    try:
        return choose_kernels(mesh.n_elements, self_contact=contact_options(scene).self, long_run=long_run,
                              requested=None if requested == "auto" else requested)
    except ValueError as exc:
        raise scene.error("kernels", f'"{requested}": {exc}') from None


def build_model(scene: Scene, mesh=None, *, contact: str | None = None, quiet: bool = False,
                membrane_scale: float = 1.0, start_check: bool = True) -> tuple[Model, dict]:
    """The model of a scene (optionally on another ``mesh`` of the same sheet) and its extras.

    ``contact``: how the obstacles act, ``"penalty"`` (in the model's energy) or ``"kinematic"`` (by the
    explicit solver; the model has no contact term); default :func:`contact_law` of the scene's analysis.
    ``quiet``: the model's warnings at debug level (a remeshed run warns for its first mesh only).
    ``membrane_scale``: the fabric's membrane rigidity multiplied by this factor, before the contact and
    self-contact stiffnesses are derived from it (a coarse level of mesh sequencing matched to the finest
    mesh's locking number, :mod:`rftstatic.app.levels`); 1: the scene's fabric.
    ``start_check``: :func:`build_contact`'s.
    ``extras``: ``{"obstacles": [...], "probes": {name: (2,) reference point [m]}, "disc": a tester's clamping
    disc (:func:`clamping_disc`) or None}``.
    """
    mesh = build_mesh(scene) if mesh is None else mesh
    material = build_material(scene).membrane_scaled(membrane_scale)
    check_thickness(scene, mesh, material.info.get("thickness"))
    if material.weight < 0:
        raise scene.error("material.weight", f"{material.weight!r} N/m^2 is negative; give the fabric's areal weight "
                          "(>= 0; upward loads are loads.pressure < 0)")
    check_weight(scene, material.weight)
    if (material.hysteresis is not None or material.shear_hysteresis is not None) and scene.analysis == "static" \
            and static_options(scene, progress=False).increments.continuation == "arc-length":
        raise scene.error("solver.continuation", '"arc-length" does not commit the friction\'s slip (material '
                          'kes_2HB_*, kes_2HG): use continuation = "load" or start = "relax"')
    if scene.analysis != "static" and not material.mass_per_area > 0:
        raise scene.error("material.weight", "an explicit (dynamic or relax) run needs a positive areal weight "
                          "(the mass); got 0")
    supports = build_supports(scene, mesh)
    load = build_load(scene, mesh, material)
    contact, obstacles = build_contact(scene, mesh, material, supports, law=contact or contact_law(scene),
                                       start_check=start_check)
    if scene.analysis == "static":
        check_static_scene(scene, material, supports, load, obstacles)
    membrane = declared_run_options(scene).membrane
    kernels = run_kernels(scene, mesh)
    self_contact = build_self_contact(scene, mesh, material, kernels=kernels)
    try:
        model = Model(mesh, material, element=scene.get("element", "RFT6"), supports=supports, load=load,
                      contact=contact, membrane=membrane, quiet=quiet, self_contact=self_contact, kernels=kernels)
    except PatchError as exc:  # the scene's mesh: say which scene and key
        raise scene.error("mesh", str(exc)) from None
    probes = {}
    u = scene.units.length
    for i, spec in enumerate(scene.get("probes", [])):
        if "name" not in spec or "at" not in spec:
            raise scene.error(f"probes.{i}", "a probe needs a name and at = [x, y]")
        if spec["name"] in probes:
            raise scene.error(f"probes.{i}.name", f'"{spec["name"]}" names an earlier probe too; give each a name '
                              "of its own")
        probes[spec["name"]] = np.asarray(spec["at"], float) * u
        check_on_sheet(scene, mesh, probes[spec["name"]][None, :], f"probes.{i}.at")
    return model, {"obstacles": obstacles, "probes": probes, "disc": clamping_disc(scene, mesh)}


def clamping_disc(scene: Scene, mesh):
    """The clamping disc of a drape tester (the first clamped ``[[supports]]`` with a ``radius``), as
    :func:`~rftstatic.post.measures.disc.clamp_disc`; None without one."""
    for i, spec in enumerate(scene.get("supports", [])):
        if "radius" in spec and spec.get("kind", "pinned") == "clamped":
            nodes = _within_radius(scene, mesh, spec, f"supports.{i}")
            centre = np.asarray(spec.get("centre", [0.0, 0.0]), float) * scene.units.length
            return clamp_disc(mesh.X3, mesh.tri, nodes, centre)
    return None


def model_factory(scene: Scene, *, contact: str | None = None):
    """``factory(mesh=None) -> (Model, extras)``: the scene's model on ``mesh`` (None: its own mesh),
    for the remeshing drivers (:mod:`rftstatic.remesh`), which rebuild the model on every new mesh."""
    return lambda mesh=None: build_model(scene, mesh=mesh, contact=contact, quiet=mesh is not None)
