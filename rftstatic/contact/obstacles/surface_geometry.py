"""Closest points on a triangle surface, its pseudo-normals and winding number, over many points at once.

The signed distance of a point ``x`` to a triangle surface is ``phi = s r``, ``r = |x - c|`` the distance
to the closest point ``c`` (:func:`closest_on_triangles`: Ericson, *Real-Time Collision Detection*,
§5.1.5, the seven Voronoi regions of a triangle, here vectorised over point-triangle pairs) and ``s`` the
side: ``sign((x - c) . n_f)`` with ``n_f`` the angle-weighted pseudo-normal of the closest feature (a face's
normal, the sum of an edge's two face normals, the incident face normals of a vertex weighted by their
corner angles; Baerentzen & Aanaes, IEEE TVCG 11, 2005: exact for a closed, consistently oriented
surface). Its derivatives, where the closest feature is unique:

    grad phi = s u,  u = (x - c) / r;
    hess phi = 0 (a face),  s (I - u u^T - t t^T) / r (an edge of unit direction t),  s (I - u u^T) / r (a vertex),

positive semi-definite times ``s`` and unbounded as ``r -> 0`` at an edge or a vertex: the curvature of
the distance to a sharp feature.

:func:`winding_number` (the generalised winding number, Jacobson et al., SIGGRAPH 2013: the sum of the
triangles' signed solid angles over 4 pi, Van Oosterom & Strackee's formula) tells inside (1) from outside (0)
for points far from the surface, where no closest feature is computed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FACE", "EDGE", "VERTEX", "closest_on_triangles", "merge_nodes", "plan_hull", "polygon_area_centre",
           "pseudo_normals", "rotation", "sharp_edges", "winding_number"]

FACE, EDGE, VERTEX = 0, 1, 2
"""Closest-feature kinds of :func:`closest_on_triangles`."""


def _dot(a, b):
    return np.einsum("pi,pi->p", a, b)


def closest_on_triangles(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray):
    """Closest point on triangle ``abc`` to ``p``, for ``P`` pairs at once.

    Parameters
    ----------
    p, a, b, c : (P, 3) the points and the triangles' corners [m]

    Returns
    -------
    q : (P, 3) closest points [m]
    kind : (P,) int8, :data:`FACE`, :data:`EDGE` or :data:`VERTEX`
    local : (P,) int8, the vertex (0, 1, 2 for a, b, c), or the edge by its opposite vertex (0: bc, 1: ca,
        2: ab); 0 for a face
    """
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = p - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = p - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        den = va + vb + vc
        v, w = vb / den, vc / den
    regions = [  # Ericson's order: the first true region wins
        ((d1 <= 0) & (d2 <= 0), VERTEX, 0, (1.0, 0.0, 0.0)),
        ((d3 >= 0) & (d4 <= d3), VERTEX, 1, (0.0, 1.0, 0.0)),
        ((vc <= 0) & (d1 >= 0) & (d3 <= 0), EDGE, 2, (1 - t_ab, t_ab, 0.0)),
        ((d6 >= 0) & (d5 <= d6), VERTEX, 2, (0.0, 0.0, 1.0)),
        ((vb <= 0) & (d2 >= 0) & (d6 <= 0), EDGE, 1, (1 - t_ac, 0.0, t_ac)),
        ((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), EDGE, 0, (0.0, 1 - t_bc, t_bc)),
    ]
    n = len(p)
    kind = np.full(n, FACE, np.int8)
    local = np.zeros(n, np.int8)
    wa, wb, wc = 1.0 - v - w, v, w
    decided = np.zeros(n, bool)
    for cond, k, j, (ba, bb, bc) in regions:  # six regions of a triangle, not a loop over pairs
        take = cond & ~decided
        kind[take], local[take] = k, j
        wa = np.where(take, ba, wa)
        wb = np.where(take, bb, wb)
        wc = np.where(take, bc, wc)
        decided |= take
    q = wa[:, None] * a + wb[:, None] * b + wc[:, None] * c
    return q, kind, local


def face_normals(V: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals ``(T, 3)`` (right-hand rule of the node order) and corner angles ``(T, 3)`` [rad]."""
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    angles = np.empty((len(T), 3))
    for k in range(3):  # the three corners
        p, q, r = (a, b, c)[k], (a, b, c)[(k + 1) % 3], (a, b, c)[(k + 2) % 3]
        e1, e2 = q - p, r - p
        cos = _dot(e1, e2) / (np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1))
        angles[:, k] = np.arccos(np.clip(cos, -1.0, 1.0))
    return n, angles


def pseudo_normals(V: np.ndarray, T: np.ndarray, edge_of: np.ndarray, n_edges: int):
    """Angle-weighted pseudo-normals of the faces ``(T, 3)``, edges ``(M, 3)`` and vertices ``(V, 3)`` (unit).

    ``edge_of (T, 3)``: the edge opposite each local vertex (:func:`rftstatic.mesh.surface.edge_table`).
    """
    nf, angles = face_normals(V, T)
    ne = np.zeros((n_edges, 3))
    np.add.at(ne, edge_of.ravel(), np.repeat(nf, 3, axis=0))
    nv = np.zeros((len(V), 3))
    np.add.at(nv, T.ravel(), (angles[:, :, None] * nf[:, None, :]).reshape(-1, 3))
    for arr in (ne, nv):
        length = np.linalg.norm(arr, axis=1, keepdims=True)
        arr /= np.where(length > 0, length, 1.0)
    return nf, ne, nv


