"""Physical ranges of a scene's numbers, checked where the scene layer reads them.

The schema (:mod:`rftstatic.scenes.schema`) checks types and refuses NaN and infinity; the numbers below
are the ranges a finite value must lie in besides. Each bound says what is physically meaningful and what
the code can represent: a value outside it is a typo or a wrong unit (``1e300``, ``-1``), and it would
otherwise overflow deep in the mesh, the material or the contact (an ``OverflowError``, a NaN node count),
or leave the model with no stiffness. Each check raises a :class:`~rftstatic.errors.SceneError` naming the
file, the key and the value, the range and what to give instead.

Lengths are compared with the sheet (its larger side or its diameter, :func:`sheet_size`) and with its mean
element size, in the scene's own length units, so that the ranges read the same in every unit system:

* the sheet's sides (``mesh.size``, ``mesh.radius``): :data:`SHEET_RANGE_M` (1 um to 1000 km);
* positions (``mesh.origin``, ``mesh.centre``, ``mesh.z``, ``supports.*.centre``): within
  :data:`MAX_OFFSET` sheet sizes of the origin or of the sheet;
* an annulus' hole (``mesh.inner_radius``): 0 or from :data:`MIN_INNER_RADIUS` of the radius;
* obstacle sizes (``radius``, ``half_width``, ``edge_radius``...): 0 or within
  [:data:`MIN_OBSTACLE_SIZE` element sizes, :data:`MAX_OBSTACLE_SIZE` sheet sizes];
* a shell's thickness (``material.thickness``): [:data:`MIN_THICKNESS` element sizes, the sheet's smaller
  side];
* ``material.weight``: at most :data:`MAX_WEIGHT`.
"""

from __future__ import annotations

import numpy as np

from rftstatic.scenes.schema import Scene

__all__ = ["MAX_OBSTACLE_SIZE", "MAX_OFFSET", "MIN_INNER_RADIUS", "MIN_NODES",
           "MIN_OBSTACLE_SIZE", "MIN_THICKNESS", "SHEET_RANGE_M", "check_mesh_table", "check_obstacle_sizes",
           "check_thickness", "check_position", "check_weight", "MAX_WEIGHT", "sheet_size"]

SHEET_RANGE_M = (1e-6, 1e6)
"""Smallest and largest side (or diameter) of a sheet [m]: 1 um to 1000 km, far beyond any specimen (a few
mm to tens of metres); outside it a value is a typo or a wrong unit, and at 1e300 the areas overflow."""

MAX_OFFSET = 1e3
"""Farthest a sheet's origin, centre or height (or a clamping disc's centre) may lie from the origin (from the
sheet), in sheet sizes: a node's coordinates keep about 16 - log10(offset / element size) digits, and the
curvature of a patch is a second difference of them; at 1e3 sheet sizes a coarse mesh still has ~11."""

MIN_INNER_RADIUS = 1e-6
"""Smallest hole of an annulus, as a fraction of its outer radius (0: a full disc): below it the first ring's
elements are slivers whose area falls below round-off (1e-300: "degenerate triangles")."""

MIN_NODES = {"rectangle": (2, 2), "polar": (2, 3), "square-polar": (2, 8)}
"""Fewest ``mesh.nodes`` of each generated mesh, as its generator (:mod:`rftstatic.mesh.trimesh`) needs them:
``[nx, ny]``, ``[n_radial, n_circ]``."""

MIN_OBSTACLE_SIZE = 1e-6
"""Smallest non-zero obstacle size (a radius, a half width, an edge radius), in mean element sizes: a smaller
one is a point to the sheet's nodes (its curvature 1/r would dwarf every other stiffness); give 0 where the
type takes it (a sharp edge)."""

MAX_OBSTACLE_SIZE = 1e3
"""Largest obstacle size, in sheet sizes (as :data:`rftstatic.scenes.build.MAX_OBSTACLE_DISTANCE` for its
position): a larger one is a plane to the sheet (use a floor), and at 1e300 its distances overflow."""

