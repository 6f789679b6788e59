"""The one step that turns a scene's ``[solver]``, ``[dynamics]`` and ``[remesh]`` tables into SI options.

Every default is written once: the static solver's in :mod:`rftstatic.solvers.options` (the app's
``[solver]`` keys in :mod:`rftstatic.scenes.run_options`), the explicit and relaxation runs' in
:data:`DYNAMICS_DEFAULTS` (per analysis type), the remeshing drivers' in
:class:`~rftstatic.remesh.options.RemeshOptions`. A bad value raises :class:`~rftstatic.errors.SceneError`
naming the file, the key and the value.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, fields, replace

import numpy as np

from rftstatic.errors import ParameterError, SceneError
from rftstatic.optionspec import from_table
from rftstatic.remesh.options import RemeshOptions
from rftstatic.scenes.run_options import SOLVER_GROUPS, CantileverOptions, RunOptions
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.options import IncrementOptions, NewtonOptions, RouteOptions, StaticOptions
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE, RELAX_REST
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.step_plan import default_max_steps


def _solver_table(scene) -> dict:
    """The scene's ``[solver]`` table split over its declared groups, in SI
    (:func:`rftstatic.optionspec.from_table`)."""
    try:
        return from_table(SOLVER_GROUPS, dict(scene.get("solver", {})), "solver", scene.units)
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


def static_options(scene, *, progress=True) -> StaticOptions:
    """The scene's ``[solver]`` table as :class:`StaticOptions` (lengths in SI [m]); the app's keys (mesh
    sequence, seeds, membrane switch) are :func:`run_options`'."""
    table = _solver_table(scene)
    try:
        return StaticOptions(newton=NewtonOptions(**table[NewtonOptions]),
                             increments=IncrementOptions(**table[IncrementOptions]),
                             route=RouteOptions(**table[RouteOptions]), progress=progress)
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


def declared_run_options(scene) -> RunOptions:
    """The app's ``[solver]`` keys as the scene gives them (``levels`` None when ``"auto"``)."""
    try:
        return RunOptions(**_solver_table(scene)[RunOptions])
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


def run_options(scene) -> RunOptions:
    """The app's ``[solver]`` keys as :class:`~rftstatic.scenes.run_options.RunOptions`, ``levels = "auto"`` (the
    default) resolved to a number of meshes by the mesh's size (:func:`rftstatic.scenes.levels.auto_levels`)."""
    from rftstatic.scenes.levels import auto_levels

    run = declared_run_options(scene)
    if run.levels is None:
        run = replace(run, levels=auto_levels(scene))
    return run


DYNAMICS_DEFAULTS = {
    # true dynamics (§4.6): the real mass, no damping unless the scene asks, rest at 1e-3 of the peak
    "dynamic": {"alpha": ExplicitOptions.alpha, "mass_scale": ExplicitOptions.mass_scale, "rest_tolerance": 1e-3},
    # dynamic relaxation (§6): alpha = 5/s with mass scaling s = 100, rest at 1e-8 of the peak
    "relax": {"alpha": 5.0, "mass_scale": RELAX_MASS_SCALE, "rest_tolerance": RELAX_REST.tol_kinetic},
}
"""Defaults of ``[dynamics]`` that depend on the analysis type (scene units); the others are in
:class:`DynamicsOptions`."""


@dataclass(frozen=True)
class DynamicsOptions:
    """``[dynamics]`` of a ``dynamic`` or ``relax`` scene, in SI.

    Attributes
    ----------
    t_end : end time (for relax: the longest simulated time) [s]
    dt : time step [s]; None: 0.9 x the Lanczos stable step
    alpha : mass damping [1/s]
    mass_scale : mass-scaling factor s [-]
    frames : (F,) sorted times of the PNG frames [s]
    checkpoint_every : simulated time between checkpoints [s] (scene default 0.2 s)
    rest_tolerance : kinetic / peak kinetic energy at rest [-]
    force_tolerance : relax: out-of-balance force / load at rest [-]
    samples : regular states saved for the VTU series and the GIF
    compare_static : relax: report the difference from the static Newton solution
    max_steps : the step limit of the run (None: :func:`~rftstatic.solvers.explicit.default_max_steps` of
        the mesh, :meth:`step_limit`): a dynamic run that needs more steps to reach ``t_end`` is refused before
        it starts; a relaxation stops there, not at rest
    """

    t_end: float
    dt: float | None
    alpha: float
    mass_scale: float
    frames: np.ndarray
    checkpoint_every: float
    rest_tolerance: float
    force_tolerance: float = RELAX_REST.tol_force
    samples: int = 30
    compare_static: bool = False
    max_steps: int | None = None

    def step_limit(self, n_nodes: float) -> int:
        """The step limit on a mesh of ``n_nodes`` nodes: ``max_steps``, or its default for that mesh."""
        return int(self.max_steps) if self.max_steps is not None else default_max_steps(n_nodes)


DYNAMICS_RANGES = {
    "alpha": (0.0, 1e6, "mass damping [1/time]: up to 1e6 /s, a damping time of a microsecond; the stable step "
                        "2/alpha would be shorter still, and at 1e300 alpha^2 overflows"),
    "mass_scale": (1e-6, 1e6, "mass-scaling factor: 1 is true dynamics, relaxation uses 100; the stable step scales "
                              "with its square root, and beyond 1e6 either way it collapses"),
}
"""``[dynamics]`` keys with a range (low, high, why), ``alpha`` in SI [1/s], beyond ``positive``."""

