"""A smooth contact surface for a triangle-mesh obstacle: the implicit moving-least-squares (IMLS) surface of its
facets (Shen, O'Brien & Shewchuk 2004; Kolluri 2008), for a body that is smooth but given as triangles.

The signed distance to a triangle surface has a crease wherever the surface is concave: outside a concave facet
edge the nearest point jumps from one facet to the other across the bisecting plane, so the contact normal jumps by
the edge's dihedral angle. A node resting in such a valley feels a force that no position balances (the penalty's
``k A phi n`` jumps by ``k A phi`` times the angle), and Newton cannot converge there. The IMLS surface blends the
facets' planes with smooth weights:

    phi(x) = S / W,   S = sum_i w_i (x - p_i) . n_i,   W = sum_i w_i,   w_i = A_i psi(|x - p_i| / h)        (S1)

with ``p_i``, ``n_i``, ``A_i`` the centroid, unit outward normal and area of facet ``i``, ``h`` the support radius and
``psi(q) = (1 - q)^4 (4 q + 1)`` for ``q < 1`` (Wendland's C2 kernel, 0 beyond). Its derivatives, with ``d_i = (x -
p_i) . n_i``, ``u_i`` the unit vector from ``p_i`` to ``x`` and ``r_i`` the distance:

    grad phi = (sum_i (w_i n_i + d_i grad w_i) - phi grad W) / W                                          (S2)
    hess phi = (sum_i (d_i hess w_i + grad w_i n_i^T + n_i grad w_i^T) - phi hess W
                - grad phi grad W^T - grad W grad phi^T) / W                                               (S3)
    grad w_i = A_i psi'(q) / h u_i,   hess w_i = A_i (psi''(q) / h^2 u_i u_i^T + psi'(q) / (h r_i) (I - u_i u_i^T))

(``psi'(q) / q = -20 (1 - q)^3`` stays finite at ``r_i = 0``). ``phi`` is C2 wherever ``W > 0``: a plane is
reproduced exactly, and on a surface of curvature ``kappa`` the zero set lies outside the facets by about
``kappa <r^2> / 2`` over the support (the weighted mean square distance of the facet centroids): a support of
about three facets keeps this within the facets' own sagitta on a finely tessellated body. ``|grad phi|`` is 1 on
a plane and near 1 elsewhere; the penalty uses ``grad phi`` itself (force = gradient of the energy).

The caller (:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle` with ``smooth``) takes (S1) wherever
some facet centroid lies within ``h`` (``W > 0``) and the triangles' own signed distance beyond, about ``h`` from the
surface, where no contact acts (the two agree there to about the bias above); it requires ``h`` of at least
:data:`MIN_SUPPORT` facet radii, so every point within ``h / 2`` of the triangles has a centroid within ``h``. The
triangles' exact distance, the costly part of a faceted body's query, is then needed only far from it.
"""

from __future__ import annotations

import numpy as np

from rftstatic.compiled import numba_available

__all__ = ["MIN_SUPPORT", "SmoothSurface", "evaluate_smooth"]

MIN_SUPPORT = 2.5
"""Smallest support radius ``h``, in the largest facet's centroid-to-corner radii ``R``: a point within ``h / 2`` of
the triangles lies within ``h / 2 + R < h`` of some facet's centroid."""

GRID_CELLS = 128
"""The facet grid's cells along the surface's longest side at most (cells are ``max(h, extent / GRID_CELLS)``)."""

FAR_SLACK = 0.1
"""A far point's nearest centroid is looked up again once it has moved this fraction of its distance to it."""


prange = range
"""Loop over point blocks in :func:`_imls_blocks`; ``numba.prange`` in its threaded compiled twin."""

PARALLEL_MIN_POINTS = 2000
"""Fewest points for which :meth:`SmoothSurface.evaluate` runs its point blocks on numba's threads (as many blocks
as ``numba.get_num_threads()``, which the explicit force's thread tuner sets); each point's sums are the same in
either kernel, so the results do not depend on it."""


