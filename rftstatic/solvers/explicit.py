"""Explicit dynamics and dynamic relaxation (Sze & Zhou 2016, §2.4 Eq. 16-22, §4.6, §6).

Equation of motion (Eq. 16) with the mass damping of Eq. 27 written so that it opposes the motion
(Eq. 27 as printed has the opposite sign):

    M D'' + alpha M D' + F(D) = P.

``M`` is the lumped mass (:func:`rftstatic.solvers.timestep.lumped_mass`, times the mass-scaling factor s),
``F`` the internal force (bending + membrane + penalty contact, the same element code as the static
solver, :mod:`rftstatic.element.explicit_force`) and ``P = model.load`` (gravity, never mass scaled). The
damping force is lagged half a step (asynchronous damping, Eq. 19) and central differences give

    a_n = M^-1 (P - F(D_n)) - alpha v_(n-1/2)                            (Eq. 20)
    v_(n+1/2) = v_(n-1/2) + a_n dt                                       (Eq. 21)
    D_(n+1) = D_n + v_(n+1/2) dt                                         (Eq. 22)

on the free dofs; supported dofs keep their displacement. After each position update the
obstacles act kinematically (§6.3, :func:`rftstatic.contact.kinematic.kinematic_contact`).

Start: from ``U0`` and the velocity ``V0`` at t = 0, the default ``start="consistent"`` sets
``v_(-1/2) = V0 - a_0 dt / 2`` with ``a_0`` from Eq. 20 at ``V0``, so that the scheme is exact for a
constant acceleration (free fall gives ``z = z0 + V0 t - g t^2 / 2`` to round-off);
``start="given"`` takes ``V0`` as ``v_(-1/2)``.

Friction: Coulomb impulses after each velocity update, on the penalty contact
(:func:`rftstatic.contact.friction.penalty_impulses`), between the sheet's layers in self-contact
(:func:`rftstatic.contact.self_contact.friction.pair_impulses`) and in the kinematic contact.

Energy bookkeeping (history): kinetic energy at step n from the mean of the two half-step
velocities, potential = stored (bending + membrane + penalty) energy - P.D_n, dissipated = the work
of the damping force ``sum alpha dt v_(n-1/2) M v_(n+1/2)`` plus, with bending or shear hysteresis, the frictions'
(:mod:`rftstatic.element.hysteresis`, H4, and :mod:`rftstatic.element.shear_friction`, S6: their slip is committed
after every step, each step a converged one; both under the key ``"bending_friction"`` of the run's accumulators):
dissipation only, never decreasing (up to the damping's O(dt^2) sign at a velocity reversal). ``contact_loss`` is
the energy the contact corrections take from the sheet (the kinematic contact's projection and velocity change,
Coulomb impulses, the self-contact step filter), measured as the scheme measures energy
(:mod:`rftstatic.solvers.contact_energy`, C1-C2: a node resting on an obstacle or sticking loses nothing, an impact
its kinetic energy). Moving obstacles (``body_work``) and supports moving at a prescribed velocity
(``model.supports.velocity``: a dragged edge, their work ``sum (F - P) . v dt`` on the driven dofs) do work on the
sheet; the mean of that reaction over the run's second half is :attr:`ExplicitResult.drive_reaction`. ``total`` =
kinetic + potential + dissipated + contact_loss - the bodies' and supports' work is conserved up to the scheme's
O(dt^2) error (the kinematic projection's change of the stored energy to first order in its move).
Growth of ``total`` beyond ``energy_tol`` times the energy scale of the run (or a non-finite value) raises
:class:`InstabilityError` naming the time, the step and the step size to use.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from rftstatic.contact.friction import penalty_impulses
from rftstatic.contact.self_contact.friction import pair_impulses
from rftstatic.element.explicit_force import ForceKernel
from rftstatic.errors import InstabilityError, ParameterError
from rftstatic.model.state import State
from rftstatic.progress import Progress
from rftstatic.solvers.contact_energy import impulse_change, kinematic_step
from rftstatic.solvers.damping import make_law
from rftstatic.solvers.drive import Pause, finish
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.step_plan import StepPlan, plan_steps
from rftstatic.solvers.timestep import StepEstimate, lumped_mass, stable_time_step

log = logging.getLogger(__name__)

HISTORY_KEYS = ("time", "kinetic", "potential", "strain", "external_work", "dissipated", "contact_loss", "total",
                "residual")


@dataclass
class ExplicitResult:
    """Outcome of :func:`run_explicit`.

    Attributes
    ----------
    U : (N, 3) final displacements [m]
    V : (N, 3) final half-step velocities v_(n-1/2) [m/s]
    t : final time [s]; steps : steps taken; dt : step used [s]
    estimate : the stable-step estimate (``None`` when neither needed nor checked)
    history : arrays of the samples: time [s], kinetic, potential, strain, external_work,
        dissipated, contact_loss, total [J], residual (out-of-balance force on the free dofs, 2-norm) [N]
    probes : (S, P, 3) displacements of the probe nodes at the samples [m]
    frames : list of (t [s], U (N, 3) [m]) at the requested frame times
    time_at_rest : first sample time [s] from which kinetic / peak kinetic energy stays at most ``options.rest_tol``
        (:meth:`~rftstatic.solvers.rest.RestCriterion.time_at_rest`), or None
    stopped : True if a callback stopped the run before ``t_end``
    wall_time : [s]; element_steps_per_second : E * steps / wall time
    drive_reaction : (3,) mean force [N] of the sheet on its driven supports (``model.supports.velocity``) over the
        run's second half (:func:`drive_reaction`), None without them
    state : the final :class:`~rftstatic.model.state.State` (U, V, t, step, contact candidates)
    """

    U: np.ndarray
    V: np.ndarray
    t: float
    steps: int
    dt: float
    estimate: StepEstimate | None
    history: dict
    probes: np.ndarray
    frames: list = field(default_factory=list)
    time_at_rest: float | None = None
    stopped: bool = False
    contact_nodes: int = 0
    wall_time: float = 0.0
    element_steps_per_second: float = 0.0
    state: State | None = None
    drive_reaction: np.ndarray | None = None


EXPLICIT = "explicit"
"""The explicit run's key in ``State.route``: its step [s], step count, stable-step estimate, energy
accumulators, history, probe records, frames and options (what a resumed run continues from)."""


def run_explicit(model, options: ExplicitOptions, *, U0=None, V0=None, obstacles=(), load=None, frame_times=(),
                 probes=None, callback=None, plan: StepPlan | None = None, friction=None) -> ExplicitResult:
    """Integrate the motion of ``model`` from t = 0 to ``options.t_end`` (module docstring): :func:`explicit_steps`
    from ``U0``, ``V0`` (N, 3) [m, m/s] (default zero), run to its end without checkpoints."""
    return finish(explicit_steps(model, State.initial(model, U0, V0), options, obstacles=obstacles, load=load,
                                 frame_times=frame_times, probes=probes, callback=callback, plan=plan,
                                 friction=friction))


def explicit_steps(model, state: State, options: ExplicitOptions, *, obstacles=(), load=None, frame_times=(),
                   probes=None, callback=None, plan: StepPlan | None = None, friction=None):
    """The explicit run as a route (:mod:`rftstatic.solvers.drive`): steps ``state`` to ``options.t_end``, pausing
    after every whole step; returns the :class:`ExplicitResult`.

    Parameters
    ----------
    model : :class:`rftstatic.model.model.Model` (supports, gravity in ``model.load``)
    state : the :class:`~rftstatic.model.state.State` to step: U, V (N, 3) [m, m/s] at t = 0 (V is zeroed on
        the supported dofs), or a saved State whose ``route`` holds the run's position (:data:`EXPLICIT`), which
        then goes on step for step as the uninterrupted run
    options : :class:`~rftstatic.solvers.explicit_options.ExplicitOptions` (end time, step, damping, mass
        scaling, start, sampling, checks, step limit)
    obstacles : obstacles acting kinematically after every step (any type, §6.3)
    load : (N, 3) external nodal load [N] to use instead of ``model.load`` (e.g. a guided stage)
    frame_times : times [s] at which to store the displacement field (first step at or after each)
    probes : node indices (P,) whose displacements are recorded at every sample
    callback : called as ``callback(state, sample)`` at every sample (``sample``: dict of the history
        values); returning True stops the run
    plan : the :class:`~rftstatic.solvers.step_plan.StepPlan` of this run, made by the caller with
        :func:`~rftstatic.solvers.step_plan.plan_steps` from the same options (default: planned here)
    friction : Coulomb friction of the kinematic obstacles (:class:`rftstatic.contact.friction.FrictionLaw`), or None
    """
    o = options
    wall0 = time.perf_counter()
    N = model.mesh.n_nodes
    obstacles = tuple(obstacles) if not hasattr(obstacles, "signed_distance") else (obstacles,)
    probes = np.zeros(0, dtype=np.int64) if probes is None else np.atleast_1d(np.asarray(probes, dtype=np.int64))
    if probes.size and (probes.min() < 0 or probes.max() >= N):
        raise ValueError(f"probe nodes must lie in 0..{N - 1}, got min {probes.min()}, max {probes.max()}")
    loop = _Loop(model, obstacles, mass_scale=o.mass_scale, alpha=o.alpha, load=load, backend=o.backend,
                 probes=probes, frame_times=np.sort(np.asarray(frame_times, dtype=float).ravel()), friction=friction,
                 law=make_law(o.damping))
    saved = state.route.get(EXPLICIT)
    if saved is None:
        state.V *= model.free
        if plan is not None and plan.t_end != o.t_end:
            raise ParameterError("plan", f"planned to t_end = {plan.t_end!r} s, the options ask {o.t_end!r} s")
        if plan is None:
            plan = plan_steps(model, t_end=o.t_end, dt=o.dt, U=state.U, alpha=o.alpha, mass_scale=o.mass_scale,
                              safety=o.safety, max_steps=o.max_steps, limit_name=o.max_steps_name,
                              check_dt=o.energy_check)
        dt, n_steps, estimate = plan.dt, plan.steps, plan.estimate
        loop.begin(dt, start_consistent=o.start == "consistent", state=state)
    else:
        dt, n_steps, estimate = saved["dt"], saved["n_steps"], saved["estimate"]
        loop.resume(dt, saved)
    sample_every = max(1, n_steps // 2000) if o.sample_every is None else o.sample_every
    state.route[EXPLICIT] = loop.position(n_steps, estimate, {
        "t_end": o.t_end, "alpha": o.alpha, "damping": o.damping, "mass_scale": o.mass_scale,
        "sample_every": int(sample_every), "energy_check": o.energy_check, "energy_tol": o.energy_tol,
        "rest_tol": o.rest_tol, "safety": o.safety,
        "frame_times": loop.frame_times, "probe_nodes": probes, "backend": loop.kernel.backend})
    check = _EnergyCheck(model, estimate, mass_scale=o.mass_scale, alpha=o.alpha, safety=o.safety, tol=o.energy_tol,
                         enabled=o.energy_check)
    bar = Progress(o.t_end, "explicit", unit=" s", enabled=o.progress)
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            stopped = yield from loop.advance(state, n_steps, int(sample_every), check, bar, callback=callback)
            loop.final_sample(state, check)
    finally:
        bar.close()
    del state.route[EXPLICIT]
    history = {k: np.asarray(v, dtype=float) for k, v in loop.hist.items()}
    wall = time.perf_counter() - wall0
    return ExplicitResult(
        U=state.U, V=state.V, t=state.t, steps=state.step, dt=dt, estimate=estimate, history=history,
        probes=np.asarray(loop.probe_hist, dtype=float).reshape(len(loop.probe_hist), len(probes), 3),
        frames=loop.frames, time_at_rest=RestCriterion(o.rest_tol).time_at_rest(history), stopped=stopped,
        contact_nodes=loop.n_contact, wall_time=wall,
        element_steps_per_second=model.mesh.n_elements * state.step / max(wall, 1e-12), state=state,
        drive_reaction=drive_reaction(loop.acc, state.step, dt))


class _Loop:
    """The central-difference loop of :func:`run_explicit` (Eq. 20-22) and its bookkeeping: energy
    accumulators, history samples, probe records and frames. The solve's state is a :class:`State`."""

    def __init__(self, model, obstacles, *, mass_scale, alpha, load, backend, probes, frame_times, friction=None,
                 law=None):
        self.model, self.obstacles, self.alpha, self.friction, self.law = model, obstacles, alpha, friction, law
        self.free = model.free
        self.mass = lumped_mass(model, mass_scale)
        self.kernel = ForceKernel(model, backend=backend)
        self.P = np.array(model.load if load is None else load, dtype=float)
        self.probes, self.frame_times = probes, frame_times
        self.minv = self.free / self.mass[:, None]  # (N, 3) inverse mass, zero on supported dofs
        sc = getattr(model, "self_contact", None)
        if sc is not None:
            from rftstatic.contact.self_contact.step_filter import StepFilter

            self.self_filter = StepFilter(sc, self.minv)
        else:
            self.self_filter = None
        self.self_friction = getattr(sc, "friction", None)  # Coulomb impulses between layers (self_contact.friction)
        self.n_contact = 0
        self.sweep = None  # the sheet against the obstacles' sharp features along each step (feature_sweep)
        if obstacles:
            from rftstatic.contact.feature_sweep import FeatureSweep

            self.sweep = FeatureSweep.for_sheet(obstacles, model.mesh.tri, model.mesh.topology.edges, model.X3)
        # friction of the penalty contact (rftstatic.contact.friction, F5); kinematic obstacles take `friction`
        self.penalty_friction = getattr(model.contact, "friction", None) if model.contact is not None else None
        # keyframed obstacles of the penalty contact (rftstatic.contact.motion): the pose of each step is State
        self.motion = getattr(model.contact, "motion", None) if model.contact is not None else None
        self.impulses = any(m is not None for m in (self.penalty_friction, self.self_friction, self.self_filter))
        drive = getattr(model.supports, "velocity", None)  # held components moving at a prescribed velocity
        self.drive = None if drive is None or not np.any(drive * ~self.free) else np.where(self.free, 0.0, drive)

    def _pose(self, state, t, work=True):
        """Set the obstacles' poses of the step from ``t`` [s] (and their surfaces' velocity over it) on ``state``;
        ``work``: add the work the move does on the sheet to ``acc["body_work"]`` (a term of the energy balance:
        :func:`_sample`): the change of the contact energy ``E(x, pose)`` from the last pose to this one, the mean
        of its values at this step's positions and the last step's (the trapezoidal rule, second order in the
        step; at the positions alone it was first order: 6.4e-6 J of a 9.3e-5 J lift unbooked at dt = 2e-4 s)."""
        if self.motion is None:
            return
        moving = work and t <= self.motion.end + self.dt
        contact, acc = self.model.contact, self.acc
        if moving:
            x = self.model.X3 + state.U
            before = contact.energy(x, candidates=state.candidates)
        state.obstacle_poses = self.motion.poses(t, self.dt)
        if moving:
            after = contact.energy(x, candidates=state.candidates)
            w = after - before
            last = acc.get("pose_last")  # (positions, contact energy) of the last step at its pose
            if last is not None:
                w = 0.5 * (w + contact.energy(last[0], candidates=state.candidates) - last[1])
            acc["body_work"] = acc.get("body_work", 0.0) + w
            acc["pose_last"] = (x, after)

    def begin(self, dt, *, start_consistent, state):
        """A fresh run with step ``dt`` [s]: empty records; ``v_(-1/2) = V0 - a_0 dt / 2`` if consistent."""
        self.dt = dt
        self.acc = {"damping": 0.0, "bending_friction": 0.0, "contact": 0.0, "total0": None, "scale": 0.0,
                    "peak_kinetic": 0.0, "frame_index": 0, "contact_energy": True}  # the booking of contact_energy
        self.hist = {k: [] for k in HISTORY_KEYS}
        self.probe_hist, self.frames = [], []
        self._pose(state, state.t, work=False)
        if start_consistent:
            f = self.kernel(state.U, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)
            a0 = (self.P - f) / self.mass[:, None] - self.alpha * state.V
            state.V = state.V - 0.5 * dt * a0 * self.free

    def resume(self, dt, r):
        """Continue the records of a saved position ``r`` (:meth:`position`)."""
        self.dt = dt
        self.acc = r["acc"]
        if not self.acc.get("contact_energy"):  # saved by the earlier booking (before contact_energy): its
            # contact_loss and total are not this one's, so the energy check measures growth from here on
            log.warning("the saved explicit run booked its contact energy the earlier way: its energy history "
                        "before the resume is not comparable, the energy check starts again from here")
            self.acc.pop("projection", None)
            self.acc.update(total0=None, scale=0.0, contact_energy=True)
        self.hist = {k: list(r["history"][k]) for k in HISTORY_KEYS}
        self.probe_hist = list(r["probes"])
        self.frames = list(r["frames"])

    def position(self, n_steps, estimate, options) -> dict:
        """The run's position (:data:`EXPLICIT`): the loop's records themselves, so it stays current as it steps."""
        return {"dt": self.dt, "n_steps": n_steps, "estimate": estimate, "acc": self.acc, "history": self.hist,
                "probes": self.probe_hist, "frames": self.frames, "options": options}

    def _frames_due(self, t, U):
        acc, times = self.acc, self.frame_times
        while acc["frame_index"] < len(times) and t >= times[acc["frame_index"]] - 1e-9 * self.dt:
            self.frames.append((t, U.copy()))
            acc["frame_index"] += 1

    def advance(self, state, n_steps, sample_every, check, bar, *, callback):
        """Step ``state`` to ``n_steps`` (Eq. 20-22), pausing after every whole step before the last; returns True
        if the callback stopped the run."""
        dt, P, minv, free, mass, acc = self.dt, self.P, self.minv, self.free, self.mass, self.acc
        U, V = state.U, state.V
        check_every = min(sample_every, 50)
        Ufix = U.copy()
        fixed_any = bool((~free).any())
        Vnew = np.empty_like(V)
        step = state.step
        stopped = False
        while step < n_steps:
            t = step * dt
            sample = step % sample_every == 0
            checked = sample or step % check_every == 0
            self._pose(state, t)
            if checked:
                f, W = self.kernel(U, energy=True, candidates=state.candidates, pairs=state.self_pairs,
                                   slip=state.slip)
            else:
                f = self.kernel(U, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)
            self._frames_due(t, U)
            if self.drive is not None:  # the driven supports' reaction f - P: its work and impulse (module docstring)
                _drive_work(acc, f, P, self.drive, dt, step, n_steps)
            # Eq. 20-21, with the damping force lagged half a step
            np.subtract(P, f, out=f)
            f *= minv
            law = self.law if self.law is not None and self.law.begin(acc)["on"] else None
            alpha = 0.0 if law is not None else self.alpha  # a velocity law takes over from the mass damping
            np.multiply(V, 1.0 - alpha * dt, out=Vnew)
            f *= dt
            Vnew += f
            if alpha:
                acc["damping"] += alpha * dt * float(np.einsum("n,ni,ni->", mass, V, Vnew))
            acc["damping"] += acc.pop("damping_pending", 0.0)  # the last step's law: the rest of its work
            if law is not None:  # FIRE or kinetic damping (rftstatic.solvers.damping)
                _apply_law(law, acc, U, V, Vnew, f, mass, free, dt)
            if checked:
                rec = _sample(t, U, V, Vnew, W, P, f, dt, mass, minv, free, acc)
                check(rec, step, dt, acc)
                if self.law is not None and law is None:
                    self.law.switch(self.law.begin(acc), rec["kinetic"])
                if sample:
                    self._record(rec, U)
                    bar.update(t, f"KE {rec['kinetic']:.3g} J")
                    if callback is not None:
                        state.U, state.V, state.t, state.step = U, V, t, step
                        stopped = bool(callback(state, rec if law is None else dict(
                            rec, kinetic=law.rest_kinetic(law.begin(acc), rec["kinetic"]))))
            V, Vnew = Vnew, V
            if self.drive is not None:
                np.copyto(V, self.drive, where=~free)
                Ufix += dt * self.drive
            if self.impulses:  # velocity corrections before Eq. 22: their energy (C1) is contact_loss
                self._impulses(state, U, V, f)
            # Eq. 22
            U += dt * V
            if self.obstacles:
                self.n_contact = kinematic_step(self.model, self.obstacles, U, V, mass, acc, self.friction, dt, f,
                                                self.sweep)
                if fixed_any:
                    np.copyto(U, Ufix, where=~free)
            step += 1
            state.U, state.V, state.t, state.step = U, V, step * dt, step
            if state.slip is not None:
                acc["bending_friction"] = acc.get("bending_friction", 0.0) + state.commit_slip(self.model, U)
            if stopped:
                break
            if step < n_steps:
                yield Pause("", keep=False, step=step)
        return stopped

    def _impulses(self, state, U, V, g):
        """The step's velocity corrections before the position update, in place on ``V`` (N, 3) [m/s]: Coulomb
        impulses on the penalty contact (F5) and between the sheet's layers, the self-contact step filter; adds
        their ``-dE`` (:mod:`rftstatic.solvers.contact_energy`, C1; ``g`` the step's velocity increment from the
        forces) and the work the moving bodies did through them to ``acc["contact"]``."""
        acc, x, dt, minv = self.acc, self.model.X3 + U, self.dt, self.minv
        before, body = V.copy(), acc.get("body_work", 0.0)
        if self.penalty_friction is not None:
            penalty_impulses(self.penalty_friction, self.model.contact, x, V, minv, dt, state.candidates, work=acc)
        if self.self_friction is not None:
            pair_impulses(self.self_friction, self.model.self_contact, x, V, minv, dt, state.self_pairs)
        if self.self_filter is not None:  # no pair of the sheet passes through another on this step
            self.self_filter(state.self_pairs, x, V, dt)
        acc["contact"] += acc.get("body_work", 0.0) - body - impulse_change(self.mass, before, V, g, self.free)

    def _record(self, rec, U):
        for k in HISTORY_KEYS:
            self.hist[k].append(rec[k])
        self.probe_hist.append(U[self.probes].copy())

    def final_sample(self, state, check):
        """The history sample (and any frame due) at the end state."""
        t, U, V, dt = state.t, state.U, state.V, self.dt
        self._pose(state, t, work=False)
        f, W = self.kernel(U, energy=True, candidates=state.candidates, pairs=state.self_pairs, slip=state.slip)
        self._frames_due(t, U)
        g = (self.P - f) * self.minv * dt
        Vend = V * (1.0 - self.alpha * dt) + g
        self.acc["damping"] += self.acc.pop("damping_pending", 0.0)
        rec = _sample(t, U, V, Vend, W, self.P, g, dt, self.mass, self.minv, self.free, self.acc)
        check(rec, state.step, dt, self.acc)
        if not self.hist["time"] or self.hist["time"][-1] != t:
            self._record(rec, U)


