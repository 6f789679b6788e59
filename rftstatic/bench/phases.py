"""Where a run's wall time goes, by phase: timers wrapped around a few functions, installed only while profiling.

:class:`PhaseClock` keeps a stack of phases; :meth:`PhaseClock.install` replaces each function or method of
:data:`TARGETS` (by module and qualified name) with a wrapper that enters the target's phase on the way in and
leaves it on the way out, and :meth:`PhaseClock.uninstall` puts the originals back. Time is attributed to the
innermost phase (exclusive time): the tangent assembly's self-contact pair forces count as pair forces, not
as assembly. Between :meth:`start` and :meth:`stop` every instant belongs to exactly one phase (the bottom
of the stack is :data:`OTHER`), so the phases add up to the total wall time by construction.

Special cases:

- *opaque* phases (the stability check, the summary measures, output writing, checkpoint writes) keep what
  they call: the tangent and the factorisation of the stability check are its cost, not assembly's;
- the *piercing* phases (numba compile and cache loads, imports) are split out everywhere, also from
  opaque phases: numba's ``Dispatcher._compile_for_args`` and ``compile``, and every module import
  (``importlib._bootstrap._find_and_load``, which the interpreter looks up at each import of a module not
  yet in ``sys.modules``; numba, llvmlite and ``*._kernels_numba`` modules count as numba);
- generator functions (the routes, the explicit loop: they pause after every step) are timed per resumption,
  so a driver's work between two steps (a checkpoint write) is not theirs;
- CHOLMOD: ``sksparse.cholmod.analyze`` is the symbolic analysis and returns the factor wrapped, so that its
  ``cholesky_inplace`` counts as a numeric factorisation and its solves (``factor(b)``, ``solve_A``) as
  back-substitutions (the CG preconditioner of the Krylov step is such a solve). SuperLU and AMG have no such
  split: their ``solve`` is a factorisation (with its first solve), ``resolve`` a back-substitution.

Modules not yet imported when profiling starts are patched right after their import (the import hook), and
names bound by ``from module import name`` in already imported ``rftstatic`` modules are rebound too.
Overhead: two ``perf_counter`` calls and a few list operations per wrapped call (about a microsecond); the
explicit loop's per-step calls dominate it (:mod:`rftstatic.bench.profile` measures it against an
unprofiled run).
"""

from __future__ import annotations

import functools
import importlib
import inspect
import sys
import time
from collections import Counter, defaultdict

FORCE = "explicit: force kernel"
STEP = "explicit: rest of step"
ESTIMATE = "explicit: stable step estimate"
TANGENT = "tangent assembly"
RESIDUAL = "residual / energy evaluations"
FACTOR = "factorisation (numeric)"
ANALYSIS = "factorisation (symbolic analysis)"
BACKSUB = "back-substitution (incl. CG preconditioner)"
BROAD = "contact: broad phase (candidate lists)"
OBSTACLE = "contact: obstacle forces (penalty, kinematic)"
PAIRS = "self-contact: pair lists (broad phase, rebuilds)"
BOUND = "self-contact: step bound"
PAIR_FORCES = "self-contact: pair forces"
STABILITY = "stability check"
BUILD = "scene, mesh and model build"
REMESH = "remeshing (size field, mesher, transfer)"
POST = "summary measures"
OUTPUT = "output writing"
CHECKPOINT = "checkpoint writes"
NUMBA = "numba compile / cache load / import"
IMPORTS = "imports (other modules)"
OTHER = "other"

PHASES = (FORCE, STEP, ESTIMATE, TANGENT, RESIDUAL, FACTOR, ANALYSIS, BACKSUB, BROAD, OBSTACLE, PAIRS, BOUND,
          PAIR_FORCES, STABILITY, BUILD, REMESH, POST, OUTPUT, CHECKPOINT, NUMBA, IMPORTS, OTHER)
"""Every phase, in the order of the tables."""

OPAQUE = frozenset({STABILITY, POST, OUTPUT, CHECKPOINT})
PIERCING = frozenset({NUMBA, IMPORTS})

