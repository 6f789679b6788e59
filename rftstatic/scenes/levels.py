"""The coarser meshes of a scene for mesh sequencing (``solver.levels``).

Mesh sequencing (nested iteration, grid continuation) solves a drape on a hierarchy of meshes of the
same sheet: the coarsest by the scene's own route, every finer one by Newton at full load from the
solution of the mesh below (:mod:`rftstatic.app.levels`). Each level has about twice the element size
of the one above it:

==================  ======================================================================
mesh kind           level ``k`` below the scene's mesh (``k = 1, 2, ...``)
==================  ======================================================================
``rectangle``       ``nodes = [ceil((nx - 1) / 2^k) + 1, ceil((ny - 1) / 2^k) + 1]``
``polar``,          ``nodes = [ceil((n_radial - 1) / 2^k) + 1, round(n_circ / 2^k)]`` (a square-polar
``square-polar``    mesh whose n_circ is a multiple of 8 keeps a multiple of 8: a node at each corner)
``unstructured``    ``h = 2^k h``
``file``            none: a mesh read from a file has no coarser version (a scene error)
==================  ======================================================================

so the rectangle's 201 x 201 nodes give 101 x 101 and 51 x 51 (nested: every coarse node is a fine
node), 81 x 81 gives 41 x 41 and 21 x 21, the round pedestal's 21 x 160 rings give 11 x 80 and 6 x 40,
its 31 x 240 give 16 x 120 and 9 x 64. A coarser level keeps the scene's obstacles, supports and loads; it
drops the probes (they report on the scene's own mesh only) and ``solver.seeds``.

``solver.levels = "auto"`` (the default of a scene) picks the number of levels from the mesh's size
(:func:`auto_levels`): one below :data:`AUTO_FROM` nodes, else as many as bring the coarsest mesh to
:data:`AUTO_COARSEST` nodes or fewer.
"""

from __future__ import annotations

import copy
import math

from rftstatic.errors import SceneError
from rftstatic.mesh import trimesh as meshmod
from rftstatic.scenes.mesh_build import structured_nodes
from rftstatic.scenes.run_options import MAX_LEVELS
from rftstatic.scenes.schema import MESH_NODES, Scene, validate

__all__ = ["AUTO_COARSEST", "AUTO_FROM", "MAX_LEVELS", "auto_levels", "level_mesh", "level_nodes", "level_scenes"]


LEAST_NODES = {"rectangle": (3, 3), "polar": (2, 12), "square-polar": (2, 12)}
"""Fewest nodes per direction of a coarse level (a patch needs neighbours; a ring at least 12 sectors)."""


def level_mesh(scene: Scene, k: int) -> dict:
    """The ``[mesh]`` table of the mesh ``k`` levels below the scene's own (k = 0: the scene's)."""
    m = dict(scene.get("mesh", {}))
    kind = m.get("kind", "rectangle")
    if kind in MESH_NODES:
        m.setdefault("nodes", list(MESH_NODES[kind]))
    if k == 0:
        return m
    if kind in LEAST_NODES:
        a, b = m["nodes"] = structured_nodes(scene)  # mesh.locking = "refine": halve the refined mesh
        m["locking"] = "warn"  # a coarse level is coarser than the finest on purpose (level_membrane)
        a2 = math.ceil((a - 1) / 2 ** k) + 1
        if kind == "rectangle":
            b2 = math.ceil((b - 1) / 2 ** k) + 1
        elif kind == "square-polar":  # a multiple of 8 sectors keeps a node at every corner of the square
            b2 = 8 * max(1, round(b / 2 ** k / 8)) if b % 8 == 0 else round(b / 2 ** k)
        else:
            b2 = round(b / 2 ** k)
        least = LEAST_NODES[kind]
        if a2 < least[0] or b2 < least[1]:
            raise scene.error("solver.levels", f"{k + 1} levels make the coarsest mesh [{a2}, {b2}] nodes from "
                              f"mesh.nodes = [{a}, {b}], fewer than a {kind} mesh needs ({list(least)}); give "
                              "fewer levels")
        m["nodes"] = [int(a2), int(b2)]
        return m
    if kind == "unstructured":
        if "h" not in m:
            raise scene.error("mesh.h", "an unstructured mesh needs its target element size h")
        m["h"] = m["h"] * 2 ** k
        return m
    raise scene.error("solver.levels", f'a mesh of kind "{kind}" has no coarser levels (it is read as it is); '
                      "use solver.levels = 1 or a generated mesh (rectangle, polar, square-polar, unstructured)")


