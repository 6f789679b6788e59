"""Newton on the displacements alone: the parts it plugs into the Newton loop (:mod:`rftstatic.solvers.loop`).

- direction (:class:`DisplacementDirection`): the safeguarded direct step
  (:func:`~rftstatic.solvers.iteration.direction`: exact tangent, modified, projected, shifted), a reused
  factorisation while the residual falls fast (modified Newton), or on large meshes the step by CG on the
  exact tangent preconditioned with the last factorisation (:mod:`~rftstatic.solvers.krylov`);
- globalisation (:class:`LineSearch`): the step cap ``max_step`` and the self-contact bound, an Armijo
  backtracking line search on the total potential energy Pi (from a given state, along the step's rotation-lifted
  curve, :mod:`~rftstatic.solvers.rotation_lift`, and a shortened step refined to the lowest energy near it,
  :func:`lowest_near`), and Levenberg-Marquardt damping of the next direction as a trust region (More's update of
  the ratio of actual to predicted decrease);
- the convergence test :class:`~rftstatic.solvers.iteration.Criteria`.
"""

from __future__ import annotations

import numpy as np

from rftstatic.solvers.iteration import Criteria, Iteration, capped_step, direction, self_contact_limited
from rftstatic.solvers.krylov import forcing, krylov_direction, uses_krylov
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.loop import Direction, Iterate, StepFailure, newton_loop
from rftstatic.solvers.rotation_lift import RotationLift


class Damping:
    """The Levenberg-Marquardt damping ``mu`` [-] (relative to the mean tangent diagonal) that the trust region
    sets and the next direction uses."""

    def __init__(self):
        self.mu = 0.0


class DisplacementDirection:
    """The displacement iteration's direction at an iterate (module docstring); ``stable`` tells whether
    the last fresh direct step's exact tangent was positive definite (None when the solver cannot tell)."""

    def __init__(self, model, opts, state, damping: Damping, first: Iterate):
        self.model, self.opts, self.state, self.damping = model, opts, state, damping
        self.krylov = uses_krylov(opts, len(first.r), state.solver)
        self.refresh = True  # krylov steps: the next step factorises the tangent anew
        self.first_rnorm = first.rnorm
        self.age = 0  # steps that reused the last factorisation
        self.stable = None
        self.curvature = 0.0  # d.K.d of the last fresh step [J]

    def __call__(self, x: Iterate) -> Direction:
        model, state, solver, mu = self.model, self.state, self.state.solver, self.damping.mu
        r = x.r
        if self.krylov and not self.refresh:
            d, dKd, self.refresh = krylov_direction(model, x.U, x.lam, r, state, mu, forcing(x.rnorm, self.first_rnorm))
            if d is not None:
                self.curvature = dKd
                return Direction(d, "krylov", fresh=True, curvature=dKd)
        elif x.reusable and self.age < self.opts.reuse_factorisation and not self.krylov:
            d = self._reused(r)
            if d is not None:
                state.modes["reused"] = state.modes.get("reused", 0) + 1
                self.age += 1
                return Direction(d, "reused", fresh=False, curvature=self.curvature)
        try:
            d, mode, shift = direction(model, x.U, x.lam, r, self.opts, state, damping=mu)
        except LinearSolveError as exc:
            raise StepFailure(f"linear solve failed ({exc})") from None
        self.stable = (mode == "exact" and mu == 0.0) if solver.detects_indefinite else None
        self.age = 0
        self.refresh = False
        # curvature of the quadratic model along d: (K + s I) d = -r  =>  d.K.d = -d.r - s d.d
        self.curvature = -float(r @ d) - shift * float(d @ d)
        return Direction(d, mode, fresh=True, curvature=self.curvature)

    def _reused(self, r):
        """The step with the last factorisation, if it is a finite descent direction (else None)."""
        try:
            d = self.state.solver.resolve(-r)
        except LinearSolveError:
            return None
        return d if (np.all(np.isfinite(d)) and float(r @ d) < 0.0) else None


