"""The at-rest test of the explicit runs: one definition for dynamics, dynamic relaxation (§6) and the
remeshed relaxation.

A sample of a run (kinetic energy ``T`` [J], out-of-balance force ``r = |P - F(U)|`` on the free dofs [N]) is
at rest under :class:`RestCriterion` ``(tol_kinetic, tol_force)`` when

    T <= tol_kinetic T_peak                  (T_peak: the largest T of the motion so far; T_peak = 0: T = 0)

and, where the criterion asks for the force too (``tol_force`` not None),

    r <= tol_force |P|                       (|P|: the external load on the free dofs)

with ``|P|`` replaced by the largest ``r`` so far for a sheet without load (the internal force of a perturbed
start); an unloaded sheet that has not moved (T_peak = 0) is at rest only at ``r = 0`` (a flat sheet).

:class:`AtRest` applies the test at every sample of a running motion (tracking the peaks; an explicit-run
callback); :meth:`RestCriterion.time_at_rest` reads a finished history. What velocity gives ``T`` is the
caller's: the explicit loop takes the mean of the two half-step velocities at step n, the remeshed relaxation
the half-step velocity at the end of a chunk.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ParameterError

__all__ = ["RestCriterion", "AtRest", "RELAX_MASS_SCALE", "RELAX_REST"]


@dataclass(frozen=True)
class RestCriterion:
    """When a moving sheet counts as at rest (module docstring).

    Attributes
    ----------
    tol_kinetic : kinetic energy / peak kinetic energy at rest [-], in (0, 1)
    tol_force : out-of-balance force / load at rest [-], > 0; None: the kinetic energy alone
    """

    tol_kinetic: float
    tol_force: float | None = None

    def __post_init__(self):
        if not (isinstance(self.tol_kinetic, (int, float)) and 0 < self.tol_kinetic < 1):
            raise ParameterError("tol_kinetic", f"must lie in (0, 1) (kinetic energy / its peak), got "
                                 f"{self.tol_kinetic!r}")
        if self.tol_force is not None and not (isinstance(self.tol_force, (int, float)) and self.tol_force > 0):
            raise ParameterError("tol_force", f"must be > 0 (out-of-balance force / load) or None, got "
                                 f"{self.tol_force!r}")

    @property
    def name(self) -> str:
        """``"kinetic"`` or ``"kinetic+force"``: what the criterion compares."""
        return "kinetic" if self.tol_force is None else "kinetic+force"

    def record(self) -> dict:
        """What a run's summary says of its rest test: criterion and tolerances."""
        return {"criterion": self.name, "tol_kinetic": self.tol_kinetic, "tol_force": self.tol_force}

    def holds(self, kinetic, peak_kinetic, residual=0.0, load_norm=0.0, peak_residual=0.0):
        """Whether samples are at rest: ``kinetic`` [J] against ``peak_kinetic`` [J] (the peak up to each
        sample), ``residual`` [N] against ``load_norm`` [N] (|P| on the free dofs), or for an unloaded sheet
        (``load_norm`` 0) against ``peak_residual`` [N] (the largest residual up to each sample). Scalars or
        arrays of samples (element-wise)."""
        kinetic, peak = np.asarray(kinetic, dtype=float), np.asarray(peak_kinetic, dtype=float)
        still = np.where(peak > 0, kinetic <= self.tol_kinetic * peak, kinetic == 0.0)
        if self.tol_force is not None:
            residual = np.asarray(residual, dtype=float)
            if load_norm > 0:
                still = still & (residual <= self.tol_force * load_norm)
            else:  # its own peak force measures an unloaded sheet; one that has not moved must have none
                still = still & (residual <= self.tol_force * np.asarray(peak_residual, dtype=float)) & (
                    (peak > 0) | (residual == 0.0))
        return bool(still) if still.ndim == 0 else still

    def time_at_rest(self, history, load_norm: float = 0.0) -> float | None:
        """The first sample time [s] of ``history`` (``time``, ``kinetic``, ``residual``: the explicit run's
        samples) from which every later sample is at rest; None when the last sample is not, when the
        motion never started (peak kinetic energy 0) or is not finite. ``load_norm``: |P| on the free dofs [N]
        (0: the force is measured against its running peak)."""
        kin = np.asarray(history["kinetic"], dtype=float)
        if len(kin) < 2 or not np.isfinite(kin).all() or kin.max() <= 0:
            return None
        res = np.asarray(history["residual"], dtype=float)
        rest = self.holds(kin, np.maximum.accumulate(kin), res, load_norm, np.maximum.accumulate(res))
        moving = np.flatnonzero(~rest)
        if len(moving) == 0 or moving[-1] == len(kin) - 1:
            return None
        return float(history["time"][moving[-1] + 1])


@dataclass
class AtRest:
    """:class:`RestCriterion` at every sample of a running motion, as an explicit-run callback
    ``(state, sample) -> bool`` (True: at rest).

    ``load_norm`` [N]: |P| on the free dofs. ``peak_kinetic`` [J] and ``peak_residual`` [N] are the peaks so far
    (updated at every sample; start them from an earlier run's peaks to resume).
    """

    criterion: RestCriterion
    load_norm: float
    peak_kinetic: float = 0.0
    peak_residual: float = 0.0

    def __call__(self, state, rec) -> bool:
        self.peak_kinetic = max(self.peak_kinetic, rec["kinetic"])
        self.peak_residual = max(self.peak_residual, rec["residual"])
        return self.criterion.holds(rec["kinetic"], self.peak_kinetic, rec["residual"], self.load_norm,
                                    self.peak_residual)

    def resume_from(self, history) -> None:
        """Take the peaks of the samples of an interrupted run (``history``: its ``kinetic``, ``residual``)."""
        kinetic = np.asarray(history["kinetic"], dtype=float)
        residual = np.asarray(history["residual"], dtype=float)
        self.peak_kinetic = max(self.peak_kinetic, float(kinetic.max())) if kinetic.size else self.peak_kinetic
        self.peak_residual = max(self.peak_residual, float(residual.max())) if residual.size else self.peak_residual


RELAX_MASS_SCALE = 100.0
"""Mass-scaling factor s of dynamic relaxation (§6 uses 100): the stable step grows by sqrt(s)
(:mod:`rftstatic.solvers.relaxation`; here, with its at-rest test, so that the options can name it without
importing the explicit solver)."""

RELAX_REST = RestCriterion(tol_kinetic=1e-8, tol_force=1e-4)
"""The at-rest test of dynamic relaxation by default: kinetic energy 1e-8 of its peak, out-of-balance force 1e-4
of the load."""