# (module, qualified name, phase, event counted at every call or None)
TARGETS = (
    ("rftstatic.element.explicit_force", "ForceKernel.__call__", FORCE, "force kernel calls"),
    ("rftstatic.solvers.explicit", "explicit_steps", STEP, None),
    ("rftstatic.solvers.explicit", "_Loop.begin", STEP, None),
    ("rftstatic.solvers.explicit", "_Loop.advance", STEP, None),
    ("rftstatic.solvers.relaxation", "relax_steps", STEP, None),  # its rest test between steps
    ("rftstatic.solvers.step_plan", "plan_steps", ESTIMATE, None),
    ("rftstatic.solvers.timestep", "stable_time_step", ESTIMATE, None),
    ("rftstatic.model.model", "Model.tangent", TANGENT, "tangent assemblies"),
    ("rftstatic.model.model", "Model.energies", RESIDUAL, None),
    ("rftstatic.model.model", "Model.internal_force", RESIDUAL, None),
    ("rftstatic.model.model", "Model.residual", RESIDUAL, None),
    ("rftstatic.solvers.linear", "CholmodSolver.solve", FACTOR, None),
    ("rftstatic.solvers.linear", "ScipySolver.solve", FACTOR, "numeric factorisations"),
    ("rftstatic.solvers.linear", "AmgSolver.solve", FACTOR, "numeric factorisations"),
    ("rftstatic.solvers.inertia", "InertiaSolver.factor", FACTOR, None),
    ("rftstatic.solvers.linear", "CholmodSolver.resolve", BACKSUB, None),
    ("rftstatic.solvers.linear", "ScipySolver.resolve", BACKSUB, "back-substitutions"),
    ("rftstatic.solvers.linear", "AmgSolver.resolve", BACKSUB, "back-substitutions"),
    ("rftstatic.solvers.inertia", "InertiaFactor.solve", BACKSUB, None),
    ("sksparse.cholmod", "analyze", ANALYSIS, "symbolic analyses"),  # returns a _TimedFactor
    ("rftstatic.contact.candidates", "CandidateList.lookup", BROAD, None),
    ("rftstatic.contact.candidates", "CandidateList.refresh", BROAD, "candidate list refreshes"),
    ("rftstatic.contact.penalty", "PenaltyContact.evaluate", OBSTACLE, None),
    ("rftstatic.contact.penalty", "PenaltyContact.energy", OBSTACLE, None),
    ("rftstatic.contact.penalty", "PenaltyContact.force", OBSTACLE, None),
    ("rftstatic.contact.penalty", "PenaltyContact.tangent_blocks", OBSTACLE, None),
    ("rftstatic.contact.kinematic", "kinematic_contact", OBSTACLE, None),
    ("rftstatic.contact.self_contact.broad_phase", "find_pairs", PAIRS, "self-contact pair searches"),
    ("rftstatic.contact.self_contact.broad_phase", "PairCache.pairs", PAIRS, None),
    ("rftstatic.contact.self_contact.near_pairs", "NearPairCache.pairs", PAIRS, None),
    ("rftstatic.contact.self_contact.near_pairs", "NearPairCache.current", PAIRS, None),
    ("rftstatic.contact.self_contact.near_pairs", "NearPairCache.rebuild", PAIRS, "self-contact pair cache rebuilds"),
    ("rftstatic.contact.self_contact.law", "SelfContact.max_step_fraction", BOUND, None),
    ("rftstatic.contact.self_contact.step_filter", "StepFilter.__call__", BOUND, None),
    ("rftstatic.contact.self_contact.law", "SelfContact.evaluate", PAIR_FORCES, None),
    ("rftstatic.contact.self_contact.law", "SelfContact.near_force", PAIR_FORCES, None),
    ("rftstatic.contact.self_contact.law", "SelfContact.evaluate_pairs", PAIR_FORCES, None),
    ("rftstatic.solvers.static", "_positive_definite", STABILITY, "definiteness checks"),
    ("rftstatic.solvers.static", "_check_stability", STABILITY, None),
    ("rftstatic.scenes.schema", "load_scene", BUILD, None),
    ("rftstatic.scenes.build", "build_model", BUILD, None),
    ("rftstatic.model.model", "Model.__init__", BUILD, "models built"),
    ("rftstatic.remesh.adapt", "adapt_mesh", REMESH, "remeshes"),
    ("rftstatic.remesh.adapt", "transfer_state", REMESH, None),
    ("rftstatic.app.static", "static_summary", POST, None),
    ("rftstatic.app.dynamic", "_summary", POST, None),
    ("rftstatic.io.results", "write_outputs", OUTPUT, None),
    ("rftstatic.app.dynamic", "_write", OUTPUT, None),
    ("rftstatic.solvers.checkpoint", "CheckpointSaver._write", CHECKPOINT, "checkpoint writes"),
    ("numba.core.dispatcher", "Dispatcher._compile_for_args", NUMBA, "numba compilations / cache loads"),
    ("numba.core.dispatcher", "Dispatcher.compile", NUMBA, None),
)

NUMBA_MODULES = ("numba", "llvmlite")


