"""The one step that turns a scene's ``[solver]``, ``[dynamics]`` and ``[remesh]`` tables into SI options.

Every default is written once: the static solver's in :class:`~rftstatic.solvers.newton.StaticOptions`,
the explicit and relaxation runs' in :data:`DYNAMICS_DEFAULTS` (per analysis type), the remeshing
drivers' in :class:`~rftstatic.remesh.options.RemeshOptions`. A bad value raises
:class:`~rftstatic.errors.SceneError` naming the file, the key and the value.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, fields

import numpy as np

from rftstatic.errors import ParameterError, SceneError
from rftstatic.remesh.options import RemeshOptions
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.newton import StaticOptions
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE, RELAX_REST
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.step_plan import default_max_steps

_STATIC_KEYS = {f.name for f in fields(StaticOptions)} - {"progress"}
_STATIC_LENGTH_KEYS = ("max_step", "increment_displacement")
_STATIC_COUNTS = {"seed": 0, "max_continuations": 0, "reuse_factorisation": 0, "max_load_steps": 1}
"""``[solver]`` integers and their least value (a seed: numpy's generators take none below 0)."""
MAX_PERTURBATION = 10.0
"""Largest ``solver.perturbation`` [element sizes]: the seeded lift tips a flat sheet off its bifurcation
(0.01-0.5 in the scenes and validations); a lift of many element sizes stretches the membrane instead, and
the relaxation from it becomes unstable (above about 200 its stable step collapses)."""


def _levels(scene, value) -> int:
    """``solver.levels`` as a count: an integer as given (checked by the mesh sequence), ``"auto"`` by the
    mesh's size."""
    from rftstatic.scenes.levels import auto_levels

    if value == "auto":
        return auto_levels(scene)
    if isinstance(value, str):
        raise scene.error("solver.levels", f'"{value}" is not a number of meshes; give an integer >= 1 or "auto" '
                          "(from 15,000 nodes as many as bring the coarsest mesh to 3,000 or fewer, else 1)")
    return value


def static_options(scene, *, progress=True) -> StaticOptions:
    """The scene's ``[solver]`` table as :class:`StaticOptions` (lengths in SI [m]); ``solver.levels`` ``"auto"``
    (the default) resolved to a number of meshes (:func:`rftstatic.scenes.levels.auto_levels`).

    ``solver.membrane`` is a model switch (:func:`rftstatic.scenes.build.build_model`), not a solver
    option, and is left out here.
    """
    s = dict(scene.get("solver", {}))
    s.pop("membrane", None)
    s.pop("seeds", None)
    u = scene.units.length
    for key in _STATIC_LENGTH_KEYS:
        if key in s:
            s[key] = s[key] * u
    unknown = set(s) - _STATIC_KEYS
    if unknown:
        raise scene.error("solver", f"unknown option(s) {sorted(unknown)}")
    for key, least in _STATIC_COUNTS.items():
        if key in s and s[key] < least:
            raise scene.error(f"solver.{key}", f"{s[key]!r} must be an integer >= {least}")
    s["levels"] = _levels(scene, s.get("levels", "auto"))
    lift = s.get("perturbation", 0.0)
    if not 0.0 <= lift <= MAX_PERTURBATION:
        raise scene.error("solver.perturbation", f"{lift!r} must lie in [0, {MAX_PERTURBATION:g}] (element sizes of "
                          "a seeded lift that tips the sheet off its bifurcation; a larger lift stretches the "
                          "membrane instead)")
    try:
        return StaticOptions(**s, progress=progress)
    except (TypeError, ValueError) as exc:
        raise scene.error("solver", str(exc)) from None


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


REMESH_LENGTH_KEYS = ("const", "h_lower", "h_upper", "kappa_h2_max")
"""``[remesh]`` keys that are lengths (scene units in the file, SI in :class:`RemeshOptions`)."""


def remesh_options(scene) -> RemeshOptions:
    """The scene's ``[remesh]`` table with defaults, checked, as :class:`~rftstatic.remesh.options.RemeshOptions`
    in SI."""
    r = dict(scene.get("remesh", {}))
    for key in ("const", "h_lower", "h_upper"):
        if key not in r:
            raise scene.error(f"remesh.{key}", f"a [remesh] table needs {key} (Eq. 29, scene length units)")
    try:
        RemeshOptions(**r)  # checked in the scene's units, which its messages then quote
    except ParameterError as exc:
        raise scene.error(f"remesh.{exc.key}", exc.detail) from None
    except TypeError as exc:  # a key the schema let through that the options do not know
        raise scene.error("remesh", str(exc)) from None
    u = scene.units.length
    return RemeshOptions(**{k: (v * u if k in REMESH_LENGTH_KEYS and v is not None else v) for k, v in r.items()})


@dataclass(frozen=True)
class CantileverOptions:
    """``[cantilever]`` of a cantilever-tester scene (Peirce; ASTM D1388, BS 3356).

    Attributes
    ----------
    angle : the tester's plane below the horizontal [rad] (41.5 deg)
    growth : overhang factor per step while the tip is above the plane [-]
    tolerance : relative change of the overhang at which the root find stops [-]
    max_solves : most static solves (growth steps and root-find steps together)
    """

    angle: float = float(np.radians(41.5))
    growth: float = 1.15
    tolerance: float = 1e-7
    max_solves: int = 60


def seed_count(scene) -> int:
    """``solver.seeds``: how many seeded starts a static drape runs (a lab's specimens), checked; 1 by default.
    More than one needs a seeded start (``solver.perturbation`` > 0)."""
    n = scene.get("solver.seeds", 1)
    if not (isinstance(n, int) and 1 <= n <= 100):
        raise scene.error("solver.seeds", f"{n!r} must be an integer in [1, 100] (seeded starts, one per specimen)")
    if n > 1 and not scene.get("solver.perturbation", 0.0) > 0:
        raise scene.error("solver.seeds", f"{n} seeded starts need a seeded lift: give solver.perturbation > 0 "
                          "(e.g. 0.01 element sizes), or every start is the same")
    if n > 1 and scene.analysis != "static":
        raise scene.error("solver.seeds", f"{n!r}: seeded starts are run by the static analysis only")
    return n


def cantilever_options(scene) -> CantileverOptions:
    """The scene's ``[cantilever]`` table checked, angles in radians."""
    c = dict(scene.get("cantilever", {}))
    if "angle" in c and not 1.0 <= c["angle"] <= 80.0:
        raise scene.error("cantilever.angle", f"{c['angle']!r} must lie in [1, 80] deg (the tester's plane below "
                          "the horizontal: 41.5 in ASTM D1388 and BS 3356)")
    if "growth" in c and not 1.0 < c["growth"] <= 2.0:
        raise scene.error("cantilever.growth", f"{c['growth']!r} must lie in (1, 2] (overhang factor per step)")
    if "tolerance" in c and not 1e-12 <= c["tolerance"] <= 1e-2:
        raise scene.error("cantilever.tolerance", f"{c['tolerance']!r} must lie in [1e-12, 1e-2]")
    if "max_solves" in c and not c["max_solves"] >= 3:
        raise scene.error("cantilever.max_solves", f"{c['max_solves']!r} must be an integer >= 3")
    if "angle" in c:
        c["angle"] = float(np.radians(c["angle"]))
    return CantileverOptions(**c)


__all__ = ["seed_count", "cantilever_options", "CantileverOptions", "static_options", "dynamics_options",
           "remesh_options", "DynamicsOptions",
           "DYNAMICS_DEFAULTS", "SceneError"]
