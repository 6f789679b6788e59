"""Triangle-surface files and their checks, shared by the sheet's mesh file and a mesh obstacle's.

:func:`read_triangles` reads any surface meshio reads (OBJ, STL, PLY, VTU, MSH, ...) into points
``(P, 3)`` and triangles ``(T, 3)``; :func:`check_triangles` refuses what neither a sheet nor an obstacle
can use. Every error is a :class:`~rftstatic.errors.MeshError` that names the file, the problem (with
the first offending triangle, edge or node and where it is) and what to do.

Checks (:func:`check_triangles`):

* degenerate triangles: area below ``DEGENERATE_AREA`` times the squared bounding-box diagonal;
* duplicate triangles: two triangles on the same three nodes (in any order);
* non-manifold edges: an edge shared by three or more triangles;
* orientation (``oriented=True``: a closed obstacle, or an open one with a stated side): across every edge
  shared by two triangles the two must run the edge in opposite directions (a consistent winding).

Quadrilateral cells: ``quads="triangulate"`` splits each quad ``abcd`` into ``abc`` and ``acd`` (a mesh
obstacle: said in the returned notes), ``quads="refuse"`` refuses them (the sheet: its triangles are
its elements, a split would be the user's choice of diagonal).
"""

from __future__ import annotations

import numpy as np

from rftstatic.errors import MeshError

__all__ = ["DEGENERATE_AREA", "check_triangles", "edge_table", "read_triangles"]

DEGENERATE_AREA = 1e-14
"""A triangle is degenerate when its area is below this fraction of the squared bounding-box diagonal."""


_READ = {}
"""The last files :func:`read_triangles` read, by (path, size, modification time, quads): a run reads its body
mesh for the solve, the crossing check, the figures and the view (0.5 s per read of the dress form's OBJ)."""


def read_triangles(path, *, quads: str = "refuse") -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Read a triangle surface with meshio (a file read before and unchanged since: from memory, as copies).

    Parameters
    ----------
    path : file name (any format meshio reads)
    quads : ``"refuse"`` or ``"triangulate"`` (module docstring)

    Returns
    -------
    points : (P, 3) coordinates in the file's unit (a 2-D file gets z = 0)
    tri : (T, 3) int64 node indices
    notes : what was changed on the way in (quads split), one sentence each

    Raises
    ------
    MeshError
        An unreadable or empty file, no triangles, other cells, node indices out of range, NaN or inf.
    """
    import os

    try:
        stat = os.stat(path)
        key = (os.path.realpath(path), stat.st_size, stat.st_mtime_ns, quads)
    except OSError:
        key = None
    if key in _READ:
        P, tri, notes = _READ[key]
        return P.copy(), tri.copy(), list(notes)
    P, tri, notes = _read_triangles(path, quads)
    if key is not None:
        if len(_READ) >= 4:
            _READ.pop(next(iter(_READ)))
        _READ[key] = (P.copy(), tri.copy(), list(notes))
    return P, tri, notes


def _read_triangles(path, quads):
    """:func:`read_triangles` from the file."""
    import meshio

    try:
        m = meshio.read(path)
    except Exception as exc:  # meshio raises many types; re-raise with the file name
        raise MeshError(f"{path}: meshio could not read it ({exc}); check the file and its extension") from exc
    except SystemExit:  # meshio's VTU reader exits the interpreter on an empty or truncated file
        raise MeshError(f"{path}: meshio could not read it (an empty or truncated file?); export the mesh "
                        "again") from None
    kinds = sorted({c.type for c in m.cells})
    notes = []
    tris = [np.asarray(c.data, np.int64) for c in m.cells if c.type == "triangle"]
    quad = [np.asarray(c.data, np.int64) for c in m.cells if c.type == "quad"]
    if quad and quads == "triangulate":
        q = np.vstack(quad)
        tris.append(np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]))
        notes.append(f"{len(q)} quad cell(s) split into two triangles each (diagonal from a quad's first node)")
        kinds = [k for k in kinds if k != "quad"]
    if not tris:
        found = f"found {kinds}" if kinds else "the file has no cells (empty?)"
        raise MeshError(f"{path}: no triangle cells ({found}); export the surface as triangles")
    other = sorted(set(kinds) - {"triangle", "vertex", "line"})
    if other:
        what = "quad cells" if other == ["quad"] else f"{', '.join(other)} cells"
        raise MeshError(f"{path}: holds {what} besides triangles; split the other cells into triangles before "
                        "exporting")
    tri = np.vstack(tris)
    P = np.asarray(m.points, float)
    if P.ndim != 2 or P.shape[1] not in (2, 3) or len(P) == 0:
        raise MeshError(f"{path}: no node coordinates (points of shape {P.shape}); export the mesh again")
    if P.shape[1] == 2:
        P = np.c_[P, np.zeros(len(P))]
    if tri.min() < 0 or tri.max() >= len(P):
        bad = int(tri.max()) if tri.max() >= len(P) else int(tri.min())
        raise MeshError(f"{path}: a triangle names node {bad}, but the file has nodes 0..{len(P) - 1}")
    if not np.isfinite(P).all():
        raise MeshError(f"{path}: node coordinates are not all finite (NaN or inf)")
    return P, tri, notes


def edge_table(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Undirected edges of ``tri (T, 3)`` and who uses them.

    Returns
    -------
    edges : (M, 2) sorted node pairs
    edge_of : (T, 3) index into ``edges`` of the edge opposite local vertex k (nodes ``k+1, k+2``)
    count : (M,) number of triangles using each edge
    """
    a = tri[:, [1, 2, 0]].ravel()
    b = tri[:, [2, 0, 1]].ravel()
    pairs = np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1)
    edges, inverse, count = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
    return edges, inverse.reshape(-1, 3), count


