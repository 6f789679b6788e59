"""What the Newton iterations at one load factor share (:mod:`rftstatic.solvers.newton`,
:mod:`rftstatic.solvers.mixed`): their outcome, the safeguarded Newton direction, the step cap and the
convergence test.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rftstatic.solvers.linear import LinearSolveError, NotPositiveDefinite


@dataclass
class Iteration:
    """Outcome of the Newton iterations at one load factor (``history``: one record per iteration)."""

    converged: bool
    U: np.ndarray
    iterations: int
    residual: float
    reason: str = ""
    stable: bool | None = None
    progress: float = 0.0  # energy drop over the last third of the iterations / the work scale [-]
    history: list = field(default_factory=list)  # per iteration: |r| before the step, step length, tangent
    stress: np.ndarray | None = None  # the mixed scheme's membrane stress at U (E, 3) [N/m]
    scheme: str = "displacement"

    @property
    def descending(self) -> bool:
        """The energy still fell markedly over the last iterations (``progress`` > :data:`DESCENDING`)."""
        return self.progress > DESCENDING


DESCENDING = 1e-6
"""Least energy drop over the last third of an unconverged Newton call, relative to the work of the load, at
which the iterate still counts as sliding downhill (snapping through) rather than stalled."""


def unloaded_scales(model) -> tuple[float, float]:
    """Force [N] and work [J] scales of the convergence test of an unloaded model: the norm of the
    nodal weights ``|w A_n|`` that gravity would apply and their work over the mean element size
    (1e-300 each for a weightless sheet, which leaves the round-off floor of the internal force)."""
    weight = float(getattr(model.material, "weight", 0.0) or 0.0)
    force = abs(weight) * float(np.linalg.norm(model.mesh.node_area))
    if not force > 0 or not np.isfinite(force):
        return 1e-300, 1e-300
    return force, force * float(model.mesh.element_size.mean())


class Criteria:
    """The convergence test of one Newton iteration at load factor ``lam`` (module docstring, 4).

    Force: ``|r| <= rtol |lam P| + floor``, the floor being the round-off of the internal force
    (:func:`roundoff_floor`, evaluated only near convergence). Energy: the work of the residual on
    the last step ``|d . r_new| <= etol W`` with ``W = |lam| max(|P . U|, |P . dU_1|)``, the work of the
    applied load; both scales come from the loads alone, so the test does not tighten or loosen with
    the membrane stiffness. With no load at all (an unloaded sheet, e.g. ``loads.gravity = false``)
    the scales are those of the sheet's weight (:func:`unloaded_scales`), or the round-off floor of a
    weightless one.
    """

    def __init__(self, model, lam, opts, U):
        self.model, self.lam = model, lam
        self.rtol = opts.rtol if lam >= 1.0 else max(opts.rtol, opts.intermediate_rtol)
        self.etol = opts.etol if lam >= 1.0 else max(opts.etol, opts.intermediate_rtol**2)
        P = model.load
        if model.load_terms:  # potential loads (end moments) count as applied forces
            P = P - sum(t.force(model.positions(U)) for t in model.load_terms)
        self.P = P
        # a floor keeps the tolerance above round-off for vanishing loads
        self.ref = max(np.linalg.norm(lam * P), 1e-6 * np.linalg.norm(P), 1e-300)
        self.atol = 0.0
        self.work_ref = 1e-300
        self.unloaded = not np.any(P)
        if self.unloaded:  # no load to scale by: the sheet's own weight, as if gravity acted (module docstring)
            self.ref, self.work_ref = unloaded_scales(model)

    def load_work(self, U, step) -> None:
        """Raise the energy scale to the work of the load on ``U`` and on the first ``step`` [J]."""
        P = self.P
        self.work_ref = max(self.work_ref, abs(self.lam) * abs(float(np.einsum("ni,ni->", P, U))),
                            abs(self.lam) * abs(float(np.einsum("ni,ni->", P, step))))

    def met(self, U, r, work, solver=None) -> bool:
        """Whether the residual ``r`` (free dofs) [N] and the last step's residual work ``work`` [J] pass.

        The energy test passes on ``work`` or, when ``solver`` can re-solve with its last factorisation
        (a back-substitution), on the energy of the correction still to come, ``|r . K^-1 r|``: after an
        exact step (a linear problem) the residual is round-off, and its work over that full step,
        ``|d| |r|``, says nothing about the energy left, which is quadratic in r."""
        rnorm = float(np.linalg.norm(r))
        tol = self.rtol * self.ref
        # close (or nothing to scale by: no load): is the rest round-off? (once an increment)
        if (tol < rnorm < 1e4 * tol or (self.unloaded and rnorm > tol)) and self.atol == 0.0:
            self.atol = roundoff_floor(self.model, U)
        if rnorm > tol + self.atol:
            return False
        limit = self.etol * self.work_ref
        if work <= limit:
            return True
        if solver is None or not getattr(solver, "cheap_resolve", False):
            return False
        try:
            left = abs(float(r @ solver.resolve(r)))
        except LinearSolveError:
            return False
        return left <= limit


MODIFIED_SHIFTS = (1e-7, 1e-1)
"""Smallest and largest diagonal shift tau of the modified exact tangent ``K + tau I``, relative to the mean
diagonal of the tangent (Nocedal & Wright, Numerical Optimization, 2nd ed., Algorithm 3.3: Cholesky with
added multiple of the identity)."""

MODIFIED_GROWTH = 8.0
"""Factor between two shifts tried."""

MODIFIED_DECREASE = 2.0
"""The first shift tried is the last one that worked divided by this factor (Nocedal & Wright's Algorithm 3.3 halves
it). Measured with the rotation-lifted walk (validation/bench_profile.md, 2026-12-05; 4 modified tries) against 8
(the growth): the factorisations of pedestal-round-50 152 -> 122, pedestal-square-80 188 -> 186, cusick-24 107 -> 97, cusick-30
48 -> 47, sphere-30 and pedestal-square-40 unchanged; the same equilibria."""

MODIFIED_TRIES = 7
"""Most factorisations of the modified exact tangent per iteration before the projected one is used: from the
smallest shift (1e-7 of the mean diagonal) seven reach 2.6e-2 of it. The projected tangent, which drops the whole
compressive geometric stiffness, is far stiffer along the fold modes than a shifted exact one: on the valley walks
of issue 34 its steps were about 10 times shorter. Measured over the seeds 1-5 of pedestal-round-50 and sphere-30
(validation/bench_profile.md, 2026-12-05): 694 and 214 factorisations in all against 805 and 249 with 4 tries;
the same equilibria."""


def direction(model, U, lam, r, opts, state, damping=0.0, stress=None):
    """Newton direction on the free dofs, with the indefinite-tangent safeguard: ``(d, mode, shift)``.

    ``damping`` adds ``damping * mean(diag K)`` to the diagonal (Levenberg-Marquardt); ``shift`` [N/m]
    is the diagonal shift of the tangent that gave ``d``; ``stress``: the mixed membrane stress of the
    geometric stiffness (:func:`rftstatic.solvers.mixed.mixed_iterations`; None: the exact Hessian).

    ``tangent = "auto"`` tries, in turn, the exact tangent; the modified exact tangent ``K + tau I``
    (:data:`MODIFIED_SHIFTS`, from the last shift that worked over :data:`MODIFIED_DECREASE`; while the
    last iteration needed one, the exact tangent is not tried first: its factorisation would fail
    again); the projected tangent (compressive membrane stress dropped); and that one shifted
    (:data:`SHIFT_LADDER`). Each tangent is assembled once per call, its shifts added to the diagonal.

    The ladder remembers (``state.fallback``): after a direction from the projected or the shifted tangent,
    the next starts where that one succeeded (the shifted tangent one rung below its shift), for at most
    :data:`FALLBACK_RUN` directions in a row; then the whole ladder is tried again from the exact tangent.
    On an indefinite stretch the failed factorisations of the rungs below are not repeated at every iteration.
    """
    solver, modes = state.solver, state.modes
    sequence = {"auto": ["exact", "modified", "psd", "shift"], "exact": ["exact", "shift"],
                "psd": ["psd", "shift"]}[opts.tangent]
    matrices = {}

    def tangent(psd, shift):
        if psd not in matrices:
            matrices[psd] = model.tangent(U, psd=psd, lam=lam, candidates=state.candidates, stress=stress,
                                          pairs=state.self_pairs, slip=state.slip)[1]
        K = matrices[psd]
        if shift:
            K = K.copy()
            K.setdiag(K.diagonal() + shift)
        return K

    base = damping * diagonal_scale(model, U, state) if damping else 0.0
    memo = state.fallback
    start_rung = 0
    if memo is not None and memo["mode"] in sequence and memo["run"] < FALLBACK_RUN:
        sequence = sequence[sequence.index(memo["mode"]):]  # the rungs below failed at the last iterate
        start_rung = max(memo.get("rung", 0) - 1, 0)
    elif "modified" in sequence:
        least = MODIFIED_SHIFTS[0] * diagonal_scale(model, U, state)
        if state.modified_shift / MODIFIED_DECREASE < least:
            state.modified_shift = 0.0
        elif base == 0.0:
            sequence = sequence[1:]  # the exact tangent was indefinite at the last iterate
    last_error = "no tangent tried"  # a message, not the exception: its traceback holds this frame, and
    for mode in sequence:              # the cycle would keep the tangents until the cyclic collector ran
        shifts = [base]
        if mode == "modified":
            scale = diagonal_scale(model, U, state)
            first = max(state.modified_shift / MODIFIED_DECREASE, MODIFIED_SHIFTS[0] * scale, base)
            shifts = [t for t in (first * MODIFIED_GROWTH ** k for k in range(MODIFIED_TRIES))
                      if t <= MODIFIED_SHIFTS[1] * scale]
        rungs = range(len(shifts))
        if mode == "shift":
            scale = float(np.abs(tangent(True, 0.0).diagonal()).mean())
            rungs = range(start_rung if sequence[0] == "shift" else 0, len(SHIFT_LADDER))
            shifts = [scale * SHIFT_LADDER[k] for k in rungs]
        for rung, shift in zip(rungs, shifts):
            K = tangent(mode not in ("exact", "modified"), shift)
            state.factorisations += 1
            try:
                d = solver.solve(K, -r)
            except NotPositiveDefinite as exc:
                last_error = str(exc)
                continue
            if not np.all(np.isfinite(d)):
                last_error = "non-finite step"
                continue
            if float(r @ d) < 0.0 or not np.any(r):
                modes[mode] = modes.get(mode, 0) + 1
                state.modified_shift = shift if mode == "modified" else 0.0
                _remember(state, mode, rung)
                return d, mode, shift
            last_error = "the step is not a descent direction of the energy"
    raise LinearSolveError(last_error)

SHIFT_LADDER = (1e-8, 1e-6, 1e-4, 1e-2, 1.0, 1e2)
"""Diagonal shifts of the projected tangent, relative to its mean diagonal, tried in turn (mode ``"shift"``)."""

FALLBACK_RUN = 4
"""Most Newton directions in a row that start from the remembered fallback tangent (``State.fallback``)
before the exact tangent is tried again. On sphere-30 (61 x 61) the mixed iteration from the relaxed state
took 3.7 factorisations per iteration without the memory, 208 of 308 on indefinite tangents."""


def _remember(state, mode, rung) -> None:
    """Keep in ``state.fallback`` where the ladder of :func:`direction` succeeded (None for the exact or the
    modified tangent: the next direction tries the whole ladder)."""
    if mode not in ("psd", "shift"):
        state.fallback = None
        return
    memo = state.fallback
    run = memo["run"] + 1 if memo is not None and memo["run"] < FALLBACK_RUN else 1
    state.fallback = {"mode": mode, "rung": int(rung), "run": run}


def roundoff_floor(model, U) -> float:
    """Residual [N] below which round-off rules: the larger of 100 eps times the summed magnitudes of
    the element forces (forces that cancel at the nodes) and eps times the round-off size of the
    membrane forces (:meth:`~rftstatic.element.membrane.MembraneOperator.force_roundoff`: the strain of
    a rotated element is a small difference of order-one terms). A membrane 10^8 times stiffer than
    the bending (per unit area) leaves a residual that no tolerance relative to the load can meet."""
    if not model.with_membrane:
        return 0.0
    from rftstatic.model.assembly import scatter_forces

    mem, Dm, n, free = model.membrane, model.material.Dm, model.mesh.n_nodes, model.free.ravel()
    eps = np.finfo(float).eps
    cancelling = scatter_forces(mem.nodes, np.abs(mem.element_forces(U, Dm)), n).ravel()[free]
    size = mem.force_roundoff(U, Dm)
    strain = scatter_forces(mem.nodes, np.repeat(size[:, :, None], 3, axis=2), n).ravel()[free]
    return eps * max(100.0 * float(np.linalg.norm(cancelling)), float(np.linalg.norm(strain)))

def diagonal_scale(model, U, state) -> float:
    """Mean diagonal of the tangent [N/m], computed once per solve (the scale of the LM damping)."""
    if state.lm_scale is None:
        _, K0 = model.tangent(U, psd=True, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)
        state.lm_scale = float(np.abs(K0.diagonal()).mean())
    return state.lm_scale

def self_contact_limited(model, U, step, state):
    """``step (N, 3)`` [m] scaled by the self-contact step bound (no pair of the sheet comes closer than
    a fraction of its distance on the way, so none passes through another,
    :meth:`~rftstatic.contact.self_contact.law.SelfContact.max_step_fraction`), and that factor (1
    without self-contact)."""
    sc = getattr(model, "self_contact", None)
    if sc is None:
        return step, 1.0
    alpha = sc.max_step_fraction(model.positions(U), step, cache=state.self_pairs)
    if alpha < 1.0:
        state.modes["self-contact limited"] = state.modes.get("self-contact limited", 0) + 1
        step = alpha * step
    return step, alpha


def capped_step(model, d, max_step):
    """The free-dof step ``d`` as ``(N, 3)`` displacements [m], scaled so that no node moves more than
    ``max_step`` [m]; and the scale factor (1 when uncapped)."""
    dfull = np.zeros(3 * model.mesh.n_nodes)
    dfull[model.free.ravel()] = d
    step = dfull.reshape(-1, 3)
    biggest = float(np.linalg.norm(step, axis=1).max())
    cap = 1.0
    if biggest > max_step:
        cap = max_step / biggest
        step *= cap
    return step, cap
