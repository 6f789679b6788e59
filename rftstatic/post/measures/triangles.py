"""The triangle arrays every drape measure takes: their check and the half-edge keys.

A mesh here is ``x`` (N, 3) or (N, 2) node positions [m] (or any length unit) and ``tri`` (E, 3)
integer node indices; nothing else (no :class:`rftstatic.mesh.trimesh.TriMesh`) is needed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_mesh", "edge_keys"]


def check_mesh(x: np.ndarray, tri: np.ndarray, who: str) -> tuple[np.ndarray, np.ndarray]:
    """``(x, tri)`` as float (N, 2|3) and integer (E, 3) arrays; ``ValueError`` naming ``who`` otherwise.

    Parameters
    ----------
    x : (N, 3) or (N, 2) array_like
        Node positions [m].
    tri : (E, 3) array_like
        Triangles, E > 0, node indices in [0, N).
    who : str
        Name of the calling function, put at the head of the error message.
    """
    x = np.asarray(x, dtype=float)
    tri = np.asarray(tri)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"{who}: x.shape = {x.shape}, expected (N, 3) (or (N, 2))")
    if tri.ndim != 2 or tri.shape[1] != 3 or tri.shape[0] == 0:
        raise ValueError(f"{who}: tri.shape = {tri.shape}, expected (E, 3) with E > 0")
    if not np.issubdtype(tri.dtype, np.integer) or tri.min() < 0 or tri.max() >= len(x):
        raise ValueError(f"{who}: tri must hold integer node indices in [0, {len(x)}); "
                         f"got dtype {tri.dtype}, range [{tri.min()}, {tri.max()}]")
    return x, tri


def edge_keys(tri: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed half-edges (3E,) a→b of every triangle and their undirected keys.

    Half-edge ``3 e + i`` runs from ``tri[e, i]`` to ``tri[e, (i + 1) % 3]``; its key
    ``min(a, b) n + max(a, b)`` (int64) is shared by the two half-edges of an interior edge.

    Parameters
    ----------
    tri : (E, 3) int ndarray
        Triangles.
    n : int
        Number of nodes (or any bound above the largest index).

    Returns
    -------
    a, b, key : (3E,) int ndarrays
        Start node, end node and undirected key of every half-edge.
    """
    a = tri.reshape(-1)
    b = np.roll(tri, -1, axis=1).reshape(-1)
    key = np.minimum(a, b).astype(np.int64) * n + np.maximum(a, b)
    return a, b, key