def _sample(t, U, V, Vnew, W, P, g, dt, mass, minv, free, acc) -> dict:
    """History values at step n; ``g`` = dt M^-1 (P - F) on the free dofs."""
    vbar = 0.5 * (V + Vnew)
    kinetic = 0.5 * float(np.einsum("n,ni,ni->", mass, vbar, vbar))
    ext = float(np.einsum("ni,ni->", P, U))
    dissipated = acc["damping"] + acc.get("bending_friction", 0.0)  # never decreasing (module docstring)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(free, g / (dt * np.where(minv > 0, minv, 1.0)), 0.0)
    # work done on the sheet by moving obstacles (rftstatic.contact.motion) and by driven supports
    work = acc.get("body_work", 0.0) + acc.get("drive", 0.0)
    return {"time": t, "kinetic": kinetic, "potential": W - ext, "strain": W, "external_work": ext,
            "dissipated": dissipated, "contact_loss": acc["contact"],
            "total": kinetic + W - ext + dissipated + acc["contact"] - work,
            "residual": float(np.linalg.norm(r))}


class _EnergyCheck:
    """Raise :class:`~rftstatic.errors.InstabilityError` when the total energy grows beyond ``tol`` times
    the run's energy scale or stops being finite (disabled: only the peak kinetic energy is tracked)."""

    def __init__(self, model, estimate, *, mass_scale, alpha, safety, tol, enabled):
        self.model, self.estimate, self.mass_scale, self.alpha = model, estimate, mass_scale, alpha
        self.safety, self.tol, self.enabled = safety, tol, enabled

    def __call__(self, rec, step, dt, acc):
        if self.enabled:
            _check_energy(rec, step, dt, self.estimate, self.model, self.mass_scale, self.alpha, self.safety,
                          self.tol, acc)


