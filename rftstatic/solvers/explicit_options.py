"""The options of one explicit run (:func:`rftstatic.solvers.explicit.run_explicit`), declared once."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.element.explicit_force import BACKENDS
from rftstatic.errors import ParameterError
from rftstatic.solvers.damping import DAMPINGS, make_law
from rftstatic.solvers.step_plan import MAX_STEPS_KEY
from rftstatic.solvers.timestep import SAFETY

__all__ = ["ExplicitOptions", "STARTS"]

STARTS = ("consistent", "given")
"""How an explicit run starts: ``v_(-1/2) = V0 - a_0 dt / 2`` (exact for a constant acceleration), or V0 itself."""


def _number(key, value, *, least=0.0, strict=True, most=None) -> None:
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) and np.isfinite(value)
    ok = ok and (value > least if strict else value >= least) and (most is None or value <= most)
    if not ok:
        bound = f"{'>' if strict else '>='} {least:g}" + ("" if most is None else f" and <= {most:g}")
        raise ParameterError(key, f"must be a finite number {bound}, got {value!r}")


def _count(key, value, *, optional=True) -> None:
    if value is None and optional:
        return
    if not (isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 1):
        raise ParameterError(key, f"must be a positive integer{' or None' if optional else ''}, got {value!r}")


@dataclass(frozen=True, kw_only=True)
class ExplicitOptions:
    """How :func:`~rftstatic.solvers.explicit.run_explicit` integrates (Eq. 16-22). A bad value raises
    :class:`~rftstatic.errors.ParameterError` naming the field.

    Attributes
    ----------
    t_end : end time [s], > 0; the step is shortened slightly so that a whole number of steps ends there
    dt : step [s]; None: ``safety`` x the critical step (:func:`~rftstatic.solvers.step_plan.plan_steps`); a
        step above the stable estimate runs with a logged warning
    alpha : mass damping factor [1/s], >= 0 (§4.6 uses 5); 0 with a velocity law (``damping``)
    damping : ``"viscous"`` (the mass damping ``alpha``), ``"fire"`` or ``"kinetic"``: a velocity law of
        :mod:`rftstatic.solvers.damping` (FIRE, kinetic damping) on the undamped motion
    mass_scale : mass-scaling factor s [-], > 0 (§6 uses 100); the load is not scaled
    start : ``"consistent"`` (v_(-1/2) = V0 - a_0 dt/2) or ``"given"`` (v_(-1/2) = V0)
    sample_every : steps between history samples [-] (None: about 2000 samples per run)
    energy_check : raise :class:`~rftstatic.errors.InstabilityError` on energy growth or non-finite values
        (and estimate the stable step also when ``dt`` is given)
    energy_tol : allowed growth of the total energy, relative to the run's energy scale [-], > 0
    rest_tol : kinetic / peak kinetic energy at rest [-], in (0, 1), for the result's ``time_at_rest``
        (:class:`~rftstatic.solvers.rest.RestCriterion` on the kinetic energy)
    safety : factor on the critical step [-], in (0, 1]
    backend : force back end, ``"auto"``, ``"numpy"`` or ``"numba"``
    max_steps : step limit [-] (None: :data:`~rftstatic.solvers.step_plan.MAX_STEPS`): a longer run, or one
        whose stable step collapsed, is refused before its first step (:class:`~rftstatic.errors.StepLimitError`)
    max_steps_name : the option that sets ``max_steps``, named in that refusal
    progress : show a progress bar
    """

    t_end: float
    dt: float | None = None
    alpha: float = 0.0
    damping: str = DAMPINGS[0]
    mass_scale: float = 1.0
    start: str = STARTS[0]
    sample_every: int | None = None
    energy_check: bool = True
    energy_tol: float = 0.25
    rest_tol: float = 1e-6
    safety: float = SAFETY
    backend: str = BACKENDS[0]
    max_steps: int | None = None
    max_steps_name: str = MAX_STEPS_KEY
    progress: bool = True

    def __post_init__(self):
        _number("t_end", self.t_end)
        if self.dt is not None:
            _number("dt", self.dt)
        _number("alpha", self.alpha, strict=False)
        make_law(self.damping)
        if self.damping in DAMPINGS[1:3] and self.alpha != 0:
            raise ParameterError("alpha", f"must be 0 with damping = {self.damping!r} (its velocity law damps the "
                                 f"motion), got {self.alpha!r}")
        _number("mass_scale", self.mass_scale)
        if self.start not in STARTS:
            raise ParameterError("start", f'"{self.start}" is unknown; use one of {", ".join(STARTS)}')
        _count("sample_every", self.sample_every)
        _number("energy_tol", self.energy_tol)
        _number("rest_tol", self.rest_tol, most=1.0)
        _number("safety", self.safety, most=1.0)
        if self.backend not in BACKENDS:
            raise ParameterError("backend", f'"{self.backend}" is unknown; use one of {", ".join(BACKENDS)}')
        _count("max_steps", self.max_steps)
