"""Edge topology of a triangle mesh: which triangle lies across which edge (half-edge adjacency), computed
once with vectorised numpy; a non-manifold edge (in three or more triangles) is a :class:`MeshError`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import MeshError

__all__ = ["EdgeTopology", "edge_topology"]


@dataclass(frozen=True, eq=False)
class EdgeTopology:
    """Half-edge adjacency of a triangle mesh.

    Local edge k of element e is the edge opposite its vertex k, i.e. nodes
    ``tri[e, (k+1)%3], tri[e, (k+2)%3]``.

    Attributes
    ----------
    neighbour : (E, 3) int, element across local edge k, or -1 on the boundary
    neighbour_vertex : (E, 3) int, local vertex of the neighbour opposite the shared edge, or -1
    edges : (M, 2) int, unique edges (sorted node pairs)
    edge_of : (E, 3) int, index into ``edges`` of local edge k
    """

    neighbour: np.ndarray
    neighbour_vertex: np.ndarray
    edges: np.ndarray
    edge_of: np.ndarray

    @property
    def is_boundary(self) -> np.ndarray:
        """(E, 3) bool, local edge k has no neighbour."""
        return self.neighbour < 0


def edge_topology(tri: np.ndarray, n_nodes: int) -> EdgeTopology:
    E = len(tri)
    a = tri[:, [1, 2, 0]]
    b = tri[:, [2, 0, 1]]
    lo, hi = np.minimum(a, b).ravel(), np.maximum(a, b).ravel()
    key = lo.astype(np.int64) * n_nodes + hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    new = np.r_[True, ks[1:] != ks[:-1]]
    edge_id_sorted = np.cumsum(new) - 1
    edge_of = np.empty(3 * E, dtype=np.int64)
    edge_of[order] = edge_id_sorted
    counts = np.bincount(edge_id_sorted)
    if counts.max(initial=0) > 2:
        bad = np.flatnonzero(counts > 2)[0]
        first = order[np.searchsorted(edge_id_sorted, bad)]
        n0, n1 = lo[first], hi[first]
        raise MeshError(
            f"edge ({n0}, {n1}) is shared by {counts[bad]} triangles; the mesh must be a manifold "
            "surface (each edge in at most two triangles)"
        )
    unique_first = order[new]
    edges = np.stack([lo[unique_first], hi[unique_first]], axis=1)
    # pair the two half-edges of every interior edge: consecutive in sorted order
    neighbour = np.full(3 * E, -1, dtype=np.int64)
    pair = np.flatnonzero(~new)  # position j pairs with j-1
    h1, h0 = order[pair], order[pair - 1]
    neighbour[h0] = h1
    neighbour[h1] = h0
    nb_elem = np.where(neighbour >= 0, neighbour // 3, -1).reshape(E, 3)
    nb_vert = np.where(neighbour >= 0, neighbour % 3, -1).reshape(E, 3)
    return EdgeTopology(nb_elem, nb_vert, edges, edge_of.reshape(E, 3))
