"""Fused internal force of the RF model for the explicit loop (the hot path of Eq. 20).

The force is the same as :meth:`rftstatic.model.Model.internal_force` (tested against it) but is
laid out for speed. The displacement gradients at all strain points are *linear* in ``U``:

    H[q, J, e, i] = sum_a G[e, q, a, J] U[n(e, a), i]                          (membrane.py)

so one constant sparse scalar operator ``B (2 Q E, N)`` gives them all, ``H = B @ U`` (the three
displacement components are the three right-hand-side columns). The membrane force is the
transpose of the same operator applied to the area-weighted first Piola-Kirchhoff stresses,

    f_m[n, i] = sum_(q, J, e) B[(q, J, e), n] P[q, J, e, i],   P_q = F_q S A / Q,

with ``S = D^m eps`` (Eq. 15) from the strain averaged over the Q strain points and ``F = I + H``.
With the constant bending stiffness (Eq. 13) the whole internal force is three sparse products,
``K_b @ U + B^T @ P``, and a few vectorised operations on ``(Q, 2, E, 3)`` arrays; no element loop.
A penalty contact term of the model (``model.contact``), if any, is added as in the static solver.

Two back ends compute the same sums: ``"numpy"`` (the sparse products above) and ``"numba"`` (one
compiled pass over the CSR rows of K_b and over the elements, imported lazily). The numba pass is
about 3-5x faster on the 41 x 41 and 51 x 51 sheets (``python -m rftstatic.bench_explicit``), because
scipy's CSR-times-dense products cost several ns per stored entry; ``"auto"`` uses numba when it
imports. Both are tested against :meth:`Model.internal_force`. On large meshes the numba pass runs on
all cores: blocks of elements write their nodal forces into a private array, and each node then
gathers its bending row and its element slots (no two threads write one entry; same sums). A
:class:`rftstatic.compiled.ThreadTuner` checks now and then that the threads pay (not on a machine
whose other core is busy) and falls back to one thread where they do not.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from rftstatic.compiled import ThreadTuner, fixed_threads, force_threads, numba_available

BACKENDS = ("auto", "numpy", "numba")



class ForceKernel:
    """Internal force and stored energy of ``model`` for displacements ``U (N, 3)`` [m].

    Parameters
    ----------
    model : :class:`rftstatic.model.Model`
    backend : ``"auto"``, ``"numpy"`` or ``"numba"``
    threads : numba back end: element blocks computed in parallel (``None``:
        :func:`rftstatic.compiled.force_threads`, all cores for large meshes); the result does not
        depend on it

    Attributes
    ----------
    B : (2 Q E, N) CSR, strain-point displacement gradients from nodal displacements [1/m]
    Bt : (N, 2 Q E) CSR, its transpose (the force scatter)
    weight : (E,) element area over the number of strain points, A / Q [m^2]
    """

    def __init__(self, model, *, backend: str = "auto", threads: int | None = None):
        if backend not in BACKENDS:
            raise ValueError(f'force backend must be one of {", ".join(BACKENDS)}, got "{backend}"')
        if backend == "auto":
            backend = "numba" if numba_available() else "numpy"
        self.backend = backend
        self.model = model
        self.Kb = model.Kb.tocsr()
        self.Dm = np.asarray(model.material.Dm, float)
        self.Db = np.asarray(model.material.Db, float)
        self.with_membrane = model.with_membrane
        self.contact = model.contact
        self.X3 = model.X3
        mem = model.membrane
        E, Q, A, _ = mem.G.shape
        self.E, self.Q = E, Q
        N = model.mesh.n_nodes
        row = (np.arange(2 * Q)[:, None] * E + np.arange(E)[None, :]).reshape(Q, 2, E, 1)
        rows = np.broadcast_to(row, (Q, 2, E, A)).ravel()
        cols = np.broadcast_to(mem.nodes[None, None], (Q, 2, E, A)).ravel()
        vals = mem.G.transpose(1, 3, 0, 2).ravel()  # (Q, 2, E, A)
        B = sp.csr_matrix((vals, (rows, cols)), shape=(2 * Q * E, N))  # sums repeated patch nodes
        B.eliminate_zeros()
        self.B = B
        self.Bt = B.T.tocsr()
        self.weight = mem.area / Q
        self.area = mem.area
        self.nodes = np.ascontiguousarray(mem.nodes, dtype=np.int64)
        self.G = np.ascontiguousarray(mem.G)
        self.threads = 1
        if backend == "numba":
            from rftstatic.element._explicit_numba import internal_force, internal_force_parallel

            self._nb = internal_force
            self.threads = force_threads(E) if threads is None else max(1, int(threads))
            if self.threads > 1:
                import numba

                # as many element blocks as threads asked for; numba runs them on what it has, and
                # unless told how many (argument, RFTSTATIC_THREADS) checks that they pay
                self._run_threads = min(self.threads, int(numba.config.NUMBA_NUM_THREADS))
                tune = threads is None and fixed_threads() is None and self._run_threads > 1
                self._tuner = ThreadTuner(self._run_threads) if tune else None
                # node -> element-slot map of the force gather: slots[slot_ptr[n]:slot_ptr[n + 1]] are
                # the flat indices e * A + a with nodes[e, a] == n (a node repeated in a patch: each slot)
                flat = self.nodes.ravel()
                self._slots = np.argsort(flat, kind="stable").astype(np.int64)
                self._slot_ptr = np.concatenate([[0], np.cumsum(np.bincount(flat, minlength=N))]).astype(np.int64)
                self._fe = np.empty((flat.size, 3))
                self._nb_parallel = internal_force_parallel

    def __call__(self, U: np.ndarray, *, energy: bool = False, candidates=None):
        """Internal force ``(N, 3)`` [N]; with ``energy=True`` also the stored energy [J].

        The stored energy is bending + membrane + penalty contact (:meth:`Model.energies`);
        ``candidates`` is the solve's contact candidate list (a cache; None: every node).
        """
        if self.backend == "numba":
            U = np.ascontiguousarray(U, dtype=float)
            f = np.empty_like(U)
            Kb = self.Kb
            if self.threads > 1:
                import numba

                tuner = self._tuner
                run = tuner.before() if tuner is not None else self._run_threads
                numba.set_num_threads(run)
                t0 = time.perf_counter()
                W = self._nb_parallel(Kb.indptr, Kb.indices, Kb.data, self.nodes, self.G, self.area, self.Dm, U,
                                      f, self._fe, self._slot_ptr, self._slots, self.with_membrane, energy,
                                      self.threads)
                if tuner is not None:
                    tuner.after(run, time.perf_counter() - t0)
            else:
                W = self._nb(Kb.indptr, Kb.indices, Kb.data, self.nodes, self.G, self.area, self.Dm, U, f,
                             self.with_membrane, energy)
        else:
            f = self.Kb @ U
            W = 0.5 * float(np.einsum("ni,ni->", U, f)) if energy else 0.0
            if self.with_membrane:
                fm, Wm = self._membrane(U, energy)
                f += fm
                W += Wm
        if self.contact is not None:
            x = self.X3 + U
            f += self.contact.force(x, candidates=candidates)
            if energy:
                W += self.contact.energy(x, candidates=candidates)
        return (f, W) if energy else f

    def _membrane(self, U, energy):
        Q, E = self.Q, self.E
        H = (self.B @ U).reshape(Q, 2, E, 3)
        Hx, Hy = H[:, 0], H[:, 1]  # (Q, E, 3): dU/dX, dU/dY
        # Green strain (membrane.py, _green_voigt) per strain point, then the mean over them
        exx = Hx[..., 0] + 0.5 * np.einsum("qei,qei->qe", Hx, Hx)
        eyy = Hy[..., 1] + 0.5 * np.einsum("qei,qei->qe", Hy, Hy)
        gxy = Hx[..., 1] + Hy[..., 0] + np.einsum("qei,qei->qe", Hx, Hy)
        eps = np.stack([exx.mean(axis=0), eyy.mean(axis=0), gxy.mean(axis=0)])  # (3, E)
        S = self.Dm @ eps  # (3, E) second Piola-Kirchhoff stress resultant [N/m]
        Wm = 0.5 * float(np.einsum("e,ke,ke->", self.area, eps, S)) if energy else 0.0
        s = S * self.weight  # A / Q folded in
        sxx, syy, sxy = s[0][:, None], s[1][:, None], s[2][:, None]
        P = np.empty_like(H)
        # P_q = F_q S with F = I + H, column J of P: sum_K F[:, K] S[K, J]
        np.multiply(Hx, sxx, out=P[:, 0])
        P[:, 0] += Hy * sxy
        np.multiply(Hx, sxy, out=P[:, 1])
        P[:, 1] += Hy * syy
        P[:, 0, :, 0] += s[0]
        P[:, 0, :, 1] += s[2]
        P[:, 1, :, 0] += s[2]
        P[:, 1, :, 1] += s[1]
        return self.Bt @ P.reshape(2 * Q * E, 3), Wm