class PhaseClock:
    """Exclusive wall time [s] and entries of every phase between :meth:`start` and :meth:`stop`.

    ``seconds[phase]``: time with ``phase`` innermost; ``calls[phase]``: entries into ``phase`` from another
    phase (a nested call of the same phase is not counted again); ``events[name]``: calls of the targets
    that count one (numeric factorisations, back-substitutions, ...), inside opaque phases too;
    ``imports[package]``: wall time of importing the package's modules, each without the modules it imports
    (what the two import phases are made of; ``rftstatic`` by subpackage).
    """

    def __init__(self):
        self.seconds = defaultdict(float)
        self.calls = Counter()
        self.events = Counter()
        self.imports = defaultdict(float)  # package -> seconds importing its modules (their own code)
        self._nested_imports = []
        self.running = False
        self.entries = 0  # phase entries (wrapped calls that took the clock), for the cost estimate
        self._stack = []
        self._opaque = 0
        self._mark = 0.0
        self._patched = []  # (owner, name, original, had_own_attribute)
        self._pending = {}  # module name -> targets not installed yet
        self._find_and_load = None

    # --- the stack ----------------------------------------------------------------------------------
    def start(self) -> None:
        self.seconds.clear()
        self.calls.clear()
        self.events.clear()
        self.imports.clear()
        self._stack = [OTHER]
        self.entries = 0
        self._opaque = 0
        self.running = True
        self._mark = time.perf_counter()

    def stop(self) -> float:
        """Stop; return the total [s] (the sum of :attr:`seconds`)."""
        now = time.perf_counter()
        self.seconds[self._stack[-1]] += now - self._mark
        self._stack = []
        self.running = False
        return sum(self.seconds.values())

    def _claims(self, phase) -> bool:
        """Whether a call of ``phase`` now enters it (not while profiling is off or an opaque phase holds)."""
        return self.running and (self._opaque == 0 or phase in PIERCING)

    def enter(self, phase) -> None:
        self.entries += 1
        now = time.perf_counter()
        top = self._stack[-1]
        self.seconds[top] += now - self._mark
        if top != phase:
            self.calls[phase] += 1
        self._stack.append(phase)
        self._opaque += phase in OPAQUE
        self._mark = now

    def leave(self) -> None:
        now = time.perf_counter()
        phase = self._stack.pop()
        self.seconds[phase] += now - self._mark
        self._opaque -= phase in OPAQUE
        self._mark = now

    def entry_cost(self, n: int = 20_000) -> float:
        """Seconds one timed call adds (a wrapped no-op against the bare one, ``n`` calls; best of 3)."""
        def noop():
            return None

        saved = (self.seconds.copy(), self.calls.copy(), self.entries, self.running, self._stack, self._mark)
        timed = self.wrap(noop, OTHER)
        self.running, self._stack, self._mark = True, [OTHER], time.perf_counter()
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            for _ in range(n):
                timed()
            t1 = time.perf_counter()
            for _ in range(n):
                noop()
            best = min(best, (t1 - t0) - (time.perf_counter() - t1))
        self.seconds, self.calls, self.entries, self.running, self._stack, self._mark = saved
        return max(best, 0.0) / n

    # --- wrappers -----------------------------------------------------------------------------------
    def wrap(self, fn, phase, event=None):
        """``fn`` timed as ``phase`` (a generator function per resumption); ``event`` counted per call."""
        clock = self
        if inspect.isgeneratorfunction(fn):
            @functools.wraps(fn)
            def generator(*args, **kwargs):
                if event and clock.running:
                    clock.events[event] += 1
                return (yield from clock._timed_generator(fn(*args, **kwargs), phase))

            return generator

        @functools.wraps(fn)
        def timed(*args, **kwargs):
            if not clock._claims(phase):
                if event and clock.running:
                    clock.events[event] += 1
                return fn(*args, **kwargs)
            if event:
                clock.events[event] += 1
            clock.enter(phase)
            try:
                return fn(*args, **kwargs)
            finally:
                clock.leave()

        return timed

    def _timed_generator(self, gen, phase):
        sent, thrown = None, None
        while True:
            claimed = self._claims(phase)
            if claimed:
                self.enter(phase)
            try:
                item = gen.throw(thrown) if thrown is not None else gen.send(sent)
            except StopIteration as stop:
                return stop.value
            finally:
                if claimed:
                    self.leave()
            try:
                sent, thrown = (yield item), None
            except GeneratorExit:
                gen.close()
                raise
            except BaseException as exc:  # noqa: BLE001 -- passed on into the route, as yield from does
                sent, thrown = None, exc

    # --- installing ---------------------------------------------------------------------------------
    def install(self, targets=TARGETS) -> None:
        """Wrap every target (now if its module is imported, else right after its import); hook imports."""
        for module, qualname, phase, event in targets:
            self._pending.setdefault(module, []).append((qualname, phase, event))
        self._install_loaded()
        bootstrap = importlib._bootstrap
        self._find_and_load = original = bootstrap._find_and_load
        clock = self

        def find_and_load(name, import_):
            phase = NUMBA if name.split(".")[0] in NUMBA_MODULES or name.endswith("._kernels_numba") else IMPORTS
            if not clock._claims(phase):
                return original(name, import_)
            nested = clock._nested_imports
            nested.append(0.0)
            t0 = time.perf_counter()
            clock.enter(phase)
            try:
                module = original(name, import_)
            finally:
                clock.leave()
                spent = time.perf_counter() - t0
                clock.imports[_package(name)] += spent - nested.pop()
                if nested:
                    nested[-1] += spent
            if clock._pending:
                clock._install_loaded()
            return module

        bootstrap._find_and_load = find_and_load

    def _install_loaded(self) -> None:
        for module in [m for m in self._pending if m in sys.modules and _loaded(sys.modules[m])]:
            for qualname, phase, event in self._pending.pop(module):
                self._patch(sys.modules[module], module, qualname, phase, event)

    def _patch(self, mod, module, qualname, phase, event) -> None:
        *owner_path, name = qualname.split(".")
        owner = mod
        for part in owner_path:
            owner = getattr(owner, part)
        if not hasattr(owner, name):
            raise AttributeError(f"profile target {module}:{qualname} does not exist: update "
                                 "rftstatic.bench.phases.TARGETS")
        own = name in vars(owner)
        original = vars(owner)[name] if own else getattr(owner, name)
        if module == "sksparse.cholmod" and qualname == "analyze":
            wrapped = self._wrap_analyze(original, event)
        else:
            wrapped = self.wrap(original, phase, event)
        setattr(owner, name, wrapped)
        self._patched.append((owner, name, original, own))
        if owner is mod:  # rebind ``from module import name`` in the package's loaded modules
            for other in list(sys.modules.values()):
                space = getattr(other, "__dict__", None)
                if other is not mod and space is not None and getattr(other, "__name__", "").startswith("rftstatic") \
                        and space.get(name) is original:
                    setattr(other, name, wrapped)
                    self._patched.append((other, name, original, True))

    def _wrap_analyze(self, analyze, event):
        clock = self
        timed = self.wrap(analyze, ANALYSIS, event)

        @functools.wraps(analyze)
        def analyse(*args, **kwargs):
            return _TimedFactor(timed(*args, **kwargs), clock)

        return analyse

    def uninstall(self) -> None:
        """Put every original back (in reverse order) and unhook imports."""
        if self._find_and_load is not None:
            importlib._bootstrap._find_and_load = self._find_and_load
            self._find_and_load = None
        for owner, name, original, own in reversed(self._patched):
            if own:
                setattr(owner, name, original)
            else:
                delattr(owner, name)
        self._patched = []
        self._pending = {}

    def table(self) -> list[dict]:
        """Every phase of :data:`PHASES` (and any other that got time): phase, seconds, calls."""
        names = list(PHASES) + [p for p in self.seconds if p not in PHASES]
        return [{"phase": p, "seconds": float(self.seconds.get(p, 0.0)), "calls": int(self.calls.get(p, 0))}
                for p in names]