class LineSearch:
    """The displacement iteration's globalisation (module docstring): capped, self-contact-bounded step,
    Armijo backtracking on Pi, trust-region update of the damping. ``energies`` holds Pi after every step
    (:meth:`progress`); the first step sets the energy scale of the convergence test. ``refine``: the walk along
    a flat valley from a given state (:func:`displacement_iterations`)."""

    def __init__(self, model, opts, state, damping: Damping, test: Criteria, max_step: float, start: Iterate,
                 refine: bool = False):
        self.model, self.opts, self.state, self.damping, self.test = model, opts, state, damping, test
        self.max_step, self.refine = max_step, refine
        self.free = model.free.ravel()
        self.energies = [start.energy]
        self.work0 = None
        self.lift = RotationLift.of_model(model) if refine and opts.line_search else None

    def _lifted(self, x: Iterate, step, slope):
        """The line search along the rotation-lifted curve of ``step`` (:mod:`~rftstatic.solvers.rotation_lift`):
        ``(alpha, parts, displacement (N, 3))``, or None when the curve's chord would bring two layers of the sheet
        closer than the self-contact step bound allows (the straight step, bounded, is taken then)."""
        model, state = self.model, self.state
        X = model.positions(x.U)
        path, trials = self.lift.path(X, step), {}

        def curve(a):  # each trial's motion once: the chosen one is taken, not lifted again
            if a not in trials:
                trials[a] = path(a)
            return trials[a]

        alpha, parts = line_search(model, x.U, step, x.lam, x.energy, slope, self.opts, state, x.energy_scale,
                                   refine=True, path=curve)
        if alpha is None:
            return None
        dU = curve(alpha)
        sc = getattr(model, "self_contact", None)
        if sc is not None and sc.max_step_fraction(X, dU, cache=state.self_pairs) < 1.0:
            return None
        return alpha, parts, dU

    def __call__(self, x: Iterate, dn: Direction):
        model, state, free, mu = self.model, self.state, self.free, self.damping.mu
        step, cap = capped_step(model, dn.d, self.max_step)
        step, frac = self_contact_limited(model, x.U, step, state)
        cap *= frac
        slope = float(x.r @ step.ravel()[free])
        lifted = self._lifted(x, step, slope) if self.lift is not None else None
        if lifted is not None:
            alpha, parts, dU = lifted
            state.modes["lifted"] = state.modes.get("lifted", 0) + 1
        else:
            alpha, parts = line_search(model, x.U, step, x.lam, x.energy, slope, self.opts, state, x.energy_scale,
                                       refine=self.refine)
            dU = None if alpha is None else alpha * step
        if alpha is None:
            raise StepFailure("line search found no decrease of the energy")
        U = x.U + dU
        Pi = parts["total"]
        self.energies.append(Pi)
        record = {"alpha": alpha, "cap": cap, "mu": mu, "fresh": dn.fresh, "mode": dn.mode}
        if dn.fresh:
            self._trust_region(x.energy, Pi, alpha, slope, cap, dn.curvature)
        r = model.residual(U, x.lam, candidates=state.candidates, pairs=state.self_pairs,
                           slip=state.slip).ravel()[free]
        work = abs(float(dU.ravel()[free] @ r))
        if self.work0 is None:
            # energy scale: the first step's work or the work of the load so far, whichever is larger
            # (a good predictor makes the first step tiny; round-off must not stall the criterion);
            # ``parts``: the energies at the new U, from the line search
            self.work0 = max(abs(alpha * slope), abs(x.lam * float(np.einsum("ni,ni->", self.test.P, U))),
                             parts["bending"] + parts["membrane"], 1e-300)
            self.test.work_ref = self.work0
        rnorm = float(np.linalg.norm(r))
        # modified Newton: keep the factorisation while it still cuts the residual fast
        new = Iterate(U, x.lam, r, rnorm, work=work, energy=Pi, energy_scale=energy_scale(parts),
                      reusable=alpha == 1.0 and rnorm < 0.3 * x.rnorm)
        if not np.isfinite(rnorm):
            raise StepFailure("non-finite residual", new)
        return new, record

    def _trust_region(self, Pi0, Pi, alpha, slope, cap, curvature) -> None:
        """Levenberg-Marquardt damping as a trust region (More's update): the ratio of the actual to the
        predicted energy decrease of a fresh Newton step decides; a step the line search had to shorten (a
        near-singular or indefinite direction: a sheet balanced on a sphere, a fold forming) damps the next one
        (with ``refine``, only below :data:`SHORT_STEP` of its length: one it took at that length or longer leaves
        the damping as it is), good full steps undo it, so the final iterations are pure Newton."""
        mu = self.damping.mu
        predicted = -(slope + 0.5 * cap * cap * curvature)
        actual = Pi0 - Pi
        tiny = 1e-10 * max(abs(Pi), abs(self.work0 or 0.0))
        if alpha == 1.0 and abs(predicted) <= tiny:
            rho = 1.0  # below what the energy resolves: the residual decides convergence
        else:
            rho = actual / predicted if (alpha == 1.0 and predicted > 0) else 0.0
        if alpha < (SHORT_STEP if self.refine else 1.0) or (alpha == 1.0 and rho < 0.25):
            mu = max(4.0 * mu, 1e-6)
        elif alpha == 1.0 and rho > 0.75:
            mu = mu / 3.0 if mu > 1e-9 else 0.0
        self.damping.mu = mu

    def progress(self, x: Iterate) -> float:
        """Energy drop over the last third of the steps over the work scale [-]: still sliding downhill?"""
        e = self.energies
        k = max(2, len(e) // 3)
        drop = e[-k] - e[-1]
        return drop / max(self.work0 or 0.0, abs(x.lam * float(np.einsum("ni,ni->", self.test.P, x.U))), 1e-300)


def displacement_iterations(model, U, lam, opts, state, max_step, refine: bool = False) -> Iteration:
    """Newton on the displacements alone from ``U`` at load factor ``lam`` (module docstring), with the
    :class:`~rftstatic.solvers.options.NewtonOptions` ``opts`` and the solve's State ``state``.

    ``refine``: the walk along a flat valley from a relaxed drape at full load (``relaxed`` of
    :func:`rftstatic.solvers.load_steps.load_steps`): a step the line search shortened is refined to the lowest
    energy near it (:func:`lowest_near`) and damps the next direction only below :data:`SHORT_STEP`. Not on the
    load-scaled path from the flat sheet, where the greedier steps measured worse (pedestal-round-50-unstructured,
    h = 2.86 cm: its first increment, at a load factor of 1e-5, no longer converged and the route fell back to the
    relaxation and another equilibrium)."""
    test = Criteria(model, lam, opts, U)
    # the final increment converges to the tight tolerance and may need longer
    max_iterations = 2 * opts.max_iterations if lam >= 1.0 else opts.max_iterations
    U = U.copy()
    parts = model.energies(U, lam, candidates=state.candidates, pairs=state.self_pairs,
                           slip=state.slip, branches=state.load_branches)
    r = model.residual(U, lam, candidates=state.candidates, pairs=state.self_pairs,
                       slip=state.slip).ravel()[model.free.ravel()]
    x = Iterate(U, lam, r, float(np.linalg.norm(r)), energy=parts["total"], energy_scale=energy_scale(parts))
    if not np.isfinite(x.rnorm):
        return Iteration(False, U, 0, x.rnorm, "non-finite residual")
    damping = Damping()
    find = DisplacementDirection(model, opts, state, damping, x)
    search = LineSearch(model, opts, state, damping, test, max_step, x, refine)
    out = newton_loop(x, test=lambda it: test.met(it.U, it.r, it.work, state.solver), direction=find,
                      globalise=search, max_iterations=max_iterations)
    x = out.x
    if out.converged:
        return Iteration(True, x.U, out.iterations, x.rnorm, stable=find.stable, history=out.history)
    reason = out.reason or f"no convergence in {max_iterations} iterations"
    return Iteration(False, x.U, out.iterations, x.rnorm, reason, progress=search.progress(x) if out.reason is None
                     else 0.0, history=out.history)


def line_search(model, U, step, lam, Pi0, slope, opts, state, scale=None, max_trials=12, refine=False, path=None):
    """Armijo backtracking on Pi along ``step (N, 3)`` [m] from ``U`` with energy ``Pi0`` [J] and slope
    ``r . step`` [J]: ``(alpha, parts)``, ``parts`` the energies (:meth:`~rftstatic.model.model.Model.energies`)
    at ``U + alpha step``; ``(None, None)`` when no trial lowers the energy. ``scale`` [J]: :func:`energy_scale`
    of the energies at ``U`` (computed when None). A full step that passes is taken as it is; with ``refine``, a
    shorter Armijo point is refined to the lowest energy near it (:func:`lowest_near`). ``path``: a curve
    ``alpha -> displacement (N, 3)`` [m] with the tangent ``step`` at 0 (:mod:`~rftstatic.solvers.rotation_lift`),
    searched in place of the straight line."""
    def parts_at(alpha):
        dU = alpha * step if path is None else path(alpha)
        return model.energies(U + dU, lam, candidates=state.candidates, pairs=state.self_pairs,
                              slip=state.slip, branches=state.load_branches)

    if not opts.line_search:
        return 1.0, parts_at(1.0)
    if scale is None:
        scale = energy_scale(model.energies(U, lam, candidates=state.candidates, pairs=state.self_pairs,
                                            slip=state.slip, branches=state.load_branches))
    if abs(slope) <= 1e-10 * scale:
        # the predicted decrease is below what the energy can resolve: near the solution the Newton
        # step is reliable, and the force residual (not the energy) decides convergence
        return 1.0, parts_at(1.0)
    roundoff = 1e-13 * scale
    alpha = 1.0
    for _ in range(max_trials):
        parts = parts_at(alpha)
        Pi = parts["total"]
        if np.isfinite(Pi) and Pi <= Pi0 + 1e-4 * alpha * slope + roundoff:
            return (alpha, parts) if alpha == 1.0 or not refine else lowest_near(parts_at, alpha, parts)
        # minimiser of the quadratic through Pi0, slope and Pi(alpha), safeguarded
        if np.isfinite(Pi):
            denom = 2.0 * (Pi - Pi0 - slope * alpha)
            a_q = -slope * alpha * alpha / denom if denom > 0 else 0.5 * alpha
            alpha = float(np.clip(a_q, 0.1 * alpha, 0.5 * alpha))
        else:
            alpha *= 0.1
    return None, None


SHORT_STEP = 0.3
"""Share of a fresh Newton step [-] below which a step the line search shortened damps the next direction
(:meth:`LineSearch._trust_region`) on the walk from a relaxed state (``refine``; elsewhere every shortened step
damps it, x 4, at least 1e-6 of the mean tangent diagonal). Measured from the relaxed states of issue 34 with the
rotation-lifted line search (validation/bench_profile.md, 2026-12-05): pedestal-round-50 94 Newton iterations and
119 factorisations at 0.3 (116, 155 at 0.5; 101, 128 at 0.45; 99, 142 at 0.25), pedestal-square-80 145 and 196
(153, 191 at 0.5), sphere-30 79 and 98; the same equilibria."""

LINE_REFINE_FACTOR = 2.0 ** 0.5
"""Ratio of two trial step lengths of :func:`lowest_near` [-]."""

LINE_REFINE_TRIALS = 4
"""Most trials of :func:`lowest_near` in each direction (longer, then shorter)."""


def lowest_near(parts_at, alpha: float, parts: dict, factor: float = LINE_REFINE_FACTOR,
                trials: int = LINE_REFINE_TRIALS) -> tuple[float, dict]:
    """The step length of lowest energy near the Armijo point ``alpha < 1`` of a backtracking: ``(alpha, parts)``.

    From ``alpha`` (energies ``parts``), the trial length is multiplied by ``factor`` (longer, below the full
    step, which failed) while the energy falls, up to ``trials`` times; if the first longer trial does not lower
    it, divided by ``factor`` the same way. The result is within a factor ``factor`` of a minimum of Pi along
    the line (where Pi has one minimum between the trials and they did not run out) and never higher than at
    ``alpha``. ``parts_at(a)``: the energies (:meth:`~rftstatic.model.model.Model.energies`, key ``"total"`` [J])
    at the step length ``a``.

    Why: the backtracking stops at the first length that passes Armijo's test, often far from the minimum
    along the line. On the static drapes' flat valleys (validation/bench_profile.md, issue 34, h-speed5) Pi
    along a Newton step is far from quadratic beyond about the full step (the membrane's strain is quadratic in
    the step), and the backtracking's quadratic interpolation undershoots: from pedestal-round-50's relaxed
    state the refined length was 1.4-4 times the Armijo point's in 21 of 24 refinements, and the displacement
    iteration took 101 Newton iterations and 112 factorisations (116 and 128 without); from
    pedestal-square-80's, 148 and 147 (165 and 157), at 2-3 energy evaluations per refinement, the same
    equilibria (energy to 1e-15 relative).
    """
    best_alpha, best = alpha, parts
    for f in (factor, 1.0 / factor):
        trial, moved = best_alpha * f, False
        for _ in range(trials):
            if not trial < 1.0:
                break
            p = parts_at(trial)
            if not (np.isfinite(p["total"]) and p["total"] < best["total"]):
                break
            best_alpha, best, moved = trial, p, True
            trial *= f
        if moved:
            break
    return best_alpha, best


def energy_scale(parts: dict) -> float:
    """Magnitude of the energy [J] against which the line search judges round-off: the summed magnitudes
    of bending, membrane, contact energies and the load's work."""
    return abs(parts["bending"]) + abs(parts["membrane"]) + abs(parts["contact"]) + abs(parts["external_work"])
