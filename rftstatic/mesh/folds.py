"""Fold lines of a mesh: edges where the sheet is creased to a rest angle (a hem turned back, a pressed pleat).

A :class:`FoldLines` names mesh edges (node pairs) across which the fabric is not smooth: the RF patches of the
elements on either side end there (each side sees a free edge, the image rule of Fig. 4b,
:func:`rftstatic.element.patch.build_patches`), and a hinge across each edge holds the crease at its rest
dihedral angle (:mod:`rftstatic.element.hinge`). A garment's ``fold`` seams give them
(:func:`rftstatic.garment.sewing.sew`); any mesh may carry them (:attr:`rftstatic.mesh.trimesh.TriMesh.folds`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import MeshError

__all__ = ["FoldLines", "fold_edge_mask"]


@dataclass(frozen=True, eq=False)
class FoldLines:
    """Creased edges and their rest state.

    Attributes
    ----------
    edges : (F, 2) int, node pairs of the creased edges (each an interior edge of the mesh: two triangles)
    angle : (F,) rest dihedral angle of each crease [rad] (0 flat, +-pi turned back onto itself), signed in the
        hinge's frame (:func:`rftstatic.element.hinge.fold_hinges`: triangle 1 the lower-numbered element)
    width : (F,) the crease's width [m]: the hinge spreads the fold's curvature over it (its stiffness is B |e| / w,
        :mod:`rftstatic.element.hinge`); NaN: the two triangles' mean height over the edge
    """

    edges: np.ndarray
    angle: np.ndarray
    width: np.ndarray

    def __post_init__(self):
        edges = np.asarray(self.edges, dtype=np.int64).reshape(-1, 2)
        angle = np.broadcast_to(np.asarray(self.angle, float), (len(edges),)).copy()
        width = np.broadcast_to(np.asarray(self.width, float), (len(edges),)).copy()
        if (edges[:, 0] == edges[:, 1]).any():
            raise MeshError("a fold edge joins a node to itself")
        if not np.isfinite(angle).all() or (np.abs(angle) > np.pi + 1e-12).any():
            raise MeshError("fold angles must be finite and within [-pi, pi] rad")
        if (width[np.isfinite(width)] <= 0).any():
            raise MeshError("fold widths must be > 0 (NaN: the elements' height over the edge)")
        for name, a in (("edges", edges), ("angle", angle), ("width", width)):
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    def __len__(self) -> int:
        return len(self.edges)


def fold_edge_mask(topology, folds: FoldLines | None, n_nodes: int) -> np.ndarray:
    """(E, 3) bool: local edge k of element e is a fold edge (``topology``:
    :class:`rftstatic.mesh.topology.EdgeTopology`). A fold edge that is not an interior edge of the mesh is a
    :class:`~rftstatic.errors.MeshError`."""
    mask = np.zeros(topology.edge_of.shape, dtype=bool)
    if folds is None or len(folds) == 0:
        return mask
    key = lambda e: np.minimum(e[:, 0], e[:, 1]) * n_nodes + np.maximum(e[:, 0], e[:, 1])  # noqa: E731
    mesh_keys = key(topology.edges)
    fold_keys = key(folds.edges)
    where = np.searchsorted(mesh_keys, fold_keys)
    found = (where < len(mesh_keys)) & (mesh_keys[np.minimum(where, len(mesh_keys) - 1)] == fold_keys)
    if not found.all():
        e = folds.edges[np.flatnonzero(~found)[0]]
        raise MeshError(f"fold edge ({e[0]}, {e[1]}) is not an edge of the mesh")
    is_fold = np.zeros(len(mesh_keys), dtype=bool)
    is_fold[where] = True
    mask = is_fold[topology.edge_of]
    lone = mask & (topology.neighbour < 0)
    if lone.any():
        e, k = (int(v[0]) for v in np.nonzero(lone))
        raise MeshError(f"fold edge of element {e} (local edge {k}) lies on the mesh's boundary: a crease needs a "
                        "triangle on each side")
    return mask
