"""Membrane energy of RFT3 (CST, Eq. 14-15) and RFT6 (six-node interpolation, Eq. 24-26).

Both are written as one kernel over *strain points*: the element's membrane strain is the mean of
the Green strains (Eq. 14) at Q points, each computed from a deformation gradient
``F_q = sum_a x_a (x) G_qa`` with constant reference gradients ``G (E, Q, A, 2)`` [1/m]:
  - RFT3: Q = 1 point, the element's three nodes (A = 3), linear shape functions;
  - RFT6: Q = 3 mid-side points I, II, III of the six-node patch (A = 6) with the quadratic shape
    functions of Eq. 24 and the chain rule of Eq. 25; a mid-side point on a boundary edge takes the
    element's own CST gradient (§3, last paragraph), so no image node enters the membrane.
The energy is ``E_m = A/2 eps^T D^m eps`` (Eq. 15) with the averaged strain (one-point rule).

This module builds the gradients ``G`` (:func:`membrane_operator`); the strain, stress, energy, force
and tangent are the kernels of :mod:`rftstatic.element.kernels`, written once and run compiled (numba)
or vectorised (numpy), which the explicit force (:mod:`rftstatic.element.explicit_force`) calls too.

Einsum letters: e element, q strain point, a/b local node, i/j space, J/K reference axis, k/l strain.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rftstatic.compiled import choose_kernels, numba_available
from rftstatic.element.kernels_numpy import (
    element_last,
    energies_numpy,
    forces_numpy,
    linearised_strain_numpy,
    strains_numpy,
    tangents_numpy,
)
from rftstatic.element.patch import Patches
from rftstatic.mesh.trimesh import TriMesh

ELEMENTS = ("RFT3", "RFT6")
BACKENDS = ("auto", "numpy", "numba")

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
    offset : (E, A, 3) reference offsets [m] of a mesh sewn from panels
        (:attr:`rftstatic.mesh.trimesh.TriMesh.element_X`): ``X3[nodes[e, a]] - (X_e,a, 0)``, the placed
        reference position of each local node less its position in the element's own flat reference, so
        that ``U + offset`` is the displacement from that flat reference; None for a flat mesh (zero)
    """

    kind: str
    nodes: np.ndarray
    G: np.ndarray
    area: np.ndarray
    offset: np.ndarray | None = None

    @cached_property
    def offset_last(self) -> np.ndarray | None:
        """:attr:`offset` as ``(A, 3, E)``, the element-last layout of the vectorised kernels (None: no offset)."""
        return None if self.offset is None else np.ascontiguousarray(np.moveaxis(self.offset, 0, -1))

    @cached_property
    def G_last(self) -> np.ndarray:
        """G as ``(Q, A, 2, E)``, the element-last layout of the vectorised kernels."""
        return element_last(self.G)

    @cached_property
    def _compiled_args(self):
        """``nodes`` (int64), ``G``, ``area`` and the offsets ``D`` (``(0, A, 3)`` without), contiguous, for the
        compiled kernels."""
        D = np.zeros((0,) + self.nodes.shape[1:] + (3,)) if self.offset is None else self.offset
        return (np.ascontiguousarray(self.nodes, dtype=np.int64), np.ascontiguousarray(self.G, dtype=float),
                np.ascontiguousarray(self.area, dtype=float), np.ascontiguousarray(D, dtype=float))

    def displacement_gradient(self, U: np.ndarray) -> np.ndarray:
        """``H = dU/dX (E, Q, 3, 2)`` [-] at every strain point for displacements ``U (N, 3)`` [m]."""
        return strains_numpy(self.G_last, self.nodes, U, self.offset_last)[1].transpose(3, 0, 2, 1)

    def strain(self, U: np.ndarray) -> np.ndarray:
        """Averaged Green membrane strain ``(E, 3)``: (e_xx, e_yy, 2 e_xy), Eq. 14 [-].

        Computed from the displacement gradient, ``E = (H + H^T + H^T H) / 2`` with F = I + H, so
        that no round-off from cancelling reference coordinates enters small strains.
        """
        return strains_numpy(self.G_last, self.nodes, U, self.offset_last)[0]

    def linearised_strain(self, U: np.ndarray, dU: np.ndarray, *, backend="auto") -> np.ndarray:
        """``eps(U) + Bbar(U) dU (E, 3)`` [-]: the averaged strain of Eq. 14 linearised about ``U (N, 3)``
        along ``dU (N, 3)`` [m] (exact to first order; the Green strain's quadratic term in dU left out)."""
        U, dU = _as_float(U), _as_float(dU)
        if _compiled(backend, len(self.nodes)):
            from rftstatic.element._kernels_numba import membrane_linearised_strains

            out = np.empty((len(self.nodes), 3))
            nodes, G, _, D = self._compiled_args
            membrane_linearised_strains(nodes, G, D, U, dU, out)
            return out
        return linearised_strain_numpy(self.G_last, self.nodes, U, dU, self.offset_last)

    def force_roundoff(self, U: np.ndarray, Dm: np.ndarray) -> np.ndarray:
        """``(E, A)`` [N]: the size of the round-off in the element forces at ``U (N, 3)`` [m], per unit
        roundoff ``eps``: ``A |g_a| |F| |D^m| (|H| + |H|^2)``. The strain of Eq. 14 sums terms of size |H|
        and |H|^2 (a rotated element: both of order 1 while the strain itself is tiny), so its error is
        ``eps (|H| + |H|^2)`` whatever the strain, and a membrane as stiff as ``|D^m|`` [N/m] turns it
        into a stress error that no force residual can go below (the strip at C/B = 1e9 /cm^2 stalls
        at 1e-9 N, 1e-5 of its weight)."""
        H = self.displacement_gradient(_as_float(U))  # (E, Q, 3, 2)
        hmag = np.sqrt((H * H).sum(axis=(2, 3))).max(axis=1)  # (E,)
        gmag = np.sqrt((self.G * self.G).sum(axis=-1)).max(axis=1)  # (E, A)
        dnorm = float(np.abs(Dm).sum(axis=1).max())
        return (self.area * (1.0 + hmag) * dnorm * (hmag + hmag * hmag))[:, None] * gmag

    def energy(self, U, Dm, *, backend="auto") -> float:
        """Membrane energy, Eq. 15 [J]."""
        return float(self.element_energy(U, Dm, backend=backend).sum())

    def element_energy(self, U, Dm, *, backend="auto") -> np.ndarray:
        """(E,) membrane energy of every element [J]."""
        U, Dm = _as_float(U), _as_float(Dm)
        if _compiled(backend, len(self.nodes)):
            from rftstatic.element._kernels_numba import membrane_energies

            We = np.empty(len(self.nodes))
            membrane_energies(*self._compiled_args, Dm, U, We)
            return We
        return energies_numpy(self.G_last, self.nodes, self.area, Dm, U, self.offset_last)

    def element_forces(self, U, Dm, *, backend="auto") -> np.ndarray:
        """Internal membrane forces ``(E, A, 3)`` [N], the gradient of :meth:`energy`."""
        U, Dm = _as_float(U), _as_float(Dm)
        if _compiled(backend, len(self.nodes)):
            from rftstatic.element._kernels_numba import membrane_forces

            fe = np.empty(self.nodes.shape + (3,))
            membrane_forces(*self._compiled_args, Dm, U, fe, 0, len(fe))
            return fe
        return np.moveaxis(forces_numpy(self.G_last, self.nodes, self.area, Dm, U, self.offset_last)[0], -1, 0)

    def element_tangents(self, U, Dm, *, psd=False, stress=None, backend="auto"):
        """Element forces ``(E, A, 3)`` [N] and tangents ``(E, A, 3, A, 3)`` [N/m].

        With ``psd=True`` the geometric (initial-stress) part uses the positive part of the stress,
        so the tangent is positive semi-definite under compression (docs/theory/membrane.md);
        the material part ``Bbar^T D^m Bbar`` is always positive semi-definite.
        ``stress (E, 3)`` [N/m]: the stress of the geometric part in place of ``D^m eps(U)`` (the mixed
        stress of MIP Newton, :mod:`rftstatic.solvers.newton`); None: the exact Hessian.
        ``backend`` (here and in the other methods): ``"numba"`` (the kernels of
        :mod:`rftstatic.element.kernels` compiled, one element at a time), ``"numpy"`` (the same
        kernels vectorised over the elements), ``"auto"``: the choice of
        :func:`rftstatic.compiled.choose_kernels` for this many elements (a Model passes its own, ``kernels``).
        """
        U, Dm = _as_float(U), _as_float(Dm)
        if _compiled(backend, len(self.nodes)):
            from rftstatic.element._kernels_numba import membrane_tangents

            E, A = self.nodes.shape
            f = np.empty((E, A, 3))
            K = np.empty((E, A, 3, A, 3))
            S = np.zeros((0, 3)) if stress is None else _as_float(stress)
            membrane_tangents(*self._compiled_args, Dm, U, bool(psd), S, f, K)
            return f, K
        return tangents_numpy(self.G_last, self.nodes, self.area, Dm, U, bool(psd), stress, self.offset_last)


    def tangents_into(self, U, Dm, emap, data, *, psd=False, stress=None, backend="auto") -> np.ndarray:
        """Add the element tangents of :meth:`element_tangents` into CSR values ``data (nnz,)`` [N/m] at
        the positions ``emap (E, A, 3, A, 3)`` (int64, contiguous); return the element forces
        ``(E, A, 3)`` [N]. Compiled: one pass, no element-matrix array (the 101 x 21 strip: 4000
        elements, 1.3 M entries, 10 MB a tangent)."""
        U, Dm = _as_float(U), _as_float(Dm)
        if _compiled(backend, len(self.nodes)):
            from rftstatic.element._kernels_numba import membrane_tangents_into

            fe = np.empty(self.nodes.shape + (3,))
            S = np.zeros((0, 3)) if stress is None else _as_float(stress)
            membrane_tangents_into(*self._compiled_args, Dm, U, bool(psd), S, emap, fe, data)
            return fe
        fe, ke = self.element_tangents(U, Dm, psd=psd, stress=stress, backend=backend)
        data += np.bincount(emap.ravel(), ke.ravel(), minlength=len(data))
        return fe