def _at(P, nodes) -> str:
    c = P[np.asarray(nodes)].mean(axis=0)
    return "(" + ", ".join(f"{v:.6g}" for v in c) + ")"


def check_triangles(P: np.ndarray, tri: np.ndarray, *, where: str, oriented: bool = False) -> dict:
    """Refuse a triangle surface that is degenerate, duplicated, non-manifold or (``oriented``) inconsistently
    wound (module docstring).

    Parameters
    ----------
    P : (P, 3) node coordinates (any length unit)
    tri : (T, 3) node indices
    where : the file (or other source) named in the messages
    oriented : also require a consistent winding across shared edges

    Returns
    -------
    ``{"edges": (M, 2), "edge_of": (T, 3), "count": (M,), "closed": every edge shared by two triangles}``

    Raises
    ------
    MeshError
        Naming the first offending triangle or edge, where it is, and what to do.
    """
    P = np.asarray(P, float)
    tri = np.asarray(tri, np.int64)
    if P.shape[1] == 2:
        P = np.c_[P, np.zeros(len(P))]
    cross = np.cross(P[tri[:, 1]] - P[tri[:, 0]], P[tri[:, 2]] - P[tri[:, 0]])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    diag2 = float(np.sum(np.ptp(P[np.unique(tri)], axis=0) ** 2))
    tiny = area <= DEGENERATE_AREA * diag2
    if tiny.any():
        t = int(np.flatnonzero(tiny)[0])
        raise MeshError(f"{where}: {int(tiny.sum())} degenerate (zero-area) triangle(s), first: triangle {t} "
                        f"(nodes {tri[t].tolist()}) at {_at(P, tri[t])}; remove them or re-mesh the surface")
    key = np.sort(tri, axis=1)
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    if (count > 1).any():
        t = int(first[np.flatnonzero(count > 1)[0]])
        raise MeshError(f"{where}: {int((count - 1).sum())} duplicate triangle(s) (the same three nodes twice), "
                        f"first: nodes {sorted(tri[t].tolist())} at {_at(P, tri[t])}; remove the copies")
    edges, edge_of, count = edge_table(tri)
    if (count > 2).any():
        e = int(np.flatnonzero(count > 2)[0])
        raise MeshError(f"{where}: edge ({edges[e, 0]}, {edges[e, 1]}) at {_at(P, edges[e])} is shared by "
                        f"{int(count[e])} triangles (a non-manifold edge); the surface must have each edge in "
                        "at most two triangles: split the surface there or remove the extra triangles")
    if oriented:
        a = tri[:, [1, 2, 0]].ravel()
        b = tri[:, [2, 0, 1]].ravel()
        _, dcount = np.unique(np.stack([a, b], axis=1), axis=0, return_counts=True)
        if (dcount > 1).any():
            same = np.stack([a, b], axis=1)
            uniq, inv, dc = np.unique(same, axis=0, return_inverse=True, return_counts=True)
            j = int(np.flatnonzero(dc[inv.ravel()] > 1)[0])
            t = j // 3
            raise MeshError(f"{where}: inconsistent orientation: triangle {t} (nodes {tri[t].tolist()}) at "
                            f"{_at(P, tri[t])} runs edge ({same[j, 0]}, {same[j, 1]}) in the same direction as its "
                            "neighbour across it; re-orient the surface consistently (e.g. meshlab's 'Re-Orient "
                            "all faces coherently' or trimesh.repair.fix_winding)")
    return {"edges": edges, "edge_of": edge_of, "count": count, "closed": bool((count == 2).all())}
