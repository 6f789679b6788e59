"""Cell-list loops of the broad phase, written once as scalar loops for the compiled (numba) twin of
:func:`.broad_phase.find_pairs` (:mod:`._kernels_numba` compiles a copy of every function here).

Boxes are given by their cell ranges ``c0, c1 (B, 3)`` (integers, inclusive) and their bounds
``lo, hi (B, 3)`` [m]. :func:`cell_list` sorts the (box, cell) entries of one kind by cell key;
:func:`join` then visits, for every box ``a`` of the other kind in order, the cells it covers and
the boxes ``b`` listed there, and keeps ``(a, b)`` if the boxes overlap and share no node, once (a stamp
per ``b`` marks the pairs already met in another common cell), without a deduplication pass; the ``b``
of one ``a`` are sorted, so the pairs come out sorted. :func:`frame` and :func:`cell_ranges` give the grid
and the cell ranges.
"""

import numpy as np


def boxes(x0, x1, prims, inflate, lo, hi):
    """Fill ``lo, hi (B, 3)`` [m] with the boxes of primitives ``prims (B, m)`` (node indices): the
    box of their nodes' positions ``x0`` (or paths ``x0 -> x1``; ``x1`` of shape ``(0, 3)``: none)
    widened by ``inflate`` [m]."""
    swept = x1.shape[0] > 0
    for b in range(prims.shape[0]):
        for i in range(3):
            v = x0[prims[b, 0], i]
            mn, mx = v, v
            for k in range(prims.shape[1]):
                v = x0[prims[b, k], i]
                mn, mx = min(mn, v), max(mx, v)
                if swept:
                    v = x1[prims[b, k], i]
                    mn, mx = min(mn, v), max(mx, v)
            lo[b, i], hi[b, i] = mn - inflate, mx + inflate


def frame(lo, hi, origin, dims):
    """The grid of the triangle boxes ``lo, hi (T, 3)`` [m]: returns the cell [m], the mean largest extent of the
    boxes (:func:`.broad_phase._cell_size`), and fills ``origin (3,)`` [m] (one cell below the lowest corner) and
    ``dims (3,)`` (cells per axis, one spare cell above): the expressions of :func:`.broad_phase._boxes`, summed
    in order (the cell's last bits differ from numpy's pairwise mean; the pairs do not depend on the grid)."""
    T = lo.shape[0]
    total = 0.0
    for t in range(T):
        total += max(hi[t, 0] - lo[t, 0], hi[t, 1] - lo[t, 1], hi[t, 2] - lo[t, 2])
    cell = total / T
    for i in range(3):
        mn, mx = lo[0, i], hi[0, i]
        for t in range(T):
            mn = min(mn, lo[t, i])
            mx = max(mx, hi[t, i])
        origin[i] = mn - cell
        dims[i] = np.int64(np.floor((mx - origin[i]) / cell)) + 2
    return cell


def cell_ranges(lo, hi, origin, cell, c0, c1):
    """Fill ``c0, c1 (B, 3)`` (int) with the cells ``floor((lo - origin) / cell)`` and ``floor((hi - origin) / cell)``
    of the boxes ``lo, hi (B, 3)`` [m] (``origin (3,)`` [m], ``cell`` [m]) in one pass without temporaries; returns
    the number of (box, cell) entries, ``sum_b prod_i (c1 - c0 + 1)``."""
    K = 0
    for b in range(lo.shape[0]):
        k = 1
        for i in range(3):
            c0[b, i] = np.int64(np.floor((lo[b, i] - origin[i]) / cell))
            c1[b, i] = np.int64(np.floor((hi[b, i] - origin[i]) / cell))
            k *= c1[b, i] - c0[b, i] + 1
        K += k
    return K


def cell_list(c0, c1, dims, dense):
    """Entries of boxes ``c0, c1 (B, 3)`` by cell: ``ukey (U,)``, ``start (U + 1,)`` and the boxes
    ``members (K,)`` (ascending within a cell), the entries of cell ``ukey[u]`` being
    ``members[start[u]:start[u + 1]]``; key ``ix + dims[0] (iy + dims[1] iz)``. ``dense``: every cell
    of the grid is listed (``U = prod(dims)``, ``ukey`` left empty, a counting sort); else only the
    occupied ones, sorted (``argsort``)."""
    B = c0.shape[0]
    K = 0
    for b in range(B):
        K += (c1[b, 0] - c0[b, 0] + 1) * (c1[b, 1] - c0[b, 1] + 1) * (c1[b, 2] - c0[b, 2] + 1)
    if dense:
        C = dims[0] * dims[1] * dims[2]
        start = np.zeros(C + 1, dtype=np.int64)
        for b in range(B):
            for iz in range(c0[b, 2], c1[b, 2] + 1):
                for iy in range(c0[b, 1], c1[b, 1] + 1):
                    for ix in range(c0[b, 0], c1[b, 0] + 1):
                        start[ix + dims[0] * (iy + dims[1] * iz) + 1] += 1
        for c in range(C):
            start[c + 1] += start[c]
        fill = start[:C].copy()
        members = np.empty(K, dtype=np.int64)
        for b in range(B):
            for iz in range(c0[b, 2], c1[b, 2] + 1):
                for iy in range(c0[b, 1], c1[b, 1] + 1):
                    for ix in range(c0[b, 0], c1[b, 0] + 1):
                        c = ix + dims[0] * (iy + dims[1] * iz)
                        members[fill[c]] = b
                        fill[c] += 1
        return np.zeros(0, dtype=np.int64), start, members
    key = np.empty(K, dtype=np.int64)
    owner = np.empty(K, dtype=np.int64)
    k = 0
    for b in range(B):
        for iz in range(c0[b, 2], c1[b, 2] + 1):
            for iy in range(c0[b, 1], c1[b, 1] + 1):
                for ix in range(c0[b, 0], c1[b, 0] + 1):
                    key[k] = ix + dims[0] * (iy + dims[1] * iz)
                    owner[k] = b
                    k += 1
    order = np.argsort(key, kind="mergesort")
    members = owner[order]
    skey = key[order]
    U = 0
    for k in range(K):
        if k == 0 or skey[k] != skey[k - 1]:
            U += 1
    ukey = np.empty(U, dtype=np.int64)
    start = np.empty(U + 1, dtype=np.int64)
    u = 0
    for k in range(K):
        if k == 0 or skey[k] != skey[k - 1]:
            ukey[u] = skey[k]
            start[u] = k
            u += 1
    start[U] = K
    return ukey, start, members