MIN_THICKNESS = 1e-6
"""Thinnest shell or fabric, in mean element sizes: a shell's bending over membrane stiffness is
t^2 / (12 h^2), below 1e-13 at this bound, under the round-off of the membrane terms."""

MAX_WEIGHT = 1e6
"""Heaviest sheet [N/m^2]: 100 t/m^2, a 13 m thick steel plate (fabrics weigh 0.5-10 N/m^2); at 1e300 the
explicit step, which scales with sqrt(mass), collapses to 0."""


def check_weight(scene: Scene, weight: float) -> None:
    """Scene error unless the material's areal weight ``weight`` [N/m^2] is at most :data:`MAX_WEIGHT`."""
    if not weight <= MAX_WEIGHT:
        limit = MAX_WEIGHT / scene.units.pressure
        raise scene.error("material.weight", f"{weight / scene.units.pressure!r} is heavier than {limit:.3g} (scene "
                          f"units; {MAX_WEIGHT:g} N/m^2, a 13 m thick steel plate): give the areal weight in the "
                          "scene's force/area unit")


def sheet_size(mesh) -> float:
    """The larger side (or the diameter) of a reference mesh [m]."""
    return max(float(np.ptp(mesh.X, axis=0).max()), 1e-300)


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _sheet_extent(m: dict, kind: str) -> tuple[str | None, list]:
    """The key giving the sheet's extent and its sides (scene units); ``(None, [])`` for a file mesh."""
    if kind in ("polar", "square-polar") or (kind == "unstructured" and "radius" in m):
        r = m.get("radius")
        return "mesh.radius", [2.0 * r] if _number(r) else []
    if kind in ("rectangle", "unstructured"):
        size = m.get("size", [1.0, 1.0])
        return "mesh.size", [v for v in size if _number(v)] if isinstance(size, list) else []
    return None, []


def check_mesh_table(scene: Scene, m: dict, kind: str) -> None:
    """Scene error unless the ``[mesh]`` table ``m`` of a generated mesh ``kind`` gives a sheet within
    :data:`SHEET_RANGE_M`, near the origin (:data:`MAX_OFFSET`), with an annulus' hole of at least
    :data:`MIN_INNER_RADIUS` of its radius and at least :data:`MIN_NODES` nodes."""
    key, sides = _sheet_extent(m, kind)
    if key is None:
        return
    u = scene.units.length
    lo, hi = SHEET_RANGE_M
    given = m.get(key.split(".")[1])
    what = "both sides" if key == "mesh.size" else "the diameter (2 x radius)"
    for side in sides:
        if not side > 0:
            raise scene.error(key, f"{given!r}: {what} must be > 0 (the sheet's size, scene length units)")
        if not lo <= side * u <= hi:
            raise scene.error(key, f"{given!r}: {what} of the sheet must lie in [{lo / u:g}, {hi / u:g}] "
                              f"({scene.units.name} length units; {lo:g} to {hi:g} m, beyond any specimen); give "
                              "the sheet's size in the scene's units")
    size = max(sides) if sides else 1.0
    for name in ("origin", "centre", "z"):
        if name in m:
            check_position(scene, f"mesh.{name}", m[name], [0.0, 0.0, 0.0], size, "the origin")
    inner = m.get("inner_radius")
    radius = m.get("radius")
    if _number(inner) and _number(radius) and radius > 0 and inner != 0 and not (
            MIN_INNER_RADIUS * radius <= inner < radius):
        raise scene.error("mesh.inner_radius", f"{inner!r} must be 0 (a full disc) or lie in "
                          f"[{MIN_INNER_RADIUS:g} x radius, radius) = [{MIN_INNER_RADIUS * radius:g}, {radius:g}) "
                          "(the hole of an annulus, scene length units)")
    nodes = m.get("nodes")
    if kind in MIN_NODES and isinstance(nodes, list) and len(nodes) == 2 and all(_number(n) for n in nodes):
        least = MIN_NODES[kind]
        if nodes[0] < least[0] or nodes[1] < least[1]:
            names = "[nx, ny]" if kind == "rectangle" else "[n_radial, n_circ]"
            raise scene.error("mesh.nodes", f"{nodes!r}: a {kind} mesh needs {names} of at least {list(least)}; "
                              "give more nodes")


