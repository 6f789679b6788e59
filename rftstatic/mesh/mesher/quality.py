"""Mesh quality figures returned with every mesh."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from rftstatic.mesh.mesher.improve import triangle_angles

__all__ = ["MeshQuality", "measure_quality", "unique_edges", "BAND"]

BAND = (0.7, 1.4)   # an edge "follows the size field" when length / h(midpoint) lies in this band


@dataclass(frozen=True)
class MeshQuality:
    """Quality of a triangulation against its size field.

    Attributes
    ----------
    min_angle : smallest interior angle of all triangles [deg]
    mean_min_angle : mean over triangles of each triangle's smallest angle [deg]
    band_share : share of edges with length / h(midpoint) in ``BAND`` = [0.7, 1.4]
    edge_ratio_min, edge_ratio_max : extreme length / h(midpoint) ratios
    n_nodes, n_triangles : counts
    wall_time : seconds spent in :func:`~rftstatic.mesh.mesher.generate` [s]
    triangles_per_second : n_triangles / wall_time [1/s]
    """

    min_angle: float
    mean_min_angle: float
    band_share: float
    edge_ratio_min: float
    edge_ratio_max: float
    n_nodes: int
    n_triangles: int
    wall_time: float
    triangles_per_second: float

    def as_dict(self):
        """Plain ``dict`` of the fields (JSON-serialisable)."""
        return asdict(self)


def unique_edges(tri):
    """(M, 2) int64 sorted node pairs of the distinct edges of ``tri`` (E, 3)."""
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e, axis=0)


def measure_quality(points, tri, size_field, wall_time=float("nan")):
    """Compute :class:`MeshQuality`.

    Parameters
    ----------
    points : (N, 2) [m]
    tri : (E, 3) counter-clockwise
    size_field : BackgroundGrid giving h [m]
    wall_time : generation time [s]
    """
    ang = np.degrees(triangle_angles(points, tri).min(axis=1))
    e = unique_edges(tri)
    a, b = points[e[:, 0]], points[e[:, 1]]
    ratio = np.hypot(*(b - a).T) / size_field.size_at(0.5 * (a + b))
    inside = (ratio >= BAND[0]) & (ratio <= BAND[1])
    return MeshQuality(
        min_angle=float(ang.min()),
        mean_min_angle=float(ang.mean()),
        band_share=float(inside.mean()),
        edge_ratio_min=float(ratio.min()),
        edge_ratio_max=float(ratio.max()),
        n_nodes=int(len(points)),
        n_triangles=int(len(tri)),
        wall_time=float(wall_time),
        triangles_per_second=float(len(tri) / wall_time) if wall_time > 0 else float("nan"),
    )
