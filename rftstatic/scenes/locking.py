"""A structured mesh refined until RFT6 does not lock on the scene's fabric (``[mesh] locking = "refine"``).

RFT6's averaged mid-side strains stiffen bending once the locking number ``(C/B) h^2`` (membrane over bending
rigidity times the mean element size squared, :func:`rftstatic.model.model.locking_number`) exceeds about
:data:`~rftstatic.model.model.LOCKING_WARN` (1e4; the wool strip of §4.1 bends 0.5 % too little at 2e4, 3.3 % at
8e4). A scene's mesh is written for its own fabric; another fabric given to it (a limp library fabric, a thin
lab fabric whose tensile rigidity comes from the plate rule ``C = 12 B / T^2``: locking number ``12 (h / T)^2``)
may be past the limit on that mesh. With ``locking = "refine"`` the scene's node counts are scaled up by one
factor on both directions when the fabric needs it, so the mesh is chosen from the fabric's ``C/B``:
``s = sqrt(lock / LOCKING_WARN)`` (``h`` goes as ``1 / s``), rounded up, then checked on the mesh built. It is
chosen where the mesh is built (:func:`rftstatic.scenes.mesh_build.structured_nodes`, also the finest level of
mesh sequencing, whose coarse levels halve it); node counts set as an override (``--set mesh.nodes=...``: a mesh
study, a quick coarse run) are kept as given, and the model warns. ``"warn"`` (the default) keeps the mesh and
warns.
Measured: validation/fabric_rules.md (the library's limp ``ctd-291-light-soft`` on the Cusick scenes).
"""

from __future__ import annotations

import logging
import math

log = logging.getLogger(__name__)

__all__ = ["LOCKING_MODES", "REFINABLE", "check_locking", "refined_nodes"]

LOCKING_MODES = ("warn", "refine")
"""``mesh.locking``: keep the mesh and warn past the limit, or refine it to the limit."""

REFINABLE = ("rectangle", "polar", "square-polar")
"""Mesh kinds whose node counts ``mesh.nodes`` ``locking = "refine"`` scales."""

MAX_TRIES = 4
"""Rebuilds after the first estimate (each 10 % finer) before the refinement gives up: the element size of the
generated meshes goes as one over the node counts, so the estimate is usually enough."""


def _scaled(kind: str, nodes, s: float) -> list[int]:
    """``mesh.nodes`` of ``kind`` with about ``s`` times the node spacing's inverse in both directions."""
    a, b = nodes
    a2 = math.ceil((a - 1) * s) + 1
    if kind == "rectangle":
        b2 = math.ceil((b - 1) * s) + 1
    elif kind == "square-polar":  # a multiple of 8 sectors keeps a node at every corner of the square
        b2 = 8 * math.ceil(b * s / 8) if b % 8 == 0 else math.ceil(b * s)
    else:
        b2 = math.ceil(b * s)
    return [int(a2), int(b2)]


def check_locking(scene, m: dict, kind: str) -> None:
    """Scene error (exit 2) naming ``mesh.locking`` for an unknown mode, or ``"refine"`` on a mesh kind without
    node counts (a file or unstructured mesh: give it a smaller ``mesh.h`` or a finer file)."""
    mode = m.get("locking", "warn")
    if mode not in LOCKING_MODES:
        raise scene.error("mesh.locking", f'{mode!r} is not a mode; use "warn" (keep the mesh, warn past '
                          f'(C/B) h^2 = 1e4) or "refine" (more nodes until it is below)')
    if mode == "refine" and kind not in REFINABLE:
        raise scene.error("mesh.locking", f'"refine" scales the node counts of a {", ".join(REFINABLE)} mesh; a '
                          f"{kind} mesh has none: give it a smaller element size (mesh.h) or a finer file, or "
                          'remove the key (the model then warns)')


def refined_nodes(scene, kind: str, given, make_mesh, max_nodes: int):
    """``(nodes, mesh)``: ``mesh.nodes`` for ``mesh.locking = "refine"``: ``given`` when RFT6 is below
    :data:`~rftstatic.model.model.LOCKING_WARN` on the scene's fabric there (or the element is RFT3), else both
    counts scaled up by ``sqrt(lock / LOCKING_WARN)`` (then 10 % more per try) until the mesh ``make_mesh(nodes)``
    is below it, and that mesh (built here once). A scene error names ``mesh.locking`` when :data:`MAX_TRIES` refinements do not get there or the
    mesh would have more than ``max_nodes`` nodes (a membrane rigidity far beyond a fabric's)."""
    if scene.get("element", "RFT6") != "RFT6":
        return list(given), make_mesh(given)
    from rftstatic.model.model import LOCKING_WARN, locking_number
    from rftstatic.scenes.material import build_material

    material = build_material(scene)
    nodes, mesh = list(given), make_mesh(given)
    lock = locking_number(mesh, material)
    s = math.sqrt(lock / LOCKING_WARN)
    tries = 0
    while lock > LOCKING_WARN:
        if tries > MAX_TRIES:
            raise scene.error("mesh.locking", f"mesh.nodes = {nodes} still has (C/B) h^2 = {lock:.3g} > "
                              f"{LOCKING_WARN:.0e} after {MAX_TRIES} refinements; give mesh.nodes yourself or "
                              'use element = "RFT3"')
        nodes = _scaled(kind, given, s)
        if nodes[0] * nodes[1] > max_nodes:
            raise scene.error("mesh.locking", f'"refine" for (C/B) h^2 = {lock:.3g} would need mesh.nodes = {nodes} '
                              f"({nodes[0] * nodes[1]:.3g} nodes, more than {max_nodes:,}): check the fabric's "
                              'membrane and bending rigidities ([material]), or use element = "RFT3" or locking = '
                              '"warn"')
        mesh = make_mesh(nodes)
        lock = locking_number(mesh, material)
        s *= 1.1
        tries += 1
    if nodes != list(given):
        log.info('mesh.locking = "refine": mesh.nodes %s -> %s for (C/B) h^2 <= %.0e on this fabric (%.3g)',
                 list(given), nodes, LOCKING_WARN, lock)
    return nodes, mesh
