"""``generate``: domain + size field -> triangle mesh with quality figures."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from rftstatic.errors import MeshingError
from rftstatic.mesh.mesher.domain import Domain
from rftstatic.mesh.mesher.front import advance_front
from rftstatic.mesh.mesher.improve import improve
from rftstatic.mesh.mesher.quality import MeshQuality, measure_quality
from rftstatic.mesh.mesher.sizefield import BackgroundGrid

__all__ = ["MeshResult", "generate"]

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class MeshResult:
    """A generated mesh.

    Attributes
    ----------
    points : (N, 2) float64 node coordinates [m]; boundary nodes come first
    triangles : (E, 3) int64 counter-clockwise node indices
    boundary : (N,) bool, True on boundary nodes (which lie exactly on the loops)
    boundary_edges : (B, 2) int64 discretised loop edges, domain on their left
    boundary_loop : (B,) int64 loop index of each boundary edge (0 outer, k hole k-1)
    quality : :class:`MeshQuality`
    size_field : the :class:`BackgroundGrid` used
    """

    points: np.ndarray
    triangles: np.ndarray
    boundary: np.ndarray
    boundary_edges: np.ndarray
    boundary_loop: np.ndarray
    quality: MeshQuality
    size_field: BackgroundGrid


def generate(domain, size_field, *, smooth_iterations=4, max_steps=None):
    """Advancing-front triangle mesh of ``domain`` following ``size_field``.

    Parameters
    ----------
    domain : :class:`Domain`
    size_field : :class:`BackgroundGrid`, or a number for a uniform size [m]
    smooth_iterations : smoothing + flipping cycles after the front closes
        (0 keeps only the Delaunay flips)
    max_steps : optional cap on front steps (default: generous estimate)

    Returns
    -------
    :class:`MeshResult`; deterministic for given inputs.

    Notes
    -----
    Measured on rectangles, discs, annuli, an L-shape with a hole and size
    fields graded 1:20: minimum angle >= 32 deg, mean minimum angle >= 50 deg,
    >= 98 % of edges within [0.7, 1.4] h, 10-15 k triangles/s.  Boundary
    nodes are fixed, so input corners sharper than ~60 deg, or a size close to
    the width of a narrow part, can leave angles below 30 deg there.

    Raises
    ------
    MeshingError
        For invalid input (see :class:`Domain`, :class:`BackgroundGrid`), a
        size field not covering the domain or larger than it, or a front that
        cannot be closed.
    """
    t0 = time.perf_counter()
    if not isinstance(domain, Domain):
        raise MeshingError(f"domain must be a rftstatic.mesh.mesher.Domain, got {type(domain).__name__}")
    if isinstance(size_field, (int, float, np.floating, np.integer)):
        size_field = BackgroundGrid.uniform(float(size_field), domain)
    if not isinstance(size_field, BackgroundGrid):
        raise MeshingError(f"size_field must be a BackgroundGrid or a number [m], got {type(size_field).__name__}")
    if int(smooth_iterations) < 0:
        raise MeshingError(f"smooth_iterations = {smooth_iterations!r} must be >= 0")
    dbox, gbox = domain.bbox, size_field.bbox
    tol = 1e-9 * max(dbox[2] - dbox[0], dbox[3] - dbox[1])
    if (gbox[:2] > dbox[:2] + tol).any() or (gbox[2:] < dbox[2:] - tol).any():
        raise MeshingError(
            f"the background grid covers {tuple(np.round(gbox, 12))} but the domain's bounding box is "
            f"{tuple(np.round(dbox, 12))}; build the grid with the domain as region")
    extent = min(dbox[2] - dbox[0], dbox[3] - dbox[1])
    if size_field.h_min > extent:
        raise MeshingError(
            f"the smallest target size {size_field.h_min:g} m exceeds the domain's width {extent:g} m; "
            "use sizes below the domain size (h_upper)")

    bpoints, bedges, bloop = domain.discretise(size_field)
    points, tri = advance_front(bpoints, bedges, size_field, max_steps=max_steps)
    t_front = time.perf_counter() - t0
    boundary = np.zeros(len(points), dtype=bool)
    boundary[: len(bpoints)] = True
    improve(points, tri, ~boundary, smooth_iterations=int(smooth_iterations))
    wall = time.perf_counter() - t0
    quality = measure_quality(points, tri, size_field, wall)
    log.info("mesher: %d nodes, %d triangles in %.3f s (front %.3f s); min angle %.1f deg",
             len(points), len(tri), wall, t_front, quality.min_angle)
    return MeshResult(points=points, triangles=tri, boundary=boundary, boundary_edges=bedges,
                      boundary_loop=bloop, quality=quality, size_field=size_field)