def _gap(c, lo, size):
    """Distance [m] along one axis from the coordinate ``c`` to the cell ``[lo, lo + size]`` (0 inside)."""
    if c < lo:
        return lo - c
    if c > lo + size:
        return c - lo - size
    return 0.0


def _imls(x, facets, hessian, out, start, stop):
    """(S1)-(S3) at the points ``x[start:stop]`` of ``x (n, 3)`` into ``out = (phi (n,), grad (n, 3), H (n, 3, 3) or
    (1, 3, 3) without ``hessian``, W (n,))``. ``facets = (p, nrm, area, grid, order, cell_start)``: centroids, unit
    normals, areas, and the facets ``order[cell_start[c]:cell_start[c + 1]]`` of the cells ``c`` around each point's
    cell (``grid = (lo_x, lo_y, lo_z, size, nx, ny, nz, h)``: cells of ``size >= h``, x fastest, and the support
    radius ``h``)."""
    p, nrm, area, grid, order, cell_start = facets
    phi, grad, H, W_out = out
    lo0, lo1, lo2, size, h = grid[0], grid[1], grid[2], grid[3], grid[7]
    nx, ny, nz = int(grid[4]), int(grid[5]), int(grid[6])
    v = np.zeros(3)
    gW = np.zeros(3)
    gS = np.zeros(3)
    hW = np.zeros((3, 3))
    hS = np.zeros((3, 3))
    reach = h * (1.0 + 1e-9) + 1e-9 * size  # a cell farther than this holds no facet within h (CELL_REACH)
    reach2 = reach * reach
    for k in range(start, stop):
        W = 0.0
        S = 0.0
        gW[:] = 0.0
        gS[:] = 0.0
        hW[:, :] = 0.0
        hS[:, :] = 0.0
        cx = int(np.floor((x[k, 0] - lo0) / size))
        cy = int(np.floor((x[k, 1] - lo1) / size))
        cz = int(np.floor((x[k, 2] - lo2) / size))
        for iz in range(max(cz - 1, 0), min(cz + 2, nz)):
            bz = _gap(x[k, 2], lo2 + iz * size, size)
            for iy in range(max(cy - 1, 0), min(cy + 2, ny)):
                by = _gap(x[k, 1], lo1 + iy * size, size)
                if bz * bz + by * by >= reach2:
                    continue
                x0, x1 = max(cx - 1, 0), min(cx + 1, nx - 1)
                # the cells of the row within reach (a contiguous run: the gap along x grows away from the point)
                while x0 <= x1 and bz * bz + by * by + _gap(x[k, 0], lo0 + x0 * size, size) ** 2 >= reach2:
                    x0 += 1
                while x1 >= x0 and bz * bz + by * by + _gap(x[k, 0], lo0 + x1 * size, size) ** 2 >= reach2:
                    x1 -= 1
                if x0 > x1:
                    continue
                row = (iz * ny + iy) * nx
                for j in range(cell_start[row + x0], cell_start[row + x1 + 1]):
                    i = order[j]
                    for a in range(3):
                        v[a] = x[k, a] - p[i, a]
                    r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
                    if r2 >= reach2:  # q > 1 (the test below would skip it): no sqrt
                        continue
                    r = np.sqrt(r2)
                    q = r / h
                    if q >= 1.0:
                        continue
                    om = 1.0 - q
                    w = area[i] * om ** 4 * (4.0 * q + 1.0)
                    d = v[0] * nrm[i, 0] + v[1] * nrm[i, 1] + v[2] * nrm[i, 2]
                    W += w
                    S += w * d
                    # grad w = A psi'(q) / h u = A (psi'(q) / q) v / h^2, psi'(q) / q = -20 (1 - q)^3
                    c1 = area[i] * (-20.0) * om ** 3 / (h * h)
                    for a in range(3):
                        gW[a] += c1 * v[a]
                        gS[a] += c1 * v[a] * d + w * nrm[i, a]
                    if hessian:
                        # hess w = grad (c1 v) = c1 I + (dc1 / dr) v v^T / r,
                        # dc1 / dr = 60 A (1 - q)^2 / h^3 (v v^T / r -> 0)
                        c2 = area[i] * 60.0 * om * om / (h * h * h * r) if r > 0.0 else 0.0
                        for a in range(3):
                            for b in range(3):
                                hw = c2 * v[a] * v[b] + (c1 if a == b else 0.0)
                                hW[a, b] += hw
                                hS[a, b] += hw * d + c1 * (v[a] * nrm[i, b] + nrm[i, a] * v[b])
        W_out[k] = W
        if W <= 0.0:
            phi[k] = 0.0
            continue
        f = S / W
        phi[k] = f
        for a in range(3):
            grad[k, a] = (gS[a] - f * gW[a]) / W
        if hessian:
            for a in range(3):
                for b in range(3):
                    H[k, a, b] = (hS[a, b] - f * hW[a, b] - grad[k, a] * gW[b] - gW[a] * grad[k, b]) / W