def _check_energy(rec, step, dt, estimate, model, mass_scale, alpha, safety, energy_tol, acc):
    total = rec["total"]
    if acc["total0"] is None:
        acc["total0"] = total
    acc["peak_kinetic"] = max(acc["peak_kinetic"], rec["kinetic"])
    scale = rec["kinetic"] + abs(rec["strain"]) + abs(rec["external_work"]) + rec["dissipated"]
    acc["scale"] = max(acc["scale"], scale) if np.isfinite(scale) else acc["scale"]
    growth = total - acc["total0"]
    if np.isfinite(total) and growth <= energy_tol * max(acc["scale"], 1e-300):
        return
    if estimate is None:
        estimate = stable_time_step(model, None, mass_scale=mass_scale, alpha=alpha, safety=safety)
    suggested = estimate.dt if dt > estimate.dt * (1 + 1e-3) else 0.5 * dt
    what = "non-finite energy" if not np.isfinite(total) else (
        f"total energy grew by {growth:.3e} J (> {energy_tol:g} x energy scale {acc['scale']:.3e} J)")
    raise InstabilityError(
        f"explicit run unstable at t = {rec['time']:.6g} s (step {step}): {what} with dt = {dt:.4g} s; "
        f"use dt <= {suggested:.4g} s (estimated critical step {estimate.dt_crit:.4g} s, "
        f"omega_max {estimate.omega_max:.4g} rad/s, mass scale {mass_scale:g})",
        t=rec["time"], step=step, dt=dt, suggested_dt=suggested)