AUTO_FROM = 15_000
"""Fewest nodes of a mesh that ``solver.levels = "auto"`` solves by mesh sequencing. Up to here the scene's
own route (relaxation, load steps or arc-length from the flat sheet) takes minutes, and the validation
reports use it: the paper's 81 x 81 (6,561 nodes), the round pedestal's 31 x 240 rings (12,464 with the
square core), with a margin for the estimate of :func:`level_nodes`. Above it the routes from flat cost more than N^1.5 (the relaxation's stable step shrinks
with the element size; measured on the 80 cm drape: 292 s at 81 x 81 nodes, not finished in 25 minutes at
201 x 201, against 22 minutes by three levels)."""

AUTO_COARSEST = 3_000
"""Most nodes of the coarsest mesh of an ``"auto"`` sequence (51 x 51 = 2,601: the 80 cm drape relaxes
there in 12 Newton iterations after the explicit stage, 20-40 s; the finer levels' Newton then starts
from folds already formed)."""


def level_nodes(scene: Scene, k: int = 0) -> int:
    """Nodes of the mesh ``k`` levels below the scene's own, counted without building it: exact for a
    rectangle and a polar mesh, within a few percent for a square-polar one (its core) and an unstructured
    one (:func:`rftstatic.mesh.trimesh.equilateral_nodes` on the sheet's area); 0 for a mesh read from a
    file."""
    m = level_mesh(scene, k)
    kind = m.get("kind", "rectangle")
    if kind in LEAST_NODES:
        a, b = (int(v) for v in m["nodes"])
        if kind == "rectangle":
            return a * b
        if kind == "polar":
            return meshmod.polar_nodes(a, b, m.get("inner_radius", 0.0))
        return meshmod.square_polar_nodes(m["radius"], a, b, m.get("inner_radius"))
    if kind == "unstructured":
        area = math.pi * m["radius"] ** 2 if "radius" in m else math.prod(m.get("size", [1.0, 1.0]))
        return int(meshmod.equilateral_nodes(area, m["h"]))
    return 0


def auto_levels(scene: Scene) -> int:
    """The levels of ``solver.levels = "auto"``: 1 for a mesh of fewer than :data:`AUTO_FROM` nodes (or one
    read from a file, which has no coarser levels), else the fewest levels whose coarsest mesh has at most
    :data:`AUTO_COARSEST` nodes (each level has about a quarter of the nodes of the next), within
    :data:`MAX_LEVELS` and the fewest nodes a coarse mesh of its kind may have (:data:`LEAST_NODES`)."""
    kind = scene.get("mesh.kind", "rectangle")
    if (kind not in LEAST_NODES and kind != "unstructured") or level_nodes(scene) < AUTO_FROM:
        return 1
    levels = 1
    while levels < MAX_LEVELS and level_nodes(scene, levels - 1) > AUTO_COARSEST:
        try:
            level_mesh(scene, levels)
        except SceneError:  # the next coarser mesh would be too coarse for its kind
            break
        levels += 1
    return levels


def level_scenes(scene: Scene, levels: int) -> list[Scene]:
    """The scenes of a sequence of ``levels`` meshes, coarsest first; the last is ``scene`` itself.

    Each coarser scene is ``scene`` with the ``[mesh]`` of :func:`level_mesh`, ``solver.levels = 1``, and
    ``solver.seeds`` and the probes removed (a level is one solve), validated like a scene file.
    """
    if not (isinstance(levels, int) and 1 <= levels <= MAX_LEVELS):
        raise scene.error("solver.levels", f"{levels!r} must be an integer in [1, {MAX_LEVELS}] (the meshes of the "
                          "sequence, the scene's own included)")
    return [_level_scene(scene, k, levels) for k in range(levels - 1, 0, -1)] + [scene]


def _level_scene(scene: Scene, k: int, levels: int) -> Scene:
    """The scene of the mesh ``k`` levels below ``scene``'s, level ``levels - k`` of ``levels``."""
    data = copy.deepcopy(scene.data)
    data["mesh"] = level_mesh(scene, k)
    solver = data.setdefault("solver", {})
    solver["levels"] = 1
    solver.pop("seeds", None)
    data.pop("probes", None)
    coarse = Scene(data, scene.path, f"{scene.name} (level {levels - k} of {levels})", dict(scene.overrides))
    validate(coarse)
    return coarse
