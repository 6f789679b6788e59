"""Broad phase of self-contact: the point-triangle and edge-edge pairs of the sheet that may be closer
than a radius, by a uniform grid of cells over axis-aligned boxes, and the cache that rebuilds them
only when some node has moved more than ``margin / 2``.

Every primitive gets a box: a node the box of its position (or of its path ``x0 -> x1`` for a
swept test), a triangle or an edge the box of its nodes' boxes; triangles are inflated by the radius
``r``, edges by ``r / 2`` each, so that two primitives closer than ``r`` always have overlapping boxes
(any axis on which the boxes are more than ``r`` apart separates the primitives by more than ``r``).
Boxes are written into the cells of a grid of size ``c`` (the mean largest extent of the triangle
boxes, swept ones for a swept test). Two paths, same pairs in the same order:

* compiled (numba installed, :func:`.distance.compiled_for`; loops in :mod:`.grid`): the entries of
  one kind are counting-sorted by cell (or ``argsort``-ed on a sparse grid); every box of the other
  kind visits its cells and keeps a listed box if the boxes overlap and share no node, once (a stamp
  per box marks the pairs met in an earlier common cell: no deduplication pass);
* numpy: cell keys sorted (``argsort``), every pair of entries of the two kinds that share a cell a
  candidate, kept as above and deduplicated by ``np.unique`` on the pair key (a loop over the three
  axes only).

The candidates of a flat or gently crumpled sheet are its neighbours one ring of elements away
(their boxes overlap, their distance is an element size); only pairs closer than the thickness enter
the law. A swept test of a long step costs several builds (tall boxes overlap many boxes: the smooth
7 cm step of the 81 x 81 sheet lists 1.06 M pairs against 44,000): the step bound of :mod:`.law` uses
it only when the step's relative motion could bring an unlisted pair into contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.contact.self_contact import distance

__all__ = ["Pairs", "SheetPrimitives", "find_pairs", "PairCache", "brute_force_pairs"]


@dataclass(frozen=True)
class Pairs:
    """Candidate pairs of one broad phase.

    Attributes
    ----------
    pt : (Q, 2) int, ``(node, triangle)`` with the node not a vertex of the triangle
    ee : (R, 2) int, ``(edge, edge)`` with ``e_1 < e_2`` and no shared node
    """

    pt: np.ndarray
    ee: np.ndarray

    @classmethod
    def empty(cls) -> Pairs:
        z = np.zeros((0, 2), dtype=np.int64)
        return cls(z, z.copy())

    def __len__(self) -> int:
        return len(self.pt) + len(self.ee)


@dataclass(frozen=True)
class SheetPrimitives:
    """The primitives of a triangle mesh: ``tri (T, 3)`` and ``edges (M, 2)`` node indices, ``n_nodes``;
    ``joined (N,)``: the node each node becomes once the mesh's open seams are sewn (a panel mesh being closed,
    :attr:`rftstatic.mesh.trimesh.TriMesh.seams`), or None. Primitives that will share a node once sewn are no
    pair: the two sides of a seam meet there, they are not in contact."""

    tri: np.ndarray
    edges: np.ndarray
    n_nodes: int
    joined: np.ndarray | None = None

    @classmethod
    def of_mesh(cls, mesh) -> SheetPrimitives:
        """From a :class:`~rftstatic.mesh.trimesh.TriMesh` (its unique edges and its open seams)."""
        seams = getattr(mesh, "seams", None)
        joined = None
        if seams is not None and len(seams):
            from scipy.sparse import coo_matrix
            from scipy.sparse.csgraph import connected_components

            n = mesh.n_nodes
            g = coo_matrix((np.ones(len(seams)), (seams[:, 0], seams[:, 1])), shape=(n, n))
            joined = connected_components(g, directed=False)[1].astype(np.int64)
        return cls(np.asarray(mesh.tri, np.int64), np.asarray(mesh.topology.edges, np.int64), mesh.n_nodes, joined)


def _drop_joined(prims: SheetPrimitives, pairs: Pairs) -> Pairs:
    """``pairs`` without those whose primitives share a node once the seams are sewn (:class:`SheetPrimitives`)."""
    j = prims.joined
    if j is None:
        return pairs
    pt, ee = pairs.pt, pairs.ee
    keep_pt = ~(j[pt[:, :1]] == j[prims.tri[pt[:, 1]]]).any(axis=1)
    a, b = j[prims.edges[ee[:, 0]]], j[prims.edges[ee[:, 1]]]
    keep_ee = ~((a[:, :1] == b).any(axis=1) | (a[:, 1:] == b).any(axis=1))
    return Pairs(pt[keep_pt], ee[keep_ee])


def _node_boxes(x0, x1):
    if x1 is None:
        return x0, x0
    return np.minimum(x0, x1), np.maximum(x0, x1)


def _cells(lo, hi, origin, cell, dims):
    """Cells covered by the boxes ``lo, hi (B, 3)``: ``(owner (K,), key (K,))``."""
    c0 = np.floor((lo - origin) / cell).astype(np.int64)
    c1 = np.floor((hi - origin) / cell).astype(np.int64)
    n = c1 - c0 + 1  # (B, 3)
    tot = n.prod(axis=1)
    owner = np.repeat(np.arange(len(lo)), tot)
    start = np.cumsum(tot) - tot
    j = np.arange(int(tot.sum())) - np.repeat(start, tot)
    nx, ny = n[owner, 0], n[owner, 1]
    ix = c0[owner, 0] + j % nx
    iy = c0[owner, 1] + (j // nx) % ny
    iz = c0[owner, 2] + j // (nx * ny)
    return owner, ix + dims[0] * (iy + dims[1] * iz)


def _join(own_a, key_a, own_b, key_b, *, same=False):
    """Every ``(a, b)`` whose cells coincide (``same``: a self-join, only ``a < b``)."""
    oa, ob = np.argsort(key_a, kind="stable"), np.argsort(key_b, kind="stable")
    ka, kb = key_a[oa], key_b[ob]
    ua, sa, ca = np.unique(ka, return_index=True, return_counts=True)
    ub, sb, cb = np.unique(kb, return_index=True, return_counts=True)
    _, ia, ib = np.intersect1d(ua, ub, assume_unique=True, return_indices=True)
    ca, cb, sa, sb = ca[ia], cb[ib], sa[ia], sb[ib]
    n = ca * cb
    g = np.repeat(np.arange(len(n)), n)
    local = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    a = own_a[oa[sa[g] + local // cb[g]]]
    b = own_b[ob[sb[g] + local % cb[g]]]
    if same:
        keep = a < b
        a, b = a[keep], b[keep]
    return a, b


def _overlap(lo_a, hi_a, lo_b, hi_b):
    return np.all((lo_a <= hi_b) & (lo_b <= hi_a), axis=1)


def _unique_pairs(a, b, nb):
    key = np.unique(a.astype(np.int64) * nb + b)
    return np.stack([key // nb, key % nb], axis=1)


def find_pairs(prims: SheetPrimitives, x0: np.ndarray, radius: float, x1: np.ndarray | None = None, *,
               compiled: bool | None = None) -> Pairs:
    """Point-triangle and edge-edge pairs whose primitives may be closer than ``radius``.

    Parameters
    ----------
    prims : the mesh's triangles and edges
    x0 : (N, 3) node positions [m]
    radius : pair radius ``r`` [m] (thickness plus margin); > 0
    x1 : (N, 3) end positions of a step [m] (swept boxes: the pairs that may come closer than
        ``radius`` somewhere on the straight path ``x0 -> x1``), or None
    compiled : the compiled cell list or the numpy one (None: :func:`.distance.compiled_for` by size)

    Returns
    -------
    Pairs, sorted and without duplicates; every pair at distance < ``radius`` is included, but for those that
    share a node once the seams are sewn (``prims.joined``).
    """
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != (prims.n_nodes, 3):
        raise ValueError(f"x0 must have shape ({prims.n_nodes}, 3), got {x0.shape}")
    if x1 is not None and np.shape(x1) != x0.shape:
        raise ValueError(f"x1 must have shape {x0.shape}, got {np.shape(x1)}")
    if not (np.isfinite(radius) and radius > 0):
        raise ValueError(f"radius must be a finite number > 0, got {radius!r}")
    tri, edges = prims.tri, prims.edges
    if distance.compiled_for(len(tri) + len(edges), compiled):
        return _drop_joined(prims, _find_pairs_compiled(prims, x0, radius, x1))
    return _drop_joined(prims, _find_pairs_numpy(prims, x0, radius, x1))


def _boxes(prims, x0, radius, x1):
    """Node, triangle and edge boxes ``(lo, hi)`` (module docstring) and the grid ``(origin, cell, dims)``."""
    lo_n, hi_n = _node_boxes(x0, x1)
    tri, edges = prims.tri, prims.edges
    lo_t, hi_t = lo_n[tri].min(axis=1) - radius, hi_n[tri].max(axis=1) + radius
    lo_e, hi_e = lo_n[edges].min(axis=1) - 0.5 * radius, hi_n[edges].max(axis=1) + 0.5 * radius
    cell = _cell_size(lo_t, hi_t)
    origin = lo_t.min(axis=0) - cell
    dims = np.floor((hi_t.max(axis=0) - origin) / cell).astype(np.int64) + 2
    return (lo_n, hi_n), (lo_t, hi_t), (lo_e, hi_e), (origin, cell, dims)


def _cell_size(lo_t, hi_t):
    """Grid cell [m]: the mean largest extent of the (inflated, for a swept test swept) triangle boxes.
    Cells much smaller than the boxes put every box into many cells: a swept test with cells from the
    boxes at ``x0`` took 23 s for the 7 cm step of the 81 x 81 sheet (numpy), 7.7 s with these."""
    return float(np.mean(np.max(hi_t - lo_t, axis=1)))


DENSE_CELLS = 8
"""The compiled cell list keeps an array over every grid cell (a counting sort) when the grid has at
most this many cells per box entry (or :data:`DENSE_MIN_CELLS` in all), else it sorts the occupied cells."""

DENSE_MIN_CELLS = 1 << 16
"""A grid of at most this many cells always gets the dense cell array (:data:`DENSE_CELLS`)."""


def _find_pairs_compiled(prims, x0, radius, x1):
    """:func:`find_pairs` by the compiled cell list (:mod:`.grid`)."""
    from rftstatic.contact.self_contact._kernels_numba import boxes, cell_list, cell_ranges, frame, join

    tri, edges = np.ascontiguousarray(prims.tri), np.ascontiguousarray(prims.edges)
    nodes = np.arange(prims.n_nodes, dtype=np.int64)[:, None]
    x0 = np.ascontiguousarray(x0)
    x1 = np.zeros((0, 3)) if x1 is None else np.ascontiguousarray(x1, dtype=float)
    box = {}
    for name, prim, inflate in (("n", nodes, 0.0), ("t", tri, radius), ("e", edges, 0.5 * radius)):
        lo, hi = np.empty((len(prim), 3)), np.empty((len(prim), 3))
        boxes(x0, x1, prim, inflate, lo, hi)
        box[name] = lo, hi
    origin, dims = np.empty(3), np.empty(3, dtype=np.int64)
    cell = frame(*box["t"], origin, dims)
    c, entries = {}, {}
    for k, (lo, hi) in box.items():
        c[k] = np.empty((len(lo), 3), dtype=np.int64), np.empty((len(lo), 3), dtype=np.int64)
        entries[k] = cell_ranges(lo, hi, origin, cell, *c[k])
    out = []
    for a, b, na, nb_, same in (("n", "t", nodes, tri, False), ("e", "e", edges, edges, True)):
        dense = int(np.prod(dims)) <= max(DENSE_CELLS * entries[b], DENSE_MIN_CELLS)
        cl = cell_list(c[b][0], c[b][1], dims, dense)
        args = (c[a][0], c[a][1], *box[a], na, *box[b], nb_, *cl, dims, dense, same)
        out.append(_join_on_threads(join, args, len(na)))
    return Pairs(out[0], out[1])


JOIN_THREADS_FROM = 4000
"""Fewest boxes ``a`` for which the compiled join runs its ranges of ``a`` on threads (as many as numba's,
``numba.get_num_threads()``, which the explicit force's thread tuner sets); the pairs come out the same."""

_POOL = []


def _join_on_threads(join, args, n):
    """``join(*args, a0, a1)`` over ``0 <= a < n``, in contiguous ranges on threads for a large ``n`` (the kernel
    holds no GIL), the ranges' pairs concatenated in order (so sorted as one call's)."""
    import numba

    threads = numba.get_num_threads() if n >= JOIN_THREADS_FROM else 1
    if threads < 2:
        return join(*args, 0, n)
    if not _POOL or _POOL[0][0] < threads:
        from concurrent.futures import ThreadPoolExecutor

        _POOL[:] = [(threads, ThreadPoolExecutor(threads, thread_name_prefix="rftstatic-join"))]
    cuts = [n * k // threads for k in range(threads + 1)]
    parts = _POOL[0][1].map(lambda k: join(*args, cuts[k], cuts[k + 1]), range(threads))
    return np.concatenate(list(parts))


def _find_pairs_numpy(prims, x0, radius, x1):
    """:func:`find_pairs` by numpy sorts and joins."""
    (lo_n, hi_n), (lo_t, hi_t), (lo_e, hi_e), (origin, cell, dims) = _boxes(prims, x0, radius, x1)
    tri, edges = prims.tri, prims.edges
    # point-triangle
    own_n, key_n = _cells(lo_n, hi_n, origin, cell, dims)
    own_t, key_t = _cells(lo_t, hi_t, origin, cell, dims)
    a, b = _join(own_n, key_n, own_t, key_t)
    keep = np.all(tri[b] != a[:, None], axis=1) & _overlap(lo_n[a], hi_n[a], lo_t[b], hi_t[b])
    pt = _unique_pairs(a[keep], b[keep], len(tri))
    # edge-edge
    own_e, key_e = _cells(lo_e, hi_e, origin, cell, dims)
    a, b = _join(own_e, key_e, own_e, key_e, same=True)
    ea, eb = edges[a], edges[b]
    share = (ea[:, :1] == eb).any(axis=1) | (ea[:, 1:] == eb).any(axis=1)
    keep = ~share & _overlap(lo_e[a], hi_e[a], lo_e[b], hi_e[b])
    ee = _unique_pairs(a[keep], b[keep], len(edges))
    return Pairs(pt, ee)


def brute_force_pairs(prims: SheetPrimitives, x0, radius, x1=None) -> Pairs:
    """The pairs of :func:`find_pairs` by testing every box against every box (tests, small meshes)."""
    lo_n, hi_n = _node_boxes(np.asarray(x0, float), x1)
    tri, edges = prims.tri, prims.edges
    lo_t, hi_t = lo_n[tri].min(axis=1) - radius, hi_n[tri].max(axis=1) + radius
    lo_e, hi_e = lo_n[edges].min(axis=1) - 0.5 * radius, hi_n[edges].max(axis=1) + 0.5 * radius
    ov = np.all((lo_n[:, None] <= hi_t[None]) & (lo_t[None] <= hi_n[:, None]), axis=2)
    ov &= ~np.any(tri[None, :, :] == np.arange(prims.n_nodes)[:, None, None], axis=2)
    pt = np.argwhere(ov)
    ov = np.all((lo_e[:, None] <= hi_e[None]) & (lo_e[None] <= hi_e[:, None]), axis=2)
    ov &= ~np.any(edges[:, None, :, None] == edges[None, :, None, :], axis=(2, 3))
    ov = np.triu(ov, 1)
    return _drop_joined(prims, Pairs(pt.astype(np.int64), np.argwhere(ov).astype(np.int64)))


class PairCache:
    """The pairs within ``radius = thickness + margin`` at the last build, reused until some node has
    moved more than ``margin / 2`` since (then every pair closer than the thickness is in the list:
    each of its two primitives moved less than ``margin / 2``). A cache of one solve (kept in the
    :class:`~rftstatic.model.state.State`); results never depend on its pairs. It also carries the solve's
    :attr:`stiffness_scale` (``State.self_contact_scale``), which they do depend on.

    Parameters
    ----------
    margin : [m], > 0
    compiled : the kernels of its broad phase (the law's, :attr:`.law.SelfContact.kernels`; None: by size)

    Attributes
    ----------
    stiffness_scale : factor on the law's stiffness in this solve [-] (1 until the static route raises it)
    friction : the solve's lagged friction between layers (``State.contact_history["self_friction"]``,
        :mod:`rftstatic.contact.self_contact.friction`), or None
    """

    def __init__(self, margin: float, *, compiled: bool | None = None):
        if not (np.isfinite(margin) and margin > 0):
            raise ValueError(f"margin must be a finite number > 0, got {margin!r}")
        self.margin = float(margin)
        self.compiled = compiled
        self.stiffness_scale = 1.0
        self.friction = None
        self.builds = 0
        self._x = None
        self._pairs = None

    def reset(self) -> None:
        """Forget the pairs (a new mesh)."""
        self._x = self._pairs = None

    def _moved(self, x) -> float:
        if self._x is None or self._x.shape != x.shape:
            return np.inf
        d = x - self._x
        return float(np.sqrt(np.max(np.einsum("ni,ni->n", d, d), initial=0.0)))

    def pairs(self, prims: SheetPrimitives, x: np.ndarray, thickness: float) -> Pairs:
        """The pairs for positions ``x (N, 3)`` [m], rebuilt when needed."""
        if self._moved(x) <= 0.5 * self.margin:
            return self._pairs
        self._pairs = find_pairs(prims, x, thickness + self.margin, compiled=self.compiled)
        self._x = np.array(x, dtype=float, copy=True)
        self._radius = thickness + self.margin
        self.builds += 1
        return self._pairs

    def unlisted_distance(self, x: np.ndarray) -> float:
        """A lower bound [m] of the distance at ``x (N, 3)`` of every pair not in the list (the list
        radius less twice the largest motion since the build); call after :meth:`pairs`."""
        return self._radius - 2.0 * self._moved(x)
