"""Sparse assembly through a plan computed once per mesh.

The tangent of an RF model couples every pair of nodes of a patch, in 3 x 3 blocks (degree of
freedom ``3 n + i``). :class:`AssemblyPlan` builds that CSR structure once, the position in the CSR
``data`` array of every entry of every element matrix, and the permutation that extracts the
matrix of the free degrees of freedom. A Newton iteration then only refills ``data`` with
``np.bincount`` (no COO conversion, no sorting).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp


class AssemblyPlan:
    """CSR structure of the 3N x 3N tangent, and scatter maps into it.

    Parameters
    ----------
    patch_nodes : (E, 6) node of each patch slot; the structure couples every pair of them
    n_nodes : N
    free : (N, 3) bool, degrees of freedom that are unknowns (True) or prescribed (False)
    couplings : (P, 2) further node pairs the structure couples (both ways), e.g. a garment's seam springs
        (:class:`rftstatic.model.loads.SeamSprings`); None: the patches' pairs only
    """

    def __init__(self, patch_nodes: np.ndarray, n_nodes: int, free: np.ndarray, couplings=None):
        self.n_nodes = n = int(n_nodes)
        self.patch_nodes = patch_nodes
        rows = np.repeat(patch_nodes, patch_nodes.shape[1], axis=1).ravel()
        cols = np.tile(patch_nodes, (1, patch_nodes.shape[1])).ravel()
        if couplings is not None and len(couplings):
            pairs = np.asarray(couplings, dtype=np.int64).reshape(-1, 2)
            rows = np.concatenate([rows, pairs[:, 0], pairs[:, 1]])
            cols = np.concatenate([cols, pairs[:, 1], pairs[:, 0]])
        keys = np.unique(rows.astype(np.int64) * n + cols)
        self._pair_keys = keys  # sorted node-pair keys = CSR order of the node graph
        r, c = keys // n, keys % n
        self._pair_row = r
        self.node_indptr = np.r_[0, np.cumsum(np.bincount(r, minlength=n))]
        self._deg = np.diff(self.node_indptr)
        # CSR of the 3N x 3N matrix: row 3n+i holds columns 3m+j for m in row n of the graph
        self.indptr = np.r_[0, np.cumsum(np.repeat(3 * self._deg, 3))]
        self.indices = self._dof_indices(r, c)
        self.nnz = len(self.indices)
        self.free = np.asarray(free, dtype=bool).reshape(n, 3)
        self.free_dofs = np.flatnonzero(self.free.ravel())
        self.diag_positions = self.positions(np.arange(n), np.arange(n))  # (N, 3, 3)

    def _dof_indices(self, r, c):
        deg3 = 3 * self._deg
        out = np.empty(9 * len(r), dtype=np.int64)
        k = np.arange(len(r))
        local = k - self.node_indptr[r]
        for i in range(3):
            for j in range(3):
                pos = 9 * self.node_indptr[r] + i * deg3[r] + 3 * local + j
                out[pos] = 3 * c + j
        return out

    def positions(self, row_nodes, col_nodes) -> np.ndarray:
        """CSR positions of the 3 x 3 blocks of node pairs -> ``(..., 3, 3)`` int."""
        row_nodes, col_nodes = np.broadcast_arrays(row_nodes, col_nodes)
        key = row_nodes.astype(np.int64) * self.n_nodes + col_nodes
        k = np.searchsorted(self._pair_keys, key)
        if np.any(k >= len(self._pair_keys)) or np.any(self._pair_keys[np.minimum(k, len(self._pair_keys) - 1)] != key):
            raise ValueError("node pair outside the patch sparsity pattern")
        r = row_nodes
        base = 9 * self.node_indptr[r] + 3 * (k - self.node_indptr[r])
        i = np.arange(3)[:, None]
        j = np.arange(3)[None, :]
        return base[..., None, None] + i * (3 * self._deg[r])[..., None, None] + j

    def element_map(self, nodes: np.ndarray) -> np.ndarray:
        """Positions of element matrices ``(E, A, 3, A, 3)`` over local nodes ``nodes (E, A)``."""
        P = self.positions(nodes[:, :, None], nodes[:, None, :])  # (E, A, A, 3, 3)
        return P.transpose(0, 1, 3, 2, 4)

    def scalar_kron_data(self, K: sp.csr_matrix) -> np.ndarray:
        """``data`` of ``K (x) I_3`` for a scalar N x N matrix within the pattern (the bending stiffness)."""
        Kc = K.tocoo()
        pos = self.positions(Kc.row, Kc.col)  # (nnz, 3, 3)
        data = np.zeros(self.nnz)
        for i in range(3):
            np.add.at(data, pos[:, i, i], Kc.data)
        return data

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The full 3N x 3N matrix with the given ``data``."""
        N3 = 3 * self.n_nodes
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(N3, N3))

    @cached_property
    def _free_structure(self):
        probe = self.matrix(np.arange(1, self.nnz + 1, dtype=float))
        sub = probe[self.free_dofs][:, self.free_dofs].tocsr()
        sub.sort_indices()
        perm = sub.data.astype(np.int64) - 1
        return sub.indices.copy(), sub.indptr.copy(), perm

    def free_matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The matrix of the free degrees of freedom, built from ``data`` by a fixed permutation.

        The structure is checked once (``_free_structure``: sorted, canonical); each new matrix takes it
        as it is, without scipy's format checks (a third of the time of this call on the 51 x 11 strip)."""
        indices, indptr, perm = self._free_structure
        n = len(self.free_dofs)
        K = sp.csr_matrix((n, n))
        K.data, K.indices, K.indptr = data[perm], indices, indptr
        K.has_sorted_indices = True
        return K


def scatter_forces(nodes: np.ndarray, fe: np.ndarray, n_nodes: int) -> np.ndarray:
    """Sum element forces ``fe (E, A, 3)`` into nodal forces ``(N, 3)``."""
    idx = (3 * nodes[..., None] + np.arange(3)).ravel()
    return np.bincount(idx, fe.ravel(), minlength=3 * n_nodes).reshape(n_nodes, 3)


def scatter_matrices(emap: np.ndarray, ke: np.ndarray, nnz: int) -> np.ndarray:
    """Sum element matrices ``ke`` into CSR ``data`` through the positions ``emap`` (same shape)."""
    return np.bincount(emap.ravel(), ke.ravel(), minlength=nnz)
