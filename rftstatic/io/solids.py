"""What a sheet rests on, as triangulated surfaces for the pictures (:mod:`.views`) and the viewer (:mod:`.viewer`).

- :func:`obstacle_surface`: any obstacle (:class:`rftstatic.contact.obstacles.Obstacle`), clipped to a
  drawing box, triangulated from its signed distance alone, so a new obstacle type is drawn without a line
  here;
- :func:`support_disc`: the clamping disc of a drape tester (Cusick: the specimen lies on an 18 cm disc,
  modelled as clamped nodes, not as an obstacle), as a thin round pedestal under the specimen;
- :func:`run_solids`: every solid of a run, from its resolved scene (``summary.json``'s ``resolved_scene``:
  ``[[obstacles]]`` and clamped ``[[supports]]`` with a ``radius``) and the sheet's reference positions, so
  the solids of any past run can be drawn.

Triangulation. A UV sphere around the drawing box is projected onto the clipped solid ``max(phi, phi_box)``
(the intersection of the obstacle with the box) by repeated closest-point steps ``x <- x - phi grad phi``.
For a convex solid (every obstacle type here) the map is continuous, so the sphere's triangles cover the
surface without folding; points that land on an edge or a corner make slivers there, which keeps the edges
sharp in the picture. All lengths in one unit (the scene's, for the drawings).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Solid", "drawing_box", "obstacle_surface", "run_solids", "support_disc"]

PROJECTION_STEPS = 40
"""Closest-point steps onto the clipped solid (each reduces the distance to it; 40 reach 1e-6 of its size)."""


class Solid(NamedTuple):
    """A triangulated surface to draw translucent under the sheet.

    Attributes
    ----------
    name : what it is ("round-pedestal", "support disc", ...)
    vertices : (M, 3) points [scene length unit]
    triangles : (K, 3) vertex indices
    """

    name: str
    vertices: np.ndarray
    triangles: np.ndarray


def _uv_sphere(n_lat: int, n_lon: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit sphere: (M, 3) points (the two poles and ``n_lat - 1`` rings of ``n_lon``) and (K, 3) triangles."""
    theta = np.linspace(0.0, np.pi, n_lat + 1)[1:-1]
    phi = 2.0 * np.pi * np.arange(n_lon) / n_lon
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.column_stack([(np.sin(t) * np.cos(p)).ravel(), (np.sin(t) * np.sin(p)).ravel(), np.cos(t).ravel()])
    pts = np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    rings = n_lat - 1
    idx = 1 + np.arange(rings * n_lon).reshape(rings, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    quads_a, quads_b, quads_c, quads_d = idx[:-1], nxt[:-1], nxt[1:], idx[1:]
    side = np.concatenate([np.stack([quads_a, quads_d, quads_c], -1).reshape(-1, 3),
                           np.stack([quads_a, quads_c, quads_b], -1).reshape(-1, 3)])
    top = np.column_stack([np.zeros(n_lon, int), idx[0], nxt[0]])[:, [0, 2, 1]]
    bottom = np.column_stack([np.full(n_lon, len(pts) - 1), idx[-1], nxt[-1]])
    return pts, np.vstack([top, side, bottom]).astype(np.int64)


def obstacle_surface(obstacle, lo, hi, *, n_lat: int = 24, n_lon: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """The surface of ``obstacle`` within the box ``lo (3,)``, ``hi (3,)``, triangulated (module notes).

    Parameters
    ----------
    obstacle : any :class:`~rftstatic.contact.obstacles.Obstacle` (``signed_distance`` in the box's unit)
    lo, hi : (3,) the drawing box: an unbounded solid (a floor, an infinitely tall pedestal) ends at its faces
    n_lat, n_lon : rings and meridians of the sphere that is projected (24 x 48: about 2200 triangles, which add
        60 % to the GIF of a 13 x 13 sheet; edges stay sharp at any count, a sphere shows facets below it)

    Returns
    -------
    vertices (M, 3), triangles (K, 3); ``None`` when the solid does not meet the box.
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    olo, ohi = (np.asarray(b, float) for b in obstacle.bounding_box())
    lo, hi = np.maximum(lo, olo), np.minimum(hi, ohi)             # the clipped solid's box
    if np.any(hi <= lo):
        return None
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)

    def phi_grad(x):
        phi, n = obstacle.signed_distance(x)
        q = np.abs(x - centre) - half                             # the box: exact outside, max face inside
        outside = np.maximum(q, 0.0)
        dist = np.linalg.norm(outside, axis=1)
        k = np.argmax(q, axis=1)
        box = np.where(dist > 0, dist, q[np.arange(len(x)), k])
        gb = np.where(dist[:, None] > 0, outside / np.maximum(dist, 1e-300)[:, None], np.eye(3)[k])
        gb *= np.sign(x - centre) + (x == centre)
        use_box = box > phi
        return np.where(use_box, box, phi), np.where(use_box[:, None], gb, n)

    pts, tri = _uv_sphere(n_lat, n_lon)
    x = centre + 1.5 * np.linalg.norm(half) * pts
    for _ in range(PROJECTION_STEPS):
        phi, n = phi_grad(x)
        x = x - phi[:, None] * n
    return x, tri


def drawing_box(x: np.ndarray, pad: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """The box the solids are drawn in: the sheet's positions ``x (N, 3)`` widened by ``pad`` of its largest
    span on every side (a pedestal shows a side under the sheet, a floor is a slab that thick)."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    span = float(np.max(hi - lo)) or 1.0
    return lo - pad * span, hi + pad * span


def support_disc(centre, radius: float, z: float) -> tuple[np.ndarray, np.ndarray]:
    """A tester's support disc of ``radius`` about ``centre (2,)`` whose top is just under the height ``z`` of
    the clamped specimen: a thin round pedestal (thickness 6 % of the radius), as vertices and triangles."""
    from rftstatic.contact.obstacles import RoundPedestal

    top = z - 2e-3 * radius                                       # under the sheet where the mesh covers the disc
    disc = RoundPedestal(np.asarray(centre, float)[:2], radius, top_z=top, edge_radius=0.01 * radius,
                         height=0.06 * radius)
    lo, hi = disc.bounding_box()
    return obstacle_surface(disc, lo - radius, hi + radius)


def run_solids(scene: dict | None, x_ref: np.ndarray, x: np.ndarray, *, obstacles=None) -> list[Solid]:
    """The solids of a run, in its scene's length unit.

    Parameters
    ----------
    scene : the run's resolved scene data (``Scene.data``, ``summary.json``'s ``resolved_scene``): its
        ``obstacles`` and ``supports`` [scene units]
    x_ref : (N, 3) the sheet's reference positions [scene length] (the height of a clamping disc)
    x : (N, 3) positions the drawing box is made for (every state shown) [scene length]
    obstacles : the obstacles [scene units], when the caller has built them (default: from ``scene``)
    """
    from rftstatic.contact.obstacles import from_spec
    from rftstatic.contact.obstacles.base import type_name_of

    scene = scene or {}
    lo, hi = drawing_box(np.asarray(x, float))
    out = []
    if obstacles is None:
        obstacles = [from_spec(spec, 1.0) for spec in scene.get("obstacles", []) or []]   # scene units throughout
    for ob in obstacles:
        surface = obstacle_surface(ob, lo, hi)
        if surface is not None:
            out.append(Solid(type_name_of(ob), *surface))
    for spec in scene.get("supports", []) or []:
        if spec.get("kind") == "clamped" and spec.get("radius") is not None:
            centre = np.asarray(spec.get("centre", (0.0, 0.0)), float)[:2]
            inside = np.hypot(*(x_ref[:, :2] - centre).T) <= float(spec["radius"]) * (1 + 1e-9)
            z = float(np.mean(x_ref[inside, 2])) if inside.any() else float(np.min(x_ref[:, 2]))
            out.append(Solid("support disc", *support_disc(centre, float(spec["radius"]), z)))
    return out
