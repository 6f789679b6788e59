"""Fused internal force of the RF model for the explicit loop (the hot path of Eq. 20).

The force is the same as :meth:`rftstatic.model.model.Model.internal_force` (tested against it) but laid
out for speed: the constant bending stiffness (Eq. 13) as one scalar CSR product ``K_b @ U`` and the
membrane forces of the kernels of :mod:`rftstatic.element.kernels` (the same code as the static
force and tangent: strain-point gradients, averaged Green strain of Eq. 14, ``S = D^m eps`` of
Eq. 15, ``f_a = A/Q sum_q F_q S g_qa``), summed into the nodes. A penalty contact term of the model
(``model.contact``), if any, is added as in the static solver, and so is its self-contact
(``model.self_contact``: the gradient of the same energy, evaluated on the near pairs of the solve's
pair cache only, :meth:`rftstatic.contact.self_contact.law.SelfContact.near_force`).

Two back ends run that code: ``"numba"`` (compiled, one pass over the elements and the CSR rows of
K_b, :func:`rftstatic.element.kernels.internal_force`; the elements in blocks of
:data:`~rftstatic.element.kernels.LANES`, their arithmetic vectorised across a block with the bits of one element
at a time: cusick-30's 3,840 elements 0.59 -> 0.21 ms a call on one thread, 0.30 -> 0.14 ms on two) and
``"numpy"`` (the same element kernels vectorised over the elements, ``scipy`` for ``K_b @ U``); ``"auto"`` uses
numba when it imports. Both are tested against :meth:`Model.internal_force`. On large meshes the numba pass runs
on all cores:
blocks of elements write their nodal forces into a private array, and each node then gathers its
bending row and its element slots (no two threads write one entry; the serial pass does the same
sums in the same order). A :class:`rftstatic.compiled.ThreadTuner` checks now and then that the
threads pay (not on a machine whose other core is busy) and falls back to one thread where they do
not. ``python -m rftstatic bench explicit`` measures the element-steps per second.
"""

from __future__ import annotations

import time

import numpy as np

from rftstatic.compiled import ThreadTuner, fixed_threads, force_threads, numba_available
from rftstatic.element.axis_terms import axis_terms
from rftstatic.element.kernels import element_slots, lane_blocks
from rftstatic.element.kernels_numpy import element_last, forces_numpy

BACKENDS = ("auto", "numpy", "numba")


