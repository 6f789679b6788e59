"""Transfer of nodal fields (displacement, velocity) from an old mesh to a new one (§5.2 f, h).

Both meshes are meshes of the same flat reference sheet, so a new node is found by its reference
coordinates ``X`` in the old mesh. Three routes:

``"mesh"`` (default)
    Linear (barycentric) interpolation in the old triangle that contains the new node. Exact for
    fields linear in X, second order for smooth ones, and it keeps any value that is the same at
    all nodes of an old edge (e.g. zero displacement along a clamped edge).
``"patch"``
    The quadratic of the RF patch (Eq. 2) of the old triangle that contains the new node: the
    six patch nodes' values fitted by 1, x, y, x^2, y^2, xy in the element's scaled coordinates
    (the fit whose second derivatives are the element's curvature, :mod:`rftstatic.element.patch`), the
    image node of a boundary edge taking the linear rule U_a + U_b - U_c. Exact for linear fields
    everywhere and for quadratic ones inside, third order for smooth fields. On a curved drape the
    new nodes then lie on the old patch surfaces rather than on the old flat triangles, so the
    chords of the new mesh are not shortened across the old folds: measured on the 20 cm square
    sheet at rest on its pedestal (509 -> 501 nodes), the membrane energy the transfer adds is 2.6
    times smaller than with route "mesh" (the rest of it sits at the pedestal's rim, a kink no
    interpolation carries over). The remeshed relaxations did not come to rest sooner with it
    (measured on the three scenes of §6): after a transfer the sheet still creeps to the new mesh's
    own equilibrium (~0.5 cm on the 20 cm sheet), which takes longer than the shock takes to die.
``"grid"``
    The paper's route (Lee & Lo 1995): the old nodal values are first put on a square background
    grid, then read back bilinearly at the new nodes. The grid values ``g`` minimise

        sum_n |B(X_n) g - u_n|^2  +  w^2 |D g|^2,

    ``B`` the bilinear interpolation at the old nodes and ``D`` the second differences of the grid
    along x and along y (so that grid nodes without old nodes nearby are filled smoothly). ``D``
    vanishes on fields a + bx + cy + dxy, so this route is exact for linear fields as well; for a
    curved field its error is the grid's interpolation error, i.e. it grows with the grid spacing.

New boundary nodes may lie slightly outside the old mesh when the boundary is curved (the new
nodes sit on the circle, the old mesh is an inscribed polygon; the gap is the sagitta ~h^2/(8R)).
Such a node is given to the nearest old triangle (the one with the nearest point). By default
(``outside="extrapolate"``) the linear field of that triangle is extended to the node, which keeps
route "mesh" exact for linear fields everywhere, so a rigid motion or a uniform stretch carries over
without spurious membrane strain (the membrane is ~10^5 times stiffer than the bending here, a
clamped value on a stretched boundary would load it). ``outside="clamp"`` takes the value at the
nearest point instead (barycentric coordinates clipped to the triangle, all >= 0), bounded by the
old values.
"""

from __future__ import annotations

import logging

import numpy as np

log = logging.getLogger(__name__)

__all__ = ["locate", "interpolate", "patch_weights", "GridField", "fit_grid", "transfer_fields", "element_values",
           "METHODS"]

METHODS = ("mesh", "patch", "grid")


def _barycentric(p, P):
    """Barycentric coordinates (M, ..., 3) of points p (M, 2) in triangles P (M, ..., 3, 2), and det."""
    q = p.reshape(p.shape[:1] + (1,) * (P.ndim - 3) + (2,))
    a, b, c = P[..., 0, :], P[..., 1, :], P[..., 2, :]
    d1, d2 = b - a, c - a
    det = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    r = q - a
    l1 = (r[..., 0] * d2[..., 1] - r[..., 1] * d2[..., 0]) / det
    l2 = (d1[..., 0] * r[..., 1] - d1[..., 1] * r[..., 0]) / det
    return det, np.stack([1.0 - l1 - l2, l1, l2], axis=-1)