def check_position(scene: Scene, key: str, value, centre, size: float, what: str) -> None:
    """Scene error unless every coordinate of ``value`` (a number: a height, or a list ``[x, y(, z)]``) lies
    within :data:`MAX_OFFSET` x ``size`` of ``centre`` (scene units; ``what`` names it in the message)."""
    numbers = value if isinstance(value, list) else [value]
    bound = MAX_OFFSET * size
    axes = "xyz" if isinstance(value, list) else "z"
    for axis, v in zip(axes, numbers):
        c = centre["xyz".index(axis)]
        if _number(v) and not abs(v - c) <= bound:
            raise scene.error(key, f"{value!r} lies more than {MAX_OFFSET:g} sheet sizes ({bound:g} scene length "
                              f"units) from {what} ({axis} = {c:g}); the coordinates would lose their digits: give "
                              "a position near the sheet")


def check_obstacle_sizes(scene: Scene, mesh, position_keys) -> None:
    """Scene error unless every length of every ``[[obstacles]]`` table that is a size, not a position (one
    of ``position_keys``), is 0 or lies in [:data:`MIN_OBSTACLE_SIZE` mean element sizes,
    :data:`MAX_OBSTACLE_SIZE` sheet sizes]; the obstacle checks its own signs and relations."""
    from rftstatic.contact.obstacles import obstacle_class

    u = scene.units.length
    h, size = float(mesh.element_size.mean()) / u, sheet_size(mesh) / u
    lo, hi = MIN_OBSTACLE_SIZE * h, MAX_OBSTACLE_SIZE * size
    for i, spec in enumerate(scene.get("obstacles", [])):
        try:
            keys = obstacle_class(spec.get("type", ""))
        except (KeyError, AttributeError):
            continue  # from_spec names an unknown type
        for key, sk in keys.scene_keys.items():
            value = spec.get(key)
            if not sk.length or key in position_keys or value is None:
                continue
            for v in value if isinstance(value, list) else [value]:
                if _number(v) and v != 0 and not lo <= abs(v) <= hi:
                    raise scene.error(f"obstacles.{i}.{key}", f"{value!r} must be 0 (where the obstacle takes it) "
                                      f"or lie in [{lo:.3g}, {hi:.3g}] scene length units: from {MIN_OBSTACLE_SIZE:g} "
                                      f"mean element sizes (a smaller obstacle is a point to the nodes) to "
                                      f"{MAX_OBSTACLE_SIZE:g} sheet sizes (a larger one is a plane: use a floor)")


def check_thickness(scene: Scene, mesh, thickness_m: float | None) -> None:
    """Scene error unless ``material.thickness`` (``thickness_m`` [m], None: not given) lies in
    [:data:`MIN_THICKNESS` mean element sizes, the sheet's smaller side]: thicker is a block, not a shell
    (the Kirchhoff plate theory of the RF triangles needs a thin sheet)."""
    if thickness_m is None:
        return
    u = scene.units.length
    h = float(mesh.element_size.mean())
    width = max(float(np.ptp(mesh.X, axis=0).min()), 1e-300)
    if not MIN_THICKNESS * h <= thickness_m <= width:
        raise scene.error("material.thickness", f"{scene.get('material.thickness')!r} must lie in "
                          f"[{MIN_THICKNESS * h / u:.3g}, {width / u:.3g}] scene length units: from {MIN_THICKNESS:g} "
                          "mean element sizes (thinner, bending is below the round-off of the membrane) to the "
                          "sheet's smaller side (thicker is a block, not a shell)")
