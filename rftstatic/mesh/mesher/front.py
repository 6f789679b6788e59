"""Advancing-front triangulation (Lo 1985; Lo & Lee 1994), pure Python core.

The front is the set of directed edges separating meshed from unmeshed area,
with the unmeshed side on the left.  It starts as the discretised boundary.
Each step takes the shortest front edge (a, b) and closes a triangle
(a, b, c) with c either an existing front node or a new node near the ideal
point

    P = m + n * sqrt(delta**2 - |ab|**2 / 4),
    delta = clamp(h, 0.7 |ab|, 1.4 |ab|)

(m midpoint, n inward unit normal, h the target size averaged between m and
a first guess of P), so that |aP| = |bP| = delta: equilateral when h = |ab|.
Candidates are ranked: existing front nodes close to P first (by distance),
then P itself, then P pulled towards the edge, then any nearby front node by
triangle quality.  A candidate is valid when the triangle is
counter-clockwise, its new sides cross no front edge and it contains no front
node; a new point must also keep clear of front nodes and edges.  The edges
(a, c) and (c, b) then enter the front unless their reverse is already there,
in which case both leave it (this is how the front closes).

All geometric searches go through one uniform bucket grid whose cell size
minimises a cost model over the size field, so every step touches O(1) cells
and items whatever the mesh size.  Items are deleted from the buckets lazily.
The loop is plain Python on lists and floats: numpy scalar access would be
several times slower for this kind of per-step work.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from rftstatic.errors import MeshingError

__all__ = ["advance_front"]

_NEAR = 0.8        # existing nodes within _NEAR * delta of P beat P
_CLEAR_NODE = 0.55  # a new point keeps this * delta from front nodes
_CLEAR_EDGE = 0.35  # ... and this * delta from front edges
_MAX_DEFER = 12    # an edge may be postponed this often before giving up
_SHRINK = 0.7      # delta >= _SHRINK * |ab|
_GROW = 1.4        # delta <= _GROW * |ab|


def bucket_size(size_field):
    """Bucket-grid cell size [m] minimising a per-step cost model.

    A query of half-width ~2 h costs ``(4 h / c + 2)**2`` cell visits, each
    holding ~``2 c / h`` front items; steps are weighted by the triangle
    density ~ 1/h**2 of the field.
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


