"""The clamping disc of a drape tester (Cusick: BS 5058, ISO 9073-9) as the drape measures need it.

The specimen is held between two discs; the scene clamps the nodes within the disc's radius
(``[[supports]] radius``). The mesh may cover the disc (its nodes inside are clamped) or stop at its
edge (an annulus whose inner ring is clamped, with zero slope across it): either way the disc is the
convex hull of the clamped nodes, its area A_disc, and the specimen's area is the mesh's plus the
part of the disc the mesh leaves open. The shadow is the union of the draped sheet's projection and
the disc (:func:`disc_fill` gives the disc as triangles to add to the shadow only).

Lengths in the units of the coordinates (SI inside the package), areas in their square.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Disc", "clamp_disc"]


class Disc(NamedTuple):
    """A clamping disc.

    Attributes
    ----------
    centre : (2,) centre [m]
    area : area of the convex hull of the clamped nodes, A_disc [m^2]
    open_area : the part of it no mesh triangle covers (the hole of an annulus) [m^2]
    fill : (H, 3, 3) the disc as a fan of triangles (z of the clamped nodes), for the shadow
    """

    centre: np.ndarray
    area: float
    open_area: float
    fill: np.ndarray


def clamp_disc(X3: np.ndarray, tri: np.ndarray, nodes: np.ndarray, centre) -> Disc:
    """The disc spanned by the clamped ``nodes`` of a mesh with reference positions ``X3 (N, 3)`` [m] and
    triangles ``tri (E, 3)``; ``centre (2,)`` [m] the disc's axis."""
    from scipy.spatial import ConvexHull

    nodes = np.asarray(nodes, dtype=np.int64)
    hull = ConvexHull(X3[nodes, :2])
    ring = nodes[hull.vertices]                               # counter-clockwise
    area = float(hull.volume)                                 # 2-D: volume is the area
    inside = np.zeros(len(X3), bool)
    inside[nodes] = True
    p = X3[tri[inside[tri].all(axis=1)]][:, :, :2]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    covered = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    c = np.array([centre[0], centre[1], float(X3[ring, 2].mean())])
    a, b = X3[ring], X3[np.roll(ring, -1)]
    fill = np.stack([np.broadcast_to(c, a.shape), a, b], axis=1)
    return Disc(np.asarray(centre, float)[:2], area, max(area - float(covered), 0.0), fill)
