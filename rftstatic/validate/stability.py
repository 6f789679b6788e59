"""The stability matrix (issue 7 item 3): does every solver either converge correctly or stop clearly?

Each *cell* is one solve at an extreme of stiffness ratio, mesh, load or time step. A cell runs in
a forked child process with a wall-time budget, so nothing can hang the report; every exception is
caught there and recorded by type and message. Outcomes:

- ``pass``: converged, and within the tolerance of its reference where one exists (heavy elastica
  for strips, Timoshenko/Navier for plates, the exact circle for the end-moment roll-up, a run at
  half the step for explicit runs, ``sqrt(s)`` for mass scaling);
- ``converged``: converged, no reference (pedestal drapes);
- ``expected stop``: stopped with the error that is the right behaviour (``InstabilityError`` above the
  critical step, with a suggested step that then runs; ``PatchError``/``MeshError`` naming the element
  for a degenerate patch);
- ``limitation``: stopped with a clear error (``ConvergenceError``) although a solution exists, or
  converged outside the tolerance on a model that warned at construction that this mesh is outside
  its accuracy (RFT6 membrane locking, :func:`rftstatic.model.locking_number`);
- ``FAIL``: a hang (budget exceeded), a crash (an unexpected exception type, or the process died), or a
  wrong answer reported as converged (error above tolerance). The benchmark passes without FAIL cells.

Cells record how the solver helped itself: load steps, cutbacks, Newton iterations, and the
tangent modes (``exact``, ``psd``: compressive stress dropped, ``shift``: Levenberg-Marquardt shift,
``reused``: modified Newton steps).

Strip cells use Kang & Yu's wool strip of §4.1 (5 x 1 cm, clamped, own weight); the stiffness ratio
C/B [1/cm^2] scales all membrane rigidities with B fixed (wool: C_warp/B_warp = 1.35e4 /cm^2).
Tip error = |computed - elastica tip| / L, the computed tip the mean of the nodes at x = L.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing as mp
import time
import traceback
from dataclasses import dataclass, field

import numpy as np

from rftstatic.validate.report import BenchmarkResult, fmt_err

L, WIDTH = 0.05, 0.01  # strip [m]
CM2 = 1e4  # 1/cm^2 in 1/m^2


@dataclass
class Cell:
    """One cell of the matrix: ``func(**kw)`` in a child process, at most ``budget`` seconds.

    ``expected``: exception names that are the right behaviour; ``limitation``: clear errors that
    are not (a solution exists), reported but not failed. Any other exception is a FAIL.
    """

    group: str
    name: str
    func: str
    kw: dict = field(default_factory=dict)
    budget: float = 60.0
    tolerance: float | None = None
    expected: tuple = ()
    limitation: tuple = ("ConvergenceError",)


# ---------------------------------------------------------------- models

def _strip(nx, ny, *, element="RFT6", ratio=None, alpha=None, pattern="right", mesh_=None, membrane=True):
    from rftstatic import material
    from rftstatic.mesh import trimesh as mesh
    from rftstatic.model import model

    m = mesh_ if mesh_ is not None else mesh.rectangle(L, WIDTH, nx, ny, origin=(0.0, -WIDTH / 2), pattern=pattern)
    mat = material.preset("wool-kang-yu")
    if ratio is not None:
        mat = dataclasses.replace(mat, Dm=mat.Dm * (ratio * CM2 / (mat.Dm[0, 0] / mat.Db[0, 0])))
    if alpha is not None:
        mat = dataclasses.replace(mat, weight=alpha * mat.Db[0, 0] / L**3)
    tol = 1e-9 * L
    sup = model.Supports(m.nodes_in_box(-tol, tol, -1, 1), np.zeros(0, np.int64), np.zeros((m.n_nodes, 3), bool))
    return model.Model(m, mat, element=element, supports=sup, load=model.gravity_load(m, mat.weight),
                       membrane=membrane)


def _static_summary(res) -> dict:
    return {"converged": bool(res.converged), "iterations": res.iterations, "load_steps": len(res.load_steps),
            "cutbacks": res.cutbacks, "tangent_modes": dict(res.tangent_modes)}


def _solve(mod, opts=None):
    from rftstatic.solvers import static

    return static.solve_static(mod, options=opts or static.StaticOptions(progress=False))


def strip_cell(nx=21, ny=5, *, element="RFT6", ratio=None, alpha=None, one_step=False, mesh_kind=None,
               h=None, jitter=None, seed=0, degenerate=None) -> dict:
    """The wool strip against the extensible heavy elastica (see module docstring)."""
    from rftstatic.references.elastica import heavy_elastica
    from rftstatic.solvers import static

    m = _strip_mesh(nx, ny, mesh_kind=mesh_kind, h=h, jitter=jitter, seed=seed, degenerate=degenerate)
    mod = _strip(nx, ny, element=element, ratio=ratio, alpha=alpha, mesh_=m)
    opts = static.StaticOptions(progress=False)
    if one_step:
        opts = static.StaticOptions(progress=False, initial_increment=1.0, max_increment=1.0,
                                    increment_displacement=1e30)
    res = _solve(mod, opts)
    mat = mod.material
    ref = heavy_elastica(mat.weight * L**3 / mat.Db[0, 0], beta=mat.weight * L / mat.Dm[0, 0])
    tip = np.flatnonzero(np.abs(mod.mesh.X[:, 0] - L) < 1e-9 * L)
    x = (mod.X3[tip] + res.U[tip]).mean(axis=0) / L
    out = _static_summary(res)
    out.update(warnings=list(mod.warnings), value=[float(x[0]), float(x[2])], reference=[ref.tip_x, ref.tip_z],
               error=float(np.hypot(x[0] - ref.tip_x, x[2] - ref.tip_z)), nodes=mod.mesh.n_nodes,
               membrane_energy_share=float(mod.energies(res.U, 1.0)["membrane"]
                                           / max(mod.energies(res.U, 1.0)["bending"], 1e-300)))
    if degenerate is not None:
        out["worst_patch_condition"] = float(mod.patches.condition.max())
    return out


def _strip_mesh(nx, ny, *, mesh_kind=None, h=None, jitter=None, seed=0, degenerate=None):
    from rftstatic.mesh import trimesh as mesh

    if mesh_kind == "unstructured":
        from rftstatic.mesh.mesher import BackgroundGrid, Domain, generate

        domain = Domain.rectangle(0.0, -WIDTH / 2, L, WIDTH)
        r = generate(domain, BackgroundGrid.uniform(h, domain))
        return mesh.TriMesh(r.points, r.triangles, name=f"unstructured h={h}")
    m = mesh.rectangle(L, WIDTH, nx, ny, origin=(0.0, -WIDTH / 2))
    X = m.X.copy()
    if jitter:
        rng = np.random.default_rng(seed)
        inner = np.setdiff1d(np.arange(m.n_nodes), m.boundary_nodes)
        X[inner] += jitter * np.array([L / (nx - 1), WIDTH / (ny - 1)]) * rng.uniform(-1, 1, (len(inner), 2))
    if degenerate is not None:
        # move an interior node n of triangle (n, a, b) toward the line ab: its distance to the
        # line becomes ``degenerate`` times the original; n is the opposite node of the patch across ab
        n = int(m.nearest_node([[0.5 * L, 0.0]])[0])
        e = int(np.flatnonzero((m.tri == n).any(axis=1))[0])
        a, b = [v for v in m.tri[e] if v != n]
        t = X[b] - X[a]
        foot = X[a] + ((X[n] - X[a]) @ t) / (t @ t) * t
        X[n] = foot + degenerate * (X[n] - foot)
    return mesh.TriMesh(X, m.tri, name=m.name)


def pedestal_cell(n=17, *, ratio=None, one_step=False) -> dict:
    """pedestal-square-20 at n x n nodes; ``ratio`` C/B [1/cm^2] via a full material table."""
    from rftstatic import material
    from rftstatic.app import static as run
    from rftstatic.scenes import build
    from rftstatic.scenes import schema as scene
    from rftstatic.solvers import static

    overrides = [f"mesh.nodes=[{n},{n}]"]
    s = scene.load_scene("pedestal-square-20", overrides)
    if ratio is not None:  # all rigidities given (the preset's values), membrane scaled
        values = dict(material.WOOL_KANG_YU_CM_GF)
        f = ratio / (values["C_warp"] / values["B_warp"])
        for k in ("C_warp", "C_weft", "C_shear"):
            values[k] *= f
        data = dict(s.data, material=values)
        s = scene.scene_from_dict(data, name=s.name)
    mod, extras = build.build_model(s)
    opts = run.static_options(s, progress=False)
    if one_step:
        opts = opts.single_step()
    res = static.solve_static(mod, options=opts)
    out = _static_summary(res)
    out["nodes"] = mod.mesh.n_nodes
    out["value"] = float(-res.U[:, 2].min())  # largest drop of any node [m]
    return out


def scene_override_cell() -> dict:
    """The scene path: ``[material] preset = ...`` with an override (``material.C_warp=...``)."""
    from rftstatic.scenes import build
    from rftstatic.scenes import schema as scene

    s = scene.load_scene("pedestal-square-20", ["mesh.nodes=[9,9]", "material.C_warp=111.82"])
    mat = build.build_material(s)
    want = 111.82 * 9.80665e-3 / 1e-2  # gf/cm -> N/m
    return {"converged": True, "value": float(mat.Dm[0, 0]), "reference": want,
            "error": abs(mat.Dm[0, 0] - want) / want, "iterations": 0}


def plate_cell(n=21, *, one_step=True) -> dict:
    """Clamped unit plate, uniform load, bending only: centre coefficient against Timoshenko."""
    from rftstatic.validate.plates import plate_coefficient

    r = plate_coefficient(n, "clamped", "uniform")
    return {"converged": r["converged"], "value": r["value"], "reference": r["reference"], "error": r["error"],
            "iterations": r["iterations"], "nodes": r["nodes"]}


def end_moment_cell(nx=25, ny=3, *, element="RFT6", steps_per_table=4) -> dict:
    """The full roll-up of Sze et al. (2004) (sze2004.end_moment) against the exact circle."""
    from rftstatic.references import load_sze2004
    from rftstatic.validate.sze2004 import end_moment

    r = end_moment(nx, ny, element, load_sze2004("end_moment"), steps_per_table=steps_per_table)
    if not r["converged"]:
        from rftstatic.errors import ConvergenceError

        raise ConvergenceError(r["message"])
    return {"converged": True, "value": r["value"], "reference": r["reference"], "error": r["error"],
            "iterations": r["iterations"], "load_steps": r["load_steps"], "cutbacks": r["cutbacks"],
            "nodes": r["nodes"]}


def _hang(n):
    from rftstatic.scenes import build
    from rftstatic.scenes import schema as scene

    s = scene.load_scene("hang-20", [f"mesh.nodes=[{n},{n}]"])
    mod, extras = build.build_model(s)
    corner = int(mod.mesh.nearest_node([[0.2, 0.1]])[0])
    return mod, corner


def explicit_dt_cell(n=11, *, factor=1.0, steps=1500, alpha=5.0) -> dict:
    """Hanging sheet (hang-20 at n x n) for ``steps`` steps at ``factor`` x the automatic step.

    Reference: the same time at half the automatic step (free-corner displacement). Above the
    critical step an :class:`InstabilityError` is the right behaviour, if the step it suggests runs.
    """
    from rftstatic.errors import InstabilityError
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.timestep import stable_time_step

    mod, corner = _hang(n)
    est = stable_time_step(mod, alpha=alpha)
    t_end = steps * est.dt
    out = {"dt_over_estimate": factor, "dt_over_critical": factor * est.dt / est.dt_crit, "estimate_dt": est.dt,
           "nodes": mod.mesh.n_nodes}
    ref = run_explicit(mod, t_end=t_end, dt=0.5 * est.dt, alpha=alpha, progress=False)
    try:
        res = run_explicit(mod, t_end=t_end, dt=factor * est.dt, alpha=alpha, progress=False)
    except InstabilityError as exc:
        out.update(stopped="InstabilityError", message=str(exc), suggested_dt=exc.suggested_dt,
                   suggested_over_estimate=exc.suggested_dt / est.dt, t_stop=exc.t)
        try:  # is the suggestion right? rerun with it
            again = run_explicit(mod, t_end=t_end, dt=exc.suggested_dt, alpha=alpha, progress=False)
            d = np.linalg.norm(again.U[corner] - ref.U[corner]) / np.linalg.norm(ref.U[corner])
            out["suggested_run"] = f"ran to t = {again.t:.4g} s, corner error {fmt_err(d)}"
            out["right_behaviour"] = bool(exc.suggested_dt < factor * est.dt and d < 0.02)
        except InstabilityError as exc2:
            out["suggested_run"] = f"InstabilityError again: {exc2}"
            out["right_behaviour"] = False
        return out
    err = float(np.linalg.norm(res.U[corner] - ref.U[corner]) / np.linalg.norm(ref.U[corner]))
    out.update(converged=True, steps=res.steps, error=err, value=res.U[corner].tolist(),
               reference=ref.U[corner].tolist(), iterations=res.steps)
    return out


def mass_scale_cell(n=11, *, scale=1.0, steps=300) -> dict:
    """Stable step with mass scaling s against sqrt(s) x the unscaled one; a short run at that step."""
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.timestep import stable_time_step

    mod, corner = _hang(n)
    base = stable_time_step(mod, alpha=5.0)
    est = stable_time_step(mod, alpha=5.0, mass_scale=scale)
    # with damping dt_crit = (sqrt(a^2 + 4 w^2) - a) / w^2, w = w1 / sqrt(s): exact sqrt(s) only at a = 0
    from rftstatic.solvers.timestep import critical_step

    expect = 0.9 * critical_step(base.omega_max / math.sqrt(scale), 5.0)
    res = run_explicit(mod, t_end=steps * est.dt, mass_scale=scale, alpha=5.0, progress=False)
    return {"converged": True, "value": est.dt / base.dt, "reference": expect / base.dt,
            "sqrt_s": math.sqrt(scale), "error": abs(est.dt / expect - 1), "iterations": res.steps,
            "nodes": mod.mesh.n_nodes, "omega_ratio": base.omega_max / est.omega_max}


# ---------------------------------------------------------------- the matrix

def strip_tolerance(nx) -> float:
    """Tip tolerance for a strip with nx nodes along: 3 x the measured O(h^2) error of RFT3, >= 0.5 %.

    (validation/strip.md: 1.28 % at 11 x 3, 0.36 % at 21 x 5, 0.10 % at 41 x 9.)
    """
    return max(0.005, 3 * 0.013 * (10.0 / (nx - 1)) ** 2)


def plate_tolerance(n) -> float:
    """3 x the measured O(h^2) error of the clamped plate (12.2 % at 11 x 11), >= 1 %, <= 100 %."""
    return float(np.clip(3 * 0.122 * (10.0 / (n - 1)) ** 2, 0.01, 1.0))


def cells(quick: bool) -> list[Cell]:
    c = []
    ratios = [1e2, 1e4, 1e6, 1e9] if quick else [1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9]
    nx, ny = (11, 3) if quick else (21, 5)
    for element in (["RFT6"] if quick else ["RFT3", "RFT6"]):
        for r in ratios:
            c.append(Cell("stiffness ratio: strip", f"C/B = {r:.0e} /cm^2, {element} {nx}x{ny}", "strip_cell",
                          dict(nx=nx, ny=ny, element=element, ratio=r), 120, strip_tolerance(nx)))
    for r in ([1e2, 1e9] if quick else [1e2, 1e4, 1e6, 1e9]):
        c.append(Cell("stiffness ratio: pedestal", f"C/B = {r:.0e} /cm^2, pedestal-square-20 9x9" if quick else
                      f"C/B = {r:.0e} /cm^2, pedestal-square-20 17x17", "pedestal_cell",
                      dict(n=9 if quick else 17, ratio=r), 240))
    c.append(Cell("stiffness ratio: pedestal", "scene preset + override material.C_warp", "scene_override_cell",
                  {}, 30, 1e-9))

    sizes = [(5, 5), (11, 3)] + ([] if quick else [(21, 5), (41, 9), (81, 17)])
    for sx, sy in sizes:
        c.append(Cell("mesh: strip size", f"strip {sx}x{sy} RFT6", "strip_cell", dict(nx=sx, ny=sy), 300,
                      strip_tolerance(sx)))
    for n in [5, 11, 41] + ([] if quick else [121, 241]):
        c.append(Cell("mesh: sheet size", f"clamped plate {n}x{n} (bending only)", "plate_cell", dict(n=n), 300,
                      plate_tolerance(n)))
    for aspect in ([10, 25] if quick else [1, 5, 10, 25, 50]):
        sx = 1 + 10 * aspect  # dy / dx = (nx - 1) / (5 (ny - 1)) with ny = 3
        c.append(Cell("mesh: sliver", f"strip {sx}x3, element aspect {aspect}", "strip_cell", dict(nx=sx, ny=3),
                      120, strip_tolerance(21)))
    for hh in ([0.0025] if quick else [0.0025, 0.00125]):
        c.append(Cell("mesh: unstructured", f"advancing front h = {hh * 100:g} cm", "strip_cell",
                      dict(mesh_kind="unstructured", h=hh), 120, strip_tolerance(round(L / hh) + 1)))
    for seed in ([0] if quick else [0, 1, 2]):
        c.append(Cell("mesh: unstructured", f"jittered 21x5, 0.3 h, seed {seed}", "strip_cell",
                      dict(nx=21, ny=5, jitter=0.3, seed=seed), 120, strip_tolerance(21)))
    for eps in ([1e-3, 1e-12] if quick else [1e-1, 1e-3, 1e-6, 1e-9, 1e-12]):
        c.append(Cell("mesh: near-degenerate patch", f"21x5, opposite node at {eps:g} of its distance to the edge",
                      "strip_cell", dict(nx=21, ny=5, degenerate=eps), 120, strip_tolerance(21),
                      expected=("PatchError", "MeshError")))

    for a in ([0.1, 1e4] if quick else [0.1, 1.0, 1e2, 1e3, 1e4]):
        sx, sy = (21, 5) if a < 1e3 else (81, 5)  # the clamp boundary layer is L / sqrt(alpha) long
        c.append(Cell("load: strip alpha", f"alpha = {a:g}, RFT6 {sx}x{sy}", "strip_cell",
                      dict(nx=sx, ny=sy, alpha=a), 240, strip_tolerance(sx)))
    c.append(Cell("load: end moment", "full roll-up 25x3 RFT6", "end_moment_cell", dict(nx=25, ny=3), 120, 0.03))
    if not quick:
        c.append(Cell("load: end moment", "full roll-up 49x3 RFT3", "end_moment_cell",
                      dict(nx=49, ny=3, element="RFT3"), 240, 0.03))
        c.append(Cell("load: end moment", "full roll-up 25x3 RFT6, 1 step per table fraction", "end_moment_cell",
                      dict(nx=25, ny=3, steps_per_table=1), 120, 0.03))
    c.append(Cell("load: one increment", "strip 21x5 RFT6, alpha 28.6", "strip_cell", dict(one_step=True), 120,
                  strip_tolerance(21)))
    if not quick:
        c.append(Cell("load: one increment", "strip 21x5 RFT3, alpha 28.6", "strip_cell",
                      dict(one_step=True, element="RFT3"), 120, strip_tolerance(21)))
        c.append(Cell("load: one increment", "strip 81x5 RFT6, alpha 1000", "strip_cell",
                      dict(nx=81, ny=5, alpha=1e3, one_step=True), 240, strip_tolerance(81)))
        c.append(Cell("load: one increment", "pedestal-square-20 17x17", "pedestal_cell", dict(one_step=True), 240))
        c.append(Cell("load: one increment", "clamped plate 41x41 (linear)", "plate_cell", dict(n=41), 60,
                      plate_tolerance(41)))

    for f in ([1.0, 1.2] if quick else [0.5, 0.8, 1.0, 1.1, 1.2]):
        c.append(Cell("explicit: time step", f"hang-20 11x11, dt = {f:g} x estimate", "explicit_dt_cell",
                      dict(factor=f), 120, 0.02, expected=("InstabilityError",)))
    for s in ([1.0, 1e4] if quick else [1.0, 10.0, 100.0, 1e3, 1e4]):
        c.append(Cell("explicit: mass scaling", f"hang-20 11x11, s = {s:g}", "mass_scale_cell", dict(scale=s), 120,
                      1e-3))
    return c


def run_cell(cell: Cell) -> dict:
    """Run one cell in a forked child with its budget; return its record with the verdict."""
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    t0 = time.perf_counter()
    proc = ctx.Process(target=_child, args=(cell.func, cell.kw, child), daemon=True)
    proc.start()
    child.close()
    rec = None
    if parent.poll(cell.budget):
        try:
            rec = parent.recv()
        except EOFError:
            rec = None
    wall = time.perf_counter() - t0
    if proc.is_alive():
        proc.terminate()
        proc.join(5)
        if proc.is_alive():
            proc.kill()
    proc.join(5)
    if rec is None:
        died = wall < cell.budget
        rec = {"exception": "process died" if died else "timeout",
               "message": (f"child exited with code {proc.exitcode}" if died
                           else f"no result within the budget of {cell.budget:g} s")}
    rec["wall_time_s"] = wall
    rec.update(group=cell.group, case=cell.name, tolerance=cell.tolerance, budget_s=cell.budget)
    rec["verdict"], rec["reason"] = _verdict(cell, rec)
    return rec


def _child(func, kw, conn):
    import logging

    logging.disable(logging.WARNING)
    try:
        rec = globals()[func](**kw)
    except BaseException as exc:  # recorded, judged by the parent
        rec = {"exception": type(exc).__name__, "message": str(exc),
               "traceback": "".join(traceback.format_exception(exc)[-6:])}
        res = getattr(exc, "result", None)
        if res is not None and hasattr(res, "tangent_modes"):
            rec.update(iterations=res.iterations, load_steps=len(res.load_steps), cutbacks=res.cutbacks,
                       tangent_modes=dict(res.tangent_modes), lam=res.lam)
    conn.send(_plain(rec))
    conn.close()


def _plain(v):
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    return v


def _verdict(cell: Cell, rec: dict) -> tuple[str, str]:
    exc = rec.get("exception")
    if exc == "timeout":
        return "FAIL", f"hang: {rec['message']}"
    if exc == "process died":
        return "FAIL", f"crash: {rec['message']}"
    if exc is not None:
        if exc in cell.expected:
            named = "element" in rec["message"]
            if exc in ("PatchError", "MeshError") and not named:
                return "FAIL", f"{exc} does not name the element"
            return "expected stop", f"{exc}, the right behaviour for this input"
        if exc in cell.limitation:
            return "limitation", f"{exc} although a solution exists"
        return "FAIL", f"crash: unexpected {exc}"
    if rec.get("stopped"):
        if rec["stopped"] in cell.expected and rec.get("right_behaviour"):
            return "expected stop", f"{rec['stopped']}; the suggested dt ran ({rec['suggested_run']})"
        return "FAIL", f"{rec['stopped']} with a suggestion that does not work ({rec.get('suggested_run')})"
    if not rec.get("converged"):
        return "FAIL", "returned without converging and without an error"
    err = rec.get("error")
    if cell.tolerance is None or err is None:
        return "converged", "no reference"
    if not (isinstance(err, float) and math.isfinite(err)) or err > cell.tolerance:
        if rec.get("warnings") and isinstance(err, float) and math.isfinite(err):
            # not silent: the model warned at construction that this mesh is outside its accuracy
            return "limitation", (f"error {fmt_err(err)} > {fmt_err(cell.tolerance)} on a mesh the model warned "
                                  f"about: {_short(rec['warnings'][0], 90)}")
        return "FAIL", f"wrong answer reported as converged: error {fmt_err(err)} > {fmt_err(cell.tolerance)}"
    return "pass", f"error {fmt_err(err)} <= {fmt_err(cell.tolerance)}"


def _modes(rec) -> str:
    m = rec.get("tangent_modes") or {}
    return ", ".join(f"{k} {v}" for k, v in m.items() if v) or ""


def run(quick: bool = False, *, out=None) -> BenchmarkResult:
    import logging

    log = logging.getLogger(__name__)
    records = []
    for cell in cells(quick):
        rec = run_cell(cell)
        log.info("%s | %s: %s (%s) %.1f s", cell.group, cell.name, rec["verdict"], rec["reason"], rec["wall_time_s"])
        print(f"  {rec['verdict']:13s} {cell.group}: {cell.name} ({rec['wall_time_s']:.1f} s) {rec['reason']}",
              flush=True)
        records.append(rec)
    fails = [r for r in records if r["verdict"] == "FAIL"]
    result = BenchmarkResult(
        name="stability", title="Stability matrix: extremes of stiffness, mesh, load and time step",
        citation="heavy elastica, Timoshenko, exact circle, half-step runs",
        reference="Per cell: the extensible heavy elastica (strips), Timoshenko's clamped plate (sheets), the "
                  "exact circle of the end-moment roll-up (Sze et al. 2004), the same explicit run at half the "
                  "step, and dt ~ sqrt(s) for mass scaling; pedestal drapes have none.",
        tolerance="No FAIL cell: no hang (each cell has a wall-time budget in a child process), no crash "
                  "(unexpected exception type), no wrong answer reported as converged (error above the cell's "
                  "tolerance: 3 x the measured O(h^2) discretisation error of the mesh, >= 0.5 % of L for "
                  "strips). ConvergenceError where a solution exists is a reported limitation.")
    result.rows = [_row(r) for r in records]
    result.passed = not fails
    counts = {v: sum(r["verdict"] == v for r in records)
              for v in ("pass", "converged", "expected stop", "limitation", "FAIL")}
    result.sections.append(("Summary", ", ".join(f"{v}: {k}" for v, k in counts.items())
                            + f" ({len(records)} cells, {sum(r['wall_time_s'] for r in records):.0f} s)."))
    groups = list(dict.fromkeys(r["group"] for r in records))
    for g in groups:
        lines = ["| cell | outcome | why | value (reference) | error (tolerance) | iterations / steps | load steps | cutbacks | "
                 "tangent modes | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|"]
        for r in records:
            if r["group"] != g:
                continue
            tol = f" ({fmt_err(r['tolerance'])})" if r.get("tolerance") is not None else ""
            err = fmt_err(r.get("error")) + tol if r.get("error") is not None else ""
            outcome = "**FAIL**" if r["verdict"] == "FAIL" else r["verdict"]
            why = r["reason"]
            if r.get("exception") and r["exception"] not in ("timeout",):
                why += f": `{_short(r['message'])}`"
            if r.get("stopped"):
                why += f": `{_short(r['message'])}`"
            val = _val(r.get("value")) + (f" ({_val(r.get('reference'))})" if r.get("reference") is not None else "")
            lines.append(f"| {r['case']} | {outcome} | {why} | {val} | {err} | {r.get('iterations', '')} | "
                         f"{r.get('load_steps', '')} | {r.get('cutbacks', '')} | {_modes(r)} | "
                         f"{r['wall_time_s']:.1f} |")
        result.sections.append((g, "\n".join(lines)))
    for r in fails:
        result.notes.append(f"FAIL {r['group']} / {r['case']}: {r['reason']}"
                            + (f"; {r.get('exception')}: {_short(r.get('message', ''), 300)}"
                               if r.get("exception") else ""))
        if r.get("traceback"):
            result.notes.append("traceback: `" + r["traceback"].strip().replace("\n", " / ")[-600:] + "`")
    locking = [r for r in records if r["group"] == "stiffness ratio: strip" and r.get("membrane_energy_share")]
    if locking:
        result.notes.append("Membrane / bending energy at equilibrium (strip, by C/B): " + "; ".join(
            f"{r['case'].split(', ')[1]} {r['case'].split(',')[0][6:]}: {r['membrane_energy_share']:.2g}"
            for r in locking) + ". The physical share falls as B/C (RFT3); a share that grows with C/B is "
                            "parasitic membrane strain in bending (membrane locking), which makes the strip too "
                            "stiff: a wrong answer on this mesh that disappears only with refinement.")
    result.notes.append("Mass scaling: with the mass damping alpha = 5/s of hang-20 the critical step is "
                        "(sqrt(alpha^2 + 4 w^2) - alpha) / w^2, which is sqrt(s) x the unscaled one only at "
                        "alpha = 0; the reference is that formula at w = w_max / sqrt(s) (value: dt(s) / dt(1)).")
    result.notes.append("Tangent modes: exact (Hessian), psd (compressive stress dropped from the geometric "
                        "stiffness), shift (Levenberg-Marquardt shift), reused (modified Newton step on the last "
                        "factorisation). Explicit cells: iterations = time steps.")
    return result


def _val(v) -> str:
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):
        return ", ".join(_val(x) for x in v)
    return f"{v:.5g}" if isinstance(v, float) else str(v)


def _short(text, n=160) -> str:
    text = " ".join(str(text).split()).replace("|", "/")
    return text if len(text) <= n else text[: n - 3] + "..."


def _row(r) -> dict:
    """A row for the generic report table (and the JSON, which keeps every field)."""
    return dict(r, element=r["group"], mesh=r["verdict"], nodes=r.get("nodes", ""), value=r.get("value"),
                reference=r.get("reference"), error=r.get("error") if r.get("error") is not None else float("nan"),
                iterations=r.get("iterations", ""))
