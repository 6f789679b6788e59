"""Dynamic relaxation with global adaptive remeshing (§5.2 a-i, §6): the damped, mass-scaled explicit
motion in chunks, remeshed on a schedule or when the curvature asks, until the sheet is at rest on a
mesh that would not change.

With bending or shear hysteresis (``model.has_friction``) the frictions' committed slips ride along: every chunk of
steps goes on from the slips the last one committed, every remesh carries them to the new elements
(:func:`~rftstatic.remesh.adapt.carry_slip`: the slip of the old element holding each new centroid), and the energy
they dissipate adds up over the run.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from rftstatic.contact.candidates import CandidateList
from rftstatic.element.explicit_force import BACKENDS
from rftstatic.errors import ParameterError
from rftstatic.remesh.adapt import (
    DAMPING,
    RemeshRecord,
    _check_extent,
    _curvature_figures,
    _factory,
    adapt_mesh,
    carry_slip,
    reference_domain,
    refinable_maxima,
    transfer_state,
)
from rftstatic.model.state import State
from rftstatic.remesh.checkpoint import REMESH_RELAX, RelaxState
from rftstatic.remesh.options import RemeshOptions, RemeshRelaxOptions
from rftstatic.solvers.drive import Pause, finish
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE
from rftstatic.solvers.timestep import SAFETY

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------- relaxation
CHAIN = 1.2024
"""Fundamental frequency of a hanging chain of length l, in units of sqrt(g / l) (j_01 / 2 = 2.4048 / 2)."""


def critical_damping(model, U, *, mass_scale, alpha_max):
    """Mass damping [1/s] that is critical for the slowest swing of the hanging sheet, at most ``alpha_max``.

    The lowest mode of a sheet hanging ``l`` below its support is close to that of a hanging chain,
    ``omega_1 = 1.2 sqrt(g / l)``; with the mass scaled by s (the weight is not) the load gives the
    mass the acceleration g / s, so ``omega_1 = 1.2 sqrt(g / (s l))`` and critical damping is
    ``alpha = 2 omega_1``. ``l`` is the present largest sag ``-min U_z`` [m]. Dynamic relaxation
    converges fastest near critical damping of its slowest mode: a larger alpha lets the overdamped
    swing creep at the rate omega_1^2 / alpha, a smaller one lets it ring. (With the mass scaled by
    s, a damping alpha gives the motion of the real sheet damped by alpha sqrt(s), slowed down
    sqrt(s) times: the same number of steps.) Measured with s = 100 on
    the 50 x 50 cm sheet over the round pedestal: the paper's alpha = 5 / s (chosen for the real
    mass, §4.6) is critical for a 2.3 cm hang and came to rest after 50.6 s (the drape hangs 25.7 cm:
    alpha = 1.48 / s, at rest after 28 s).

    Returns ``alpha_max`` while the sheet has not sagged (``-min U_z <= 0``) or carries no load.

    Parameters
    ----------
    model : the model (``load`` [N], lumped mass from :func:`rftstatic.solvers.timestep.lumped_mass`)
    U : (N, 3) displacements [m]
    mass_scale : s [-]
    alpha_max : upper bound [1/s] (the scene's alpha)
    """
    from rftstatic.solvers.timestep import lumped_mass

    sag = float(-U[:, 2].min(initial=0.0))
    mass = float(lumped_mass(model, mass_scale)[model.free.any(axis=1)].sum())
    weight = float(-np.where(model.free, model.load, 0.0)[:, 2].sum())
    if not (sag > 0 and weight > 0 and mass > 0):
        return float(alpha_max)
    omega = CHAIN * np.sqrt(weight / mass / sag)
    return float(min(alpha_max, 2.0 * omega))


class NearObstacle:
    """An obstacle whose signed distance is computed only for the points near it (a candidate list).

    For the kinematic contact of the explicit steps (:func:`rftstatic.contact.kinematic.kinematic_contact`
    needs phi only to find phi < 0, and the normal there). The exact distance of every point is
    computed when the list is (re)made; the candidates are the points within ``margin`` of the
    obstacle. Until some point has moved more than ``margin / 2`` since then, only the candidates
    are evaluated: a signed distance changes no faster than the point moves (it is 1-Lipschitz), so
    every other point is still more than ``margin / 2`` outside, and it gets that lower bound with a
    zero normal. The contact is therefore the same as with the plain obstacle, and a step pays for
    the few points near the obstacle. Measured on the 50 x 50 cm sheet over the round pedestal
    (~1900 nodes): the kinematic contact took more time than the internal force before.

    Parameters
    ----------
    obstacle : any obstacle (``signed_distance``, ``normal_gradient``)
    margin : candidate distance [m]; :meth:`reset` sets it (e.g. to the mean element size)
    """

    def __init__(self, obstacle, margin):
        self.obstacle = obstacle
        self.candidates = CandidateList(margin)

    @property
    def margin(self) -> float:
        return self.candidates.margin

    @property
    def refreshes(self) -> int:
        return self.candidates.refreshes

    def segment_crossings(self, x0, x1):
        """The wrapped obstacle's continuous collision detection of the steps ``x0 -> x1`` (``(n, 3)`` [m];
        :meth:`rftstatic.contact.obstacles.Obstacle.segment_crossings`), or None."""
        ccd = getattr(self.obstacle, "segment_crossings", None)
        return None if ccd is None else ccd(x0, x1)

    def reset(self, margin=None):
        """Forget the candidate list (a new mesh); optionally a new ``margin`` [m]."""
        self.candidates.reset(margin)

    def signed_distance(self, x):
        x = np.asarray(x, dtype=float)
        hit = self.candidates.lookup(x)
        if hit is not None:
            idx, phi = hit
            normal = np.zeros_like(x)
            if len(idx):
                phi[idx], normal[idx] = self.obstacle.signed_distance(x[idx])
            return phi, normal
        phi, normal = self.obstacle.signed_distance(x)
        self.candidates.refresh(x, phi)
        return phi, normal

    def normal_gradient(self, x):
        return self.obstacle.normal_gradient(x)


class ExplicitStepper:
    """An ``advance(model, U, V, n_steps) -> (U, V, t)`` stepper on :func:`rftstatic.solvers.explicit.run_explicit`.

    ``V`` is the half-step velocity v_(n-1/2) [m/s] and is passed back in with ``start="given"``, so
    chunks continue the central-difference sequence exactly. ``t`` is the time advanced [s]. The
    stable step is estimated once per model (``dt=None``; ``safety`` times the critical step at the
    state the mesh starts from, with the damping ``alpha``), with the mass scaled by ``mass_scale``
    (§6: 100; the weight is not scaled). ``energy_check=True`` makes every chunk re-estimate the
    step (a Lanczos run per chunk, and a warning whenever the sheet has stiffened by a few 0.1 %
    since the mesh's estimate); by default the driver only checks that the state stays finite.

    ``damping="fixed"``: every chunk is damped with ``alpha`` [1/s]. ``damping="critical"``: each
    chunk with :func:`critical_damping` of the state it starts from (at most ``alpha``).
    ``alphas`` lists the damping of every chunk [1/s]. The obstacles act kinematically
    through :class:`NearObstacle` candidate lists (the same contact, fewer distance evaluations).
    """

    def __init__(self, *, alpha, mass_scale=RELAX_MASS_SCALE, dt=None, obstacles=(), safety=SAFETY,
                 backend=BACKENDS[0], energy_check=False, damping=DAMPING[0]):
        if damping not in DAMPING:
            raise ValueError(f'damping = "{damping}" is unknown; use one of {", ".join(DAMPING)}')
        obstacles = (obstacles,) if hasattr(obstacles, "signed_distance") else tuple(obstacles)
        self.alpha, self.mass_scale, self.dt, self.safety = alpha, mass_scale, dt, safety
        self.backend, self.energy_check, self.damping = backend, energy_check, damping
        self.near = tuple(NearObstacle(ob, 0.0) for ob in obstacles)
        self.alphas = []
        self._model, self._dt = None, None  # the mesh the candidate lists and the step belong to
        self._resumed_dt = None

    def state(self) -> dict:
        """What a checkpoint keeps: the damping of every chunk so far [1/s] and the present mesh's step [s]."""
        return {"alphas": list(self.alphas), "dt": self._dt}

    def restore(self, state: dict, *, same_mesh: bool) -> None:
        """Continue from :meth:`state`; ``same_mesh``: the next call is on the mesh that ``state["dt"]`` was
        estimated for (else the step is estimated afresh, as the uninterrupted run did on a new mesh)."""
        self.alphas = [float(a) for a in state["alphas"]]
        self._resumed_dt = state["dt"] if same_mesh else None

    def __call__(self, model, U, V, n_steps, *, max_time=None, slip=None):
        """Advance ``n_steps`` steps, or fewer (the last one shortened) that end at ``max_time`` [s] when
        ``n_steps`` would go beyond it; ``last_steps`` is the number taken. Returns ``(U, V, t)``; given the
        frictions' committed ``slip (E, k)`` (:meth:`rftstatic.model.model.Model.initial_slip`), the steps go on from
        it and it returns ``(U, V, t, slip, dissipated)``, the slips committed by the last step and the energy the
        frictions dissipated over the chunk [J] (without, each chunk starts from the virgin fabric)."""
        from rftstatic.model.state import State
        from rftstatic.solvers.drive import finish
        from rftstatic.solvers.explicit import explicit_steps
        from rftstatic.solvers.explicit_options import ExplicitOptions
        from rftstatic.solvers.timestep import stable_time_step

        if self._model is not model:
            for ob in self.near:  # candidates within a mean element size of the obstacle
                ob.reset(float(model.mesh.element_size.mean()))
            self._model, self._dt, self._resumed_dt = model, self._resumed_dt, None
        step = self.dt
        if step is None:
            if self._dt is None:
                # alpha bounds the chunk's damping, and a larger damping shortens the critical step
                self._dt = stable_time_step(model, U, mass_scale=self.mass_scale, alpha=self.alpha,
                                            safety=self.safety).dt
            step = self._dt
        a = self.alpha if self.damping == "fixed" else critical_damping(model, U, mass_scale=self.mass_scale,
                                                                       alpha_max=self.alpha)
        self.alphas.append(a)
        span = n_steps * step if max_time is None or not max_time < n_steps * step else max_time
        options = ExplicitOptions(t_end=span, dt=step, alpha=a, mass_scale=self.mass_scale, start="given",
                                  sample_every=max(1, n_steps), progress=False, energy_check=self.energy_check,
                                  backend=self.backend)
        state = State.initial(model, U, V)
        if slip is not None:
            state.slip = np.array(slip, dtype=float)
        run = finish(explicit_steps(model, state, options, obstacles=self.near))
        self.last_steps = run.steps
        if slip is None:
            return run.U, run.V, run.t
        return run.U, run.V, run.t, state.slip, state.dissipated


def explicit_advance(**options) -> ExplicitStepper:
    """The default stepper of :func:`remesh_relax` (:class:`ExplicitStepper` with these options)."""
    return ExplicitStepper(**options)


@dataclass
class RemeshRelaxResult:
    """Outcome of :func:`remesh_relax`: final U, V (N, 3) [m, m/s], model and extras, the time [s]
    and steps advanced, one :class:`RemeshRecord` per mesh, whether the sheet came to rest on a
    mesh that no longer changes, how many triggered remeshes were skipped (mesh settled), the frictions'
    committed slips (E, k) on the final mesh (None without hysteresis) and the energy they dissipated [J]."""

    U: np.ndarray
    V: np.ndarray
    model: object
    extras: dict
    t: float
    steps: int
    records: list
    converged: bool
    skipped: int = 0
    slip: np.ndarray | None = None
    dissipated: float = 0.0


def _chunk(advance, model, U, V, n, slip):
    """``(U, V, t_advanced, slip, dissipated)``: ``n`` steps by ``advance`` from U, V (N, 3) [m, m/s]; for a model with
    hysteresis (``slip`` (E, k) its frictions' committed slips, not None) ``advance(model, U, V, n, slip=slip)``, which
    returns the slips committed at the chunk's end and the energy the frictions dissipated in it [J]
    (:class:`ExplicitStepper`), else ``advance(model, U, V, n)`` (slip None, nothing dissipated)."""
    if slip is None:
        return (*advance(model, U, V, n), None, 0.0)
    return advance(model, U, V, n, slip=slip)


def _friction_history(model, state, restart) -> tuple:
    """``(slip, dissipated)`` the route starts from on ``model``: the frictions' committed slips (E, k) (None: no
    hysteresis) and the energy they dissipated so far [J]; those ``state`` saved with the position ``restart``, else
    (a fresh run, or a checkpoint of a model with hysteresis written before its slips were kept) the virgin fabric."""
    if restart is not None and state.slip is not None:
        return state.slip, state.dissipated
    return model.initial_slip(), 0.0 if restart is None else float(state.dissipated)


def _initial_state(model, U0, V0) -> RelaxState:
    """The state a remeshed relaxation starts from: U0, V0 (N, 3) [m, m/s] (default zero) on ``model``'s mesh."""
    N = model.mesh.n_nodes
    U = np.zeros((N, 3)) if U0 is None else np.array(U0, dtype=float)
    V = np.zeros((N, 3)) if V0 is None else np.array(V0, dtype=float)
    record = RemeshRecord(0, N, model.mesh.n_elements, dict(model.mesh.info.get("quality", {})))
    return RelaxState([model.mesh], U, V, t=0.0, steps=0, since=0, n_remesh=0, skipped=0, peak=0.0, records=[record])


def remesh_relax(problem, options: RemeshOptions, motion: RemeshRelaxOptions = RemeshRelaxOptions(), *, advance=None,
                 domain=None, U0=None, V0=None, residual=None) -> RemeshRelaxResult:
    """Dynamic relaxation with global adaptive remeshing: :func:`remesh_relax_route` from ``U0``, ``V0`` (N, 3)
    [m, m/s] on the initial mesh (default zero), run to its end without checkpoints."""
    state = State(U=np.zeros((0, 3)) if U0 is None else np.array(U0, dtype=float),
                  V=np.zeros((0, 3)) if V0 is None else np.array(V0, dtype=float))
    return finish(remesh_relax_route(problem, options, state, motion, advance=advance, domain=domain,
                                     start=(U0, V0), residual=residual))


def remesh_relax_route(problem, options: RemeshOptions, state: State, motion: RemeshRelaxOptions = RemeshRelaxOptions(),
                       *, advance=None, domain=None, start=(None, None), residual=None):
    """Dynamic relaxation with global adaptive remeshing (§5.2 a-i, §6), as a route (:mod:`rftstatic.solvers.drive`).

    The motion is advanced ``motion.chunk`` steps at a time. After each chunk (step d) the mesh is
    remeshed when ``options.every`` steps have passed since the last remesh, or when the largest
    |kappa| h^2 exceeds ``options.kappa_h2_max`` [m]; U and V are transferred (step h). When the sheet is
    at rest (``motion.rest``, :class:`~rftstatic.solvers.rest.RestCriterion`: the out-of-balance force on the
    free dofs against |P| and the kinetic energy of the half-step velocity against its peak on the present
    mesh), the mesh it would get is sized: a node-count change below ``options.tol`` ends the run (converged),
    otherwise it remeshes and goes on.

    Parameters
    ----------
    problem : ``factory(mesh) -> Model | (Model, extras)`` (as in :func:`remesh_static`)
    options : :class:`~rftstatic.remesh.options.RemeshOptions`; this route reads ``const``, ``h_lower``,
        ``h_upper`` (Eq. 29 [m]), ``gradation``, ``transfer``, ``tol`` (relative node-count change below which
        the mesh counts as settled, and, with ``kappa_h2_max``, max |kappa| h^2 <= kappa_h2_max), ``every``,
        ``kappa_h2_max`` (over the elements not already at the size floor h_lower, :func:`refinable_maxima`)
        and ``damping`` (of the default stepper: ``"fixed"`` or ``"critical"``, :func:`critical_damping`)
    motion : :class:`~rftstatic.remesh.options.RemeshRelaxOptions` (damping, mass scaling, chunk, limits, rest
        test, skipping of settled meshes)
    advance : ``advance(model, U, V, n_steps) -> (U, V, t_advanced)``, with hysteresis ``advance(..., slip=slip)
        -> (U, V, t_advanced, slip, dissipated)`` (:func:`_chunk`); default :func:`explicit_advance` with
        ``motion.alpha``, ``motion.mass_scale`` and the scene's obstacles
    domain : mesher Domain of the sheet (default: :func:`reference_domain` of the initial mesh)
    state : the run's :class:`~rftstatic.model.state.State`; its position ``state.route[REMESH_RELAX]`` (a
        :class:`~rftstatic.remesh.checkpoint.RelaxState`) before every chunk (a pause, held back by the saver's
        throttle; final after a remesh) and at the end (final), with U, V, t, step and the frictions' ``slip`` and
        ``dissipated``. Given a State with a saved position, the run goes on
        from there (``start`` unused). With an ``advance`` that keeps state of its own (the damping history, the
        stable step of the mesh), the caller restores that too.
    start : ``(U0, V0)``, (N, 3) start on the initial mesh [m, m/s] (default zero)
    residual : ``residual(model, U) -> (N, 3)`` [N], the out-of-balance force of the rest test (with hysteresis
        ``slip=`` the frictions' committed slips too; default ``model.residual``; with kinematic obstacles,
        :func:`rftstatic.contact.kinematic.contact_reaction_residual` takes their reaction off)

    Returns
    -------
    :class:`RemeshRelaxResult`
    """
    from rftstatic.solvers.timestep import lumped_mass

    o, m = options, motion
    const, h_lower, h_upper, every, kappa_h2_max, tol = o.const, o.h_lower, o.h_upper, o.every, o.kappa_h2_max, o.tol
    max_steps, mass_scale = m.max_steps, m.mass_scale
    make = _factory(problem)
    if residual is None:
        def residual(model, U, slip=None):
            return model.residual(U, slip=slip)
    model, extras = make(None)
    _check_extent(model.mesh, const, h_lower, h_upper)
    if advance is None:
        if m.alpha is None:
            raise ParameterError("alpha", "the mass damping [1/s] is needed by the default explicit stepper; or pass "
                                 "advance=")
        advance = explicit_advance(alpha=m.alpha, mass_scale=mass_scale, obstacles=extras.get("obstacles", ()),
                                   damping=o.damping)
    if domain is None:
        domain = reference_domain(model.mesh)
    wall = time.perf_counter()
    restart = state.route.get(REMESH_RELAX)
    r = _initial_state(model, *start) if restart is None else restart
    U, V, t, steps, since, n_remesh, skipped = r.U.copy(), r.V.copy(), r.t, r.steps, r.since, r.n_remesh, r.skipped
    peak, records, meshes, done, converged = r.peak, list(r.records), list(r.meshes), r.done, r.converged
    if len(meshes) > 1:  # a restart on a later mesh (the initial model serves mesh 0)
        model, extras = make(meshes[-1])
    slip, dissipated = _friction_history(model, state, restart)
    phase = None  # what the next snapshot is: None (the state just loaded or started), "chunk", "remesh"

    def pause(phase):
        state.route[REMESH_RELAX] = RelaxState(meshes, U, V, t, steps, since, n_remesh, skipped, peak, records,
                                               done=done, converged=converged, phase=phase)
        state.U, state.V, state.t, state.step = U, V, t, steps
        state.slip, state.dissipated = slip, dissipated
        return Pause(f"t = {t:.4g} s, step {steps}, mesh {len(meshes) - 1} ({meshes[-1].n_nodes} nodes)",
                     final=phase != "chunk")

    while steps < max_steps and not done:
        if phase is not None:
            yield pause(phase)  # every path through the loop ends here: the state the next chunk starts from
        phase = "chunk"
        n = int(min(m.chunk, max_steps - steps))
        U, V, dt_adv, slip, spent = _chunk(advance, model, U, V, n, slip)
        dissipated += float(spent)
        if not (np.isfinite(U).all() and np.isfinite(V).all()):
            raise FloatingPointError(f"remesh_relax: non-finite state after step {steps + n} (t = {t:.4g} s) on a "
                                     f"mesh of {model.mesh.n_nodes} nodes; reduce the time step (safety) or raise alpha")
        t, steps, since = t + float(dt_adv), steps + n, since + n
        kappa, kh, kh2 = _curvature_figures(model, U)
        rkh, rkh2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
        mass = lumped_mass(model, mass_scale)
        kinetic = 0.5 * float(np.einsum("n,ni,ni->", mass, V, V))
        peak = max(peak, kinetic)
        P = np.where(model.free, model.load, 0.0)
        at = {} if slip is None else {"slip": slip}  # the frictions' committed slips, with hysteresis
        r = float(np.linalg.norm(np.where(model.free, residual(model, U, **at), 0.0)))
        # no residual peak is kept across chunks: an unloaded sheet is at rest at r = 0 only
        rest = m.rest.holds(kinetic, peak, r, float(np.linalg.norm(P)), r)
        reason = ("rest" if rest else "every" if every is not None and since >= every
                  else "curvature" if kappa_h2_max is not None and rkh2 > kappa_h2_max else None)
        if reason is None:
            continue
        if n_remesh >= m.max_remesh:
            if rest:
                done, converged = True, False
            continue
        new_mesh, _ = adapt_mesh(model.mesh, kappa, const=const, h_lower=h_lower, h_upper=h_upper,
                                 gradation=o.gradation, domain=domain)
        rec = records[-1]
        rec.max_kappa_h, rec.max_kappa_h2 = kh, kh2
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = rkh, rkh2
        rec.node_change = abs(new_mesh.n_nodes - model.mesh.n_nodes) / model.mesh.n_nodes
        settled = rec.node_change < tol and (kappa_h2_max is None or rkh2 <= kappa_h2_max)
        if rest and settled:
            done, converged = True, True
            continue
        if settled and m.skip_settled:
            since = 0
            skipped += 1
            continue
        new_model, new_extras = make(new_mesh)
        U, V = transfer_state(model, new_model, U, V, method=o.transfer)
        slip = carry_slip(model, slip, new_model)
        model, extras = new_model, new_extras
        n_remesh += 1
        since, peak = 0, 0.0
        now = time.perf_counter()
        rec.wall_time, wall = now - wall, now
        records.append(RemeshRecord(n_remesh, new_mesh.n_nodes, new_mesh.n_elements, new_mesh.info["quality"],
                                    time=t, step=steps, reason=reason))
        meshes.append(new_mesh)
        phase = "remesh"
        log.info("remesh_relax: t = %.4g s, step %d (%s): %d -> %d nodes, max |kappa| h %.3g",
                 t, steps, reason, rec.nodes, new_mesh.n_nodes, kh)
    if phase is not None:
        done = True
        yield pause("done")
    state.route.pop(REMESH_RELAX, None)
    rec = records[-1]
    if not np.isfinite(rec.max_kappa_h):
        kappa, rec.max_kappa_h, rec.max_kappa_h2 = _curvature_figures(model, U)
        rec.refinable_kappa_h, rec.refinable_kappa_h2 = refinable_maxima(model.mesh, kappa, const=const, h_lower=h_lower)
    rec.wall_time = time.perf_counter() - wall
    if not converged:
        log.warning("remesh_relax: not at rest on a settled mesh after %d steps (t = %.4g s, %d remeshes)",
                    steps, t, n_remesh)
    return RemeshRelaxResult(U=U, V=V, model=model, extras=extras, t=t, steps=steps, records=records,
                             converged=converged, skipped=skipped, slip=slip, dissipated=float(dissipated))
