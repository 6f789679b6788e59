"""Rotation-lifted steps: a Newton step followed along a curve that turns the sheet's edges instead of stretching them.

Why. From a relaxed drape the displacement iteration walks a long, flat valley whose floor is made of
inextensional fold motions (validation/bench_profile.md, issue 34): a straight step ``x + alpha d`` along such a
motion stretches every turning edge to second order, ``|e + alpha de| - |e| = alpha^2 |de|^2 / (2 |e|)`` for
``de`` normal to ``e``, so the membrane energy grows as ``alpha^4`` and the line search cuts the step to what
that allows. The curve built here has the same start and the same tangent ``d`` at ``alpha = 0`` but turns each
edge by the rotation the step describes, so a rigid turn keeps every edge length exactly and a smooth bending
motion keeps them to second order in the change of the rotation across an element.

Construction (``x (N, 3)`` the positions, ``d (N, 3)`` the step, over the mesh's edges ``e_ij = x_j - x_i``
and their rates ``de_ij = d_j - d_i``):

    A_i w_i = sum_j e_ij x de_ij,        A_i = sum_j (|e_ij|^2 I - e_ij e_ij^T)                      (R1)

the least-squares rotation rate ``w_i`` of node ``i``'s edges (``de ~ w x e``);

    w_ij = (w_i + w_j) / 2,               s_ij = de_ij - w_ij x e_ij                                 (R2)

the edge's rotation rate and the rest of its rate (stretch and shear);

    t_ij(alpha) = R(alpha w_ij) e_ij + alpha s_ij                                                    (R3)

its target at ``alpha``, ``R`` the rotation by the vector ``alpha w_ij`` (Rodrigues); and the positions

    y(alpha) = argmin_y  sum_ij |y_j - y_i - t_ij|^2 + sum_i k_i |y_i - x_i - alpha d_i|^2            (R4)

with a weak anchor ``k_i = ANCHOR x`` the mean node degree on free nodes (it fixes the translation and, for a
compatible linear field, returns ``x + alpha d`` exactly) and the nodes with a supported degree of freedom held
at ``x_i + alpha d_i`` (their prescribed components stay as the step sets them). The matrix of (R4) is a graph
Laplacian plus the anchors: symmetric positive definite, the same for every step of a mesh, factorised once.
Since ``t_ij = e_ij + alpha de_ij + O(alpha^2)``, ``y(alpha) = x + alpha d + O(alpha^2)``: the line search's slope
``r . d`` holds for the curve.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["RotationLift", "ANCHOR"]

ANCHOR = 1e-6
"""Weight of the free nodes' anchor in (R4), relative to the mean node degree [-]: small enough to leave the
edge fit alone (it moves a rigid turn's edge lengths by about this relative amount), large enough to keep the
matrix well conditioned."""


class RotationLift:
    """The rotation-lifted curve (R1)-(R4) of a mesh, its matrix factorised once.

    Parameters
    ----------
    edges : (M, 2) int, the mesh's unique edges (node pairs)
    n_nodes : N
    held : (N,) bool, nodes held on the straight step (a supported degree of freedom)
    """

    def __init__(self, edges: np.ndarray, n_nodes: int, held: np.ndarray | None = None):
        edges = np.asarray(edges, dtype=np.int64)
        if edges.ndim != 2 or edges.shape[1] != 2 or (edges.size and (edges.min() < 0 or edges.max() >= n_nodes)):
            raise ValueError(f"edges must be an (M, 2) array of node indices below {n_nodes}, got shape {edges.shape}")
        held = np.zeros(n_nodes, bool) if held is None else np.asarray(held, bool).reshape(n_nodes)
        self.edges, self.n_nodes, self.held = edges, int(n_nodes), held
        m = len(edges)
        rows = np.repeat(np.arange(m), 2)
        self.D = sp.csr_matrix((np.tile([-1.0, 1.0], m), (rows, edges.ravel())), shape=(m, n_nodes))  # e = D x
        self._ends = abs(self.D).T.tocsr()  # (N, M): sums an edge quantity into both its nodes
        L = (self.D.T @ self.D).tocsc()
        degree = float(L.diagonal().mean()) if n_nodes else 1.0
        self.free = ~held
        self.anchor = ANCHOR * degree
        Lff = L[self.free][:, self.free] + self.anchor * sp.identity(int(self.free.sum()), format="csc")
        self._Lfh = L[self.free][:, held]
        from scipy.sparse.linalg import splu

        self._lu = splu(Lff.tocsc()) if self.free.any() else None

    @classmethod
    def of_model(cls, model) -> RotationLift:
        """The lift of a :class:`~rftstatic.model.model.Model`'s sheet: its mesh's edges, held where a dof is fixed."""
        return cls(model.mesh.topology.edges, model.mesh.n_nodes, np.asarray(model.fixed).reshape(-1, 3).any(axis=1))

    def rates(self, x: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(w (M, 3) [rad per unit alpha], e (M, 3) [m], s (M, 3) [m])``: every edge's rotation rate, vector
        and remaining rate, (R1)-(R2), at positions ``x (N, 3)`` [m] for the step ``d (N, 3)`` [m]."""
        E = self.edges
        e = x[E[:, 1]] - x[E[:, 0]]
        de = d[E[:, 1]] - d[E[:, 0]]
        blocks = np.einsum("mi,mi->m", e, e)[:, None, None] * np.eye(3) - e[:, :, None] * e[:, None, :]
        A = (self._ends @ blocks.reshape(-1, 9)).reshape(-1, 3, 3)
        b = self._ends @ _cross(e, de)
        # a node whose edges are collinear (none on a sheet) has no rotation about their line: a tiny Tikhonov term
        A += (1e-12 * np.trace(A, axis1=1, axis2=2) + 1e-300)[:, None, None] * np.eye(3)
        w_node = np.linalg.solve(A, b[..., None])[..., 0]
        w = 0.5 * (w_node[E[:, 0]] + w_node[E[:, 1]])
        return w, e, de - _cross(w, e)

    def path(self, x: np.ndarray, d: np.ndarray):
        """The curve of ``d (N, 3)`` [m] from ``x (N, 3)`` [m]: a function ``alpha -> y(alpha) - x (N, 3)`` [m],
        (R3)-(R4); ``alpha`` [-] scales the step as on the straight line."""
        x, d = np.asarray(x, float), np.asarray(d, float)
        w, e, s = self.rates(x, d)
        held, free = self.held, self.free

        def displacement(alpha: float) -> np.ndarray:
            theta = alpha * w
            angle = np.sqrt(np.einsum("mi,mi->m", theta, theta))
            k = theta / np.where(angle > 0, angle, 1.0)[:, None]
            c, sn = np.cos(angle)[:, None], np.sin(angle)[:, None]
            turned = e * c + _cross(k, e) * sn + k * (np.einsum("mi,mi->m", k, e)[:, None] * (1.0 - c))
            change = turned - e + alpha * s  # (R3) less the edge now: (R4) solved for the motion y - x
            out = alpha * d  # the held nodes' motion, and the anchors' targets
            if self._lu is not None:
                rhs = (self.D.T @ change)[free] + self.anchor * out[free] - self._Lfh @ out[held]
                out[free] = self._lu.solve(rhs)  # (R4)
            return out

        return displacement


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise ``a x b`` of ``(M, 3)`` arrays (numpy's ``cross`` is slower on many short rows)."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out
