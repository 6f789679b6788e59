"""The static solver's options, declared once (:mod:`rftstatic.optionspec`), split by concern.

A scene's ``[solver]`` table is flat (``solver.rtol``, ``solver.start``); each of its keys belongs to one
group here:

- :class:`NewtonOptions`: the Newton iteration at one load factor (:mod:`rftstatic.solvers.newton`,
  :mod:`rftstatic.solvers.mixed`, :mod:`rftstatic.solvers.krylov`) and its convergence test;
- :class:`IncrementOptions`: how the load factor is followed from 0 to 1 (load increments,
  :mod:`rftstatic.solvers.load_steps`, or arc length, :mod:`rftstatic.solvers.continuation`);
- :class:`RouteOptions`: how the solve starts (flat, perturbed, relaxed) and where it falls back
  (:mod:`rftstatic.solvers.static`).

:class:`StaticOptions` holds the three and the progress bar switch. The mesh sequence and the seeded
specimens are the app's (:class:`rftstatic.scenes.run_options.RunOptions`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from rftstatic.errors import ParameterError
from rftstatic.optionspec import check, declared, option

__all__ = ["IncrementOptions", "NewtonOptions", "RouteOptions", "StaticOptions", "MAX_PERTURBATION"]

SECTION = "solver"
"""The scene table of these options."""

MAX_PERTURBATION = 10.0
"""Largest ``solver.perturbation`` [element sizes]: the seeded lift tips a flat sheet off its bifurcation
(0.01-0.5 in the scenes and validations); a lift of many element sizes stretches the membrane instead, and
the relaxation from it becomes unstable (above about 200 its stable step collapses)."""


@dataclass(frozen=True, kw_only=True)
class NewtonOptions:
    """The Newton iteration at one load factor and its convergence test (scene keys ``solver.<name>``).

    The force test is ``|r| <= rtol |lam P|`` at full load (``intermediate_rtol`` on the way there), the
    energy test ``|d . r_new| <= etol W`` (:class:`~rftstatic.solvers.iteration.Criteria`).
    """

    iteration: str = option("mixed", "mixed (MIP Newton, the membrane stress carried as an unknown; an increment "
                            "it cannot converge is retried by the displacement iteration) or displacement "
                            "(Newton on the displacements alone, energy line search)",
                            choices=("mixed", "displacement"))
    max_iterations: int = option(30, "Newton iterations per load increment (twice at full load)", low=1, high=100_000)
    rtol: float = option(1e-6, "force tolerance at full load, relative to the applied load |P|",
                         low=0.0, high=1.0, open_low=True)
    intermediate_rtol: float = option(0.1, "looser force tolerance of the increments before full load",
                                      low=0.0, high=1.0, open_low=True)
    etol: float = option(1e-12, "energy tolerance: work of the residual on the last step over the work of the load",
                         low=0.0, high=1.0)
    max_step: float | None = option(None, "cap on the largest nodal move per Newton iteration (auto: 10 % of the "
                                    "sheet's diagonal)", kind="float", unit="length", low=0.0, open_low=True)
    line_search: bool = option(True, "Armijo backtracking on the energy (displacement iteration)")
    tangent: str = option("auto", "auto (exact, safeguarded when indefinite), exact or psd (compressive membrane "
                          "stress dropped)", choices=("auto", "exact", "psd"))
    linear_solver: str = option("auto", "linear solver of the Newton steps: auto, cholmod, scipy (SuperLU) or amg",
                                choices=("auto", "cholmod", "scipy", "amg"))
    step_solver: str = option("auto", "direct (a factorisation per step), krylov (CG preconditioned with the last "
                              "factorisation) or auto (krylov from 60,000 unknowns)",
                              choices=("auto", "direct", "krylov"))
    reuse_factorisation: int = option(2, "steps that may reuse a factorisation while the residual falls fast "
                                      "(modified Newton; 0: full Newton)", low=0, high=1000)

    def __post_init__(self):
        check(self, SECTION)


@dataclass(frozen=True, kw_only=True)
class IncrementOptions:
    """How the load factor goes from 0 to 1 (scene keys ``solver.<name>``)."""

    continuation: str = option("load", "load (load increments) or arc-length (path following with the tangent's "
                               "inertia tracked and branch switching)", choices=("load", "arc-length"))
    initial_increment: float = option(0.1, "first load-factor increment", low=0.0, high=1.0, open_low=True)
    min_increment: float = option(1e-5, "smallest increment before the solve gives up", low=0.0, high=1.0,
                                  open_low=True)
    max_increment: float = option(1.0, "largest increment", low=0.0, high=1.0, open_low=True)
    increment_displacement: float | None = option(
        None, "target largest nodal displacement per increment, which sizes the next increment (auto: 10 % of the "
        "sheet's diagonal)", kind="float", unit="length", low=0.0, open_low=True)
    max_load_steps: int = option(2000, "most load increments (or arc-length steps)", low=1, high=10_000_000)
    max_continuations: int = option(10, "snap-through continuations of an increment whose energy still falls "
                                    "when its iterations run out", low=0, high=10_000)

    def __post_init__(self):
        check(self, SECTION)
        if not self.min_increment <= self.initial_increment <= self.max_increment:
            names = (f"{SECTION}.{k}" for k in ("min_increment", "initial_increment", "max_increment"))
            raise ParameterError(f"{SECTION}.initial_increment", f"need {' <= '.join(names)}, got "
                                 f"{self.min_increment:g}, {self.initial_increment:g}, {self.max_increment:g}")



HANDOVER_KINETIC = 1e-2
"""Default ``solver.handover_kinetic`` without friction (:func:`rftstatic.solvers.friction_lag.handover_kinetic`).
Measured 2026-12-04 (main at 090f6ea, load 1.5-2, one run each, the same equilibria to 1e-14 in energy): against
1e-4, cusick-30 7.3 against 14.9 s (7,801 explicit steps and 66 Newton iterations against 13,701 and 9),
pedestal-round-50 37.2 against 49.2 s, pedestal-square-80 63.7 against 73.7 s, sphere-30 23.6 against 23.9 s:
Newton walks the last of the valley faster than the damped motion creeps down it. A garment's flat ring is still
folding at 1e-2 (skirt-circle 182 s against 134 s): the garment scenes keep 1e-4."""

HANDOVER_KINETIC_FRICTION = 1e-4
"""Default ``solver.handover_kinetic`` with Coulomb friction: the stick anchors are set where the relaxation hands
over, so it waits until the sliding has died down (a layer resting on another below its friction angle moved 5.2e-5 m
by an earlier handover at 1e-2, 1.5e-6 m at 1e-4; tests/contact/self_contact/test_self_friction_relax.py)."""

@dataclass(frozen=True, kw_only=True)
class RouteOptions:
    """How the static solve starts and where it falls back (scene keys ``solver.<name>``)."""

    start: str = option("load-steps", "load-steps (load-scaled Newton from the flat sheet), relax (dynamic "
                        "relaxation at full load, then Newton) or release (the sheet at full load on a support "
                        "plane lowered step by step, Newton at each)", choices=("load-steps", "relax", "release"))
    release_step: float = option(0.2, "release route: the support's first lowering step, in element sizes (x 1.5 "
                                 "after each converged step, up to 4 x; x 1/4 where Newton fails)", low=0.0, high=100.0,
                                 open_low=True)
    relax_fallback: bool = option(True, "try dynamic relaxation + Newton when the load steps fail")
    perturbation: float = option(0.0, "seeded out-of-plane start, in element sizes (0: the flat sheet)",
                                 low=0.0, high=MAX_PERTURBATION)
    seed: int = option(0, "seed of that perturbation (and of the fold guide's phase)", low=0, high=2**32 - 1)
    perturbation_folds: int = option(0, "0: random low Fourier modes; n: an n-fold lift about the sheet's centre",
                                     low=0, high=1000)
    guide_folds: int = option(0, "relax route: n-fold modulation of the weight in the first stage (0: none)",
                              low=0, high=1000)
    guide_weight: float = option(0.0, "relative amplitude of that modulation (it keeps the weight downward)",
                                 low=0.0, high=1.0, open_high=True)
    handover_kinetic: float | None = option(None, "relax route: the relaxation first hands over to Newton when the "
                                            "kinetic energy has fallen to this fraction of its peak (and the "
                                            "out-of-balance force below the weight; later handovers wait for 1e-4; "
                                            "auto: 1e-2, 1e-4 with Coulomb friction)", kind="float", low=0.0,
                                            high=1.0, open_low=True, open_high=True)
    relax_damping: str = option("viscous", "relax route: how the relaxation damps the motion: viscous (mass damping "
                                "critical for the pendulum mode), fire (FIRE velocity mixing and resets) or kinetic "
                                "(velocities zeroed at each peak of the kinetic energy) or viscous-fire (viscous until the kinetic "
                                "energy has fallen to 0.1 of its peak, FIRE after); with Coulomb friction always "
                                "viscous", choices=("viscous", "fire", "kinetic", "viscous-fire"))

    def __post_init__(self):
        check(self, SECTION)
        if self.guide_folds and self.guide_weight and self.start != "relax":
            raise ParameterError(f"{SECTION}.guide_folds", 'the fold guide acts on the dynamic relaxation: it needs '
                                 'solver.start = "relax"')


GROUPS = (NewtonOptions, IncrementOptions, RouteOptions)
"""The option groups of :class:`StaticOptions`, in the order of its fields."""

_OWNER = {name: (attr, cls) for attr, cls in (("newton", NewtonOptions), ("increments", IncrementOptions),
                                             ("route", RouteOptions)) for name, _, _ in declared(cls)}


@dataclass(frozen=True, kw_only=True)
class StaticOptions:
    """Options of :func:`~rftstatic.solvers.static.solve_static`: the three groups and the progress bar.

    Build it from groups, ``StaticOptions(newton=NewtonOptions(rtol=1e-8))``, or from flat keys as a
    scene's ``[solver]`` table has them, ``StaticOptions.from_keys(rtol=1e-8, start="relax")``;
    :meth:`replace` changes flat keys of a copy.
    """

    newton: NewtonOptions = field(default_factory=NewtonOptions)
    increments: IncrementOptions = field(default_factory=IncrementOptions)
    route: RouteOptions = field(default_factory=RouteOptions)
    progress: bool = True

    @classmethod
    def from_keys(cls, *, progress: bool = True, **keys) -> StaticOptions:
        """Options from flat ``[solver]`` keys in SI (each routed to its group); an unknown key is a
        :class:`ParameterError`."""
        return cls(progress=progress).replace(**keys)

    def replace(self, **keys) -> StaticOptions:
        """A copy with the flat keys ``keys`` changed (``progress`` included)."""
        groups = {}
        for key, value in keys.items():
            if key == "progress":
                continue
            if key not in _OWNER:
                raise ParameterError(f"{SECTION}.{key}", f"unknown option; known: {', '.join(sorted(_OWNER))}")
            attr, _ = _OWNER[key]
            groups.setdefault(attr, {})[key] = value
        changed = {attr: replace(getattr(self, attr), **values) for attr, values in groups.items()}
        return replace(self, **changed, progress=keys.get("progress", self.progress))

    def single_step(self) -> StaticOptions:
        """These options with the whole load in one increment (no displacement-sized increments)."""
        return self.replace(initial_increment=1.0, max_increment=1.0, increment_displacement=1e30)

    def from_state(self, *, relax_fallback: bool | None = None) -> StaticOptions:
        """Options for Newton at full load straight from a given state (a relaxed or transferred
        equilibrium): one load step, no relaxation start, no perturbation or fold guide.
        ``relax_fallback``: override the fallback to relaxation when that Newton fails."""
        fallback = self.route.relax_fallback if relax_fallback is None else relax_fallback
        return self.single_step().replace(start="load-steps", perturbation=0.0, guide_folds=0, relax_fallback=fallback)
