"""RF triangle patches, boundary image nodes and the constant curvature operator (Eq. 1-13).

Element = triangle 4-5-6 (local vertices 0, 1, 2). Patch node 1 is the vertex opposite edge 5-6
in the neighbouring triangle across 5-6, node 2 the one across 6-4, node 3 the one across 4-5, so
the six patch nodes are ``[opp0, opp1, opp2, v0, v1, v2]`` (the paper's 1..6).

The quadratic fit of Eq. 2, ``w = c1 + c2 x + c3 y + c4 x^2/2 + c5 y^2/2 + c6 xy/2``, is made in
local coordinates centred on the element and scaled by its size so that C (Eq. 2) stays well
conditioned; L, the lower half of C^-1, maps the six nodal values to (w_xx, w_yy, 2 w_xy) (Eq. 3).

Where an edge a-b of element c-a-b has no neighbour (or is a fold edge, :mod:`rftstatic.mesh.folds`, where the
crease's hinge carries the bending across, :mod:`rftstatic.element.hinge`), the missing patch node is an *image node* at
X_img = X_a + X_b - X_c (Fig. 4b) whose displacement is a fixed combination of real nodes:
  - free edge:    U_img = U_a + U_b - U_c  (linear across the edge: no moment across it);
  - clamped edge: U_img = U_c              (mirror: zero slope), when both a and b are clamped.
Folding these rules into L gives ``L_real (E, 3, 6)`` acting on six real nodes, and the bending
stiffness is constant (Eq. 13): ``k_b = A L^T D^b L`` per element, one scalar N x N matrix for
all three displacement components (B = L (x) I_3, Eq. 12).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rftstatic.errors import PatchError
from rftstatic.mesh.trimesh import TriMesh

log = logging.getLogger(__name__)

COND_ERROR = 1e10
"""Condition number of the scaled patch matrix C above which a patch is singular (an error)."""
COND_WARN = 1e6
"""Condition number above which a patch is reported as badly conditioned (a warning)."""



def quadratic_basis(x, y):
    """Rows (1, x, y, x^2/2, y^2/2, xy/2) of Eq. 2 for points ``x, y (..., P)`` -> ``(..., P, 6)``."""
    return np.stack([np.ones_like(x), x, y, 0.5 * x * x, 0.5 * y * y, 0.5 * x * y], axis=-1)


@dataclass(frozen=True, eq=False)
class Patches:
    """Patch topology and the curvature operator of every element.

    Attributes
    ----------
    nodes : (E, 6) int, real node of each patch slot (a missing opposite node is replaced by the
        element vertex it mirrors; its coefficient is folded away)
    has_opposite : (E, 3) bool, slot k (0..2) has a real opposite node
    clamped_edge : (E, 3) bool, boundary edge k is clamped (image rule U_img = U_c)
    X_patch : (E, 6, 2) reference coordinates of the six patch points, image nodes included [m]
    L_geom : (E, 3, 6) curvature operator of the six patch points (image nodes as points) [1/m^2]
    L : (E, 3, 6) curvature operator on ``nodes`` after folding the image-node rules [1/m^2]
    condition : (E,) condition number of the scaled C
    """

    nodes: np.ndarray
    has_opposite: np.ndarray
    clamped_edge: np.ndarray
    X_patch: np.ndarray
    L_geom: np.ndarray
    L: np.ndarray
    condition: np.ndarray

    @property
    def n_elements(self) -> int:
        return len(self.nodes)


def build_patches(mesh: TriMesh, *, clamped_nodes=None, check=True) -> Patches:
    """Patch topology, image nodes and curvature operator for every element of ``mesh``.

    Parameters
    ----------
    mesh : the flat reference mesh
    clamped_nodes : node indices that are clamped; a boundary edge with both ends clamped uses the
        mirror image rule (zero slope), every other boundary edge the free rule
    check : raise :class:`PatchError` for singular patches, log badly conditioned ones
    """
    tri = mesh.tri
    topo = mesh.topology
    has_opp = ~topo.is_boundary & ~mesh.fold_mask  # a fold edge ends the patch (rftstatic.mesh.folds)
    nb = np.maximum(topo.neighbour, 0)
    opp_real = tri[nb, np.maximum(topo.neighbour_vertex, 0)]  # (E, 3)
    # image node coordinates X_a + X_b - X_c for edge k (a, b = the other two vertices, c = vertex k)
    Xe = mesh.corners  # (E, 3, 2)
    X_img = Xe[:, [1, 2, 0]] + Xe[:, [2, 0, 1]] - Xe
    X_nb = mesh.X[opp_real] if mesh.element_X is None else unfolded_opposites(mesh)
    X_opp = np.where(has_opp[..., None], X_nb, X_img)
    X_patch = np.concatenate([X_opp, Xe], axis=1)  # (E, 6, 2)

    # scaled local coordinates: centred on the centroid, divided by the element size
    centroid = Xe.mean(axis=1, keepdims=True)
    h = mesh.element_size[:, None]
    xi = (X_patch - centroid) / h[..., None]
    C = quadratic_basis(xi[..., 0], xi[..., 1])  # (E, 6, 6)
    sv = np.linalg.svd(C, compute_uv=False)
    condition = sv[:, 0] / np.maximum(sv[:, -1], 1e-300)
    if check:
        _report_conditioning(mesh, condition)
    Cinv = np.linalg.inv(np.where((condition < COND_ERROR)[:, None, None], C, np.eye(6)))
    L_geom = Cinv[:, 3:6, :] / (h[..., None] ** 2)  # back to physical coordinates

    clamped = np.zeros(mesh.n_nodes, dtype=bool)
    if clamped_nodes is not None:
        clamped[np.asarray(clamped_nodes, dtype=np.int64)] = True
    a_node, b_node = tri[:, [1, 2, 0]], tri[:, [2, 0, 1]]
    clamped_edge = ~has_opp & clamped[a_node] & clamped[b_node]

    L = L_geom.copy()
    nodes = np.concatenate([np.where(has_opp, opp_real, tri), tri], axis=1)
    for k in range(3):  # fold the image rule of slot k into the element's own vertices
        img = ~has_opp[:, k]
        coef = np.where(img[:, None], L[:, :, k], 0.0)  # (E, 3)
        free = img & ~clamped_edge[:, k]
        a, b = 3 + (k + 1) % 3, 3 + (k + 2) % 3
        L[:, :, a] += np.where(free[:, None], coef, 0.0)
        L[:, :, b] += np.where(free[:, None], coef, 0.0)
        L[:, :, 3 + k] += np.where(free[:, None], -coef, coef)
        L[:, :, k] = np.where(img[:, None], 0.0, L[:, :, k])
    return Patches(nodes, has_opp, clamped_edge, X_patch, L_geom, L, condition)


def unfolded_opposites(mesh: TriMesh) -> np.ndarray:
    """(E, 3, 2) [m]: the vertex of the neighbour across each edge k of every element, unfolded into the element's
    own flat reference (``mesh.corners``), for a mesh whose elements each keep their own flat shape (a sewn mesh,
    :attr:`rftstatic.mesh.trimesh.TriMesh.element_X`). The neighbour is turned flat about the shared edge a-b: its
    opposite vertex keeps its coordinates along a-b and across it, in units of the edge's length in the neighbour
    (so across a seam eased by a few per cent it scales with the element's own edge), on the far side of a-b from
    the element's vertex k. In a flat mesh this is ``X[opposite]`` exactly (rigid motions of one chart); entries of
    boundary edges are meaningless (the image nodes take them)."""
    tri, topo, P = mesh.tri, mesh.topology, mesh.corners
    nb, nv = np.maximum(topo.neighbour, 0), np.maximum(topo.neighbour_vertex, 0)  # (E, 3)
    k = np.arange(3)
    Pa, Pb = P[:, (k + 1) % 3], P[:, (k + 2) % 3]  # the element's edge k, a -> b (counter-clockwise)
    Q = P[nb]  # (E, 3, 3, 2): the neighbour's corners; there the same edge runs b -> a
    rows = np.arange(len(tri))[:, None]
    Qc = Q[rows, k[None, :], nv]  # the neighbour's opposite vertex
    Qb, Qa = Q[rows, k[None, :], (nv + 1) % 3], Q[rows, k[None, :], (nv + 2) % 3]
    d = Qa - Qb  # in the neighbour's frame, along b -> a
    L2 = np.maximum((d * d).sum(-1), 1e-300)
    r = Qc - Qb
    s = (r * d).sum(-1) / L2  # along b -> a
    t = (d[..., 0] * r[..., 1] - d[..., 1] * r[..., 0]) / L2  # left of b -> a (> 0: counter-clockwise)
    e = Pa - Pb  # the element's b -> a: its left side is away from the element's vertex k
    left = np.stack([-e[..., 1], e[..., 0]], axis=-1)
    return Pb + s[..., None] * e + t[..., None] * left


def _report_conditioning(mesh: TriMesh, condition: np.ndarray) -> None:
    bad = np.flatnonzero(~(condition < COND_ERROR))
    centroid = lambda e: mesh.X[mesh.tri[e]].mean(axis=0)  # noqa: E731
    if len(bad):
        where = "; ".join(
            f"element {e} at ({centroid(e)[0]:.6g}, {centroid(e)[1]:.6g}) m, cond {condition[e]:.3g}"
            for e in bad[:5]
        )
        raise PatchError(
            f"{len(bad)} singular patch(es): the six patch points lie on one conic. {where}. "
            "Re-mesh around these elements (e.g. another diagonal pattern or an unstructured mesh)."
        )
    poor = np.flatnonzero(condition > COND_WARN)
    if len(poor):
        e = poor[np.argmax(condition[poor])]
        c = centroid(e)
        log.warning(
            "%d badly conditioned patch(es) (cond > %.0e); worst: element %d at (%.6g, %.6g) m, cond %.3g",
            len(poor), COND_WARN, e, c[0], c[1], condition[e],
        )


def bending_stiffness(mesh: TriMesh, patches: Patches, Db: np.ndarray) -> sp.csr_matrix:
    """Constant scalar bending stiffness K_b (N x N) [N m / m^2 = N/m], Eq. 13.

    The bending energy is ``E_b = 1/2 sum_i U[:, i] . K_b U[:, i]``; the bending force is
    ``K_b @ U`` for displacements ``U (N, 3)``.
    """
    ke = mesh.area[:, None, None] * np.einsum("eka,kl,elb->eab", patches.L, Db, patches.L)
    rows = np.repeat(patches.nodes, 6, axis=1).ravel()
    cols = np.tile(patches.nodes, (1, 6)).ravel()
    n = mesh.n_nodes
    K = sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    K.sum_duplicates()
    return K


def curvature(patches: Patches, U: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Curvature vectors (k_xx, k_yy, 2 k_xy) of every element, Eq. 7 [1/m].

    Parameters
    ----------
    U : (N, 3) displacements [m] (the image rules act on displacements, not positions)
    x : (N, 3) current positions [m], for the element normals n of Eq. 7

    Returns
    -------
    (E, 3) signed curvatures, taken along the current element normal.
    """
    d2 = np.einsum("eka,eai->eki", patches.L, U[patches.nodes])  # (E, 3, 3): U_,xx U_,yy 2U_,xy
    P = x[patches.nodes[:, 3:]]
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    return np.einsum("eki,ei->ek", d2, n)
