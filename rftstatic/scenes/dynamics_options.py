"""The ``[dynamics]`` table of a ``dynamic`` or ``relax`` scene, declared once (:mod:`rftstatic.optionspec`).

Each key is a field of :class:`DynamicsOptions` with its type, unit, range (SI), default and help; the scene
schema, ``python -m rftstatic options dynamics`` and the scene -> SI conversion
(:func:`rftstatic.scenes.options.dynamics_options`) are generated from it. Two things are not plain
declarations:

* the defaults that depend on the analysis type: the declared default is the true-dynamics one, and
  :data:`DYNAMICS_DEFAULTS` names the few a relaxation changes (the help of those keys says so);
* ``frames``, a list of times each in [0, t_end] (a bound given by another key): a plain field, its schema
  entry written by hand (help :data:`FRAMES_HELP`) and checked where the scene is read.

This module imports nothing heavy (the scene schema imports it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rftstatic.optionspec import REQUIRED, check, option
from rftstatic.solvers.rest import RELAX_MASS_SCALE, RELAX_REST

__all__ = ["DynamicsOptions", "DYNAMICS_DEFAULTS", "FRAMES_HELP", "MAX_SAMPLES"]

MAX_SAMPLES = 1000
"""Most regular states ``dynamics.samples`` a run may save (a VTU file and a GIF frame each)."""

RELAX_ALPHA = 5.0
"""Mass damping of a relaxation by default [1/time of the scene] (§6: alpha = 5/s with s = 100)."""

DYNAMICS_DEFAULTS = {
    # true dynamics (§4.6): the declared defaults: the real mass, no damping unless the scene asks, rest at 1e-3
    "dynamic": {},
    # dynamic relaxation (§6): alpha = 5/s with mass scaling s = 100, rest at 1e-8 of the peak
    "relax": {"alpha": RELAX_ALPHA, "mass_scale": RELAX_MASS_SCALE, "rest_tolerance": RELAX_REST.tol_kinetic},
}
"""Per analysis type, the ``[dynamics]`` defaults that differ from the declared ones (scene units)."""

FRAMES_HELP = "times of the PNG frames [time], each in [0, t_end] (default none)"
"""Help of ``dynamics.frames`` (a list, not a declared option: see the module's docstring)."""


@dataclass(frozen=True, kw_only=True)
class DynamicsOptions:
    """``[dynamics]`` of a ``dynamic`` or ``relax`` scene, in SI; ``frames``: (F,) sorted times of the PNG
    frames [s]. A bad value raises :class:`~rftstatic.errors.ParameterError` naming ``dynamics.<field>``."""

    t_end: float = option(REQUIRED, "end time (relax: the longest simulated time)", kind="float", unit="time",
                          low=0.0, open_low=True)
    dt: float | None = option(None, 'time step ("auto": 0.9 x the Lanczos stable step)', kind="float", unit="time",
                              low=0.0, open_low=True)
    alpha: float = option(0.0, f"mass damping (relax: {RELAX_ALPHA:g} by default); up to 1e6 /s, beyond which the "
                          "stable step 2/alpha collapses", unit="rate", low=0.0, high=1e6)
    mass_scale: float = option(1.0, f"mass-scaling factor s (relax: {RELAX_MASS_SCALE:g} by default); the stable "
                               "step scales with its square root", low=1e-6, high=1e6)
    checkpoint_every: float = option(0.2, "simulated time between checkpoints", unit="time", low=0.0, open_low=True)
    rest_tolerance: float = option(1e-3, "kinetic / peak kinetic energy at which the sheet is at rest (relax: "
                                   f"{RELAX_REST.tol_kinetic:g} by default)", low=0.0, high=1.0, open_low=True,
                                   open_high=True)
    force_tolerance: float = option(RELAX_REST.tol_force, "relax: out-of-balance force / load at which the sheet "
                                    "is at rest", low=0.0, open_low=True)
    samples: int = option(30, "regular states saved for the VTU series and the GIF (each a VTU file)", low=0,
                          high=MAX_SAMPLES)
    compare_static: bool = option(False, "relax: report the difference from the static Newton solution")
    max_steps: int | None = option(None, 'step limit: a dynamic run needing more is refused, a relaxation stops '
                                   'there ("auto": 10^4 sqrt(nodes), 5e4..1e7)', kind="int", low=1)
    frames: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        check(self, "dynamics")

    def step_limit(self, n_nodes: float) -> int:
        """The step limit on a mesh of ``n_nodes`` nodes: ``max_steps``, or its default for that mesh
        (:func:`~rftstatic.solvers.step_plan.default_max_steps`)."""
        from rftstatic.solvers.step_plan import default_max_steps

        return int(self.max_steps) if self.max_steps is not None else default_max_steps(n_nodes)