def advance_front(bpoints, bedges, size_field, *, max_steps=None):
    """Fill the region bounded by ``bedges`` with triangles.

    Parameters
    ----------
    bpoints : (B, 2) boundary nodes [m]
    bedges : (B, 2) boundary edges, the domain on the left of each
    size_field : BackgroundGrid, target size [m]
    max_steps : optional bound on the number of front steps

    Returns
    -------
    points : (N, 2) float64 nodes [m]; the first B are ``bpoints``
    triangles : (E, 3) int64 counter-clockwise

    Raises
    ------
    MeshingError
        If some front edge cannot be closed (reported with its location).
    """
    X = [float(v) for v in bpoints[:, 0]]
    Y = [float(v) for v in bpoints[:, 1]]
    nb = len(X)

    # ---- size field, bilinear, on plain floats
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

    # ---- bucket grid
    cs = bucket_size(size_field)
    margin = 2.0 * cs
    bx0 = min(X) - margin
    by0 = min(Y) - margin
    ncx = int((max(X) + margin - bx0) / cs) + 1
    ncy = int((max(Y) + margin - by0) / cs) + 1
    if ncx * ncy > 50_000_000:
        raise MeshingError(f"bucket grid of {ncx} x {ncy} cells is too large; the size field spans too many scales")
    cinv = 1.0 / cs
    node_cells = [None] * (ncx * ncy)
    edge_cells = [None] * (ncx * ncy)

    def add_node(n):
        k = int((X[n] - bx0) * cinv) * ncy + int((Y[n] - by0) * cinv)
        lst = node_cells[k]
        if lst is None:
            node_cells[k] = [n]
        else:
            lst.append(n)

    SHIFT = 1 << 32
    # edge key a*SHIFT+b -> record (key, a, b, ax, ay, bx, by, seq); buckets hold
    # the records, so a record is alive while the front maps its key to it
    front = {}
    deg = [0] * nb  # number of front edges at each node
    heap = []
    seq = 0

    def add_edge(a, b):
        nonlocal seq
        ax, ay, bx, by = X[a], Y[a], X[b], Y[b]
        key = a * SHIFT + b
        seq += 1
        rec = (key, a, b, ax, ay, bx, by, seq)
        front[key] = rec
        deg[a] += 1
        deg[b] += 1
        heapq.heappush(heap, (math.hypot(bx - ax, by - ay), seq, a, b))
        i0 = int((min(ax, bx) - bx0) * cinv)
        i1 = int((max(ax, bx) - bx0) * cinv)
        j0 = int((min(ay, by) - by0) * cinv)
        j1 = int((max(ay, by) - by0) * cinv)
        for i in range(i0, i1 + 1):
            for k in range(i * ncy + j0, i * ncy + j1 + 1):
                lst = edge_cells[k]
                if lst is None:
                    edge_cells[k] = [rec]
                else:
                    lst.append(rec)

    for n in range(nb):
        add_node(n)
    for a, b in np.asarray(bedges, dtype=np.int64).tolist():
        add_edge(a, b)

    tris = []
    deferred = {}
    steps = 0
    if max_steps is None:
        max_steps = 50 * (nb + int(4.0 * _area_estimate(bpoints, bedges, size_field))) + 1000
    sqrt = math.sqrt

    while heap:
        L, s, a, b = heapq.heappop(heap)
        key = a * SHIFT + b
        rec = front.get(key)
        if rec is None or rec[7] != s:
            continue
        steps += 1
        if steps > max_steps:
            raise MeshingError(f"advancing front did not finish within {max_steps} steps "
                               f"({len(front)} front edges left near ({X[a]:g}, {Y[a]:g}))")
        ax, ay, bx, by = X[a], Y[a], X[b], Y[b]
        dx = bx - ax
        dy = by - ay
        L = sqrt(dx * dx + dy * dy)
        mx = 0.5 * (ax + bx)
        my = 0.5 * (ay + by)
        ux = -dy / L
        uy = dx / L
        h = h_at(mx, my)
        lo = _SHRINK * L
        hi = _GROW * L
        d = lo if h < lo else (hi if h > hi else h)
        ht = sqrt(d * d - 0.25 * L * L)
        h = 0.5 * (h + h_at(mx + ux * ht, my + uy * ht))
        d = lo if h < lo else (hi if h > hi else h)
        ht = sqrt(d * d - 0.25 * L * L)
        px = mx + ux * ht
        py = my + uy * ht

        # ---- gather front nodes and edges around the edge
        W = 2.5 * d
        i0 = int((mx - W - bx0) * cinv)
        i1 = int((mx + W - bx0) * cinv)
        j0 = int((my - W - by0) * cinv)
        j1 = int((my + W - by0) * cinv)
        if i0 < 0:
            i0 = 0
        if j0 < 0:
            j0 = 0
        if i1 >= ncx:
            i1 = ncx - 1
        if j1 >= ncy:
            j1 = ncy - 1
        lnodes = []
        ledges = []     # may hold an edge twice (it spans two cells): harmless
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
        tol = 1e-9 * L * L
        eps = 1e-6 * L

        def valid(cx, cy, c):
            # counter-clockwise with a sensible height
            if dx * (cy - ay) - dy * (cx - ax) <= 1e-6 * L * L:
                return False
            xmin = min(ax, bx, cx)
            xmax = max(ax, bx, cx)
            ymin = min(ay, by, cy)
            ymax = max(ay, by, cy)
            for _k, p, q, ppx, ppy, qqx, qqy, _s in ledges:
                if (ppx < xmin and qqx < xmin) or (ppx > xmax and qqx > xmax) or \
                   (ppy < ymin and qqy < ymin) or (ppy > ymax and qqy > ymax):
                    continue
                # new side a-c
                if p != a and q != a and p != c and q != c:
                    o1 = (cx - ax) * (ppy - ay) - (cy - ay) * (ppx - ax)
                    o2 = (cx - ax) * (qqy - ay) - (cy - ay) * (qqx - ax)
                    if (o1 > 0.0 and o2 < 0.0) or (o1 < 0.0 and o2 > 0.0):
                        o3 = (qqx - ppx) * (ay - ppy) - (qqy - ppy) * (ax - ppx)
                        o4 = (qqx - ppx) * (cy - ppy) - (qqy - ppy) * (cx - ppx)
                        if (o3 > 0.0 and o4 < 0.0) or (o3 < 0.0 and o4 > 0.0):
                            return False
                # new side c-b
                if p != b and q != b and p != c and q != c:
                    o1 = (bx - cx) * (ppy - cy) - (by - cy) * (ppx - cx)
                    o2 = (bx - cx) * (qqy - cy) - (by - cy) * (qqx - cx)
                    if (o1 > 0.0 and o2 < 0.0) or (o1 < 0.0 and o2 > 0.0):
                        o3 = (qqx - ppx) * (cy - ppy) - (qqy - ppy) * (cx - ppx)
                        o4 = (qqx - ppx) * (by - ppy) - (qqy - ppy) * (bx - ppx)
                        if (o3 > 0.0 and o4 < 0.0) or (o3 < 0.0 and o4 > 0.0):
                            return False
            # nodes on a side count as inside: widen the box by a rounding margin
            xmin -= eps
            xmax += eps
            ymin -= eps
            ymax += eps
            for n in lnodes:
                if n == c or n == a or n == b:
                    continue
                nx_ = X[n]
                ny_ = Y[n]
                if nx_ < xmin or nx_ > xmax or ny_ < ymin or ny_ > ymax:
                    continue
                if (dx * (ny_ - ay) - dy * (nx_ - ax) >= -tol
                        and (cx - bx) * (ny_ - by) - (cy - by) * (nx_ - bx) >= -tol
                        and (ax - cx) * (ny_ - cy) - (ay - cy) * (nx_ - cx) >= -tol):
                    return False
            return True

        def clear(qx, qy, dd):
            rn = (_CLEAR_NODE * dd) ** 2
            for n in lnodes:
                ex = X[n] - qx
                ey = Y[n] - qy
                if ex * ex + ey * ey < rn:
                    return False
            re = (_CLEAR_EDGE * dd) ** 2
            for ek, p, q, ppx, ppy, qqx, qqy, _s in ledges:
                if ek == key:
                    continue
                sx = qqx - ppx
                sy = qqy - ppy
                t = ((qx - ppx) * sx + (qy - ppy) * sy) / (sx * sx + sy * sy)
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
                ex = ppx + t * sx - qx
                ey = ppy + t * sy - qy
                if ex * ex + ey * ey < re:
                    return False
            return True

        c = -1
        near = (_NEAR * d) ** 2
        close = []
        for n in lnodes:
            if n == a or n == b:
                continue
            ex = X[n] - px
            ey = Y[n] - py
            r2 = ex * ex + ey * ey
            if r2 < near:
                close.append((r2, n))
        if close:
            close.sort()
            for _, n in close:
                if valid(X[n], Y[n], n):
                    c = n
                    break
        if c < 0:
            for f in (1.0, 0.6, 0.35):
                qx = mx + ux * ht * f
                qy = my + uy * ht * f
                dd = d if f == 1.0 else sqrt(0.25 * L * L + (ht * f) ** 2)
                if clear(qx, qy, dd) and valid(qx, qy, -1):
                    c = len(X)
                    X.append(qx)
                    Y.append(qy)
                    deg.append(0)
                    add_node(c)
                    break
                if f == 1.0:
                    # P failed: before shrinking it, try the best-shaped existing node
                    c = _best_existing(lnodes, a, b, ax, ay, bx, by, X, Y, valid, 0.35)
                    if c >= 0:
                        break
        if c < 0:
            c = _best_existing(lnodes, a, b, ax, ay, bx, by, X, Y, valid, 0.0)
        if c < 0:
            n_def = deferred.get(key, 0) + 1
            if n_def > _MAX_DEFER:
                raise MeshingError(
                    f"advancing front stuck at edge ({ax:g}, {ay:g})-({bx:g}, {by:g}) after {len(tris)} "
                    f"triangles; the size field probably varies too fast there (lower the gradation) or "
                    "the boundary is too coarse for the holes/corners nearby")
            deferred[key] = n_def
            seq += 1
            rec = rec[:7] + (seq,)
            front[key] = rec
            for i in range(int((min(ax, bx) - bx0) * cinv), int((max(ax, bx) - bx0) * cinv) + 1):
                for k in range(i * ncy + int((min(ay, by) - by0) * cinv),
                               i * ncy + int((max(ay, by) - by0) * cinv) + 1):
                    edge_cells[k].append(rec)
            heapq.heappush(heap, (L * (1.0 + 0.5 * n_def), seq, a, b))
            continue

        # ---- accept triangle (a, b, c), update the front
        tris.append((a, b, c))
        del front[key]
        deg[a] -= 1
        deg[b] -= 1
        for u, v in ((a, c), (c, b)):
            rkey = v * SHIFT + u
            if rkey in front:
                del front[rkey]
                deg[u] -= 1
                deg[v] -= 1
            else:
                add_edge(u, v)

    points = np.column_stack([np.asarray(X), np.asarray(Y)])
    return points, np.asarray(tris, dtype=np.int64).reshape(-1, 3)


def _best_existing(lnodes, a, b, ax, ay, bx, by, X, Y, valid, qmin):
    """Valid front node c maximising the shape quality of (a, b, c), or -1."""
    dx = bx - ax
    dy = by - ay
    l0 = dx * dx + dy * dy
    ranked = []
    for n in lnodes:
        if n == a or n == b:
            continue
        cx = X[n]
        cy = Y[n]
        area2 = dx * (cy - ay) - dy * (cx - ax)
        if area2 <= 0.0:
            continue
        l1 = (cx - ax) ** 2 + (cy - ay) ** 2
        l2 = (cx - bx) ** 2 + (cy - by) ** 2
        q = 2.0 * math.sqrt(3.0) * area2 / (l0 + l1 + l2)
        if q > qmin:
            ranked.append((-q, n))
    ranked.sort()
    for _, n in ranked:
        if valid(X[n], Y[n], n):
            return n
    return -1


def _area_estimate(bpoints, bedges, size_field):
    """Rough number of triangles: enclosed area / (sqrt(3)/4 h_mean**2)."""
    p, q = bpoints[bedges[:, 0]], bpoints[bedges[:, 1]]
    area = 0.5 * abs(float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1])))
    h = size_field.h_min
    return area / (0.43 * h * h)
