"""Arc-length path following of the load-scaled route (``solver.continuation = "arc-length"``).

The equilibrium path R(U, lam) = f(U) - lam P = 0 is followed from the flat sheet (lam = 0) to the full
load (lam = 1) by pseudo-arclength continuation (Keller 1977; Riks 1979, Crisfield 1981 for the
structural form), in the scaled variables u = U / c, c = L sqrt(N) (L the sheet's diagonal, N the
nodes: u is the RMS nodal displacement per sheet size), so one unit of arc length is one sheet size of
RMS displacement or the whole load:

- predictor: the unit tangent t = (K^-1 P / c, 1) / norm at the last point, oriented along the previous
  one (t . t_prev > 0, which turns the load factor back at a limit point), or with dlam > 0 after a
  branch switch; the step is (U, lam) + ds t;
- corrector: Newton on R = 0 with the linear constraint t . ((U, lam) - (U_n, lam_n)) = ds, solved by
  the bordering algorithm: two back-substitutions with the factorisation of the exact tangent,
  K dU_r = -R, K dU_P = P, dlam = -(t_u . dU_r / c) / (t_u . dU_P / c + t_lam), dU = dU_r + dlam dU_P;
  each step is capped (``max_step``) and bounded by the self-contact collision test, alike on dU and dlam;
- ds doubles after a step that took at most 4 iterations, halves after one that took more than 8 or
  failed; a failed step restarts from the last point (penalty contact makes the path only piecewise
  smooth: its kinks are passed with smaller steps).

Inertia: every factorisation counts the tangent's negative pivots
(:class:`~rftstatic.solvers.inertia.InertiaSolver`), and the converged point's own factorisation is
the next predictor's. A change of the count between two points means a critical point between them:
a limit point when the load factor turned back (t_lam changed sign), else a bifurcation. The step is
halved (at most :data:`LOCATE_HALVINGS` times) to land close past it; when the count has risen, the
branch is switched along the lowest mode (:func:`~rftstatic.solvers.branches.switch_branch`) at the
larger of the current and the largest load factor reached (plus a quarter of the last increment at a
limit point) and the path continues from the stable equilibrium found.

The last step takes the constraint lam = 1 (the tangent predictor to full load), then Newton polishes
the equilibrium to the solver's full tolerance (:func:`~rftstatic.solvers.newton.newton`) and the
inertia must be 0 (a stable equilibrium); if it is not, the branch is switched at lam = 1 (at most
:data:`FINAL_SWITCHES` times). ``result.path`` records every step (load factor, arc length, negative
pivots, iterations), each critical point and each branch taken.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace

import numpy as np

from rftstatic.errors import ConvergenceError
from rftstatic.progress import Progress
from rftstatic.solvers.branches import switch_branch
from rftstatic.solvers.inertia import InertiaSolver
from rftstatic.solvers.iteration import capped_step, roundoff_floor, self_contact_limited
from rftstatic.solvers.linear import LinearSolveError
from rftstatic.solvers.loop import Direction, Iterate, StepFailure, newton_loop
from rftstatic.model.state import State
from rftstatic.solvers.newton import StaticResult, close_record, newton, start_state
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.perturbation import start_perturbation

log = logging.getLogger(__name__)

FIRST_ARC = 0.005
"""First arc length [-]: half a percent of the sheet size in RMS displacement (the flat sheet's
skirt sags 100 m per unit load factor in the linear response: the first load increment is ~1e-4)."""

MAX_ARC = 0.1
"""Largest arc length of a step [-]."""

MIN_ARC = 1e-7
"""Smallest arc length [-] before the route gives up (ConvergenceError)."""

CORRECTOR_ITERATIONS = 10
"""Most corrector iterations of one step; a step that needs more is retried with half the arc length."""

PATH_RTOL = 1e-4
"""Force tolerance of a path point, relative to ``max(lam, LAM_FLOOR) |P|`` (the last point is polished
to the solver's ``rtol``). Also the tolerance of the branch switches' descents. A path point's load
factor is off by about this share near a limit point (1e-2 put the von Mises truss's limit 1 % high,
past the true maximum, and the switch fell back onto the branch that had ended)."""

LAM_FLOOR = 1e-4
"""Load factor below which the path tolerance stops shrinking with the load (the sheet's lift off the
smoothed contact layer at lam -> 0 would otherwise ask for forces below round-off)."""

LAM_START = 1e-6
"""Load factor of the path's first point (:func:`_start`)."""

START_ITERATIONS = 60
"""Newton iterations of the first point: where the weight rests on a few nodes (a sheet balanced on a
sphere's top) the lift guess is poor and Newton converges linearly to the layer's root at first."""

LOCATE_HALVINGS = 4
"""Times a step that crossed a critical point is halved to land closer past it."""

LAYER_STEP = 0.5
"""Largest gap change per corrector iteration of a node in the contact layer, in layer widths (:meth:`_Path.layer_limit`)."""

DESCENT_ARC = 1e-5
"""Arc length below which a failing step gives way to a descent at fixed load (:func:`_descend`)."""

DESCENT_LOAD = 1e-3
"""Least load increment of such a descent [-] (else the last positive load increment)."""

MAX_DESCENTS = 50
DESCENT_CONTINUATIONS = 5
"""Times a descent that ran out of iterations while the energy was still falling goes on (80 each)."""
"""Most descents of one path."""

SNAP_SHARE = 0.02
"""Least load step, as a share of the largest load factor reached, of the descent that replaces a stable
branch followed towards lower loads (the round pedestal at lam = 1.05e-3 turned back to lam = 1e-7 on
one, then came back up)."""

REPEAT_LOAD = 1e-3
"""A switch requested within this share of the load factor of the previous one means the branch found
was only marginally stable (a flat energy valley: sphere-30 17 x 17 at lam = 0.2579 switched 14 times
between states 1e-8 apart in load): the path then jumps by a descent at a load 4^k times this share
higher (k the repeat count) from the last stable point."""

FINAL_SWITCHES = 3
"""Branch switches at full load when the equilibrium reached is not stable."""


@dataclass
class _Point:
    """A converged point of the path: displacements (N, 3) [m], load factor, the factorisation of its
    tangent (inertia), its unit tangent (free dofs scaled by 1/c, and the load factor component)."""

    U: np.ndarray
    lam: float
    K: object
    fac: object
    t_u: np.ndarray | None = None
    t_lam: float = 0.0


class _Path:
    """What one arc-length solve shares: model, options, State, the inertia solver, the scale c."""

    def __init__(self, model, opts, state):
        self.model, self.opts, self.state = model, opts, state
        self.free = model.free.ravel()
        self.P = model.load.ravel()[self.free]
        self.Pnorm = float(np.linalg.norm(self.P))
        diagonal = float(np.linalg.norm(np.ptp(model.mesh.X, axis=0)))
        self.c = diagonal * np.sqrt(model.mesh.n_nodes)
        self.max_step = opts.newton.max_step if opts.newton.max_step is not None else 0.1 * diagonal
        self.inertia = InertiaSolver()
        self.eps = float(getattr(model.contact, "smoothing", 0.0) or 0.0) if model.contact is not None else 0.0

    def point(self, U, lam) -> _Point:
        _, K = self.model.tangent(U, lam=lam, candidates=self.state.candidates, pairs=self.state.self_pairs)
        return _Point(U, lam, K, self.inertia.factor(K))

    def tangent(self, pt: _Point, prev: _Point | None) -> None:
        """Set ``pt``'s unit tangent, oriented along ``prev``'s (or with dlam > 0)."""
        v = pt.fac.solve(self.P) / self.c
        norm = np.sqrt(float(v @ v) + 1.0)
        t_u, t_lam = v / norm, 1.0 / norm
        if prev is not None and prev.t_u is not None and float(t_u @ prev.t_u) + t_lam * prev.t_lam < 0.0:
            t_u, t_lam = -t_u, -t_lam
        pt.t_u, pt.t_lam = t_u, t_lam

    def layer_limit(self, U, step) -> float:
        """Factor <= 1 on ``step (N, 3)`` [m] so that no node in or entering the contact law's smoothing
        layer (gap below its width ``eps``) changes its gap by more than :data:`LAYER_STEP` ``eps``: the
        layer's stiffness ramps from 0 to ``k`` across ``eps`` (1 mm on the 17 x 17 sphere), and Newton
        steps of a few ``eps`` jumped nodes in and out of it without end (measured: |r| alternating
        2e-3 / 1e-1 N at lam = 0.28 on sphere-30 17 x 17)."""
        eps = self.eps
        if not eps > 0:
            return 1.0
        x = self.model.positions(U)
        g0, g1 = self.model.contact.gaps(x), self.model.contact.gaps(x + step)
        near = np.minimum(g0, g1) < eps
        if not np.any(near):
            return 1.0
        change = float(np.abs(g1[near] - g0[near]).max())
        return 1.0 if change <= LAYER_STEP * eps else LAYER_STEP * eps / change

    def tolerance(self, U, lam, rnorm=None) -> float:
        """Force tolerance [N] of a path point; when ``rnorm`` is within 1e3 of it, raised by the round-off
        of the internal force at ``U`` (:func:`~rftstatic.solvers.iteration.roundoff_floor`, evaluated
        there: it grows with the membrane's stretch, and a floor taken at the flat start left the
        sphere's path stuck at |r| = 2.6e-7 N, its round-off, at lam = 0.258)."""
        tol = PATH_RTOL * max(abs(lam), LAM_FLOOR) * self.Pnorm
        if rnorm is not None and tol < rnorm < 1e3 * tol:
            tol += 10.0 * roundoff_floor(self.model, U)
        return tol

    def corrector(self, pt: _Point, ds: float, *, target: float | None = None, iterations=CORRECTOR_ITERATIONS):
        """One pseudo-arclength step of length ``ds`` from ``pt`` (``target``: to that load factor
        instead, from the tangent predictor). Returns ``(point, iterations)``, point None when the
        corrector failed."""
        model, free = self.model, self.free
        if target is not None:
            a_u, a_lam = np.zeros(len(free.nonzero()[0])), 1.0
            dl0 = target - pt.lam
            du0 = pt.fac.solve(self.P) * dl0 if dl0 else np.zeros_like(a_u)
        else:
            a_u, a_lam = pt.t_u / self.c, pt.t_lam
            du0, dl0 = ds * pt.t_u * self.c, ds * pt.t_lam
        step, _ = capped_step(model, du0, np.inf)
        x = Iterate(pt.U + step, pt.lam + dl0)
        out = newton_loop(x, test=self._converged, direction=lambda x: self._bordered(x, a_u, a_lam),
                          globalise=self._advance, max_iterations=iterations, first_test=1, final_test=False)
        if not out.converged:
            return None, out.iterations
        x = out.x
        return _Point(x.U, x.lam, x.tangent, x.factor), out.iterations

    def _converged(self, x: Iterate) -> bool:
        """The corrector's test: the residual at ``x`` within :meth:`tolerance`; evaluates and factorises the
        tangent there (the converged point keeps both: its inertia and the next predictor)."""
        f, x.tangent = self.model.tangent(x.U, lam=x.lam, candidates=self.state.candidates, pairs=self.state.self_pairs)
        x.r = (f - x.lam * self.model.load).ravel()[self.free]
        x.rnorm = float(np.linalg.norm(x.r))
        if not np.isfinite(x.rnorm):
            raise StepFailure("non-finite residual")
        try:
            x.factor = self.inertia.factor(x.tangent)
        except LinearSolveError as exc:
            raise StepFailure(f"linear solve failed ({exc})") from None
        return x.rnorm <= self.tolerance(x.U, x.lam, x.rnorm)

    def _bordered(self, x: Iterate, a_u, a_lam) -> Direction:
        """The bordered direction (module docstring): ``K dU_r = -R``, ``K dU_P = P`` with the factorisation at
        ``x``, ``dlam`` from the linear constraint ``a_u . dU + a_lam dlam = 0``."""
        try:
            d_r, d_p = x.factor.solve(-x.r), x.factor.solve(self.P)
        except LinearSolveError as exc:
            raise StepFailure(f"linear solve failed ({exc})") from None
        dlam = -float(a_u @ d_r) / (float(a_u @ d_p) + a_lam)
        return Direction(d_r + dlam * d_p, "exact", dlam=dlam)

    def _advance(self, x: Iterate, dn: Direction):
        """The corrector's step: capped (``max_step``), bounded by the self-contact collision test and the
        contact layer (:meth:`layer_limit`), the load factor scaled alike."""
        step, cap = capped_step(self.model, dn.d, self.max_step)
        step, frac = self_contact_limited(self.model, x.U, step, self.state)
        layer = self.layer_limit(x.U, step)
        step, frac = step * layer, frac * layer
        return Iterate(x.U + step, x.lam + cap * frac * dn.dlam), {"cap": cap * frac, "dlam": cap * frac * dn.dlam}


def solve_arc_length(model, *, U0=None, options: StaticOptions | None = None, callback=None,
                     state: State | None = None) -> StaticResult:
    """The load-scaled route by arc-length path following (module docstring).

    Raises :class:`~rftstatic.errors.ConvergenceError` naming the step, load factor and residual when a
    step cannot converge even with the smallest arc length, or the path runs out of steps; ``.result``
    holds the last equilibrium (``converged=False``).
    """
    opts = options or StaticOptions()
    if model.load_terms or not np.any(model.load):
        raise ValueError('solver.continuation = "arc-length" needs a fixed load vector (no end moments, not '
                         'unloaded); use solver.continuation = "load"')
    t0 = time.perf_counter()
    n = model.mesh.n_nodes
    U = np.zeros((n, 3)) if U0 is None else np.array(U0, dtype=float)
    seed = None
    if opts.route.perturbation and U0 is None:
        seed = opts.route.seed
        U[:, 2] += start_perturbation(model.mesh, opts.route) * model.free[:, 2]
    state = state if state is not None else start_state(model, opts.newton.linear_solver)
    state.modes = {"exact": 0, "psd": 0, "shift": 0}
    path = _Path(model, opts, state)
    record = {"steps": [], "critical_points": [], "switches": [], "arc_length": 0.0}
    result = StaticResult(U=U, lam=0.0, converged=False, linear_solver=path.inertia.name, seed=seed,
                          route="arc-length", path=record)
    bar = Progress(1.0, f"arc-length {model.element}", enabled=opts.progress)

    def inertia_counters(res):
        res.factorisations += path.inertia.factorisations
        res.tangent_modes["ldl"] = path.inertia.ldl

    try:
        pt = _start(path, U, result)
        record["start_negative"] = pt.fac.negative
        _accept(path, result, record, pt, result.iterations, 0.0, pt.lam, "start")
        _follow(path, pt, result, record, bar, callback)
    except ConvergenceError as exc:
        close_record(model, result, state, t0, exc, counts=inertia_counters)
        raise
    finally:
        bar.close()
    return close_record(model, result, state, t0, counts=inertia_counters)


def _start(path, U, result) -> _Point:
    """The path's first point: the equilibrium at load factor :data:`LAM_START`, from the sheet lifted by
    the contact law's smoothing length less the layer's compression under that load.

    Why (measured): the smoothed penalty pushes a node that touches an obstacle (phi = 0) with
    ``k A eps / 2``; on the flat sheet lying on its support that is 60 x the norm of the whole load
    (sphere-30 17 x 17: |r| = 0.60 N against |P| = 0.010 N), and at lam -> 0 the equilibrium lies where
    the layer's force ``k A (eps - phi)^2 / (2 eps)`` vanishes, a double root: Newton from phi = 0 only
    halves the distance to it per iteration (the residual falls by exactly 4 per iteration) and the
    load-increment route ran out of iterations there (pedestal-round-50: |r| = 4.2e-8 N at
    lam = 1.5e-5 after 30 iterations). Lifted as a rigid body until the contact carries the load
    (:func:`_lift`), Newton starts next to the simple root."""
    model = path.model
    U = U.copy()
    if model.contact is not None:
        U[:, 2] += _lift(model, U) * model.free[:, 2]
    pt = path.point(U, LAM_START)
    pt.t_u, pt.t_lam = np.zeros(len(path.P)), 1.0
    start, its = path.corrector(pt, 0.0, target=LAM_START, iterations=START_ITERATIONS)
    result.iterations += its
    if start is None:
        r = model.residual(U, LAM_START, candidates=path.state.candidates, pairs=path.state.self_pairs).ravel()[path.free]
        raise ConvergenceError(f"arc-length start, load factor {LAM_START:g}: Newton did not converge in "
                               f"{START_ITERATIONS} iterations; |r| = {np.linalg.norm(r):.3e} N at the lifted start; "
                               "try solver.continuation = \"load\" (load steps) or solver.start = \"relax\"", None)
    path.tangent(start, None)
    return start


def _lift(model, U) -> float:
    """The rigid upward shift [m] of the sheet ``U (N, 3)`` at which the obstacles' contact force carries
    the load at :data:`LAM_START` (bisection between 0 and the sheet's total z-extent of contact: 60
    evaluations of the contact force; only the contact law's ``force`` is used)."""
    W = -LAM_START * float(model.load[:, 2].sum())  # weight to carry [N] (> 0 for gravity downwards)
    x = model.positions(U)

    def carried(h):
        return -float(model.contact.force(x + np.array([0.0, 0.0, h]))[:, 2].sum())

    if not W > 0 or not carried(0.0) > W:
        return 0.0
    lo, hi = 0.0, float(np.ptp(model.mesh.X, axis=0).max())
    while carried(hi) > W and hi < 1e3:
        hi *= 2.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if carried(mid) > W else (lo, mid)
    return lo


def _accept(path, result, record, pt, its, s, dlam, kind=None):
    result.U, result.lam = pt.U, pt.lam
    result.iterations += its
    result.load_steps.append({"lam": pt.lam, "iterations": its, "residual": float("nan"), "increment": dlam,
                              "scheme": "arc-length"})
    record["steps"].append({"lam": float(pt.lam), "s": float(s), "negative": int(pt.fac.negative),
                            "iterations": int(its), **({"event": kind} if kind else {})})
    log.info("arc-length step %d: load factor %.6g, arc length %.4g, %d negative pivots, %d iterations%s",
             len(record["steps"]), pt.lam, s, pt.fac.negative, its, f" ({kind})" if kind else "")


def _follow(path, pt, result, record, bar, callback):
    """Steps from ``pt`` to lam = 1 (module docstring); the final polish and stability in :func:`_finish`."""
    opts = path.opts
    ds, s, halvings, descents = FIRST_ARC, 0.0, 0, 0
    last_switch, repeat = -1.0, 0
    lam_max, last_dlam = pt.lam, 0.0
    while True:
        if len(record["steps"]) >= opts.increments.max_load_steps:
            raise ConvergenceError(f"arc-length step {len(record['steps']) + 1}, load factor {pt.lam:.6g}: "
                                   f"{opts.increments.max_load_steps} steps used without reaching full load; raise "
                                   "solver.max_load_steps", None)
        final = pt.t_lam > 0 and pt.lam + ds * pt.t_lam >= 1.0
        new, its = path.corrector(pt, ds, target=1.0 if final else None)
        if new is None:
            result.cutbacks += 1
            result.iterations += its
            ds *= 0.5
            if ds < DESCENT_ARC and descents < MAX_DESCENTS:
                descents += 1
                new = _descend(path, result, record, pt, max(last_dlam, DESCENT_LOAD))
                if new is not None:
                    pt, ds = new, FIRST_ARC
                    lam_max = max(lam_max, pt.lam)
                    continue
            if ds < MIN_ARC:
                r = path.model.residual(pt.U, pt.lam, candidates=path.state.candidates, pairs=path.state.self_pairs)
                raise ConvergenceError(
                    f"arc-length step {len(record['steps']) + 1}, load factor {pt.lam:.6g}: the corrector did not "
                    f"converge even with arc length {ds:.3g}; |r| = {np.linalg.norm(r.ravel()[path.free]):.3e} N at "
                    f"the last point; try solver.start = \"relax\" (dynamic relaxation at full load) or a finer mesh",
                    None)
            continue
        path.tangent(new, pt)
        changed = new.fac.negative != pt.fac.negative
        if changed and not final and halvings < LOCATE_HALVINGS and ds > 16 * MIN_ARC:
            halvings += 1
            ds *= 0.5
            continue
        halvings = 0
        step_s = ds if not final else float(np.hypot(np.linalg.norm((new.U - pt.U).ravel()[path.free]) / path.c,
                                                     new.lam - pt.lam))
        s += step_s
        kind = None
        if changed:
            kind = "limit" if (new.t_lam > 0) != (pt.t_lam > 0) or new.lam < pt.lam else "bifurcation"
            record["critical_points"].append({"kind": kind, "lam": float(new.lam), "s": float(s),
                                              "negative_before": int(pt.fac.negative),
                                              "negative_after": int(new.fac.negative)})
        dlam = new.lam - pt.lam
        _accept(path, result, record, new, its, s, dlam, kind)
        if dlam > 0:
            last_dlam = dlam
        lam_max = max(lam_max, new.lam)
        bar.update(min(max(new.lam, 0.0), 1.0), f"s {s:.3g} neg {new.fac.negative}")
        if callback is not None:
            callback(new.lam, new.U)
        if new.fac.negative == 0 and new.lam < pt.lam and not final:
            # a stable branch followed towards lower loads leads back to a fold already passed: under a
            # rising load the sheet snaps from that fold, so jump by a descent beyond the largest load
            snapped = _descend(path, result, record, new, lam_max - new.lam + max(last_dlam, SNAP_SHARE * lam_max))
            if snapped is not None:
                pt, ds = snapped, min(ds, FIRST_ARC)
                lam_max = max(lam_max, pt.lam)
                continue
        if changed and new.fac.negative > pt.fac.negative and not final:
            lam_s = max(new.lam, lam_max) + (0.25 * last_dlam if kind == "limit" else 0.0)
            repeat = repeat + 1 if abs(lam_s - last_switch) < REPEAT_LOAD * max(lam_s, LAM_FLOOR) else 0
            last_switch = lam_s
            snapped = None
            if repeat and pt.fac.negative == 0:  # back at the same load: jump over the unstable stretch
                snapped = _descend(path, result, record, pt, REPEAT_LOAD * max(lam_s, LAM_FLOOR) * 4.0**repeat)
            new = snapped if snapped is not None else _switch(path, result, record, new, min(lam_s, 1.0),
                                                              pt if kind == "limit" else None)
            lam_max = max(lam_max, new.lam)
            ds = min(ds, FIRST_ARC)  # the branch found may turn back soon: approach it gently
        ds = float(np.clip(ds * (2.0 if its <= 4 else 0.5 if its > 8 else 1.0), MIN_ARC, MAX_ARC))
        pt = new
        if final:
            _finish(path, result, record, pt)
            record["arc_length"] = float(s)
            return


def _switch(path, result, record, pt, lam, prev):
    """Branch switch from ``pt`` at load factor ``lam`` (:func:`switch_branch`); returns the point to go on
    from (``pt`` itself when no push converged), its tangent oriented with dlam > 0."""
    looser = replace(path.opts.newton, intermediate_rtol=PATH_RTOL)
    choice, rec = switch_branch(path.model, pt.U, lam, pt.K, pt.fac, looser,
                                path.state, path.inertia,
                                path.max_step, seed=len(record["switches"]),
                                away_from=None if prev is None else prev.U)
    rec["step"] = len(record["steps"])
    record["switches"].append(rec)
    if choice is None:
        log.warning("branch switch at load factor %.6g failed (%s); following the unstable branch", lam,
                    rec.get("error", "no push converged"))
        return pt
    new = _Point(choice["U"], lam, choice["K"], choice["factor"])
    path.tangent(new, None)
    result.U, result.lam = new.U, new.lam
    result.iterations += sum(b["iterations"] for b in rec["branches"])
    return new


def _descend(path, result, record, pt, dlam):
    """Where the corrector fails even with short arcs (a kink of the penalty contact, a snap the tangent
    does not see), the energy's line-searched descent at fixed load factor ``lam + dlam``
    (:func:`~rftstatic.solvers.newton.newton`, displacement iteration) from ``pt``: the point it reaches
    (its tangent oriented with dlam > 0), or None."""
    lam = min(1.0, pt.lam + dlam)
    base = path.opts.newton
    opts = replace(base, max_iterations=max(base.max_iterations, 80), intermediate_rtol=PATH_RTOL)
    nt = newton(path.model, pt.U, lam, opts, path.state, path.max_step, scheme="displacement")
    result.iterations += nt.iterations
    for _ in range(DESCENT_CONTINUATIONS):  # a fold forming: still sliding downhill
        if nt.converged or not nt.descending:
            break
        nt = newton(path.model, nt.U, lam, opts, path.state, path.max_step, scheme="displacement")
        result.iterations += nt.iterations
    record["descents"] = record.get("descents", 0) + 1
    if not nt.converged:
        return None
    new = path.point(nt.U, lam)
    path.tangent(new, None)
    _accept(path, result, record, new, nt.iterations, record["steps"][-1]["s"] if record["steps"] else 0.0,
            lam - pt.lam, "descent")
    log.info("arc-length: descent to load factor %.6g (%d iterations, %d negative pivots)", lam, nt.iterations,
             new.fac.negative)
    return new


def _finish(path, result, record, pt):
    """Newton at lam = 1 to the solver's tolerance from the path's last point; switch branches while the
    equilibrium is unstable (:data:`FINAL_SWITCHES`)."""
    model, opts, state = path.model, path.opts, path.state
    U = pt.U
    for attempt in range(FINAL_SWITCHES + 1):
        nt = newton(model, U, 1.0, opts.newton, state, path.max_step)
        if not nt.converged:
            nt = newton(model, U, 1.0, opts.newton, state, path.max_step, scheme="displacement")
        result.iterations += nt.iterations
        if not nt.converged:
            raise ConvergenceError(f"arc-length final point, load factor 1, iteration {nt.iterations}: {nt.reason}, "
                                   f"|r| = {nt.residual:.3e} N; try a larger solver.max_iterations or solver.start = "
                                   "\"relax\"", None)
        result.U, result.lam, result.residual = nt.U, 1.0, nt.residual
        end = path.point(nt.U, 1.0)
        record["final_negative"] = end.fac.negative
        if end.fac.negative == 0 or attempt == FINAL_SWITCHES:
            return
        new = _switch(path, result, record, end, 1.0, None)
        if new is end:
            return
        U = new.U
