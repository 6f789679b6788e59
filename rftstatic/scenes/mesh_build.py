"""The flat reference mesh of a scene (``[mesh]``): generated (rectangle, polar, square-polar), read from a file,
or made by the advancing-front mesher (unstructured), in SI units."""

from __future__ import annotations

import math

import numpy as np

from rftstatic.mesh import trimesh as meshmod
from rftstatic.scenes.locking import check_locking, refined_nodes
from rftstatic.scenes.ranges import check_mesh_table
from rftstatic.scenes.schema import MESH_NODES, Scene

__all__ = ["MAX_MESH_NODES", "MESH_KEYS", "STRUCTURED", "build_mesh", "pair", "structured_nodes"]

STRUCTURED = ("rectangle", "polar", "square-polar")
"""Mesh kinds generated from node counts (``mesh.nodes``)."""

MESH_KEYS = {
    "rectangle": {"size", "nodes", "origin", "pattern", "locking"},
    "polar": {"radius", "inner_radius", "nodes", "centre", "pattern", "grading", "locking"},
    "square-polar": {"radius", "inner_radius", "nodes", "centre", "pattern", "locking"},
    "file": {"path", "locking"},
    "unstructured": {"h", "size", "origin", "radius", "centre", "locking"},
}
"""The ``[mesh]`` keys each mesh kind reads (besides ``kind`` and ``z``); any other is a scene error."""


def _structured(scene, m, kind, nodes, u, z0):
    """The generated mesh of a rectangle, polar or square-polar ``[mesh]`` table ``m`` with ``nodes`` [SI]."""
    nr, nc = nodes
    if kind == "rectangle":
        lx, ly = pair(scene, "mesh.size", m.get("size", [1.0, 1.0]))
        ox, oy = pair(scene, "mesh.origin", m.get("origin", [-lx / 2, -ly / 2]))
        return meshmod.rectangle(lx * u, ly * u, nr, nc, origin=(ox * u, oy * u),
                                 pattern=m.get("pattern", "right"), z0=z0)
    cx, cy = pair(scene, "mesh.centre", m.get("centre", [0.0, 0.0]))
    if kind == "square-polar":
        if "radius" not in m:
            raise scene.error("mesh.radius", "a square-polar mesh needs its half side as radius")
        core = m.get("inner_radius")
        return meshmod.square_polar(m["radius"] * u, nr, nc, centre=(cx * u, cy * u),
                                    core_radius=None if core is None else core * u,
                                    pattern=m.get("pattern", "right"), z0=z0)
    if "radius" not in m:
        raise scene.error("mesh.radius", f"a {kind} mesh needs its radius")
    return meshmod.polar(m["radius"] * u, nr, nc, r_inner=m.get("inner_radius", 0.0) * u,
                         centre=(cx * u, cy * u), pattern=m.get("pattern", "alternate"), z0=z0,
                         grading=m.get("grading", 1.0))


def _structured_mesh(scene, m: dict, kind: str):
    """``(nodes, mesh)`` of a generated (rectangle, polar, square-polar) ``[mesh]`` table ``m``: the given or default
    counts, refined for the fabric when ``mesh.locking = "refine"`` (:mod:`rftstatic.scenes.locking`)."""
    u = scene.units.length
    z0 = m.get("z", 0.0) * u
    nodes = list(pair(scene, "mesh.nodes", m.get("nodes", MESH_NODES[kind]), int))
    if m.get("locking", "warn") == "warn" or "mesh.nodes" in scene.overrides:
        return nodes, _structured(scene, m, kind, nodes, u, z0)
    return refined_nodes(scene, kind, nodes, lambda n: _structured(scene, m, kind, n, u, z0), MAX_MESH_NODES)


def structured_nodes(scene) -> list[int]:
    """``mesh.nodes`` of the scene's generated (rectangle, polar, square-polar) mesh as built (refined for the
    fabric when ``mesh.locking = "refine"``)."""
    m = scene.get("mesh", {})
    return _structured_mesh(scene, m, m.get("kind", "rectangle"))[0]


