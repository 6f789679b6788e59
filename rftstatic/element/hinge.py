"""Fold hinges: the bending energy of a crease held at a rest dihedral angle (a hem turned back, a pleat).

The RF patch (Eq. 1-13) measures curvature from a smooth quadratic over an element and its three neighbours; a
crease is not smooth, so the patches end at a fold edge (:mod:`rftstatic.mesh.folds`) and a hinge carries the
bending across it. For the fold edge a-b shared by triangles (a, b, c) and (b, a, d), with normals
``N1 = (b - a) x (c - a)``, ``N2 = (d - b) x (b - a)`` (the same direction on a flat, consistently oriented sheet),
the signed dihedral angle about the edge direction e = b - a is

    theta = atan2( e/|e| . (N1 x N2),  N1 . N2 ),                                          (H1)

and the hinge's energy, for the rest angle theta_0 of the fold,

    E = 1/2 k (theta - theta_0)^2,   k = B_n |e| / w,                                      (H2)

the bending energy 1/2 B_n kappa^2 of a crease of width w (curvature kappa = (theta - theta_0) / w over w, per
length |e|); B_n = v . D^b v with v = (n_x^2, n_y^2, 2 n_x n_y) is the bending rigidity across the edge, n the
edge's in-plane normal in triangle 1's material frame (``mesh.corners``, warp along x). The default width is the
two triangles' mean height over the edge, (A_1 + A_2) / |e|: the crease is as wide as the elements that meet there.
The difference theta - theta_0 is taken on (-pi, pi], so a rest angle of +-pi (a hem lying turned back) is smooth.

Gradient (the standard one of the dihedral angle: the opposite vertices move the plane of their own triangle about
the edge, the edge's ends by the projections alpha = (c - a) . e / |e|^2, beta = (d - a) . e / |e|^2):

    dtheta/dc = -|e| N1 / |N1|^2,  dtheta/dd = -|e| N2 / |N2|^2,
    dtheta/da = -(1 - alpha) dtheta/dc - (1 - beta) dtheta/dd,  dtheta/db = -alpha dtheta/dc - beta dtheta/dd. (H3)

The force is k (theta - theta_0) dtheta/dx and the tangent k (dtheta dtheta^T + (theta - theta_0) d^2 theta);
d^2 theta is the derivative of (H3), taken by the complex step (H3 is analytic in x: products, sums and one
square root; the step 1e-30 |e| gives it to round-off, with no subtraction). Checked against finite differences
of the energy and the force (tests/element/test_hinge.py).
"""

from __future__ import annotations

import numpy as np

__all__ = ["FoldHinges", "fold_hinges", "dihedral_angles"]

_COMPLEX_STEP = 1e-30
"""The complex step of d^2 theta, relative to the edge length [-]."""


def _cross(u, v):
    """Cross product along the last axis, for real or complex arrays (no conjugation)."""
    return np.stack([u[..., 1] * v[..., 2] - u[..., 2] * v[..., 1],
                     u[..., 2] * v[..., 0] - u[..., 0] * v[..., 2],
                     u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]], axis=-1)


def _dot(u, v):
    return (u * v).sum(-1)


def _normals(xa, xb, xc, xd):
    e = xb - xa
    return e, _cross(e, xc - xa), _cross(xd - xb, e)


def dihedral_angles(xa, xb, xc, xd) -> np.ndarray:
    """(H,) signed dihedral angle theta [rad] of (H1) across edges a-b of triangles (a, b, c) and (b, a, d), for
    positions ``(H, 3)`` [m] each."""
    e, N1, N2 = _normals(xa, xb, xc, xd)
    sin = _dot(e, _cross(N1, N2)) / np.sqrt(_dot(e, e))
    return np.arctan2(sin, _dot(N1, N2))