def _compiled(backend: str, n_elements: int) -> bool:
    """Whether ``backend`` (``"auto"``, ``"numpy"`` or ``"numba"``) means the compiled kernels for a mesh
    of ``n_elements`` (``"auto"``: :func:`rftstatic.compiled.choose_kernels`, a function of the size alone)."""
    if backend not in BACKENDS:
        raise ValueError(f'membrane backend must be one of {", ".join(BACKENDS)}, got "{backend}"')
    if backend == "numba" and not numba_available():
        raise ValueError('membrane backend "numba" needs numba: pip install "rftstatic[fast]"')
    return backend == "numba" or (backend == "auto" and choose_kernels(n_elements) == "compiled")


def _as_float(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def membrane_operator(kind: str, mesh: TriMesh, patches: Patches | None = None) -> MembraneOperator:
    """Strain-point gradients of RFT3 or RFT6 for every element of ``mesh``."""
    if kind not in ELEMENTS:
        raise ValueError(f'unknown element "{kind}"; use one of {", ".join(ELEMENTS)}')
    Xe = mesh.corners
    cst = cst_gradients(Xe)  # (E, 3, 2)
    if kind == "RFT3":
        return MembraneOperator(kind, mesh.tri, cst[:, None], mesh.area, _offset(mesh, mesh.tri, Xe))
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
    return MembraneOperator(kind, patches.nodes, G, mesh.area, _offset(mesh, patches.nodes, Xp))


def _offset(mesh: TriMesh, nodes: np.ndarray, Xloc: np.ndarray) -> np.ndarray | None:
    """:attr:`MembraneOperator.offset` ``(E, A, 3)`` [m] of a sewn mesh (None for a flat one): the placed reference
    positions of the local ``nodes (E, A)`` less their flat element coordinates ``Xloc (E, A, 2)`` (at z = 0; a
    constant shift drops out of the gradients)."""
    if mesh.element_X is None:
        return None
    flat = np.concatenate([Xloc, np.zeros(Xloc.shape[:2] + (1,))], axis=2)
    return mesh.X3[nodes] - flat