def _closest_on_triangles(p, P):
    """Closest points of triangles to points.

    Parameters
    ----------
    p : (M, 2) points [m]
    P : (M, K, 3, 2) K candidate triangles per point (counter-clockwise) [m]

    Returns
    -------
    dist : (M, K) distances [m] (0 inside)
    bary : (M, K, 3) barycentric coordinates of the closest points (all >= 0, sum 1)
    """
    q = p[:, None, :]
    _, bary = _barycentric(p, P)
    inside = (bary >= 0.0).all(axis=-1)
    dist = np.where(inside, 0.0, np.inf)
    best = bary.copy()
    for k in range(3):  # edge from local vertex k to k+1 (3 edges, not a loop over the mesh)
        i, j = k, (k + 1) % 3
        e0, e1 = P[:, :, i], P[:, :, j]
        e = e1 - e0
        t = np.clip(np.einsum("mki,mki->mk", q - e0, e) / np.einsum("mki,mki->mk", e, e), 0.0, 1.0)
        x = e0 + t[..., None] * e
        dk = np.linalg.norm(q - x, axis=-1)
        better = ~inside & (dk < dist)
        dist = np.where(better, dk, dist)
        bk = np.zeros_like(bary)
        bk[..., i] = 1.0 - t
        bk[..., j] = t
        best = np.where(better[..., None], bk, best)
    return dist, best


def locate(mesh, points, *, candidates=12, outside="extrapolate"):
    """Old triangle and barycentric coordinates of every point, also just outside the mesh.

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.trimesh.TriMesh` (reference coordinates [m])
    points : (P, 2) reference points [m]
    candidates : triangles (nearest centroids) examined for a point the point location misses
    outside : for points outside the mesh, ``"extrapolate"`` (barycentric coordinates of the point
        itself in the nearest triangle, some < 0) or ``"clamp"`` (those of the nearest point, >= 0)

    Returns
    -------
    elem : (P,) int64 triangle index (always valid)
    bary : (P, 3) barycentric coordinates (see ``outside``)
    distance : (P,) distance from the point to the mesh [m] (0 inside)
    """
    if outside not in ("extrapolate", "clamp"):
        raise ValueError(f'outside = "{outside}" is unknown; use "extrapolate" or "clamp"')
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must have shape (P, 2) [m], got {pts.shape}")
    elem, bary = mesh.locate(pts)
    distance = np.zeros(len(pts))
    miss = np.flatnonzero(elem < 0)
    if len(miss):
        from scipy.spatial import cKDTree

        k = int(min(candidates, mesh.n_elements))
        centroids = mesh.X[mesh.tri].mean(axis=1)
        _, cand = cKDTree(centroids).query(pts[miss], k=k)
        cand = np.asarray(cand, dtype=np.int64).reshape(len(miss), k)
        dist, b = _closest_on_triangles(pts[miss], mesh.X[mesh.tri[cand]])
        pick = dist.argmin(axis=1)
        rows = np.arange(len(miss))
        elem[miss] = cand[rows, pick]
        distance[miss] = dist[rows, pick]
        if outside == "clamp":
            bary[miss] = b[rows, pick]
        else:
            _, raw = _barycentric(pts[miss], mesh.X[mesh.tri[elem[miss]]])
            bary[miss] = raw
    return elem, bary, distance


def interpolate(mesh, values, points=None, *, elem=None, bary=None):
    """Barycentric interpolation of nodal ``values (N, ...)`` at reference ``points (P, 2)`` [m].

    Give either ``points`` or a location ``(elem, bary)`` from :func:`locate`. Returns ``(P, ...)``.
    """
    values = np.asarray(values, dtype=float)
    if values.shape[0] != mesh.n_nodes:
        raise ValueError(f"values must have one row per node of the old mesh ({mesh.n_nodes}), got {values.shape}")
    if elem is None:
        elem, bary, _ = locate(mesh, points)
    return np.einsum("pa,pa...->p...", bary, values[mesh.tri[elem]])


def patch_weights(mesh, elem, points, *, patches=None):
    """Weights of the quadratic patch interpolant (route ``"patch"``) at ``points (P, 2)`` [m].

    Parameters
    ----------
    mesh : the old :class:`rftstatic.mesh.trimesh.TriMesh`
    elem : (P,) old triangle of each point (:func:`locate`)
    points : (P, 2) reference points [m]
    patches : :class:`rftstatic.element.patch.Patches` of ``mesh`` (default: built here)

    Returns
    -------
    nodes : (P, 6) old nodes (the patch nodes of ``elem``)
    weights : (P, 6) their weights; a value at a point is ``sum_a weights[p, a] * values[nodes[p, a]]``.
        An element whose patch is singular (six points on a conic) falls back to its barycentric
        weights.
    """
    from rftstatic.element.patch import COND_ERROR, build_patches, quadratic_basis

    if patches is None:
        patches = build_patches(mesh, check=False)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    elem = np.asarray(elem, dtype=np.int64)
    Xe = mesh.X[mesh.tri[elem]]  # (P, 3, 2)
    centroid = Xe.mean(axis=1)
    h = mesh.element_size[elem]
    xi = (patches.X_patch[elem] - centroid[:, None, :]) / h[:, None, None]
    ok = patches.condition[elem] < COND_ERROR
    C = quadratic_basis(xi[..., 0], xi[..., 1])  # (P, 6 points, 6 terms)
    Cinv = np.linalg.inv(np.where(ok[:, None, None], C, np.eye(6)))
    q = (pts - centroid) / h[:, None]
    w = np.einsum("pj,pja->pa", quadratic_basis(q[:, 0], q[:, 1]), Cinv)  # on the six patch points
    # image node of slot k (no neighbour across edge k): U_img = U_a + U_b - U_c (linear rule)
    has = patches.has_opposite[elem]
    for k in range(3):
        img = ~has[:, k]
        coef = np.where(img, w[:, k], 0.0)
        w[:, 3 + (k + 1) % 3] += coef
        w[:, 3 + (k + 2) % 3] += coef
        w[:, 3 + k] -= coef
        w[:, k] = np.where(img, 0.0, w[:, k])
    if not ok.all():
        _, bary = _barycentric(pts[~ok], Xe[~ok])
        w[~ok] = np.concatenate([np.zeros((int((~ok).sum()), 3)), bary], axis=1)
    return patches.nodes[elem], w