MAX_SAMPLES = 1000
"""Most regular states ``dynamics.samples`` a run may save (a VTU file and a GIF frame each)."""

CHECKPOINT_EVERY_S = 0.2
"""Default simulated time between checkpoints [s]."""


def dynamics_options(scene) -> DynamicsOptions:
    """The scene's ``[dynamics]`` table checked and converted to SI, with the defaults filled in."""
    analysis = scene.analysis
    if analysis not in DYNAMICS_DEFAULTS:
        raise scene.error("analysis", f'"{analysis}" has no [dynamics]; use "dynamic" or "relax"')
    d = dict(scene.get("dynamics", {}))
    u = scene.units
    if "t_end" not in d:
        raise scene.error("dynamics.t_end", f"an analysis = \"{analysis}\" scene needs its end time "
                          "(dynamics.t_end, the longest simulated time for relax)")
    defaults = {f.name: f.default for f in fields(DynamicsOptions) if f.default is not MISSING}
    opts = {**defaults, **DYNAMICS_DEFAULTS[analysis], "checkpoint_every": CHECKPOINT_EVERY_S / u.time, "frames": []}
    opts.update(d)

    def positive(key, strict=True):
        v = opts[key]
        if not (isinstance(v, (int, float)) and (v > 0 if strict else v >= 0)):
            raise scene.error(f"dynamics.{key}", f"must be {'> 0' if strict else '>= 0'}, got {v!r}")

    for key in ("t_end", "mass_scale", "rest_tolerance", "force_tolerance", "checkpoint_every"):
        positive(key)
    positive("alpha", strict=False)
    for key, (lo, hi, why) in DYNAMICS_RANGES.items():
        scale = u.time if key == "alpha" else 1.0  # alpha's bounds are in 1/s, the scene's in 1/(its time unit)
        if not lo * scale <= opts[key] <= hi * scale:
            raise scene.error(f"dynamics.{key}", f"{opts[key]!r} must lie in [{lo * scale:g}, {hi * scale:g}] ({why})")
    try:
        RestCriterion(opts["rest_tolerance"], opts["force_tolerance"])
    except ParameterError as exc:
        key = {"tol_kinetic": "rest_tolerance", "tol_force": "force_tolerance"}[exc.key]
        raise scene.error(f"dynamics.{key}", exc.detail) from None
    if opts["max_steps"] is not None and not (isinstance(opts["max_steps"], int) and opts["max_steps"] >= 1):
        raise scene.error("dynamics.max_steps", f"must be a positive integer, got {opts['max_steps']!r}")
    if opts.get("dt") is not None:
        positive("dt")
    if not 0 <= opts["samples"] <= MAX_SAMPLES:
        raise scene.error("dynamics.samples", f"must lie in [0, {MAX_SAMPLES}] (each is a VTU file), got "
                          f"{opts['samples']}")
    frames = opts["frames"]
    if not all(isinstance(f, (int, float)) and 0 <= f <= opts["t_end"] for f in frames):
        raise scene.error("dynamics.frames", f"expected times in [0, t_end = {opts['t_end']}], got {frames!r}")
    t = u.time
    return DynamicsOptions(
        t_end=opts["t_end"] * t, dt=None if opts.get("dt") is None else opts["dt"] * t, alpha=opts["alpha"] / t,
        mass_scale=float(opts["mass_scale"]), frames=np.array(sorted(set(float(f) * t for f in frames))),
        checkpoint_every=opts["checkpoint_every"] * t, rest_tolerance=float(opts["rest_tolerance"]),
        force_tolerance=float(opts["force_tolerance"]), samples=int(opts["samples"]),
        compare_static=bool(opts["compare_static"]),
        max_steps=None if opts["max_steps"] is None else int(opts["max_steps"]))


def remesh_options(scene) -> RemeshOptions:
    """The scene's ``[remesh]`` table checked against its declarations (:class:`~rftstatic.remesh.options.RemeshOptions`)
    and converted to SI (:func:`rftstatic.optionspec.from_table`)."""
    try:
        table = from_table((RemeshOptions,), dict(scene.get("remesh", {})), "remesh", scene.units)
        return RemeshOptions(**table[RemeshOptions])
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


def seed_count(scene) -> int:
    """``solver.seeds``: how many seeded starts a static drape runs (a lab's specimens), checked; 1 by default.
    More than one needs a seeded start (``solver.perturbation`` > 0)."""
    n = declared_run_options(scene).seeds
    if n > 1 and not static_options(scene).route.perturbation > 0:
        raise scene.error("solver.seeds", f"{n} seeded starts need a seeded lift: give solver.perturbation > 0 "
                          "(e.g. 0.01 element sizes), or every start is the same")
    if n > 1 and scene.analysis != "static":
        raise scene.error("solver.seeds", f"{n!r}: seeded starts are run by the static analysis only")
    return n


def cantilever_options(scene) -> CantileverOptions:
    """The scene's ``[cantilever]`` table checked (:class:`~rftstatic.scenes.run_options.CantileverOptions`), the
    angle in radians."""
    try:
        table = from_table((CantileverOptions,), dict(scene.get("cantilever", {})), "cantilever", scene.units)
        return CantileverOptions(**table[CantileverOptions])
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None


__all__ = ["run_options", "declared_run_options", "seed_count", "cantilever_options", "CantileverOptions",
           "static_options", "dynamics_options", "remesh_options", "DynamicsOptions", "DYNAMICS_DEFAULTS", "SceneError"]