def build_mesh(scene: Scene) -> meshmod.TriMesh:
    """The scene's flat reference mesh [m] (``[mesh]``: :data:`MESH_KEYS` of its kind)."""
    u = scene.units.length
    m = scene.get("mesh", {})
    kind = m.get("kind", "rectangle")
    if kind in MESH_KEYS:
        extra = sorted(set(m) - MESH_KEYS[kind] - {"kind", "z"})
        if "mesh.kind" in scene.overrides:  # --set mesh.kind=...: the file's keys of its own kind give way
            extra = [k for k in extra if f"mesh.{k}" in scene.overrides]
            m = {k: v for k, v in m.items() if k in MESH_KEYS[kind] | {"kind", "z"}}
        if extra:
            raise scene.error(f"mesh.{extra[0]}", f"does not apply to a {kind} mesh (it reads "
                              f"{', '.join(sorted(MESH_KEYS[kind]))}, kind and z); remove it")
    check_mesh_table(scene, m, kind)
    check_locking(scene, m, kind)
    z0 = m.get("z", 0.0) * u
    nodes = m.get("nodes") if kind in STRUCTURED else None
    if (isinstance(nodes, list) and len(nodes) == 2 and all(isinstance(n, int) for n in nodes)
            and nodes[0] * nodes[1] > MAX_MESH_NODES):
        raise scene.error("mesh.nodes", f"{nodes!r} asks for {nodes[0] * nodes[1]:.3g} nodes, more than "
                          f"{MAX_MESH_NODES:,}; give fewer nodes")
    try:
        if kind in STRUCTURED:
            return _structured_mesh(scene, m, kind)[1]
        if kind == "file":
            if "path" not in m:
                raise scene.error("mesh.path", "a file mesh needs the path of the mesh file")
            path = m["path"]
            if scene.path is not None and not __import__("os").path.isabs(path):
                path = str(scene.path.parent / path)
            return meshmod.read(path, length_scale=u, z0=z0 if "z" in m else None)
        if kind == "unstructured":
            return _unstructured(scene, m, u, z0)
    except meshmod.MeshError as exc:
        raise scene.error("mesh", str(exc)) from None
    raise scene.error("mesh.kind", f'"{kind}" is not a mesh kind; use rectangle, polar, square-polar, file or unstructured')


def _unstructured(scene, m, u, z0):
    from rftstatic.errors import MeshingError
    from rftstatic.mesh.mesher import BackgroundGrid, Domain, generate

    if "h" not in m:
        raise scene.error("mesh.h", "an unstructured mesh needs its target element size h")
    h = m["h"] * u
    if "radius" in m:
        cx, cy = pair(scene, "mesh.centre", m.get("centre", [0.0, 0.0]))
        if not m["radius"] > 0:
            raise scene.error("mesh.radius", f"{m['radius']!r} must be > 0 (the radius of the disc)")
        _check_unstructured_size(scene, m["h"], 2.0 * m["radius"], np.pi * m["radius"] * m["radius"])
        shape = (Domain.disc, cx * u, cy * u, m["radius"] * u)
    else:
        lx, ly = pair(scene, "mesh.size", m.get("size", [1.0, 1.0]))
        ox, oy = pair(scene, "mesh.origin", m.get("origin", [-lx / 2, -ly / 2]))
        if not (lx > 0 and ly > 0):
            raise scene.error("mesh.size", f"{m.get('size')!r}: both sides must be > 0")
        _check_unstructured_size(scene, m["h"], min(lx, ly), lx * ly)
        shape = (Domain.rectangle, ox * u, oy * u, lx * u, ly * u)
    try:
        domain = shape[0](*shape[1:])
        res = generate(domain, BackgroundGrid.uniform(h, domain))
    except MeshingError as exc:
        raise scene.error("mesh", str(exc)) from None
    return meshmod.TriMesh(res.points, res.triangles, z0=z0, name=f"unstructured h={m['h']}",
                           info={"generator": "advancing-front", "quality": res.quality.as_dict()})


MAX_MESH_NODES = 2_000_000
"""Largest mesh a scene may ask for: a bigger one is refused before it is built (its static solve would need
tens of GB; a mistyped size usually asks for far more)."""


def _check_unstructured_size(scene, h, width, area) -> None:
    """Scene error unless ``mesh.h`` (scene units) is positive, at most the sheet's ``width`` and gives at
    most :data:`MAX_MESH_NODES` nodes on its ``area`` (equilateral triangles of side h)."""
    if not h > 0:
        raise scene.error("mesh.h", f"{h!r} must be > 0 (the target element size)")
    if h > width:
        raise scene.error("mesh.h", f"{h!r} is larger than the sheet ({width:g} across, scene units); give an "
                          "element size below it")
    nodes = meshmod.equilateral_nodes(area, h)
    if nodes > MAX_MESH_NODES:
        many = f"about {nodes:.3g}" if math.isfinite(nodes) else "countless"
        raise scene.error("mesh.h", f"{h!r} would give {many} nodes, more than {MAX_MESH_NODES:,}; give a larger "
                          "element size (scene length units)")


def pair(scene, key, value, kind=float):
    """``value`` as two numbers of ``kind``, else a scene error naming ``key``."""
    if not (isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value)):
        raise scene.error(key, f"expected two numbers [a, b], got {value!r}")
    return kind(value[0]), kind(value[1])