def _angle_gradient(x4):
    """(H, 4, 3) dtheta/dx of (H3) for the hinge nodes ``x4 (H, 4, 3)`` (a, b, c, d), real or complex."""
    xa, xb, xc, xd = (x4[:, i] for i in range(4))
    e, N1, N2 = _normals(xa, xb, xc, xd)
    ee = _dot(e, e)
    le = np.sqrt(ee)
    gc = -(le / _dot(N1, N1))[:, None] * N1
    gd = -(le / _dot(N2, N2))[:, None] * N2
    alpha = (_dot(xc - xa, e) / ee)[:, None]
    beta = (_dot(xd - xa, e) / ee)[:, None]
    ga = -(1 - alpha) * gc - (1 - beta) * gd
    gb = -alpha * gc - beta * gd
    return np.stack([ga, gb, gc, gd], axis=1)


class FoldHinges:
    """The hinges of a mesh's fold lines (module docstring), read-only once built.

    Parameters
    ----------
    nodes : (H, 4) int, the nodes a, b (the fold edge), c, d (the opposite vertices) of every hinge
    rest : (H,) rest angle theta_0 [rad], (H1)
    stiffness : (H,) k of (H2) [N m]
    fold : (H,) the index of each hinge's edge in the mesh's :class:`~rftstatic.mesh.folds.FoldLines` (set by
        :func:`fold_hinges`), or None
    """

    def __init__(self, nodes, rest, stiffness, *, fold=None):
        self.nodes = np.array(nodes, dtype=np.int64).reshape(-1, 4)
        self.fold = None if fold is None else np.array(fold, dtype=np.int64)
        self.rest = np.broadcast_to(np.asarray(rest, float), (len(self.nodes),)).copy()
        self.stiffness = np.broadcast_to(np.asarray(stiffness, float), (len(self.nodes),)).copy()
        if not (np.isfinite(self.stiffness).all() and (self.stiffness >= 0).all()):
            raise ValueError("hinge stiffness must be finite and >= 0")
        for a in (self.nodes, self.rest, self.stiffness):
            a.flags.writeable = False

    def __len__(self) -> int:
        return len(self.nodes)

    def angles(self, x: np.ndarray) -> np.ndarray:
        """(H,) dihedral angles theta [rad] at positions ``x (N, 3)`` [m], (H1)."""
        a, b, c, d = self.nodes.T
        return dihedral_angles(x[a], x[b], x[c], x[d])

    def excess(self, x: np.ndarray) -> np.ndarray:
        """(H,) theta - theta_0 on (-pi, pi] [rad]."""
        return np.angle(np.exp(1j * (self.angles(x) - self.rest)))

    def energy(self, x: np.ndarray) -> float:
        """E of (H2) summed over the hinges [J]."""
        t = self.excess(x)
        return 0.5 * float(self.stiffness @ (t * t))

    def force(self, x: np.ndarray) -> np.ndarray:
        """dE/dx ``(N, 3)`` [N]."""
        return self.energy_force(x)[1]

    def energy_force(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """E [J] and dE/dx ``(N, 3)`` [N] from one evaluation of the angles (the explicit step's call)."""
        t = self.excess(x)
        g = (self.stiffness * t)[:, None, None] * _angle_gradient(x[self.nodes])
        return 0.5 * float(self.stiffness @ (t * t)), self._scatter(g, x.shape)

    def _scatter(self, g, shape) -> np.ndarray:
        """Hinge node forces ``(H, 4, 3)`` summed into ``shape`` (N, 3)."""
        f = np.zeros(shape)
        np.add.at(f, self.nodes.ravel(), g.reshape(-1, 3))
        return f

    def element_tangents(self, x: np.ndarray, *, psd: bool = False):
        """Force ``(H, 4, 3)`` [N] and tangent ``(H, 4, 3, 4, 3)`` [N/m] of every hinge; ``psd`` drops the
        (theta - theta_0) d^2 theta term (the rest is k dtheta dtheta^T, positive semi-definite)."""
        x4 = x[self.nodes]
        g = _angle_gradient(x4)  # (H, 4, 3)
        t = self.excess(x)
        k = self.stiffness
        K = k[:, None, None, None, None] * g[:, :, :, None, None] * g[:, None, None, :, :]
        if not psd:
            H = len(x4)
            step = _COMPLEX_STEP * np.sqrt(_dot(x4[:, 1] - x4[:, 0], x4[:, 1] - x4[:, 0]))  # (H,)
            second = np.empty((H, 4, 3, 4, 3))
            for j in range(12):  # d(dtheta)/dx_j by the complex step, all hinges at once
                xj = x4.astype(complex)
                xj[:, j // 3, j % 3] += 1j * step
                second[:, :, :, j // 3, j % 3] = _angle_gradient(xj).imag / step[:, None, None]
            K += (k * t)[:, None, None, None, None] * second
        return (k * t)[:, None, None] * g, K

    def force_tangent_blocks(self, x: np.ndarray, *, psd: bool = False):
        """dE/dx ``(N, 3)`` [N] and the tangent as ``(rows (16H,), cols (16H,), blocks (16H, 3, 3))`` [N/m]
        (node-pair blocks), from one evaluation."""
        fe, K = self.element_tangents(x, psd=psd)
        i, j = np.meshgrid(np.arange(4), np.arange(4), indexing="ij")
        rows = self.nodes[:, i.ravel()].ravel()
        cols = self.nodes[:, j.ravel()].ravel()
        blocks = K.transpose(0, 1, 3, 2, 4)[:, i.ravel(), j.ravel()].reshape(-1, 3, 3)
        return self._scatter(fe, x.shape), (rows, cols, blocks)

    def couplings(self) -> np.ndarray:
        """(6H, 2) the node pairs a hinge couples (c-d lies outside the cut patches: the tangent's structure)."""
        n = self.nodes
        return np.concatenate([n[:, [0, 1]], n[:, [0, 2]], n[:, [0, 3]], n[:, [1, 2]], n[:, [1, 3]], n[:, [2, 3]]])


def fold_hinges(mesh, Db) -> FoldHinges | None:
    """The :class:`FoldHinges` of ``mesh.folds`` (None without folds) for the bending rigidity ``Db (3, 3)`` [N m]
    (module docstring, (H2)). Triangle 1 of a hinge is the lower-numbered element at the fold edge, a -> b its
    counter-clockwise edge (``mesh.tri``) and c its third vertex; ``mesh.folds.angle`` is signed in this frame
    (:func:`rftstatic.garment.sewing.sew` measures it so)."""
    folds = getattr(mesh, "folds", None)
    if folds is None or len(folds) == 0:
        return None
    from rftstatic.mesh.folds import fold_edge_mask

    topo = mesh.topology
    mask = fold_edge_mask(topo, folds, mesh.n_nodes)
    e1, k1 = np.nonzero(mask)
    tri = mesh.tri
    a, b = tri[e1, (k1 + 1) % 3], tri[e1, (k1 + 2) % 3]
    keep = e1 < topo.neighbour[e1, k1]  # one hinge per fold edge: triangle 1 the lower-numbered element
    e1, k1, a, b = e1[keep], k1[keep], a[keep], b[keep]
    e2, k2 = topo.neighbour[e1, k1], topo.neighbour_vertex[e1, k1]
    c, d = tri[e1, k1], tri[e2, k2]
    n = mesh.n_nodes  # the fold's rest angle and width, matched to these edges
    key = np.minimum(folds.edges[:, 0], folds.edges[:, 1]) * n + np.maximum(folds.edges[:, 0], folds.edges[:, 1])
    order = np.argsort(key)
    at = order[np.searchsorted(key[order], np.minimum(a, b) * n + np.maximum(a, b))]
    rest = folds.angle[at]
    # bending rigidity across the edge, in triangle 1's material frame
    P = mesh.corners
    t = P[e1, (k1 + 2) % 3] - P[e1, (k1 + 1) % 3]
    length = np.linalg.norm(t, axis=1)
    nrm = np.stack([t[:, 1], -t[:, 0]], axis=1) / length[:, None]
    v = np.stack([nrm[:, 0] ** 2, nrm[:, 1] ** 2, 2 * nrm[:, 0] * nrm[:, 1]], axis=1)
    Bn = np.einsum("hi,ij,hj->h", v, np.asarray(Db, float), v)
    width = folds.width[at]
    width = np.where(np.isfinite(width), width, (mesh.area[e1] + mesh.area[e2]) / length)
    return FoldHinges(np.stack([a, b, c, d], axis=1), rest, Bn * length / width, fold=at)
