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

One step, one function each:

- front selection: :meth:`FrontState.pop_shortest <rftstatic.mesh.mesher.frontstate.FrontState.pop_shortest>`;
- candidate point: :func:`_ideal_point` (P), :func:`_choose_apex` (the ranking, with
  :func:`_nearest_valid`, :func:`_new_point` and :func:`_best_existing`);
- validity checks: :func:`_valid` (the triangle), :func:`_clear` (a new point);
- triangle creation and front update: ``FrontState.accept``; an edge no candidate fits
  is postponed by :func:`_defer`;
- closing: ``FrontState.add_or_close`` removes an edge meeting its reverse, and the
  loop of :func:`advance_front` ends when the queue is empty.

The state (nodes, front, queue, bucket grid) lives in :mod:`rftstatic.mesh.mesher.frontstate`.
"""

# Conditional expressions, not min()/max() calls, clamp the floats of the per-step loop: faster.
# ruff: noqa: FURB136

from __future__ import annotations

import math

import numpy as np

from rftstatic.errors import MeshingError
from rftstatic.mesh.mesher.frontstate import FrontState, bilinear, bucket_size

__all__ = ["advance_front"]

_NEAR = 0.8        # existing nodes within _NEAR * delta of P beat P
_CLEAR_NODE = 0.55  # a new point keeps this * delta from front nodes
_CLEAR_EDGE = 0.35  # ... and this * delta from front edges
_MAX_DEFER = 12    # an edge may be postponed this often before giving up
_SHRINK = 0.7      # delta >= _SHRINK * |ab|
_GROW = 1.4        # delta <= _GROW * |ab|
_SEARCH = 2.5      # front items are gathered within _SEARCH * delta of the edge midpoint
_PULL = (1.0, 0.6, 0.35)  # new-point candidates: P, then P pulled towards the edge


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
    state = FrontState(bpoints, bedges, bucket_size(size_field))
    h_at = bilinear(size_field)
    if max_steps is None:
        max_steps = 50 * (len(bpoints) + int(4.0 * _area_estimate(bpoints, bedges, size_field))) + 1000
    steps = 0
    while True:
        rec = state.pop_shortest()                      # front selection
        if rec is None:
            break                                       # the front has closed
        key = rec[0]
        steps += 1
        if steps > max_steps:
            raise MeshingError(f"advancing front did not finish within {max_steps} steps ({len(state.front)} "
                               f"front edges left near ({state.X[rec[1]]:g}, {state.Y[rec[1]]:g}))")
        ideal = _ideal_point(rec, h_at)                 # candidate point P
        lnodes, ledges = state.gather(ideal[1], ideal[2], _SEARCH * ideal[5])
        c = _choose_apex(state, rec, ideal, lnodes, ledges)
        if c < 0:
            _defer(state, key, rec, ideal[0])
        else:
            state.accept(key, rec[1], rec[2], c)        # triangle creation, front update and closing
    return state.arrays()


def _ideal_point(rec, h_at):
    """Candidate point: the ideal apex P of the triangle on the edge of ``rec``.

    Parameters
    ----------
    rec : front record (key, a, b, ax, ay, bx, by, seq) of the edge: node indices, coordinates [m]
    h_at : target size [m] at a point, ``h_at(x, y)``

    Returns
    -------
    (L, mx, my, ux, uy, d, ht) : edge length [m], midpoint m [m], inward unit normal n,
    the clamped size delta [m] and the height [m] of P = m + ht n above the edge
    """
    _, _, _, ax, ay, bx, by, _ = rec
    dx = bx - ax
    dy = by - ay
    L = math.sqrt(dx * dx + dy * dy)
    mx = 0.5 * (ax + bx)
    my = 0.5 * (ay + by)
    ux = -dy / L
    uy = dx / L
    h = h_at(mx, my)
    lo = _SHRINK * L
    hi = _GROW * L
    d = lo if h < lo else (hi if h > hi else h)
    ht = math.sqrt(d * d - 0.25 * L * L)
    h = 0.5 * (h + h_at(mx + ux * ht, my + uy * ht))   # size averaged between m and a first guess of P
    d = lo if h < lo else (hi if h > hi else h)
    ht = math.sqrt(d * d - 0.25 * L * L)
    return L, mx, my, ux, uy, d, ht


def _choose_apex(state, rec, ideal, lnodes, ledges):
    """Candidate ranking: the apex c of the triangle (a, b, c) on the edge (a, b) of ``rec``, or -1 if none is valid.

    In order: front nodes within ``_NEAR * delta`` of P (nearest first), P itself, the
    best-shaped front node of quality > 0.35, P pulled towards the edge, then any valid
    front node by quality.  A new point is added to ``state`` (not yet to the front).

    Parameters
    ----------
    state : FrontState
    rec : front record (key, a, b, ax, ay, bx, by, seq) of the edge
    ideal : (L, mx, my, ux, uy, d, ht) from :func:`_ideal_point`
    lnodes, ledges : front nodes and edge records near the edge (``FrontState.gather``)

    Returns
    -------
    int, node index of the apex, or -1
    """
    X, Y = state.X, state.Y
    L = ideal[0]
    c = _nearest_valid(rec, L, ideal[1] + ideal[3] * ideal[6], ideal[2] + ideal[4] * ideal[6],
                       (_NEAR * ideal[5]) ** 2, lnodes, ledges, X, Y)
    if c < 0:
        c = _new_point(state, rec, ideal, lnodes, ledges)
    if c < 0:
        c = _best_existing(rec, L, 0.0, lnodes, ledges, X, Y)
    return c


def _nearest_valid(rec, L, px, py, near, lnodes, ledges, X, Y):
    """The front node nearest to P = (px, py) [m], within ``sqrt(near)`` [m] of it, that makes a valid triangle; or -1."""
    a, b = rec[1], rec[2]
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
            if _valid(rec, L, n, X[n], Y[n], lnodes, ledges, X, Y):
                return n
    return -1


def _new_point(state, rec, ideal, lnodes, ledges):
    """A new node at P, else (after trying the best-shaped front node) at P pulled towards the edge.

    A new point must keep clear of the front (:func:`_clear`) and make a valid triangle.

    Returns
    -------
    int, index of the new node (added to ``state``) or of the chosen front node, or -1
    """
    X, Y = state.X, state.Y
    L, mx, my, ux, uy, d, ht = ideal
    for f in _PULL:
        qx = mx + ux * ht * f
        qy = my + uy * ht * f
        dd = d if f == 1.0 else math.sqrt(0.25 * L * L + (ht * f) ** 2)
        if _clear(rec[0], qx, qy, dd, lnodes, ledges, X, Y) and _valid(rec, L, -1, qx, qy, lnodes, ledges, X, Y):
            return state.add_node(qx, qy)
        if f == 1.0:
            # P failed: before shrinking it, try the best-shaped existing node
            c = _best_existing(rec, L, 0.35, lnodes, ledges, X, Y)
            if c >= 0:
                return c
    return -1


def _valid(rec, L, c, cx, cy, lnodes, ledges, X, Y):
    """Validity check of the triangle (a, b, c) with apex (cx, cy) [m] (``c`` = -1 for a new point).

    Valid when counter-clockwise with a height above 1e-6 L, when its new sides (a, c) and
    (c, b) properly cross no front edge of ``ledges`` and when no other front node of
    ``lnodes`` lies inside it or on its sides (within a rounding margin).
    """
    _, a, b, ax, ay, bx, by, _ = rec
    dx = bx - ax
    dy = by - ay
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
    eps = 1e-6 * L
    tol = 1e-9 * L * L
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


def _clear(key, qx, qy, dd, lnodes, ledges, X, Y):
    """Validity check of a new point (qx, qy) [m]: at least ``_CLEAR_NODE * dd`` from every front
    node and ``_CLEAR_EDGE * dd`` from every front edge but its own (``key``); ``dd`` [m]."""
    rn = (_CLEAR_NODE * dd) ** 2
    for n in lnodes:
        ex = X[n] - qx
        ey = Y[n] - qy
        if ex * ex + ey * ey < rn:
            return False
    re = (_CLEAR_EDGE * dd) ** 2
    for ek, _p, _q, ppx, ppy, qqx, qqy, _s in ledges:
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


def _best_existing(rec, L, qmin, lnodes, ledges, X, Y):
    """Valid front node c maximising the shape quality of (a, b, c), among those of quality > ``qmin``; or -1.

    Quality ``2 sqrt(3) area2 / (l0 + l1 + l2)`` (1 for an equilateral triangle; area2
    twice the area [m^2], l the squared side lengths [m^2]).
    """
    _, a, b, ax, ay, bx, by, _ = rec
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
        if _valid(rec, L, n, X[n], Y[n], lnodes, ledges, X, Y):
            return n
    return -1


def _defer(state, key, rec, L):
    """No candidate fits the edge of record ``rec`` now: queue it again, later each time, or give up.

    Raises
    ------
    MeshingError
        After ``_MAX_DEFER`` postponements of the same edge.
    """
    n_def = state.deferred.get(key, 0) + 1
    if n_def > _MAX_DEFER:
        _, _, _, ax, ay, bx, by, _ = rec
        raise MeshingError(
            f"advancing front stuck at edge ({ax:g}, {ay:g})-({bx:g}, {by:g}) after {len(state.tris)} "
            f"triangles; the size field probably varies too fast there (lower the gradation) or "
            "the boundary is too coarse for the holes/corners nearby")
    state.deferred[key] = n_def
    state.requeue(key, rec, L * (1.0 + 0.5 * n_def))


def _area_estimate(bpoints, bedges, size_field):
    """Rough number of triangles: enclosed area / (sqrt(3)/4 h_mean**2)."""
    p, q = bpoints[bedges[:, 0]], bpoints[bedges[:, 1]]
    area = 0.5 * abs(float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1])))
    h = size_field.h_min
    return area / (0.43 * h * h)
