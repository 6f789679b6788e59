"""State of the advancing front: nodes, front edges, their priority queue and bucket grid.

:class:`FrontState` owns every mutable structure of :func:`rftstatic.mesh.mesher.front.advance_front`:

- node coordinates ``X``, ``Y`` [m] as plain Python lists of floats (numpy scalar access
  would be several times slower for this per-step work) and ``deg``, the number of front
  edges at each node (0: the node has left the front);
- the front, a dict ``key -> record`` with ``key = a * SHIFT + b`` for the directed edge
  (a, b) and ``record = (key, a, b, ax, ay, bx, by, seq)``; a record is alive while the
  front maps its key to it (so a re-queued edge makes its older records stale);
- a heap of ``(priority [m], seq, a, b)``, shortest edge first;
- a uniform bucket grid of front nodes and edge records, with lazy deletion of items
  that have left the front.

It also provides the two size-field helpers of the front: :func:`bucket_size` (cell size
of the grid) and :func:`bilinear` (target size at a point, on plain floats).
"""

# Conditional expressions and ifs, not min()/max() calls, clamp the floats of the per-step loop: faster.
# ruff: noqa: FURB136, PLR1730

from __future__ import annotations

import heapq
import math

import numpy as np

from rftstatic.errors import MeshingError

__all__ = ["SHIFT", "FrontState", "bilinear", "bucket_size"]

SHIFT = 1 << 32          # edge key a * SHIFT + b
_MAX_CELLS = 50_000_000  # bucket-grid cells beyond which the size field spans too many scales


def bucket_size(size_field):
    """Bucket-grid cell size [m] minimising a per-step cost model.

    A query of half-width ~2 h costs ``(4 h / c + 2)**2`` cell visits, each
    holding ~``2 c / h`` front items; steps are weighted by the triangle
    density ~ 1/h**2 of the field.

    Parameters
    ----------
    size_field : BackgroundGrid, target size [m]

    Returns
    -------
    float, cell size [m]
    """
    h = size_field.values.ravel()
    lo, hi = h.min(), h.max()
    if hi <= lo * (1 + 1e-9):
        return 3.0 * float(lo)       # the model's optimum for a uniform field
    # weights binned in log h keep this O(grid) once, not O(grid x candidates)
    w, edges = np.histogram(np.log(h), bins=64, weights=1.0 / h**2)
    hb = np.exp(0.5 * (edges[1:] + edges[:-1]))[:, None]
    cands = np.geomspace(0.5 * lo, 4.0 * hi, 60)[None, :]
    cost = (w[:, None] * (4.0 * hb / cands + 2.0) ** 2 * (1.0 + 2.0 * cands / hb)).sum(axis=0)
    return float(cands[0, int(np.argmin(cost))])


def bilinear(size_field):
    """Bilinear interpolation of ``size_field`` on plain floats.

    Parameters
    ----------
    size_field : BackgroundGrid, target size [m] on a (nx, ny) grid

    Returns
    -------
    ``h_at(x, y) -> float``: target size [m] at the point (x, y) [m], clamped to the grid.
    """
    gvals = size_field.values.ravel().tolist()
    gnx, gny = size_field.values.shape
    gx0, gy0 = float(size_field.origin[0]), float(size_field.origin[1])
    ginv = 1.0 / size_field.spacing
    umax, vmax = gnx - 1.0, gny - 1.0

    def h_at(x, y):
        u = (x - gx0) * ginv
        v = (y - gy0) * ginv
        u = 0.0 if u < 0.0 else (umax if u > umax else u)
        v = 0.0 if v < 0.0 else (vmax if v > vmax else v)
        i = int(u)
        j = int(v)
        if i > gnx - 2:
            i = gnx - 2
        if j > gny - 2:
            j = gny - 2
        fu = u - i
        fv = v - j
        k = i * gny + j
        return ((1.0 - fu) * ((1.0 - fv) * gvals[k] + fv * gvals[k + 1])
                + fu * ((1.0 - fv) * gvals[k + gny] + fv * gvals[k + gny + 1]))

    return h_at