class ForceKernel:
    """Internal force and stored energy of ``model`` for displacements ``U (N, 3)`` [m].

    Parameters
    ----------
    model : :class:`rftstatic.model.model.Model`
    backend : ``"auto"``, ``"numpy"`` or ``"numba"``
    threads : numba back end: element blocks computed in parallel (``None``:
        :func:`rftstatic.compiled.force_threads`, all cores for large meshes); the result does not
        depend on it

    Attributes
    ----------
    nodes : (E, A) int64, the membrane's local-to-global node map
    G : (E, Q, A, 2) strain-point shape-function gradients [1/m]
    area : (E,) element areas [m^2]
    """

    def __init__(self, model, *, backend: str = "auto", threads: int | None = None):
        if backend not in BACKENDS:
            raise ValueError(f'force backend must be one of {", ".join(BACKENDS)}, got "{backend}"')
        if backend == "auto":
            backend = "numba" if numba_available() else "numpy"
        self.backend = backend
        self.model = model
        self.Kb = model.Kb.tocsr()
        self.Dm = np.ascontiguousarray(model.material.Dm, dtype=float)
        self.with_membrane = model.with_membrane
        self.contact = model.contact
        self.load_terms = model.load_terms
        self.self_contact = getattr(model, "self_contact", None)
        self.X3 = model.X3
        mem = model.membrane
        E, Q, A, _ = mem.G.shape
        self.E, self.Q = E, Q
        N = model.mesh.n_nodes
        self.area = np.ascontiguousarray(mem.area, dtype=float)
        self.nodes = np.ascontiguousarray(mem.nodes, dtype=np.int64)
        self.G = np.ascontiguousarray(mem.G, dtype=float)
        self._D, self._D_last = mem._compiled_args[3], mem.offset_last  # a sewn mesh's reference offsets
        # a sewn mesh bends from its placed reference: K_b (X3 + U) = K_b U + b (Model.bending_displacement)
        self._bend_offset = None if model.mesh.element_X is None else model.Kb @ self.X3
        self._bend_energy = 0.0 if self._bend_offset is None else 0.5 * float(np.einsum("ni,ni->", self.X3,
                                                                                          self._bend_offset))
        self.threads = 1
        self.hinges = getattr(model, "hinges", None)
        # the patch terms of the material-axes curvature, added in __call__: bending friction
        # (rftstatic.element.hysteresis) and softening (rftstatic.element.nonlinear_bending) on one patch pass,
        # compiled on the numba back end (rftstatic.element.axis_terms)
        self.axis_terms = axis_terms(getattr(model, "bending_friction", None), getattr(model, "bending_softening", None),
                                     backend=backend)
        # the shear friction (rftstatic.element.shear_friction, numpy) on the membrane's elements
        self.shear_friction = getattr(model, "shear_friction", None)
        if backend == "numpy":
            self._G_last = element_last(self.G)
            self._dofs = (3 * self.nodes.T[:, None, :] + np.arange(3)[:, None]).ravel()  # scatter of fe (A, 3, E)
            return
        from rftstatic.element._kernels_numba import explicit_kernel

        self._nb = explicit_kernel(Q, A, False)
        # nodes, G, area and offsets by blocks of elements (the compiled kernel's lanes), and the node ->
        # element-slot map of the force gather (in element order)
        self._blocks = lane_blocks(self.nodes, self.G, self.area, self._D)
        self._slot_ptr, self._slots = element_slots(self.nodes, N)
        self._fe = np.empty((E, A, 3))
        self.threads = force_threads(E) if threads is None else max(1, int(threads))
        if self.threads > 1:
            import numba

            # as many element blocks as threads asked for; numba runs them on what it has, and
            # unless told how many (argument, RFTSTATIC_THREADS) checks that they pay
            self._run_threads = min(self.threads, int(numba.config.NUMBA_NUM_THREADS))
            tune = threads is None and fixed_threads() is None and self._run_threads > 1
            self._tuner = ThreadTuner(self._run_threads) if tune else None
            self._nb_parallel = explicit_kernel(Q, A, True)

    def __call__(self, U: np.ndarray, *, energy: bool = False, candidates=None, pairs=None, slip=None):
        """Internal force ``(N, 3)`` [N]; with ``energy=True`` also the stored energy [J].

        The stored energy is bending + membrane + penalty contact + self-contact (:meth:`Model.energies`), and
        the potential of the model's potential loads (``model.load_terms``) at load factor 1;
        ``candidates`` is the solve's contact candidate list (a cache; None: every node), ``pairs`` its
        self-contact pair cache (``State.self_pairs``; None: a fresh broad phase), ``slip`` the committed
        slips of the frictions (``State.slip``: :mod:`rftstatic.element.hysteresis` and
        :mod:`rftstatic.element.shear_friction`, :meth:`Model.split_slip`).
        """
        U = np.ascontiguousarray(U, dtype=float)
        if self.backend == "numba":
            f = np.empty_like(U)
            Kb = self.Kb
            args = (Kb.indptr, Kb.indices, Kb.data, *self._blocks, self.Dm, U, f, self._fe, self._slot_ptr,
                    self._slots, self.with_membrane)
            if self.threads > 1:
                import numba

                tuner = self._tuner
                run = tuner.before() if tuner is not None else self._run_threads
                numba.set_num_threads(run)
                t0 = time.perf_counter()
                W = self._nb_parallel(*args, self.threads)
                if tuner is not None:
                    tuner.after(run, time.perf_counter() - t0)
            else:
                W = self._nb(*args, 1)
        else:
            f = self.Kb @ U
            W = 0.5 * float(np.einsum("ni,ni->", U, f)) if energy else 0.0
            if self.with_membrane:
                fe, We = forces_numpy(self._G_last, self.nodes, self.area, self.Dm, U, self._D_last)
                f += np.bincount(self._dofs, fe.ravel(), minlength=f.size).reshape(f.shape)
                W += float(We.sum()) if energy else 0.0
        if self._bend_offset is not None:
            f += self._bend_offset
            W += float(np.einsum("ni,ni->", U, self._bend_offset)) + self._bend_energy if energy else 0.0
        if self.axis_terms is not None or self.shear_friction is not None:
            bend, shear = self.model.split_slip(slip)
        if self.axis_terms is not None:
            Wt = self.axis_terms.add_forces(U if self._bend_offset is None else self.X3 + U, self.X3 + U, f, bend)
            W += Wt if energy else 0.0
        if self.shear_friction is not None:
            Ws, fs = self.shear_friction.nodal_force(U, shear)
            f += fs
            W += Ws if energy else 0.0
        if self.hinges is not None:
            Wh, fh = self.hinges.energy_force(self.X3 + U)
            f += fh
            W += Wh if energy else 0.0
        for term in self.load_terms:  # potential loads at load factor 1 (the explicit loads act in full)
            x = self.X3 + U
            f += term.force(x)
            W += term.potential(x) if energy else 0.0
        if self.contact is not None:
            x = self.X3 + U
            if energy:  # one distance query for both (a surface obstacle's query is most of a contact step)
                state = self.contact.evaluate(x, tangent=False, candidates=candidates)
                f += state.force
                W += state.energy
            else:
                f += self.contact.force(x, candidates=candidates)
        if self.self_contact is not None:
            fs = self.self_contact.near_force(self.X3 + U, pairs, energy=energy)
            if energy:
                f += fs[0]
                W += fs[1]
            else:
                f += fs
        return (f, W) if energy else f