def _package(name: str) -> str:
    """The package an import is counted under: the top-level one, ``rftstatic``'s by subpackage."""
    parts = name.split(".")
    return ".".join(parts[:2]) if parts[0] == "rftstatic" and len(parts) > 1 else parts[0]


def _loaded(module) -> bool:
    """Whether ``module`` has finished its import (a module being imported is in sys.modules already)."""
    return not getattr(getattr(module, "__spec__", None), "_initializing", False)


class _TimedFactor:
    """A CHOLMOD factor whose numeric factorisations and solves are timed (see the module docstring)."""

    __slots__ = ("_factor", "_clock")

    def __init__(self, factor, clock: PhaseClock):
        self._factor, self._clock = factor, clock

    def _timed(self, phase, event, method, *args, **kwargs):
        clock = self._clock
        if clock.running:
            clock.events[event] += 1
        if not clock._claims(phase):
            return method(*args, **kwargs)
        clock.enter(phase)
        try:
            return method(*args, **kwargs)
        finally:
            clock.leave()

    def cholesky_inplace(self, *args, **kwargs):
        try:
            return self._timed(FACTOR, "numeric factorisations", self._factor.cholesky_inplace, *args, **kwargs)
        except Exception as exc:
            if "NotPositiveDefinite" in type(exc).__name__ and self._clock.running:
                self._clock.events["numeric factorisations: not positive definite"] += 1
            raise

    def __call__(self, *args, **kwargs):
        return self._timed(BACKSUB, "back-substitutions", self._factor, *args, **kwargs)

    def solve_A(self, *args, **kwargs):  # noqa: N802 -- scikit-sparse's name
        return self._timed(BACKSUB, "back-substitutions", self._factor.solve_A, *args, **kwargs)

    def copy(self):
        return _TimedFactor(self._factor.copy(), self._clock)

    def __getattr__(self, name):
        return getattr(self._factor, name)