class GridField:
    """Nodal values on a square grid, read bilinearly.

    Parameters
    ----------
    origin : (2,) grid node (0, 0) [m]
    spacing : grid spacing [m]
    values : (nx, ny, C) values at the grid nodes; ``values[i, j]`` at ``origin + spacing (i, j)``
    """

    def __init__(self, origin, spacing, values):
        self.origin = np.asarray(origin, dtype=float)
        self.spacing = float(spacing)
        self.values = np.asarray(values, dtype=float)

    def _weights(self, points):
        nx, ny = self.values.shape[:2]
        p = np.atleast_2d(np.asarray(points, dtype=float))
        u = np.clip((p[:, 0] - self.origin[0]) / self.spacing, 0.0, nx - 1.0)
        v = np.clip((p[:, 1] - self.origin[1]) / self.spacing, 0.0, ny - 1.0)
        i = np.minimum(u.astype(np.int64), nx - 2)
        j = np.minimum(v.astype(np.int64), ny - 2)
        fu, fv = u - i, v - j
        idx = np.stack([i * ny + j, i * ny + j + 1, (i + 1) * ny + j, (i + 1) * ny + j + 1], axis=1)
        w = np.stack([(1 - fu) * (1 - fv), (1 - fu) * fv, fu * (1 - fv), fu * fv], axis=1)
        return idx, w

    def at(self, points):
        """(P, C) bilinear values at ``points (P, 2)`` [m] (clamped to the grid)."""
        idx, w = self._weights(points)
        flat = self.values.reshape(-1, self.values.shape[2])
        return np.einsum("pa,pac->pc", w, flat[idx])


def fit_grid(X, values, *, spacing, region=None, smoothing=1e-3) -> GridField:
    """Least-squares background-grid field of scattered nodal values (module docstring, route "grid").

    Parameters
    ----------
    X : (N, 2) old node reference coordinates [m]
    values : (N, C) nodal values
    spacing : grid spacing [m]
    region : (xmin, ymin, xmax, ymax) [m] to cover (default: bounding box of ``X``)
    smoothing : w^2 relative to the mean diagonal of B^T B [-]
    """
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    X = np.asarray(X, dtype=float)
    values = np.asarray(values, dtype=float).reshape(len(X), -1)
    if not (np.isfinite(spacing) and spacing > 0):
        raise ValueError(f"grid spacing = {spacing!r} must be positive [m]")
    lo, hi = (X.min(axis=0), X.max(axis=0)) if region is None else (np.asarray(region[:2], float), np.asarray(region[2:], float))
    nx = max(int(np.ceil((hi[0] - lo[0]) / spacing - 1e-9)) + 1, 3)
    ny = max(int(np.ceil((hi[1] - lo[1]) / spacing - 1e-9)) + 1, 3)
    G = nx * ny
    grid = GridField(lo, spacing, np.zeros((nx, ny, values.shape[1])))
    idx, w = grid._weights(X)
    B = sp.csr_matrix((w.ravel(), (np.repeat(np.arange(len(X)), 4), idx.ravel())), shape=(len(X), G))
    node = np.arange(G).reshape(nx, ny)
    rows = []
    for a, b, c in ((node[:-2, :], node[1:-1, :], node[2:, :]), (node[:, :-2], node[:, 1:-1], node[:, 2:])):
        m = a.size
        r = np.repeat(np.arange(m), 3)
        cols = np.stack([a.ravel(), b.ravel(), c.ravel()], axis=1).ravel()
        rows.append(sp.csr_matrix((np.tile([1.0, -2.0, 1.0], m), (r, cols)), shape=(m, G)))
    D = sp.vstack(rows)
    BtB = (B.T @ B).tocsc()
    scale = float(BtB.diagonal().mean())
    M = (BtB + smoothing * scale * (D.T @ D)).tocsc()
    g = splu(M).solve(np.asarray(B.T @ values))
    grid.values = g.reshape(nx, ny, -1)
    return grid


