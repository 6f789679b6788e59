"""Load terms with a potential beyond dead nodal forces: the end moment of a strip, and the seam springs that
close a garment's seams (:class:`SeamSprings`).

With translational degrees of freedom only, a moment has no rotation to act on. A conservative
end moment M about the y axis is given the potential

    Pi_M = -lam * sum_k M_k phi_k,     phi_k = atan2(r_z, r_x),   r = x_lever,k - x_tip,k,

where phi_k is the angle, in the x-z plane, of the segment from a tip node to a "lever" node one
element beyond the tip (the strip extended by one element): the work of a moment on a rotation.
Its gradient is the follower couple M/|r| perpendicular to r (exactly M on [0, L]), and its Hessian
is the load stiffness, so the moment enters the Newton solver, its energy line search and its
safeguards like any other term. phi is tracked continuously through full turns (the roll-up of Sze
et al. 2004 rotates the end by 2 pi): :meth:`LeverMoment.branch` gives the branch at every converged
increment, which the solve keeps in its State (``State.load_branches``) and hands back to
:meth:`LeverMoment.potential`; the load itself is read-only once built.
"""

from __future__ import annotations

import numpy as np

from rftstatic.model.frozen import Frozen


class LeverMoment(Frozen):
    """Conservative end moment about +y on ``(tip, lever)`` node pairs (read-only once built).

    Parameters
    ----------
    tip, lever : (K,) node indices: each lever node lies one element beyond its tip node
    moments : (K,) moment carried by each pair at load factor 1 [N m] (sum = the end moment)
    """

    def __init__(self, tip, lever, moments):
        self.tip = np.array(tip, dtype=np.int64)
        self.lever = np.array(lever, dtype=np.int64)
        self.moments = np.array(moments, dtype=float)
        if not (self.tip.shape == self.lever.shape == self.moments.shape):
            raise ValueError(f"tip, lever and moments must have one entry per pair, got "
                             f"{self.tip.shape}, {self.lever.shape}, {self.moments.shape}")
        for a in (self.tip, self.lever, self.moments):
            a.flags.writeable = False
        self._freeze()

    def angles(self, x: np.ndarray, branch: np.ndarray | None = None) -> np.ndarray:
        """Lever angles ``phi (K,)`` [rad] at positions ``x (N, 3)`` [m], each within pi of ``branch (K,)``
        [rad] (the committed angles, :meth:`branch`; None: the principal values in (-pi, pi])."""
        r = x[self.lever] - x[self.tip]
        raw = np.arctan2(r[:, 2], r[:, 0])
        if branch is None:
            return raw
        return branch + np.angle(np.exp(1j * (raw - branch)))

    def branch(self, x: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
        """The branch ``(K,)`` [rad] to commit at a converged state ``x (N, 3)`` [m]: its angles, continuous
        from the ``previous`` branch (None: the principal values)."""
        return self.angles(x, previous)

    def potential(self, x: np.ndarray, branch: np.ndarray | None = None) -> float:
        """Potential per unit load factor, ``-sum M_k phi_k`` [J], the angles on ``branch`` (:meth:`angles`)."""
        return -float(self.moments @ self.angles(x, branch))

    def _grad_hess(self, x):
        r = x[self.lever] - x[self.tip]
        rx, rz = r[:, 0], r[:, 2]
        rho2 = rx * rx + rz * rz
        g = np.zeros((len(r), 3))
        g[:, 0], g[:, 2] = -rz / rho2, rx / rho2
        H = np.zeros((len(r), 3, 3))
        H[:, 0, 0] = 2 * rx * rz / rho2**2
        H[:, 0, 2] = H[:, 2, 0] = (rz * rz - rx * rx) / rho2**2
        H[:, 2, 2] = -2 * rx * rz / rho2**2
        return g, H

    def force(self, x: np.ndarray) -> np.ndarray:
        """Gradient of :meth:`potential` ``(N, 3)`` [N]."""
        g, _ = self._grad_hess(x)
        f = np.zeros_like(x)
        np.add.at(f, self.lever, -self.moments[:, None] * g)
        np.add.at(f, self.tip, self.moments[:, None] * g)
        return f

    def tangent_blocks(self, x: np.ndarray):
        """Hessian of :meth:`potential` as ``(rows (4K,), cols (4K,), blocks (4K, 3, 3))`` [N/m]."""
        _, H = self._grad_hess(x)
        B = -self.moments[:, None, None] * H
        rows = np.concatenate([self.lever, self.tip, self.lever, self.tip])
        cols = np.concatenate([self.lever, self.tip, self.tip, self.lever])
        return rows, cols, np.concatenate([B, B, -B, -B])


class SeamSprings(Frozen):
    """Zero-length springs pulling the two sides of a garment's seams together (read-only once built).

    The sewing stage's closing load (:mod:`rftstatic.garment.sewing`): for node pairs (a_k, b_k) with stiffness k_k

        Pi_S = lam * 1/2 sum_k k_k |x_a,k - x_b,k|^2,

    a potential load (``Model(load_terms=...)``) whose gradient pulls each pair together along the gap and whose
    Hessian is the constant ``k_k [[I, -I], [-I, I]]``; no branches (:meth:`branch` gives None).

    Parameters
    ----------
    pairs : (S, 2) node indices, side A and side B of each seam node pair
    stiffness : (S,) or scalar spring stiffness [N/m]
    """

    def __init__(self, pairs, stiffness):
        self.pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        self.stiffness = np.broadcast_to(np.asarray(stiffness, dtype=float), (len(self.pairs),)).copy()
        if not (np.isfinite(self.stiffness).all() and (self.stiffness >= 0).all()):
            raise ValueError("seam spring stiffness must be finite and >= 0")
        for a in (self.pairs, self.stiffness):
            a.flags.writeable = False
        self._freeze()

    def gaps(self, x: np.ndarray) -> np.ndarray:
        """(S,) distance between the two nodes of each pair [m] at positions ``x (N, 3)`` [m]."""
        return np.linalg.norm(x[self.pairs[:, 0]] - x[self.pairs[:, 1]], axis=1)

    def branch(self, x: np.ndarray, previous=None):
        return None

    def couplings(self) -> np.ndarray:
        """(S, 2) the node pairs the springs couple (outside the RF patches: the tangent's structure takes them)."""
        return self.pairs

    def potential(self, x: np.ndarray, branch=None) -> float:
        """``1/2 sum k |x_a - x_b|^2`` [J] per unit load factor."""
        d = x[self.pairs[:, 0]] - x[self.pairs[:, 1]]
        return 0.5 * float(np.einsum("s,si,si->", self.stiffness, d, d))

    def force(self, x: np.ndarray) -> np.ndarray:
        """Gradient of :meth:`potential` ``(N, 3)`` [N]."""
        g = self.stiffness[:, None] * (x[self.pairs[:, 0]] - x[self.pairs[:, 1]])
        f = np.zeros_like(x)
        np.add.at(f, self.pairs[:, 0], g)
        np.add.at(f, self.pairs[:, 1], -g)
        return f

    def tangent_blocks(self, x: np.ndarray):
        """Hessian of :meth:`potential` as ``(rows (4S,), cols (4S,), blocks (4S, 3, 3))`` [N/m]."""
        a, b = self.pairs[:, 0], self.pairs[:, 1]
        B = self.stiffness[:, None, None] * np.eye(3)
        return np.concatenate([a, b, a, b]), np.concatenate([a, b, b, a]), np.concatenate([B, B, -B, -B])
