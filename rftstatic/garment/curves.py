"""Panel edges as plane curves: straight segments, circular arcs and Bézier curves, in panel coordinates [m].

An edge runs from point ``a`` to point ``b`` (2,) [m]:

- ``line``: the segment ab;
- ``arc``: the circular arc of radius r >= |ab| / 2 through a and b, given as GarmentCode writes it
  (``CircleEdge.assembly``, the SVG arc flags): ``right`` -- the arc's midpoint lies to the right of
  the chord a -> b; ``large`` -- the arc spans more than half the circle (angle > pi). With the chord
  c = |ab| and the half angle alpha = asin(c / 2r), the arc spans theta = 2 alpha (2 pi - 2 alpha if
  large), its length is r theta, and it turns about its centre counter-clockwise when ``right``,
  clockwise otherwise;
- ``bezier``: the quadratic or cubic Bézier curve with control points ``controls`` (k, 2) [m]
  (absolute panel coordinates); its arc length is integrated on a fine polyline.

:func:`edge_points` samples an edge uniformly by arc length: the nodes of a seam edge, so the two
sides of a seam with the same number of segments pair one to one. The outline and placement checks use the
mesher's vectorised crossing test, :func:`~rftstatic.mesh.mesher.domain.segments_cross`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["EDGE_KINDS", "arc_geometry", "edge_length", "edge_points", "edge_turning",
           "points_in_polygon"]

EDGE_KINDS = ("line", "arc", "bezier")

_FINE = 1024
"""Polyline segments on which a Bézier curve's arc length is integrated (relative error ~1e-7)."""


def arc_geometry(a, b, radius, *, large, right):
    """Centre (2,) [m], start angle [rad] and signed sweep [rad] (> 0 counter-clockwise) of an arc edge.

    Raises ``ValueError`` when the radius is below half the chord (no such arc).
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    c = float(np.hypot(*d))
    if not radius >= 0.5 * c * (1 - 1e-9):
        raise ValueError(f"arc radius {radius:g} m is smaller than half its chord ({0.5 * c:g} m)")
    half = float(np.arcsin(min(1.0, 0.5 * c / radius)))
    theta = 2 * np.pi - 2 * half if large else 2 * half
    left = np.array([-d[1], d[0]]) / c
    offset = np.sqrt(max(radius * radius - 0.25 * c * c, 0.0))
    # a small arc bulging right has its centre on the left of the chord; a large one on the right
    centre = 0.5 * (a + b) + (1.0 if right != large else -1.0) * offset * left
    phi = float(np.arctan2(a[1] - centre[1], a[0] - centre[0]))
    return centre, phi, theta if right else -theta


def _bernstein(points, t):
    """Bézier curve with control polygon ``points`` (k+1, 2) at parameters t (M,) -> (M, 2)."""
    k = len(points) - 1
    coef = np.array([math.comb(k, j) for j in range(k + 1)], dtype=float)
    j = np.arange(k + 1)
    basis = coef * t[:, None] ** j * (1 - t[:, None]) ** (k - j)
    return basis @ points


def _bezier_polygon(a, b, controls):
    return np.vstack([a, np.asarray(controls, float).reshape(-1, 2), b])


def edge_length(a, b, kind, *, radius=0.0, large=False, right=False, controls=()):
    """Arc length [m] of an edge from a to b (2,) [m] (module docstring for the kinds)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if kind == "line":
        return float(np.hypot(*(b - a)))
    if kind == "arc":
        _, _, sweep = arc_geometry(a, b, radius, large=large, right=right)
        return float(radius * abs(sweep))
    p = _bernstein(_bezier_polygon(a, b, controls), np.linspace(0.0, 1.0, _FINE + 1))
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def edge_turning(a, b, kind, *, radius=0.0, large=False, right=False, controls=()):
    """Total turning of the tangent along the edge [rad] (0 for a line); sets a curved edge's least
    number of segments."""
    if kind == "line":
        return 0.0
    if kind == "arc":
        return abs(arc_geometry(a, b, radius, large=large, right=right)[2])
    p = _bernstein(_bezier_polygon(a, b, controls), np.linspace(0.0, 1.0, 65))
    t = np.diff(p, axis=0)
    ang = np.arctan2(t[:, 1], t[:, 0])
    return float(np.abs(np.angle(np.exp(1j * np.diff(ang)))).sum())


def edge_points(a, b, n, kind, *, radius=0.0, large=False, right=False, controls=()):
    """``n + 1`` points (n+1, 2) [m] from a to b along the edge, equally spaced in arc length.

    The first and last points are a and b exactly.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    s = np.linspace(0.0, 1.0, int(n) + 1)
    if kind == "line":
        pts = a + s[:, None] * (b - a)
    elif kind == "arc":
        centre, phi, sweep = arc_geometry(a, b, radius, large=large, right=right)
        ang = phi + sweep * s
        pts = centre + radius * np.column_stack([np.cos(ang), np.sin(ang)])
    else:
        poly = _bezier_polygon(a, b, controls)
        t = np.linspace(0.0, 1.0, _FINE + 1)
        cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(_bernstein(poly, t), axis=0).T))])
        pts = _bernstein(poly, np.interp(s * cum[-1], cum, t))
    pts[0], pts[-1] = a, b
    return pts


def points_in_polygon(p, v, w=None):
    """(M,) bool: points p (M, 2) inside the closed polygon v (K, 2) (even-odd rule) [m].

    ``w`` (K, 2): the other end of each side (default: the next vertex), so that several loops (an
    outline and its holes) count together.
    """
    a, b = v[None], (np.roll(v, -1, axis=0) if w is None else w)[None]
    y = p[:, None, 1]
    cond = (a[..., 1] > y) != (b[..., 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = a[..., 0] + (y - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
    return (np.count_nonzero(cond & (p[:, None, 0] < xs), axis=1) % 2).astype(bool)
