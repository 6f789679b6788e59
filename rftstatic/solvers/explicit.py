"""Explicit dynamics and dynamic relaxation (Sze & Zhou 2016, §2.4 Eq. 16-22, §4.6, §6).

Equation of motion (Eq. 16) with the mass damping of Eq. 27 written so that it opposes the motion
(method.md: Eq. 27 prints the wrong sign):

    M D'' + alpha M D' + F(D) = P.

``M`` is the lumped mass (:func:`rftstatic.timestep.lumped_mass`, times the mass-scaling factor s),
``F`` the internal force (bending + membrane + penalty contact, the same element code as the static
solver, :mod:`rftstatic.explicit_force`) and ``P = model.load`` (gravity, never mass scaled). The
damping force is lagged half a step (asynchronous damping, Eq. 19) and central differences give

    a_n = M^-1 (P - F(D_n)) - alpha v_(n-1/2)                            (Eq. 20)
    v_(n+1/2) = v_(n-1/2) + a_n dt                                       (Eq. 21)
    D_(n+1) = D_n + v_(n+1/2) dt                                         (Eq. 22)

on the free dofs; supported dofs keep their displacement. After each position update the
obstacles act kinematically (§6.3, :func:`rftstatic.contact.kinematic_contact`).

Start: from ``U0`` and the velocity ``V0`` at t = 0, the default ``start="consistent"`` sets
``v_(-1/2) = V0 - a_0 dt / 2`` with ``a_0`` from Eq. 20 at ``V0``, so that the scheme is exact for a
constant acceleration (free fall gives ``z = z0 + V0 t - g t^2 / 2`` to round-off);
``start="given"`` takes ``V0`` as ``v_(-1/2)``.

Energy bookkeeping (history): kinetic energy at step n from the mean of the two half-step
velocities, potential = stored (bending + membrane + penalty) energy - P.D_n, dissipated = the work
of the damping force ``sum alpha dt v_(n-1/2) M v_(n+1/2)``. ``total`` = kinetic + potential +
dissipated is conserved up to the scheme's O(dt^2) error without obstacles. The kinematic contact
is not conservative: it removes the inward normal velocity (``contact_loss``, the kinetic energy
removed, reported apart) and its position projection does work that is not tracked; on balance
it lowers ``total``, by about ``contact_loss``. Growth of ``total`` beyond ``energy_tol`` times the
energy scale of the run (or a non-finite
value) raises :class:`InstabilityError` naming the time, the step and the step size to use.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from rftstatic.element.explicit_force import ForceKernel
from rftstatic.errors import InstabilityError
from rftstatic.progress import Progress
from rftstatic.solvers.timestep import StepEstimate, lumped_mass, stable_time_step

log = logging.getLogger(__name__)

HISTORY_KEYS = ("time", "kinetic", "potential", "strain", "external_work", "dissipated", "contact_loss", "total",
                "residual")


@dataclass
class State:
    """What changes from step to step.

    Attributes
    ----------
    t : time of ``U`` [s]
    U : (N, 3) displacements D_n [m]
    V_half : (N, 3) velocities v_(n-1/2) [m/s]
    step : step number n
    """

    t: float
    U: np.ndarray
    V_half: np.ndarray
    step: int


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
    time_at_rest : first sample time after which kinetic/peak kinetic stays below ``rest_tol``, or None
    stopped : True if a callback stopped the run before ``t_end``
    wall_time : [s]; element_steps_per_second : E * steps / wall time
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

    def summary(self) -> dict:
        return {"t": self.t, "steps": self.steps, "dt": self.dt, "time_at_rest": self.time_at_rest,
                "stopped": self.stopped, "wall_time": self.wall_time,
                "element_steps_per_second": self.element_steps_per_second,
                "final_total_energy": float(self.history["total"][-1]) if len(self.history["time"]) else None}


def run_explicit(model, *, t_end: float, dt: float | None = None, alpha: float = 0.0, mass_scale: float = 1.0,
                 obstacles=(), U0=None, V0=None, start: str = "consistent", frame_times=(), probes=None,
                 sample_every: int | None = None, callback=None, checkpoint=None, progress: bool = True,
                 energy_check: bool = True, energy_tol: float = 0.25, rest_tol: float = 1e-6,
                 safety: float = 0.9, backend: str = "auto", load=None,
                 _restart: dict | None = None) -> ExplicitResult:
    """Integrate the motion of ``model`` from t = 0 to ``t_end`` (module docstring).

    Parameters
    ----------
    model : :class:`rftstatic.model.Model` (supports, gravity in ``model.load``)
    t_end : end time [s]; the step is shortened slightly so that a whole number of steps ends there
    dt : step [s]; ``None``: ``safety * dt_crit`` from :func:`rftstatic.timestep.stable_time_step`.
        A step above that estimate runs with a logged warning.
    alpha : mass damping factor [1/s] (§4.6 uses 5)
    mass_scale : mass-scaling factor s [-] (§6 uses 100); the load is not scaled
    load : (N, 3) external nodal load [N] to use instead of ``model.load`` (e.g. a guided stage)
    obstacles : obstacles acting kinematically after every step (any type, §6.3)
    U0, V0 : (N, 3) initial displacements [m] and velocities [m/s] (default zero)
    start : ``"consistent"`` (v_(-1/2) = V0 - a_0 dt/2) or ``"given"`` (v_(-1/2) = V0)
    frame_times : times [s] at which to store the displacement field (first step at or after each)
    probes : node indices (P,) whose displacements are recorded at every sample
    sample_every : steps between history samples (default: about 2000 samples per run)
    callback : called as ``callback(state, sample)`` at every sample (``sample``: dict of the history
        values); returning True stops the run
    checkpoint : :class:`rftstatic.checkpoint.Checkpointer` saving the state at intervals
    progress : show a progress bar
    energy_check : raise :class:`InstabilityError` on energy growth or non-finite values
    energy_tol : allowed growth of the total energy, relative to the run's energy scale [-]
    rest_tol : kinetic / peak kinetic energy below which the sheet counts as at rest [-]
    safety : safety factor on the critical step [-]
    backend : force back end, ``"auto"``, ``"numpy"`` or ``"numba"``

    Returns
    -------
    ExplicitResult
    """
    if not t_end > 0:
        raise ValueError(f"t_end must be > 0 [s], got {t_end}")
    if alpha < 0:
        raise ValueError(f"mass damping alpha must be >= 0 [1/s], got {alpha}")
    if start not in ("consistent", "given"):
        raise ValueError(f'start must be "consistent" or "given", got "{start}"')
    wall0 = time.perf_counter()
    N = model.mesh.n_nodes
    free = model.free
    obstacles = tuple(obstacles) if not hasattr(obstacles, "signed_distance") else (obstacles,)
    mass = lumped_mass(model, mass_scale)
    kernel = ForceKernel(model, backend=backend)
    P = np.array(model.load if load is None else load, dtype=float)
    probes = np.zeros(0, dtype=np.int64) if probes is None else np.atleast_1d(np.asarray(probes, dtype=np.int64))
    if probes.size and (probes.min() < 0 or probes.max() >= N):
        raise ValueError(f"probe nodes must lie in 0..{N - 1}, got min {probes.min()}, max {probes.max()}")
    frame_times = np.sort(np.asarray(frame_times, dtype=float).ravel())

    if _restart is None:
        U = np.zeros((N, 3)) if U0 is None else np.array(U0, dtype=float)
        V = np.zeros((N, 3)) if V0 is None else np.array(V0, dtype=float)
        for name, arr in (("U0", U), ("V0", V)):
            if arr.shape != (N, 3):
                raise ValueError(f"{name} must have shape ({N}, 3), got {arr.shape}")
        V *= free
        estimate, dt = _choose_step(model, U, dt, alpha=alpha, mass_scale=mass_scale, safety=safety,
                                    needed=energy_check or dt is None)
        n_steps = max(1, int(np.ceil(t_end / dt - 1e-9)))
        dt = t_end / n_steps
        step = 0
        acc = {"damping": 0.0, "contact": 0.0, "total0": None, "scale": 0.0, "peak_kinetic": 0.0,
               "frame_index": 0}
        hist = {k: [] for k in HISTORY_KEYS}
        probe_hist, frames = [], []
        if start == "consistent":
            a0 = (P - kernel(U)) / mass[:, None] - alpha * V
            V = V - 0.5 * dt * a0 * free
    else:
        r = _restart
        U, V, step, dt, n_steps = r["U"], r["V_half"], r["step"], r["dt"], r["n_steps"]
        estimate, acc = r["estimate"], r["acc"]
        hist = {k: list(r["history"][k]) for k in HISTORY_KEYS}
        probe_hist = list(r["probes"])
        frames = list(r["frames"])
    if sample_every is None:
        sample_every = max(1, n_steps // 2000)
    sample_every = int(sample_every)
    check_every = min(sample_every, 50)
    Ufix = U.copy()
    fixed_any = bool((~free).any())
    minv = free / mass[:, None]  # (N, 3) inverse mass, zero on supported dofs
    damp = 1.0 - alpha * dt
    Vnew = np.empty_like(V)
    opts = {"t_end": t_end, "alpha": alpha, "mass_scale": mass_scale, "sample_every": sample_every,
            "energy_check": energy_check, "energy_tol": energy_tol, "rest_tol": rest_tol, "safety": safety,
            "frame_times": frame_times, "probe_nodes": probes, "backend": kernel.backend}
    bar = Progress(t_end, "explicit", unit=" s", enabled=progress)
    stopped = False
    n_contact = 0
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            while step < n_steps:
                t = step * dt
                sample = step % sample_every == 0
                check = sample or step % check_every == 0
                if check:
                    f, W = kernel(U, energy=True)
                else:
                    f = kernel(U)
                while acc["frame_index"] < len(frame_times) and t >= frame_times[acc["frame_index"]] - 1e-9 * dt:
                    frames.append((t, U.copy()))
                    acc["frame_index"] += 1
                # Eq. 20-21, with the damping force lagged half a step
                np.subtract(P, f, out=f)
                f *= minv
                np.multiply(V, damp, out=Vnew)
                f *= dt
                Vnew += f
                if alpha:
                    acc["damping"] += alpha * dt * float(np.einsum("n,ni,ni->", mass, V, Vnew))
                if check:
                    rec = _sample(t, U, V, Vnew, W, P, f, dt, mass, minv, free, acc)
                    if energy_check:
                        _check_energy(rec, step, dt, estimate, model, mass_scale, alpha, safety, energy_tol, acc)
                    if sample:
                        for k in HISTORY_KEYS:
                            hist[k].append(rec[k])
                        probe_hist.append(U[probes].copy())
                        bar.update(t, f"KE {rec['kinetic']:.3g} J")
                        if callback is not None and callback(State(t, U, V, step), rec):
                            stopped = True
                V, Vnew = Vnew, V
                # Eq. 22
                U += dt * V
                if obstacles:
                    n_contact = _contact(model, obstacles, U, V, mass, acc)
                    if fixed_any:
                        np.copyto(U, Ufix, where=~free)
                step += 1
                if stopped:
                    break
                if checkpoint is not None and checkpoint.due(step) and step < n_steps:
                    checkpoint.save(model, obstacles, State(step * dt, U, V, step), dt=dt, n_steps=n_steps,
                                    estimate=estimate, acc=acc, history=hist, probes=probe_hist,
                                    frames=frames, options=opts)
            t = step * dt
            # final sample at the end state
            f, W = kernel(U, energy=True)
            while acc["frame_index"] < len(frame_times) and t >= frame_times[acc["frame_index"]] - 1e-9 * dt:
                frames.append((t, U.copy()))
                acc["frame_index"] += 1
            g = (P - f) * minv * dt
            Vend = V * damp + g
            rec = _sample(t, U, V, Vend, W, P, g, dt, mass, minv, free, acc)
            if energy_check:
                _check_energy(rec, step, dt, estimate, model, mass_scale, alpha, safety, energy_tol, acc)
            if not hist["time"] or hist["time"][-1] != t:
                for k in HISTORY_KEYS:
                    hist[k].append(rec[k])
                probe_hist.append(U[probes].copy())
    finally:
        bar.close()
    history = {k: np.asarray(v, dtype=float) for k, v in hist.items()}
    wall = time.perf_counter() - wall0
    return ExplicitResult(
        U=U, V=V, t=t, steps=step, dt=dt, estimate=estimate, history=history,
        probes=np.asarray(probe_hist, dtype=float).reshape(len(probe_hist), len(probes), 3), frames=frames,
        time_at_rest=_time_at_rest(history, rest_tol), stopped=stopped, contact_nodes=n_contact,
        wall_time=wall, element_steps_per_second=model.mesh.n_elements * step / max(wall, 1e-12))


def _choose_step(model, U, dt, *, alpha, mass_scale, safety, needed):
    estimate = stable_time_step(model, U, mass_scale=mass_scale, alpha=alpha, safety=safety) if needed else None
    if dt is None:
        return estimate, estimate.dt
    if not dt > 0:
        raise ValueError(f"time step dt must be > 0 [s], got {dt}")
    if estimate is not None and dt > estimate.dt * (1 + 1e-3):  # Lanczos digits vary run to run
        log.warning("time step dt = %.4g s exceeds the stable estimate %.4g s (critical %.4g s, omega_max "
                    "%.4g rad/s); the run may become unstable", dt, estimate.dt, estimate.dt_crit,
                    estimate.omega_max)
    return estimate, float(dt)


def _sample(t, U, V, Vnew, W, P, g, dt, mass, minv, free, acc) -> dict:
    """History values at step n; ``g`` = dt M^-1 (P - F) on the free dofs."""
    vbar = 0.5 * (V + Vnew)
    kinetic = 0.5 * float(np.einsum("n,ni,ni->", mass, vbar, vbar))
    ext = float(np.einsum("ni,ni->", P, U))
    dissipated = acc["damping"]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(free, g / (dt * np.where(minv > 0, minv, 1.0)), 0.0)
    return {"time": t, "kinetic": kinetic, "potential": W - ext, "strain": W, "external_work": ext,
            "dissipated": dissipated, "contact_loss": acc["contact"], "total": kinetic + W - ext + dissipated,
            "residual": float(np.linalg.norm(r))}


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


def _contact(model, obstacles, U, V, mass, acc) -> int:
    from rftstatic.contact.kinematic import kinematic_contact

    X3 = model.X3
    x_new, v_new, n_active = kinematic_contact(obstacles, X3 + U, V)
    if n_active:
        # the projection along the normal must not give a supported dof a velocity (a node held in
        # x, y on a sphere would otherwise keep a spurious, never damped in-plane speed)
        v_new *= model.free
        k_before = float(np.einsum("n,ni,ni->", mass, V, V))
        k_after = float(np.einsum("n,ni,ni->", mass, v_new, v_new))
        acc["contact"] += 0.5 * (k_before - k_after)
        np.subtract(x_new, X3, out=U)
        V[...] = v_new
    return n_active


def _time_at_rest(history, rest_tol):
    kin = history["kinetic"]
    if len(kin) < 2 or not np.isfinite(kin).all() or kin.max() <= 0:
        return None
    moving = np.flatnonzero(kin > rest_tol * kin.max())
    if len(moving) == 0 or moving[-1] == len(kin) - 1:
        return None
    return float(history["time"][moving[-1] + 1])