def _grow(out, n):
    if n < out.shape[0]:
        return out
    bigger = np.empty((2 * out.shape[0] + 16, 2), dtype=np.int64)
    bigger[:n] = out[:n]
    return bigger


def join(c0a, c1a, lo_a, hi_a, nodes_a, lo_b, hi_b, nodes_b, ukey, start, members, dims, dense, same, a0, a1):
    """Pairs ``(a, b) (Q, 2)``, sorted, of boxes ``a0 <= a < a1`` (cell ranges ``c0a, c1a``, bounds ``lo_a, hi_a``,
    nodes ``nodes_a (A, m)``) and ``b`` (the :func:`cell_list` of their cell ranges; bounds, ``nodes_b (B, n)``)
    that overlap and share no node; ``same``: both are one kind, only ``a < b``. Compiled only (its numpy
    path is :func:`.broad_phase._join`): a numba kernel on flat arrays, the exception to the rule of at
    most 12 parameters; it holds no GIL, so ranges of ``a`` can run on threads.

    The box test comes first (one branch for the six comparisons: most listed boxes of a cell miss); a pair
    met again in another common cell is skipped by a stamp (``seen[b] == a``), needed only when ``a`` covers
    more than one cell; with ``same`` a cell's boxes are scanned from the highest index down to the first
    ``b <= a`` (a cell lists its boxes in ascending order). The ``b`` of one ``a`` are kept sorted by insertion
    (a few per box). The pt join of the 81 x 81 draped sheet 3.1 -> 1.5 ms, its ee join 11 -> 9 ms."""
    out = np.empty((4 * (a1 - a0) + 16, 2), dtype=np.int64)
    found = np.empty(64, dtype=np.int64)
    seen = np.full(lo_b.shape[0], -1, dtype=np.int64)
    n = 0
    for a in range(a0, a1):
        nf = 0
        l0, l1, l2 = lo_a[a, 0], lo_a[a, 1], lo_a[a, 2]
        h0, h1, h2 = hi_a[a, 0], hi_a[a, 1], hi_a[a, 2]
        single = c0a[a, 0] == c1a[a, 0] and c0a[a, 1] == c1a[a, 1] and c0a[a, 2] == c1a[a, 2]
        for iz in range(c0a[a, 2], c1a[a, 2] + 1):
            for iy in range(c0a[a, 1], c1a[a, 1] + 1):
                for ix in range(c0a[a, 0], c1a[a, 0] + 1):
                    key = ix + dims[0] * (iy + dims[1] * iz)
                    if dense:
                        u = key
                    else:
                        u = np.searchsorted(ukey, key)
                        if u == ukey.shape[0] or ukey[u] != key:
                            continue
                    k0, k1 = start[u], start[u + 1]
                    for kk in range(k0, k1):
                        b = members[k1 - 1 - (kk - k0)] if same else members[kk]
                        if same and b <= a:
                            break
                        if not (((l0 <= hi_b[b, 0]) & (lo_b[b, 0] <= h0)) & ((l1 <= hi_b[b, 1]) & (lo_b[b, 1] <= h1))
                                & ((l2 <= hi_b[b, 2]) & (lo_b[b, 2] <= h2))):
                            continue
                        if not single:
                            if seen[b] == a:
                                continue  # met in an earlier common cell
                            seen[b] = a
                        shared = False
                        for i in range(nodes_a.shape[1]):
                            for j in range(nodes_b.shape[1]):
                                if nodes_a[a, i] == nodes_b[b, j]:
                                    shared = True
                        if shared:
                            continue
                        if nf == found.shape[0]:
                            more = np.empty(2 * nf, dtype=np.int64)
                            more[:nf] = found[:nf]
                            found = more
                        i = nf
                        while i > 0 and found[i - 1] > b:
                            found[i] = found[i - 1]
                            i -= 1
                        found[i] = b
                        nf += 1
        for f in range(nf):
            out = _grow(out, n)
            out[n, 0] = a
            out[n, 1] = found[f]
            n += 1
    return out[:n].copy()