def _imls_blocks(x, facets, hessian, out, blocks):
    """:func:`_imls` over ``blocks`` contiguous blocks of the points ``x (n, 3)``, one block per loop pass."""
    n = x.shape[0]
    for b in prange(blocks):
        _imls(x, facets, hessian, out, b * n // blocks, (b + 1) * n // blocks)


_KERNELS = {}


def _kernels():
    """``{"serial": kernel, "parallel": kernel or None}``: :func:`_imls_blocks` compiled by numba (cached; the
    threaded twin with ``prange`` as ``numba.prange``) when it is installed, else the Python function alone."""
    if not _KERNELS:
        if numba_available():
            import types

            import numba

            scope = dict(globals())
            scope["_gap"] = numba.njit(cache=True, nogil=True, inline="always")(_gap)
            scope["_imls"] = numba.njit(cache=True, nogil=True)(types.FunctionType(_imls.__code__, scope, "_imls"))
            for name, options in (("serial", {}), ("parallel", {"parallel": True})):
                own = dict(scope, prange=numba.prange)
                copy = types.FunctionType(_imls_blocks.__code__, own, "_imls_blocks")
                copy.__qualname__ = "_imls_blocks_" + name  # numba's cache entry is named after it
                _KERNELS[name] = numba.njit(cache=True, nogil=True, **options)(copy)
        else:
            _KERNELS.update(serial=_imls_blocks, parallel=None)
    return _KERNELS


class SmoothSurface:
    """The IMLS surface (S1) of the facets of a closed, outward-wound triangle surface ``V (m, 3)`` [m], ``T (t, 3)``
    with support radius ``h`` [m] (module docstring). The facets are binned in a grid of cells of at least ``h``
    (:data:`GRID_CELLS` along the longest side at most), so a point's facets within ``h`` lie in its own and the 26
    cells around it. ``tree``: a k-d tree of the facet centroids in facet order (the obstacle's own), else one is
    built."""

    def __init__(self, V: np.ndarray, T: np.ndarray, h: float, tree=None):
        from scipy.spatial import cKDTree

        a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
        cross = np.cross(b - a, c - a)
        twice = np.linalg.norm(cross, axis=1)
        self.p = np.ascontiguousarray((a + b + c) / 3.0)
        self.n = np.ascontiguousarray(cross / twice[:, None])
        self.area = np.ascontiguousarray(0.5 * twice)
        self.h = float(h)
        lo, hi = self.p.min(axis=0), self.p.max(axis=0)
        size = max(self.h, float(np.max(hi - lo)) / GRID_CELLS)
        dims = np.floor((hi - lo) / size).astype(np.int64) + 1
        cx, cy, cz = np.floor((self.p - lo) / size).astype(np.int64).T
        cx, cy, cz = np.minimum(cx, dims[0] - 1), np.minimum(cy, dims[1] - 1), np.minimum(cz, dims[2] - 1)
        cell = (cz * dims[1] + cy) * dims[0] + cx
        self.order = np.argsort(cell, kind="stable").astype(np.int64)
        self.cell_start = np.searchsorted(cell[self.order], np.arange(int(np.prod(dims)) + 1)).astype(np.int64)
        self.grid = np.array([*lo, size, *dims, self.h], dtype=float)
        self.tree = cKDTree(self.p) if tree is None else tree
        self._far = {}  # len(x) -> (x_ref, slack^2, facet): the held nearest centroids of far points (nearest_far)

    def nearest_far(self, x: np.ndarray, far: np.ndarray) -> np.ndarray:
        """The facet ``(f,)`` whose centroid stands for the nearest one of each point ``x[far]`` that no facet's
        support reaches (``W = 0``): the nearest when last asked for that point, kept while the point has moved
        less than :data:`FAR_SLACK` of that distance ``d0`` (so the distance to it exceeds the nearest one's by at
        most ``2 FAR_SLACK d0``: a far point's value is an estimate, no contact acts there), else found again."""
        held = self._far.get(len(x))
        if held is None:
            held = (np.zeros_like(x), np.full(len(x), -1.0), np.full(len(x), -1, np.int64))
            if len(self._far) >= 8:
                self._far.pop(next(iter(self._far)))
            self._far[len(x)] = held
        x_ref, slack2, facet = held
        d = x[far] - x_ref[far]
        ask = far[np.einsum("pi,pi->p", d, d) >= slack2[far]]
        if ask.size:
            d0, facet[ask] = self.tree.query(x[ask], k=1)
            x_ref[ask], slack2[ask] = x[ask], (FAR_SLACK * d0) ** 2
        return facet[far]

    def evaluate(self, x: np.ndarray, hessian: bool = False):
        """``(phi (n,) [m], grad (n, 3) [-], H (n, 3, 3) [1/m] or None, W (n,))`` of (S1)-(S3) at ``x (n, 3)`` [m];
        ``W = 0`` where no facet's support reaches (``phi``, ``grad`` 0 there)."""
        x = np.ascontiguousarray(x, dtype=float)
        n = len(x)
        phi, grad, W = np.zeros(n), np.zeros((n, 3)), np.zeros(n)
        H = np.zeros((n, 3, 3) if hessian else (1, 3, 3))
        kernels, blocks = _kernels(), 1
        if kernels["parallel"] is not None and n >= PARALLEL_MIN_POINTS:
            import numba

            blocks = numba.get_num_threads()
        kernel = kernels["parallel"] if blocks > 1 else kernels["serial"]
        kernel(x, (self.p, self.n, self.area, self.grid, self.order, self.cell_start), hessian, (phi, grad, H, W), blocks)
        return phi, grad, (H if hessian else None), W


def evaluate_smooth(ob, x: np.ndarray, hessian: bool):
    """``(phi (n,) [m], normal (n, 3), H (n, 3, 3) or None)`` of a smooth surface obstacle ``ob``
    (:class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle` with ``smooth``) at ``x (n, 3)`` [m]: (S1)-(S3)
    less its offset wherever a facet's support reaches; beyond (``h`` or more from every centroid) the distance to
    the nearest centroid (as held by :meth:`SmoothSurface.nearest_far`) less ``R`` less the offset, signed by the
    side of that facet's plane the point lies on (an estimate of the distance, as the faceted query's far points
    have: no contact acts there; Hessian 0)."""
    phi, normal, H, W = ob._smooth.evaluate(x, hessian)
    phi = phi - ob.offset
    far = np.flatnonzero(W <= 0.0)
    if far.size:
        surface = ob._smooth
        k = surface.nearest_far(x, far)
        away = x[far] - surface.p[k]
        d = np.sqrt(np.einsum("pi,pi->p", away, away))
        side = np.where(np.einsum("pi,pi->p", away, surface.n[k]) < 0.0, -1.0, 1.0)
        phi[far] = side * (d - ob.radius) - ob.offset
        normal[far] = side[:, None] * away / np.maximum(d, 1e-300)[:, None]
    return phi, normal, H