def transfer_fields(old_mesh, new_points, fields, *, method="mesh", outside="extrapolate", spacing=None,
                    smoothing=1e-3, patches=None):
    """Steps f and h of §5.2: nodal fields of the old mesh at the nodes of the new one.

    Parameters
    ----------
    old_mesh : :class:`rftstatic.mesh.trimesh.TriMesh`
    new_points : (P, 2) reference coordinates of the new nodes [m]
    fields : sequence of (N, ...) nodal arrays of the old mesh (e.g. U (N, 3) [m], V (N, 3) [m/s])
    method : ``"mesh"`` (barycentric in the old mesh, default), ``"patch"`` (quadratic of the old RF
        patch, :func:`patch_weights`) or ``"grid"`` (background grid)
    outside : route "mesh", new nodes outside the old mesh: ``"extrapolate"`` or ``"clamp"``
        (:func:`locate`); route "patch" always extends the quadratic of the nearest old triangle
    spacing : grid spacing of route "grid" [m] (default: the old mean element size)
    smoothing : regularisation of route "grid" (:func:`fit_grid`)
    patches : route "patch": the old mesh's :class:`rftstatic.element.patch.Patches` (default: built)

    Returns
    -------
    list of (P, ...) arrays, in the order of ``fields``
    """
    if method not in METHODS:
        raise ValueError(f'transfer method "{method}" is unknown; use "mesh", "patch" or "grid"')
    pts = np.atleast_2d(np.asarray(new_points, dtype=float))
    fields = [np.asarray(f, dtype=float) for f in fields]
    for k, f in enumerate(fields):
        if f.shape[0] != old_mesh.n_nodes:
            raise ValueError(f"fields[{k}] has {f.shape[0]} rows, but the old mesh has {old_mesh.n_nodes} nodes")
    if method == "mesh":
        elem, bary, dist = locate(old_mesh, pts, outside=outside)
        if dist.max(initial=0.0) > 0:
            log.debug("transfer: %d new node(s) outside the old mesh, largest distance %.3g m",
                      int((dist > 0).sum()), dist.max())
        return [interpolate(old_mesh, f, elem=elem, bary=bary) for f in fields]
    if method == "patch":
        elem, _, _ = locate(old_mesh, pts)
        nodes, w = patch_weights(old_mesh, elem, pts, patches=patches)
        return [np.einsum("pa,pa...->p...", w, f[nodes]) for f in fields]
    if spacing is None:
        spacing = float(old_mesh.element_size.mean())
    lo = np.minimum(old_mesh.X.min(axis=0), pts.min(axis=0))
    hi = np.maximum(old_mesh.X.max(axis=0), pts.max(axis=0))
    stacked = np.concatenate([f.reshape(len(f), -1) for f in fields], axis=1)
    out = fit_grid(old_mesh.X, stacked, spacing=spacing, region=(*lo, *hi), smoothing=smoothing).at(pts)
    result, c = [], 0
    for f in fields:
        n = int(np.prod(f.shape[1:], dtype=np.int64))
        result.append(out[:, c:c + n].reshape((len(pts),) + f.shape[1:]))
        c += n
    return result


def element_values(old_mesh, values, new_mesh) -> np.ndarray:
    """Per-element values ``(E_old, ...)`` of ``old_mesh`` on the elements of ``new_mesh``: ``(E_new, ...)``.

    Each new element takes the value of the old element that holds its centroid (reference coordinates; a centroid
    outside the old mesh takes the nearest old element's, :func:`locate` with ``outside="clamp"``): piecewise
    constant, as the internal variables it carries are (the frictions' committed slips,
    :meth:`rftstatic.model.model.Model.initial_slip`), so the values stay within the old ones' range."""
    values = np.asarray(values, dtype=float)
    if values.shape[0] != old_mesh.n_elements:
        raise ValueError(f"values must have one row per element of the old mesh ({old_mesh.n_elements}), got "
                         f"{values.shape}")
    centroids = new_mesh.X[new_mesh.tri].mean(axis=1)
    elem, _, _ = locate(old_mesh, centroids, outside="clamp")
    return values[elem].copy()