def winding_number(x: np.ndarray, V: np.ndarray, T: np.ndarray, chunk: int = 2_000_000) -> np.ndarray:
    """Generalised winding number ``(N,)`` of the points ``x (N, 3)`` [m] about the surface ``V, T``: 1 inside
    a closed outward-oriented surface, 0 outside (module docstring). Costs ``N T`` solid angles, in chunks
    of ``chunk`` pairs."""
    out = np.zeros(len(x))
    step = max(1, chunk // max(len(T), 1))
    A, B, C = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    for s in range(0, len(x), step):  # chunks of points, so the pair arrays stay bounded
        p = x[s:s + step, None, :]
        a, b, c = A[None] - p, B[None] - p, C[None] - p
        la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
        det = np.einsum("pti,pti->pt", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("pti,pti->pt", a, b) * lc + np.einsum("pti,pti->pt", b, c) * la
               + np.einsum("pti,pti->pt", c, a) * lb)
        out[s:s + step] = np.arctan2(det, den).sum(axis=1) / (2.0 * np.pi)
    return out


def sharp_edges(V, T, edges, edge_of, nf, ne, boundary_edge, feature_angle, *, two_sided=False):
    """The sharp features of a triangle surface ``V (n, 3)`` [m], ``T (t, 3)`` with unique ``edges (m, 2)``,
    ``edge_of (t, 3)``, face and edge pseudo-normals ``nf``, ``ne``: the convex edges whose faces meet at more than
    ``feature_angle`` [deg] from flat and the open boundary (``boundary_edge (m,)``); returns ``(feature edges
    (k, 2), their outward normals (k, 3), corners (c,))``, the corners the ends or junctions of feature edges. An
    open rim's outward direction lies in its face's plane, away from it, tilted along the face's normal for a
    one-sided surface (not ``two_sided``)."""
    e_tris = np.full((len(edges), 2), -1, np.int64)
    flat = edge_of.ravel()
    order = np.argsort(flat, kind="stable")
    start = np.searchsorted(flat[order], np.arange(len(edges)))
    e_tris[:, 0] = order[start] // 3
    two = boundary_edge == False  # noqa: E712 (numpy)
    e_tris[two, 1] = order[start[two] + 1] // 3
    n0, n1 = nf[e_tris[:, 0]], nf[np.maximum(e_tris[:, 1], 0)]
    bend = np.degrees(np.arccos(np.clip(np.einsum("ei,ei->e", n0, n1), -1.0, 1.0)))
    # convex: the far corner of the second face lies behind the first face's plane
    t1 = T[np.maximum(e_tris[:, 1], 0)]
    far = V[t1].sum(axis=1) - V[edges].sum(axis=1)  # the corner not on the edge
    convex = np.einsum("ei,ei->e", far - V[edges[:, 0]], n0) < 0
    sharp = (two & convex & (bend > feature_angle)) | boundary_edge
    # an open rim's outward direction: in the plane of its face, away from it (and along the face's normal
    # for a one-sided surface)
    rim = boundary_edge
    e0, e1 = V[edges[rim, 0]], V[edges[rim, 1]]
    nr = nf[e_tris[rim, 0]]
    out = np.cross(nr, e1 - e0)
    third = V[T[e_tris[rim, 0]]].sum(axis=1) - e0 - e1
    out *= np.where(np.einsum("ei,ei->e", out, 0.5 * (e0 + e1) - third) < 0, -1.0, 1.0)[:, None]
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    if not two_sided:
        out = out + nr
        out /= np.linalg.norm(out, axis=1, keepdims=True)
    normals = ne.copy()
    normals[rim] = out
    deg = np.bincount(edges[sharp].ravel(), minlength=len(V))
    return edges[sharp], normals[sharp], np.flatnonzero((deg > 0) & (deg != 2))


def rotation(angles_deg) -> np.ndarray:
    """Rotation matrix (3, 3) of the angles [deg] about x, then y, then z."""
    rx, ry, rz = np.radians(np.asarray(angles_deg, float))
    cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def merge_nodes(P, tri):
    """Merge coincident nodes (1e-12 of the bounding-box diagonal; an STL file repeats them per facet)."""
    diag = float(np.linalg.norm(np.ptp(P, axis=0))) or 1.0
    key = np.round(P / (1e-12 * diag)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    used = np.unique(inverse.ravel()[tri.ravel()])
    remap = np.full(len(first), -1, np.int64)
    remap[used] = np.arange(len(used))
    return P[first[used]], remap[inverse.ravel()[tri]]


def plan_hull(V, offset: float = 0.0, around: int = 32):
    """The convex hull ``(k, 2)`` [m] (counter-clockwise) of the points ``V (n, 3)`` [m] seen from above, grown by
    ``offset`` [m] (a rounded surface's: each hull corner's circle of ``around`` points), and the mean height [m] of
    the hull's corners."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(V[:, :2])
    xy, z = V[hull.vertices, :2], float(V[hull.vertices, 2].mean())
    if offset > 0:
        t = 2.0 * np.pi * np.arange(around) / around
        ring = (xy[:, None, :] + offset * np.stack([np.cos(t), np.sin(t)], -1)).reshape(-1, 2)
        xy = ring[ConvexHull(ring).vertices]
    return xy.copy(), z


def polygon_area_centre(xy):
    """Area [m^2] and centroid (2,) [m] of the counter-clockwise polygon ``xy (k, 2)`` [m] (the shoelace formula)."""
    x, y = xy[:, 0], xy[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    area = 0.5 * cross.sum()
    centre = np.array([np.sum((x + np.roll(x, -1)) * cross), np.sum((y + np.roll(y, -1)) * cross)]) / (6 * area)
    return float(area), centre
