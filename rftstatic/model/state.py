"""The state of a solve: what changes while the :class:`~rftstatic.model.model.Model` stays fixed.

A Model is built once per mesh and is read-only during a solve; everything a solver advances or caches
lives in a :class:`State`. Solvers take and return States; checkpoints save them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class State:
    """Displacements, velocities, time, load factor and the contact caches of one solve.

    Attributes
    ----------
    U : (N, 3) nodal displacements from the flat reference [m]
    V : (N, 3) nodal velocities [m/s]; for the central-difference scheme the half-step velocity
        v_(n-1/2) (Eq. 21); zero for a static solve
    t : time of ``U`` [s] (0 for a static solve)
    step : explicit step number n (0 for a static solve)
    lam : load factor [-] (1 for dynamics: the full load acts from t = 0)
    candidates : contact candidate list (:class:`~rftstatic.contact.candidates.CandidateList`), a
        cache of the contact law (results never depend on it); None without penalty contact
    self_pairs : self-contact pair cache (:class:`~rftstatic.contact.self_contact.broad_phase.PairCache`),
        likewise a cache; None without self-contact
    contact_history : per-contact history carried from step to step (e.g. friction anchors), keyed
        by the contact law's name; empty for frictionless contact
    """

    U: np.ndarray
    V: np.ndarray
    t: float = 0.0
    step: int = 0
    lam: float = 1.0
    candidates: object | None = None
    self_pairs: object | None = None
    contact_history: dict = field(default_factory=dict)

    @classmethod
    def initial(cls, model, U=None, V=None, *, t: float = 0.0, step: int = 0, lam: float = 1.0) -> State:
        """A state of ``model`` (default: at rest in the flat reference), with fresh contact caches."""
        n = model.mesh.n_nodes
        U = np.zeros((n, 3)) if U is None else np.array(U, dtype=float)
        V = np.zeros((n, 3)) if V is None else np.array(V, dtype=float)
        for name, arr in (("U", U), ("V", V)):
            if arr.shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3) (nodes x xyz), got {arr.shape}")
        candidates = model.contact.new_candidates() if model.contact is not None else None
        sc = getattr(model, "self_contact", None)
        pairs = sc.new_pairs() if sc is not None else None
        return cls(U=U, V=V, t=float(t), step=int(step), lam=float(lam), candidates=candidates, self_pairs=pairs)

    @property
    def V_half(self) -> np.ndarray:
        """The half-step velocity v_(n-1/2) of the central-difference scheme [m/s] (= ``V``)."""
        return self.V