class FrontState:
    """Nodes, front edges, priority queue, bucket grid and triangles of one advancing front.

    Parameters
    ----------
    bpoints : (B, 2) boundary nodes [m]
    bedges : (B, 2) boundary edges, the domain on the left of each; they form the initial front
    cell : bucket-grid cell size [m] (see :func:`bucket_size`)

    Raises
    ------
    MeshingError
        If the bucket grid would have more than 50 million cells.
    """

    __slots__ = ("X", "Y", "deferred", "deg", "edge_cells", "front", "heap", "inv", "ncx", "ncy",
                 "node_cells", "seq", "tris", "x0", "y0")

    def __init__(self, bpoints, bedges, cell):
        X = [float(v) for v in bpoints[:, 0]]
        Y = [float(v) for v in bpoints[:, 1]]
        margin = 2.0 * cell
        self.x0 = min(X) - margin
        self.y0 = min(Y) - margin
        self.ncx = int((max(X) + margin - self.x0) / cell) + 1
        self.ncy = int((max(Y) + margin - self.y0) / cell) + 1
        if self.ncx * self.ncy > _MAX_CELLS:
            raise MeshingError(f"bucket grid of {self.ncx} x {self.ncy} cells is too large; "
                               "the size field spans too many scales")
        self.inv = 1.0 / cell
        self.node_cells = [None] * (self.ncx * self.ncy)
        self.edge_cells = [None] * (self.ncx * self.ncy)
        self.X, self.Y = X, Y
        self.deg = [0] * len(X)     # number of front edges at each node
        self.front = {}
        self.heap = []
        self.seq = 0
        self.tris = []              # accepted triangles (a, b, c), counter-clockwise
        self.deferred = {}          # edge key -> times the edge was postponed
        for n in range(len(X)):
            self._bucket_node(n)
        for a, b in np.asarray(bedges, dtype=np.int64).tolist():
            self.add_edge(a, b)

    # ------------------------------------------------------------------ nodes
    def _bucket_node(self, n):
        """File node ``n`` in the bucket of its cell."""
        k = int((self.X[n] - self.x0) * self.inv) * self.ncy + int((self.Y[n] - self.y0) * self.inv)
        lst = self.node_cells[k]
        if lst is None:
            self.node_cells[k] = [n]
        else:
            lst.append(n)

    def add_node(self, x, y):
        """Append a node at (x, y) [m], not yet on the front; return its index."""
        n = len(self.X)
        self.X.append(x)
        self.Y.append(y)
        self.deg.append(0)
        self._bucket_node(n)
        return n

    # ------------------------------------------------------------------ edges
    def _bucket_edge(self, rec):
        """File the edge record ``rec`` in every cell its bounding box overlaps."""
        _, _, _, ax, ay, bx, by, _ = rec
        x0, y0, inv, ncy, edge_cells = self.x0, self.y0, self.inv, self.ncy, self.edge_cells
        i0 = int((min(ax, bx) - x0) * inv)
        i1 = int((max(ax, bx) - x0) * inv)
        j0 = int((min(ay, by) - y0) * inv)
        j1 = int((max(ay, by) - y0) * inv)
        for i in range(i0, i1 + 1):
            for k in range(i * ncy + j0, i * ncy + j1 + 1):
                lst = edge_cells[k]
                if lst is None:
                    edge_cells[k] = [rec]
                else:
                    lst.append(rec)

    def add_edge(self, a, b):
        """Put the directed edge (a, b) on the front, queued by its length [m]."""
        X, Y = self.X, self.Y
        ax, ay, bx, by = X[a], Y[a], X[b], Y[b]
        key = a * SHIFT + b
        seq = self.seq = self.seq + 1
        rec = (key, a, b, ax, ay, bx, by, seq)
        self.front[key] = rec
        deg = self.deg
        deg[a] += 1
        deg[b] += 1
        heapq.heappush(self.heap, (math.hypot(bx - ax, by - ay), seq, a, b))
        self._bucket_edge(rec)

    def requeue(self, key, rec, priority):
        """Queue the front edge of record ``rec`` again, with ``priority`` [m]; its old records go stale."""
        self.seq += 1
        rec = rec[:7] + (self.seq,)
        self.front[key] = rec
        self._bucket_edge(rec)
        heapq.heappush(self.heap, (priority, self.seq, rec[1], rec[2]))

    def pop_shortest(self):
        """Front selection: the live front edge of least priority, removed from the queue.

        Returns
        -------
        The edge's record ``(key, a, b, ax, ay, bx, by, seq)``, or None when the queue is empty
        (the front has closed).
        """
        heap, front = self.heap, self.front
        while heap:
            _, s, a, b = heapq.heappop(heap)
            key = a * SHIFT + b
            rec = front.get(key)
            if rec is not None and rec[7] == s:
                return rec
        return None

    def gather(self, mx, my, w):
        """Front nodes and edge records in the cells overlapping the square of half-width ``w`` [m] at (mx, my).

        Items that have left the front are dropped from their cells on the way.

        Returns
        -------
        lnodes : list of node indices
        ledges : list of edge records (an edge spanning two cells may appear twice: harmless)
        """
        x0, y0, inv, ncx, ncy = self.x0, self.y0, self.inv, self.ncx, self.ncy
        node_cells, edge_cells, deg, front = self.node_cells, self.edge_cells, self.deg, self.front
        i0 = int((mx - w - x0) * inv)
        i1 = int((mx + w - x0) * inv)
        j0 = int((my - w - y0) * inv)
        j1 = int((my + w - y0) * inv)
        if i0 < 0:
            i0 = 0
        if j0 < 0:
            j0 = 0
        if i1 >= ncx:
            i1 = ncx - 1
        if j1 >= ncy:
            j1 = ncy - 1
        lnodes = []
        ledges = []
        for i in range(i0, i1 + 1):
            base = i * ncy
            for k in range(base + j0, base + j1 + 1):
                lst = node_cells[k]
                if lst:
                    alive = [n for n in lst if deg[n]]
                    if len(alive) != len(lst):
                        node_cells[k] = alive
                    lnodes.extend(alive)
                lst = edge_cells[k]
                if lst:
                    alive = [r for r in lst if front.get(r[0]) is r]
                    if len(alive) != len(lst):
                        edge_cells[k] = alive
                    ledges.extend(alive)
        return lnodes, ledges

    # ------------------------------------------------------------------ triangles
    def accept(self, key, a, b, c):
        """Triangle creation: add (a, b, c); the edge (a, b) leaves the front, (a, c) and (c, b) meet it."""
        self.tris.append((a, b, c))
        del self.front[key]
        deg = self.deg
        deg[a] -= 1
        deg[b] -= 1
        self.add_or_close(a, c)
        self.add_or_close(c, b)

    def add_or_close(self, u, v):
        """Closing: (u, v) joins the front, unless its reverse (v, u) is there, when both leave it."""
        front = self.front
        rkey = v * SHIFT + u
        if rkey in front:
            del front[rkey]
            deg = self.deg
            deg[u] -= 1
            deg[v] -= 1
        else:
            self.add_edge(u, v)

    def arrays(self):
        """The mesh so far.

        Returns
        -------
        points : (N, 2) float64 nodes [m]
        triangles : (E, 3) int64 counter-clockwise
        """
        points = np.column_stack([np.asarray(self.X), np.asarray(self.Y)])
        return points, np.asarray(self.tris, dtype=np.int64).reshape(-1, 3)
