"""Dynamic relaxation (§6): damped, mass-scaled explicit motion until the sheet is at rest.

Mass scaling (s = 100 as in §6) lengthens the stable step by sqrt(s); the load is not scaled, so the
resting state is the static equilibrium.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from rftstatic.contact.friction import held_by_contacts, obstacle_holds, seated
from rftstatic.contact.self_contact.friction import pair_holds
from rftstatic.element.explicit_force import BACKENDS
from rftstatic.errors import FallError, ParameterError
from rftstatic.model.state import State
from rftstatic.solvers.damping import DAMPINGS
from rftstatic.solvers.drive import finish
from rftstatic.solvers.explicit import EXPLICIT, ExplicitResult, explicit_steps
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.rest import RELAX_MASS_SCALE, RELAX_REST, AtRest, RestCriterion
from rftstatic.solvers.step_plan import MAX_STEPS_KEY
from rftstatic.solvers.timestep import lumped_mass

log = logging.getLogger(__name__)

FALL_DIAGONALS = 3.0
"""A relaxation stops with a :class:`~rftstatic.errors.FallError` once the sheet's mass centre has moved this many
of its reference diagonals along the load from the reference (:func:`_fall_guard`): a drape hangs within about
one diagonal of where it was placed, so a sheet that far away is falling with nothing to hold it (a garment slid
off its form: a limp circle skirt, fabric F of validation/garments.md, went 14 m down in the 177 s of its route)."""

@dataclass
class RelaxResult:
    """Outcome of :func:`relax`: resting displacements ``U (N, 3)`` [m], whether the criteria were
    met, the time [s] and steps used, the explicit run (histories), the final half-step velocity
    ``V (N, 3)`` [m/s] and the peak kinetic energy [J] (to resume)."""

    U: np.ndarray
    converged: bool
    t: float
    steps: int
    run: ExplicitResult
    V: np.ndarray | None = None
    peak_kinetic: float = 0.0




@dataclass(frozen=True, kw_only=True)
class RelaxOptions:
    """How :func:`relax` relaxes. A bad value raises :class:`~rftstatic.errors.ParameterError` naming the field.

    Attributes
    ----------
    alpha : mass damping [1/s], >= 0; near ``2 omega_1 / sqrt(s)`` (critical for the lowest mode of the
        scaled system) relaxes fastest
    max_time : give up after this simulated time [s], > 0 (``converged=False``, logged)
    mass_scale : mass-scaling factor s [-] (§6: 100); the load is not scaled
    rest : when the sheet is at rest (:class:`~rftstatic.solvers.rest.RestCriterion`: kinetic energy / its
        peak, out-of-balance force / load)
    dt : step [s]; None: the stable step (:func:`~rftstatic.solvers.step_plan.plan_steps`)
    sample_every : steps between rest tests (history samples) [-]
    progress : show a progress bar
    backend : force back end, ``"auto"``, ``"numpy"`` or ``"numba"``
    max_steps : refuse a relaxation of more explicit steps than this, or whose stable step collapsed
        (:class:`~rftstatic.errors.StepLimitError`, before the first step); None: the explicit solver's limit
    max_steps_name : the option that sets ``max_steps``, named in that refusal
    damping : ``"viscous"`` (the mass damping ``alpha``) or a velocity law of :mod:`rftstatic.solvers.damping`
        (``"fire"``, ``"kinetic"``) on the undamped motion; ``alpha`` then only sets the time scale of the caller
    """

    alpha: float
    max_time: float
    mass_scale: float = RELAX_MASS_SCALE
    rest: RestCriterion = RELAX_REST
    dt: float | None = None
    sample_every: int = 20
    progress: bool = True
    backend: str = BACKENDS[0]
    max_steps: int | None = None
    max_steps_name: str = MAX_STEPS_KEY
    damping: str = DAMPINGS[0]

    def __post_init__(self):
        if not (isinstance(self.max_time, (int, float)) and self.max_time > 0):
            raise ParameterError("max_time", f"must be > 0 [s], got {self.max_time!r}")
        if not isinstance(self.rest, RestCriterion):
            raise ParameterError("rest", f"must be a RestCriterion, got {self.rest!r}")
        self.explicit(given_velocity=False)  # the explicit run's checks, naming the same fields

    def explicit(self, *, given_velocity: bool) -> ExplicitOptions:
        """The explicit run of the relaxation: from a given half-step velocity, or consistent from rest."""
        alpha = 0.0 if self.damping in DAMPINGS[1:3] else self.alpha
        return ExplicitOptions(t_end=self.max_time, dt=self.dt, alpha=alpha, damping=self.damping,
                               mass_scale=self.mass_scale,
                               start="given" if given_velocity else "consistent", sample_every=self.sample_every,
                               progress=self.progress, backend=self.backend, max_steps=self.max_steps,
                               max_steps_name=self.max_steps_name)


def relax(model, options: RelaxOptions, *, U0=None, V0=None, obstacles=(), load=None,
          peak_kinetic: float = 0.0) -> RelaxResult:
    """Dynamic relaxation (§6) from ``U0`` [m] and the half-step velocity ``V0`` [m/s] (default zero; given, it
    is v_(-1/2), e.g. to resume from a :class:`RelaxResult`'s ``U``, ``V``): :func:`relax_steps` run to its end."""
    state = State.initial(model, U0, V0)
    return finish(relax_steps(model, state, options, given_velocity=V0 is not None, obstacles=obstacles, load=load,
                              peak_kinetic=peak_kinetic))


def relax_steps(model, state: State, options: RelaxOptions, *, given_velocity: bool = False, obstacles=(), load=None,
                peak_kinetic: float = 0.0):
    """Dynamic relaxation (§6) as a route (:mod:`rftstatic.solvers.drive`): damped explicit motion of ``state``
    until the sheet is at rest, pausing after every step; returns the :class:`RelaxResult`.

    At rest: ``options.rest`` (:class:`~rftstatic.solvers.rest.RestCriterion`) at a sample, kinetic energy
    against its peak and the out-of-balance force on the free dofs ``|P - F(U)|`` against ``|P|``. Mass scaling
    (default s = 100 as in §6) lengthens the stable step by sqrt(s); the load is not scaled, so the resting
    state is the static equilibrium. With Coulomb friction on the penalty contact the explicit steps apply its
    impulses (:func:`rftstatic.contact.friction.penalty_impulses`), and a relaxation from rest starts with the sheet
    seated on the penalty (:func:`rftstatic.contact.friction.seated`); between layers in self-contact, the pairs'
    (:func:`rftstatic.contact.self_contact.friction.pair_impulses`). The rest test then measures what friction does
    not hold (:func:`_held_rest`).

    Parameters
    ----------
    state : U, V (N, 3) [m, m/s] to start from, or a saved State inside the relaxation (its ``route`` holds the
        explicit run's position), which goes on step for step as the uninterrupted run
    options : :class:`RelaxOptions`
    given_velocity : ``state.V`` is the half-step velocity v_(-1/2) (else the start is consistent from it)
    obstacles : obstacles acting kinematically (§6.3)
    load : (N, 3) external nodal load [N] instead of ``model.load`` (the resting state then balances it)
    peak_kinetic : peak kinetic energy [J] of the motion before this relaxation (``RelaxResult.peak_kinetic``)
    """
    P = model.load if load is None else load
    P_norm = float(np.linalg.norm(np.where(model.free, P, 0.0)))
    at_rest = AtRest(options.rest, load_norm=P_norm, peak_kinetic=peak_kinetic)
    saved = state.route.get(EXPLICIT)
    if saved is not None:  # the peaks of the samples before the interruption, as the rest test saw them
        at_rest.resume_from(saved["history"])
    elif not given_velocity and getattr(model.contact, "friction", None) is not None:  # thrown off, it would slide
        state.U += (seated(model.contact, model.positions(state.U), P) - model.positions(state.U)) * model.free
    rest = _fall_guard(model, _held_rest(model, state, at_rest, P, options.mass_scale), P)
    run = yield from explicit_steps(model, state, options.explicit(given_velocity=given_velocity), obstacles=obstacles,
                                    load=load, callback=rest)
    state.route.pop(FRICTION_REST, None)
    if not run.stopped:  # the caller decides what follows (the static route relaxes on or hands over)
        log.info("dynamic relaxation not at rest after %.4g s (%d steps): kinetic %.3e J, |r| %.3e N",
                 run.t, run.steps, run.history["kinetic"][-1], run.history["residual"][-1])
    return RelaxResult(U=run.U, converged=run.stopped, t=run.t, steps=run.steps, run=run, V=run.V,
                       peak_kinetic=at_rest.peak_kinetic)


FRICTION_REST = "relax-friction-rest"
"""Key in ``State.route`` of the peaks of a frictional relaxation's rest test (:func:`_held_rest`), so that a resumed
run tests as the uninterrupted one did (its history holds the frictionless measures)."""


def _fall_guard(model, test, P):
    """The rest test ``test`` of a relaxation under the load ``P (N, 3)`` [N], which first raises a
    :class:`~rftstatic.errors.FallError` at a sample where the sheet's mass centre lies more than
    :data:`FALL_DIAGONALS` reference diagonals from the reference along the load's resultant (a sheet with no
    resultant load is not tested)."""
    resultant = np.where(model.free, P, 0.0).sum(axis=0)
    size = float(np.linalg.norm(resultant))
    if not size > 0.0:
        return test
    down = resultant / size
    share = model.mesh.node_area / model.mesh.node_area.sum()
    X = model.X3
    limit = FALL_DIAGONALS * float(np.linalg.norm(X.max(axis=0) - X.min(axis=0)))

    def guarded(st, sample):
        drop = float(share @ (st.U @ down))
        if drop > limit:
            raise FallError(f"the sheet fell: its mass centre is {drop:.3g} m from where it was placed, along the "
                            f"load (more than {FALL_DIAGONALS:g} of its diagonals, {limit:.3g} m), after {st.t:.3g} s: "
                            "nothing holds it. Check the supports and obstacles; a garment slid off its form: give it "
                            "friction ([contact] friction, e.g. 0.3) or a pattern that fits the body closer")
        return test(st, sample)

    return guarded


def _held_rest(model, state, at_rest: AtRest, P, mass_scale):
    """The rest test of a relaxation: ``at_rest`` itself, or with Coulomb friction (on the penalty contact, between
    the layers in self-contact), one that measures what the friction does not hold: the kinetic energy of the
    velocities its impulses left (the motion's peak counts the sample's own, impulse-free, so a sheet released from
    rest has moved before it can rest) and the out-of-balance force with a reaction the static friction of the
    obstacle contacts and of the layers' pairs can give taken off (:func:`rftstatic.contact.friction.held_by_contacts`,
    H1-H2; :func:`rftstatic.contact.friction.obstacle_holds`,
    :func:`rftstatic.contact.self_contact.friction.pair_holds`)."""
    law = getattr(model.contact, "friction", None)
    sc = getattr(model, "self_contact", None)
    self_law = getattr(sc, "friction", None) if sc is not None else None
    if law is None and self_law is None:
        return at_rest
    mass = lumped_mass(model, mass_scale)
    mobile = model.free.any(axis=1)
    peaks = state.route.setdefault(FRICTION_REST, {"kinetic": at_rest.peak_kinetic, "residual": 0.0})
    at_rest.peak_kinetic, at_rest.peak_residual = peaks["kinetic"], peaks["residual"]

    def test(st, sample):
        r = -model.residual(st.U, 1.0, candidates=st.candidates, pairs=st.self_pairs, slip=st.slip)
        x = model.positions(st.U)
        holds = [] if law is None else [obstacle_holds(law, model.contact, x)]
        if self_law is not None:
            holds.append(pair_holds(self_law, sc, x, st.self_pairs))
        r = held_by_contacts(np.where(model.free, r - model.load + P, 0.0), holds, mobile)
        r = np.where(model.free, r, 0.0)
        at_rest.peak_kinetic = max(at_rest.peak_kinetic, sample["kinetic"])
        kinetic = 0.5 * float(np.einsum("n,ni,ni->", mass, st.V, st.V))
        done = at_rest(st, dict(sample, kinetic=kinetic, residual=float(np.linalg.norm(r))))
        peaks.update(kinetic=at_rest.peak_kinetic, residual=at_rest.peak_residual)
        return done

    return test


def newton_descent(model, state: State, route, result) -> bool:
    """After a failed Newton handover, let the relaxation ``route`` (:class:`~rftstatic.solvers.static.RelaxRoute`) go
    on from the handover's last iterate ``result.U (N, 3)`` [m], at rest, when that is at full load and lower in total
    potential than the relaxed state ``route.U`` (on a flat landscape, e.g. leaving a saddle, Newton's line-searched
    descent is kept instead of thrown away); return whether it did. Not with bending hysteresis (its energy depends on
    the path: the relaxation's own history is kept)."""
    if result is None or result.lam < 1.0 or state.slip is not None or not np.all(np.isfinite(result.U)):
        return False
    new, old = (model.potential(U, 1.0, candidates=state.candidates) for U in (result.U, route.U))
    if not new < old:
        return False
    route.U, route.V = result.U.copy(), np.zeros_like(result.U)
    return True
