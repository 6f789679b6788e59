"""Membrane energy of RFT3 (CST, Eq. 14-15) and RFT6 (six-node interpolation, Eq. 24-26).

Both are written as one kernel over *strain points*: the element's membrane strain is the mean of
the Green strains (Eq. 14) at Q points, each computed from a deformation gradient
``F_q = sum_a x_a (x) G_qa`` with constant reference gradients ``G (E, Q, A, 2)`` [1/m]:
  - RFT3: Q = 1 point, the element's three nodes (A = 3), linear shape functions;
  - RFT6: Q = 3 mid-side points I, II, III of the six-node patch (A = 6) with the quadratic shape
    functions of Eq. 24 and the chain rule of Eq. 25; a mid-side point on a boundary edge takes the
    element's own CST gradient (§3, last paragraph), so no image node enters the membrane.
The energy is ``E_m = A/2 eps^T D^m eps`` (Eq. 15) with the averaged strain (one-point rule).

Einsum letters: e element, q strain point, a/b local node, i/j space, J/K reference axis, k/l strain.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.element.patch import Patches
from rftstatic.mesh.trimesh import TriMesh

ELEMENTS = ("RFT3", "RFT6")

# parametric coordinates (xi, eta) of the mid-side points I (5-6), II (6-4), III (4-5)
_MIDSIDE = np.array([[0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])


def six_node_shape_gradients(xi, eta):
    """d N_i / d(xi, eta) of the six-node interpolation of Eq. 24 -> (2, 6), nodes in patch order 1..6."""
    zeta = 1.0 - xi - eta
    dxi = [0.0, -(2 * zeta - 1) / 2, (2 * xi - 1) / 2, zeta - xi, eta - 1.0, 1.0 - eta]
    deta = [(2 * eta - 1) / 2, -(2 * zeta - 1) / 2, 0.0, 1.0 - xi, xi - 1.0, zeta - eta]
    return np.array([dxi, deta])


def cst_gradients(Xe: np.ndarray) -> np.ndarray:
    """Gradients of the linear shape functions ``(E, 3, 2)`` [1/m] for triangles ``Xe (E, 3, 2)``."""
    d = Xe[:, [1, 2, 0]] - Xe[:, [2, 0, 1]]  # edge opposite each vertex
    area2 = d[:, 0, 0] * d[:, 1, 1] - d[:, 0, 1] * d[:, 1, 0]
    # grad N_a = perp(edge opposite a) / 2A, pointing towards a
    return np.stack([d[..., 1], -d[..., 0]], axis=-1) / area2[:, None, None]


@dataclass(frozen=True, eq=False)
class MembraneOperator:
    """Strain-point gradients of one element kind.

    Attributes
    ----------
    kind : "RFT3" or "RFT6"
    nodes : (E, A) global node of each local node
    G : (E, Q, A, 2) reference gradients of the shape functions at the strain points [1/m]
    area : (E,) reference areas [m^2]
    """

    kind: str
    nodes: np.ndarray
    G: np.ndarray
    area: np.ndarray

    @cached_property
    def _G_aqJ(self) -> np.ndarray:
        """G as ``(E, A, Q*2)`` for batched matrix products."""
        E, Q, A, _ = self.G.shape
        return np.ascontiguousarray(self.G.transpose(0, 2, 1, 3).reshape(E, A, 2 * Q))

    def displacement_gradient(self, U: np.ndarray) -> np.ndarray:
        """``H = dU/dX (E, Q, 3, 2)`` at every strain point for displacements ``U (N, 3)`` [m]."""
        E, Q = self.G.shape[:2]
        Ue = U[self.nodes].transpose(0, 2, 1)  # (E, 3, A)
        return np.matmul(Ue, self._G_aqJ).reshape(E, 3, Q, 2).transpose(0, 2, 1, 3)

    def strain(self, U: np.ndarray) -> np.ndarray:
        """Averaged Green membrane strain ``(E, 3)``: (e_xx, e_yy, 2 e_xy), Eq. 14 [-].

        Computed from the displacement gradient, ``E = (H + H^T + H^T H) / 2`` with F = I + H, so
        that no round-off from cancelling reference coordinates enters small strains.
        """
        return _green_voigt(self.displacement_gradient(U)).mean(axis=1)

    def energy(self, U, Dm) -> float:
        """Membrane energy, Eq. 15 [J]."""
        return float(self.element_energy(U, Dm).sum())

    def element_energy(self, U, Dm) -> np.ndarray:
        """(E,) membrane energy of every element [J]."""
        eps = self.strain(U)
        return 0.5 * self.area * np.einsum("ek,ek->e", eps @ Dm, eps)

    def _kinematics(self, U, Dm):
        H = self.displacement_gradient(U)
        eps = _green_voigt(H).mean(axis=1)
        F = H
        F[..., 0, 0] += 1.0
        F[..., 1, 1] += 1.0
        S = eps @ Dm  # (E, 3) second Piola-Kirchhoff membrane stress resultant [N/m]
        E, Q, A, _ = self.G.shape
        # dEps_k / dx_ai averaged over the strain points: Bbar (E, 3, 3*A), columns (a, i)
        G = self.G
        FT = F.transpose(0, 3, 2, 1)  # (E, J, i, q)
        B0 = np.matmul(FT[:, 0], G[..., 0])  # (E, i, a): sum_q F_q[i,0] G_q[a,0]
        B1 = np.matmul(FT[:, 1], G[..., 1])
        B2 = np.matmul(FT[:, 0], G[..., 1]) + np.matmul(FT[:, 1], G[..., 0])
        Bbar = np.stack([B0, B1, B2], axis=1).transpose(0, 1, 3, 2).reshape(E, 3, 3 * A) / Q
        return eps, S, Bbar

    def element_forces(self, U, Dm) -> np.ndarray:
        """Internal membrane forces ``(E, A, 3)`` [N], the gradient of :meth:`energy`."""
        _, S, Bbar = self._kinematics(U, Dm)
        E, A = self.nodes.shape
        return (self.area[:, None] * np.matmul(S[:, None, :], Bbar)[:, 0]).reshape(E, A, 3)

    def element_tangents(self, U, Dm, *, psd=False, backend="auto"):
        """Element forces ``(E, A, 3)`` [N] and tangents ``(E, A, 3, A, 3)`` [N/m].

        With ``psd=True`` the geometric (initial-stress) part uses the positive part of the stress,
        so the tangent is positive semi-definite under compression (the safeguard of method.md);
        the material part ``Bbar^T D^m Bbar`` is always positive semi-definite.
        ``backend``: ``"numba"`` (compiled, :mod:`rftstatic._membrane_numba`; 10-20 x faster),
        ``"numpy"`` (batched matrix products), ``"auto"``: numba when installed.
        """
        if backend == "auto":
            backend = "numba" if numba_available() else "numpy"
        if backend == "numba":
            from rftstatic.element._membrane_numba import element_tangents

            E, Q, A, _ = self.G.shape
            f = np.empty((E, A, 3))
            K = np.empty((E, A, 3, A, 3))
            element_tangents(np.ascontiguousarray(self.nodes, dtype=np.int64), np.ascontiguousarray(self.G),
                             self.area, np.ascontiguousarray(Dm, dtype=float),
                             np.ascontiguousarray(U, dtype=float), bool(psd), f, K)
            return f, K
        _, S, Bbar = self._kinematics(U, Dm)
        E, A = self.nodes.shape
        Q = self.G.shape[1]
        area = self.area
        f = (area[:, None] * np.matmul(S[:, None, :], Bbar)[:, 0]).reshape(E, A, 3)
        Km = np.matmul(Bbar.transpose(0, 2, 1), np.matmul(Dm, Bbar))  # (E, 3A, 3A)
        St = np.stack([np.stack([S[:, 0], S[:, 2]], -1), np.stack([S[:, 2], S[:, 1]], -1)], -2)
        if psd:
            w, v = np.linalg.eigh(St)
            St = np.matmul(v * np.maximum(w, 0.0)[:, None, :], v.transpose(0, 2, 1))
        GS = np.matmul(self.G, St[:, None])  # (E, Q, A, 2)
        g = np.matmul(GS.transpose(0, 2, 1, 3).reshape(E, A, 2 * Q), self._G_aqJ.transpose(0, 2, 1)) / Q
        Km = Km.reshape(E, A, 3, A, 3)
        Km += g[:, :, None, :, None] * np.eye(3)[None, None, :, None, :]
        Km *= area[:, None, None, None, None]
        return f, Km



def _green_voigt(H: np.ndarray) -> np.ndarray:
    """Green strain (e_xx, e_yy, 2 e_xy) from the displacement gradient ``H (..., 3, 2)``, F = I + H."""
    HH = np.einsum("...iJ,...iK->...JK", H, H)
    return np.stack([H[..., 0, 0] + 0.5 * HH[..., 0, 0], H[..., 1, 1] + 0.5 * HH[..., 1, 1],
                     H[..., 0, 1] + H[..., 1, 0] + HH[..., 0, 1]], axis=-1)


def membrane_operator(kind: str, mesh: TriMesh, patches: Patches | None = None) -> MembraneOperator:
    """Strain-point gradients of RFT3 or RFT6 for every element of ``mesh``."""
    if kind not in ELEMENTS:
        raise ValueError(f'unknown element "{kind}"; use one of {", ".join(ELEMENTS)}')
    Xe = mesh.X[mesh.tri]
    cst = cst_gradients(Xe)  # (E, 3, 2)
    if kind == "RFT3":
        return MembraneOperator(kind, mesh.tri, cst[:, None], mesh.area)
    if patches is None:
        raise ValueError("RFT6 needs the element patches")
    Xp = patches.X_patch  # (E, 6, 2), image nodes included (they never get a non-zero weight)
    G = np.empty((mesh.n_elements, 3, 6, 2))
    for q, (xi, eta) in enumerate(_MIDSIDE):
        dN = six_node_shape_gradients(xi, eta)  # (2, 6)
        J = np.einsum("pa,eaJ->epJ", dN, Xp)  # J[e, p, J] = d X_J / d xi_p
        G[:, q] = np.einsum("eJp,pa->eaJ", np.linalg.inv(J), dN)
        # a mid-side point on a boundary edge takes the element's own CST strain (§3)
        boundary = ~patches.has_opposite[:, q]
        cst6 = np.concatenate([np.zeros((mesh.n_elements, 3, 2)), cst], axis=1)
        G[boundary, q] = cst6[boundary]
    return MembraneOperator(kind, patches.nodes, G, mesh.area)
