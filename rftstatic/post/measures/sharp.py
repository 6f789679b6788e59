"""Sharp-fold indicators (Sze & Zhou 2016, §3, Figs. 1 and 8): dihedral angles and |κ|h.

A dihedral angle between adjacent triangles, or a relative curvature |κ|h, far above its
neighbours' flags the non-physical folds RFT6 is meant to suppress.

- :func:`dihedral_angles`: the angle between the normals at every interior edge [rad];
- :func:`sharp_fold_indicator`: the largest dihedral angle and the largest |κ|h, and where they occur
  (|κ| is :func:`rftstatic.element.curvature.curvature_norm`).
"""

from __future__ import annotations

import numpy as np

from rftstatic.element.curvature import curvature_norm
from rftstatic.post.measures.triangles import check_mesh, edge_keys

__all__ = ["dihedral_angles", "sharp_fold_indicator"]


def _normals(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    p = x[tri]
    nrm = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    if np.any(ln == 0.0):
        raise ValueError(f"dihedral_angles: degenerate triangle(s) {np.flatnonzero(ln[:, 0] == 0)[:5]}")
    return nrm / ln


def dihedral_angles(x: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Angles between the normals of the two triangles at every interior edge.

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Consistently oriented triangles.

    Returns
    -------
    edges : (M, 2) int ndarray
        Interior edges as node pairs (smaller index first).
    angle : (M,) ndarray
        Angle between the adjacent normals [rad], 0 for a flat pair, π for a sheet folded
        flat onto itself (atan2 of |n₁×n₂| and n₁·n₂, accurate at both ends).

    Raises
    ------
    ValueError
        If an edge is shared by more than two triangles.
    """
    x, tri = check_mesh(x, tri, "dihedral_angles")
    n = len(x)
    a, b, key = edge_keys(tri, n)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    _, counts = np.unique(ks, return_counts=True)
    if counts.max(initial=0) > 2:
        raise ValueError(f"dihedral_angles: {int(np.sum(counts > 2))} edge(s) shared by more than "
                         "two triangles; the mesh must be a manifold")
    pair = np.flatnonzero(ks[1:] == ks[:-1])
    h1, h2 = order[pair], order[pair + 1]                   # half-edges; triangle = half-edge // 3
    nrm = _normals(x, tri)
    n1, n2 = nrm[h1 // 3], nrm[h2 // 3]
    ang = np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1), np.einsum("mi,mi->m", n1, n2))
    edges = np.stack([np.minimum(a[h1], b[h1]), np.maximum(a[h1], b[h1])], axis=1)
    return edges, ang


def sharp_fold_indicator(x: np.ndarray, tri: np.ndarray, curvature: np.ndarray | None = None,
                         h: np.ndarray | None = None) -> dict:
    """Largest relative curvature |κ|h and largest dihedral angle, and where they occur.

    Parameters
    ----------
    x : (N, 3) ndarray
        Node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    curvature : (E, 3) ndarray, optional
        Curvature vector (κ_xx, κ_yy, 2κ_xy) per element [1/m]; see
        :func:`rftstatic.element.curvature.curvature_norm`.
    h : (E,) ndarray, optional
        Element size [m], the mean side length (``mesh.element_size``, the h of §2.2 and
        Eq. 28); needed with ``curvature``.

    Returns
    -------
    dict
        ``max_dihedral_deg`` [deg], ``median_dihedral_deg`` [deg], ``max_dihedral_edge``
        (node pair), ``max_dihedral_at`` (edge mid-point, [m]); with curvature also
        ``max_relative_curvature`` [-] (max |κ|h), ``max_relative_curvature_element`` and
        ``max_relative_curvature_at`` (element centroid, [m]). Plain Python values.
    """
    x, tri = check_mesh(x, tri, "sharp_fold_indicator")
    out: dict = {}
    edges, ang = dihedral_angles(x, tri)
    if ang.size:
        i = int(np.argmax(ang))
        out.update(max_dihedral_deg=float(np.degrees(ang[i])),
                   median_dihedral_deg=float(np.degrees(np.median(ang))),
                   max_dihedral_edge=[int(edges[i, 0]), int(edges[i, 1])],
                   max_dihedral_at=[float(v) for v in x[edges[i]].mean(axis=0)])
    if curvature is not None:
        if h is None:
            raise ValueError("sharp_fold_indicator: curvature given without h; pass the element "
                             "sizes h (E,) [m]")
        hh = np.asarray(h, dtype=float).reshape(-1)
        if hh.shape[0] != len(tri) or np.shape(curvature)[0] != len(tri):
            raise ValueError(f"sharp_fold_indicator: len(tri) = {len(tri)}, but len(curvature) = "
                             f"{np.shape(curvature)[0]} and len(h) = {hh.shape[0]}")
        rel = curvature_norm(curvature) * hh
        j = int(np.argmax(rel))
        out.update(max_relative_curvature=float(rel[j]), max_relative_curvature_element=j,
                   max_relative_curvature_at=[float(v) for v in x[tri[j]].mean(axis=0)])
    return out
