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
        likewise a cache; None without self-contact. It also carries :attr:`self_contact_scale`, which is
        not a cache: it travels with the pairs to every self-contact evaluation (``pairs=``)
    load_branches : the committed branch of each of the model's potential loads (one entry per
        ``model.load_terms``, e.g. a :class:`~rftstatic.model.loads.LeverMoment`'s angles (K,) [rad]), set
        after every converged increment (:meth:`~rftstatic.model.model.Model.load_branches`); None before
        the first (the principal branches)
    contact_history : per-contact history carried from step to step (e.g. friction anchors), keyed
        by the contact law's name; empty for frictionless contact
    solver : the solve's one linear solver (:func:`~rftstatic.solvers.linear.make_solver`), a cache: its
        symbolic analysis serves every Newton phase of the solve while the tangent's pattern holds; None
        outside a Newton solve (:func:`~rftstatic.solvers.newton.start_state` makes it)
    modes : counts of the Newton tangents used in the solve: exact, psd, shift, modified, reused, krylov
        (steps by preconditioned CG, and their "CG iterations"), "self-contact limited", "mixed failed"
    factorisations : numeric factorisations of a tangent in the solve (failed Cholesky attempts included;
        the stability check not)
    lm_scale : mean tangent diagonal [N/m], the scale of the Levenberg-Marquardt damping, computed once per
        solve at the state where damping is first needed (None before)
    modified_shift : the last diagonal shift [N/m] that made an indefinite exact tangent positive definite
        (:func:`~rftstatic.solvers.iteration.direction`, mode ``"modified"``): the next try starts below it
    fallback : the last tangent beyond the exact and modified ones that gave a Newton direction, and how many
        directions in a row it has given: ``{"mode": "psd" | "shift", "rung": index into SHIFT_LADDER, "run": int}``; the next
        direction starts from it (:func:`~rftstatic.solvers.iteration.direction`); None after an exact or
        modified step
    slip : the committed slips of the model's friction terms (E, k) (:meth:`rftstatic.model.model.Model.
        initial_slip`): the bending friction's slip curvature
        (E, 2) [1/m], warp and weft in material axes (:mod:`rftstatic.element.hysteresis`, internal variable of
        the return mapping (H4)), then the shear friction's slip angle (E, 1) [-]
        (:mod:`rftstatic.element.shear_friction`, S6), each present when the material has that hysteresis; set at
        every converged step (:meth:`commit_slip`); None for a model without hysteresis
    dissipated : energy dissipated by the frictions since the flat start [J] (sum of (H4) and (S6) over the
        committed steps)
    route : the position of every route under way, keyed by route (:mod:`rftstatic.solvers.drive`): what a
        checkpoint of this State lets the route go on from (e.g. the load steps' next increment, the
        relaxation route's phase, an explicit run's records)
    """

    U: np.ndarray
    V: np.ndarray
    t: float = 0.0
    step: int = 0
    lam: float = 1.0
    candidates: object | None = None
    self_pairs: object | None = None
    contact_history: dict = field(default_factory=dict)
    load_branches: tuple | None = None
    solver: object | None = None
    modes: dict = field(default_factory=lambda: {"exact": 0, "psd": 0, "shift": 0})
    factorisations: int = 0
    lm_scale: float | None = None
    modified_shift: float = 0.0
    fallback: dict | None = None
    route: dict = field(default_factory=dict)
    slip: np.ndarray | None = None
    dissipated: float = 0.0

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
        initial_slip = getattr(model, "initial_slip", None)
        slip = initial_slip() if initial_slip is not None else None
        return cls(U=U, V=V, t=float(t), step=int(step), lam=float(lam), candidates=candidates, self_pairs=pairs,
                   slip=slip)

    def commit_slip(self, model, U=None) -> float:
        """Return mapping of the frictions at a converged ``U (N, 3)`` [m] (default ``self.U``): the new
        :attr:`slip` and :attr:`dissipated` (:meth:`rftstatic.model.model.Model.commit_slip`); returns the
        energy dissipated in the step [J] (0 without hysteresis)."""
        if self.slip is None:
            return 0.0
        self.slip, d = model.commit_slip(self.U if U is None else U, self.slip)
        self.dissipated += d
        return d

    @property
    def self_contact_scale(self) -> float:
        """Factor on the self-contact law's stiffness in this solve [-] (1 without self-contact): raised by the
        static route's continuation (:func:`rftstatic.solvers.static.solve_static`), never the law itself.
        Kept on the pair cache :attr:`self_pairs`, which every self-contact evaluation receives."""
        return 1.0 if self.self_pairs is None else self.self_pairs.stiffness_scale

    @self_contact_scale.setter
    def self_contact_scale(self, value: float) -> None:
        if self.self_pairs is None:
            raise ValueError("this state has no self-contact: its stiffness scale stays 1")
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"self-contact stiffness scale must be a finite number > 0, got {value!r}")
        self.self_pairs.stiffness_scale = float(value)

    @property
    def obstacle_offsets(self) -> np.ndarray | None:
        """``(M, 3)`` translation [m] of each obstacle of the model's contact law from its built pose in this solve
        (a support lowered by a route, :mod:`rftstatic.solvers.release`); None: all where they were built. Not a
        cache: it travels on the candidate list :attr:`candidates` to every contact evaluation
        (:attr:`rftstatic.contact.candidates.CandidateList.offsets`)."""
        return None if self.candidates is None else self.candidates.offsets

    @obstacle_offsets.setter
    def obstacle_offsets(self, value) -> None:
        if self.candidates is None:
            if value is None:
                return
            raise ValueError("this state has no penalty contact: it has no obstacles to move")
        self.candidates.offsets = value

    @property
    def obstacle_poses(self):
        """The rigid pose of each obstacle of the model's contact law in this solve
        (:class:`rftstatic.contact.motion.Poses`: rotation, translation and the surfaces' velocity, e.g. a body
        turned by its keyframes); None: all where they were built. Not a cache: it travels on the candidate list
        :attr:`candidates` to every contact evaluation (:attr:`rftstatic.contact.candidates.CandidateList.poses`);
        :attr:`obstacle_offsets` is its translation part."""
        return None if self.candidates is None else self.candidates.poses

    @obstacle_poses.setter
    def obstacle_poses(self, value) -> None:
        if self.candidates is None:
            if value is None:
                return
            raise ValueError("this state has no penalty contact: it has no obstacles to move")
        self.candidates.poses = value

    @property
    def V_half(self) -> np.ndarray:
        """The half-step velocity v_(n-1/2) of the central-difference scheme [m/s] (= ``V``)."""
        return self.V