def _apply_law(law, acc, U, V, Vnew, g, mass, free, dt) -> None:
    """A velocity law (FIRE, kinetic damping: :mod:`rftstatic.solvers.damping`) on ``Vnew`` = v_(n+1/2) in place,
    and its work in ``acc["damping"]``: the kinetic energy it took as step n's sample measures it now, and the rest
    of the change it made to the scheme's energy (C1 of :mod:`rftstatic.solvers.contact_energy`, a velocity
    correction before the position update) at the next step (``"damping_pending"``), so every sample balances and
    the sum is the law's whole work (booked as the first alone, the strip of tests/solvers/test_damping.py lost 19 %
    of gravity's work from the balance over 2 s with either law)."""
    undamped = Vnew.copy()
    taken = law(law.begin(acc), U, V, Vnew, g, mass, free, dt)
    acc["damping"] += taken
    acc["damping_pending"] = -impulse_change(mass, undamped, Vnew, g, free) - taken


def _drive_work(acc, f, P, drive, dt, step, n_steps) -> None:
    """Add a step of the driven supports' work ``(f - P) . v dt`` [J] (a work term of the energy balance) and
    impulse ``sum (f - P) dt`` [N s] over the driven dofs (``drive (N, 3)`` [m/s], zero elsewhere); the impulse at
    half the run is kept, so the mean reaction of its second half is ``(impulse - impulse_half) / (t - t_half)``."""
    moving = drive != 0.0
    r = np.where(moving, f - P, 0.0)
    acc["drive"] = acc.get("drive", 0.0) + dt * float(np.einsum("ni,ni->", r, drive))
    impulse = np.asarray(acc.get("drive_impulse", np.zeros(3)), float) + dt * r.sum(axis=0)
    acc["drive_impulse"] = impulse
    if step == n_steps // 2:
        acc["drive_half_impulse"], acc["drive_half_step"] = impulse.copy(), int(step)


def drive_reaction(acc, steps: int, dt: float):
    """The mean force ``(3,)`` [N] the sheet pulls its driven supports with, ``f - P`` summed over their driven dofs,
    over the second half of a run of ``steps`` steps of ``dt`` [s] (:func:`_drive_work`'s records ``acc``), or None
    without a drive."""
    if "drive_half_step" not in acc:
        return None
    impulse, half = np.asarray(acc["drive_half_impulse"]), int(acc["drive_half_step"])
    return (np.asarray(acc["drive_impulse"]) - impulse) / max((steps - half) * dt, 1e-300)
