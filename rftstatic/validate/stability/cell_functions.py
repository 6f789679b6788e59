"""What each cell of the stability matrix computes (:mod:`rftstatic.validate.stability`).

A cell function takes keywords (numbers, strings, booleans: JSON, since it runs in a child
interpreter) and returns a record: ``converged``, ``value`` and ``reference`` (the computed and the
reference quantity), ``error`` (relative, or per strip length L), ``iterations``, ``nodes`` and
the solver's statistics (``load_steps``, ``cutbacks``, ``tangent_modes``); an exception is the
cell's outcome too (recorded by :mod:`rftstatic.validate.stability.runner`).

Strip cells use Kang & Yu's wool strip of §4.1 (5 x 1 cm, clamped, own weight); the stiffness ratio
C/B [1/cm^2] scales all membrane rigidities with B fixed (wool: C_warp/B_warp = 1.35e4 /cm^2).
Tip error = |computed - elastica tip| / L, the computed tip the mean of the nodes at x = L.
Explicit cells run the hanging sheet hang-20; plate cells the clamped unit Kirchhoff plate.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rftstatic.validate.report import fmt_err

L, WIDTH = 0.05, 0.01  # strip [m]
CM2 = 1e4  # 1/cm^2 in 1/m^2


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
        opts = opts.single_step()
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
    from rftstatic.scenes import build
    from rftstatic.scenes import schema as scene
    from rftstatic.scenes.options import static_options
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
    mod, _ = build.build_model(s)
    opts = static_options(s, progress=False)
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
    mod, _ = build.build_model(s)
    corner = int(mod.mesh.nearest_node([[0.2, 0.1]])[0])
    return mod, corner


def explicit_dt_cell(n=11, *, factor=1.0, steps=1500, alpha=5.0) -> dict:
    """Hanging sheet (hang-20 at n x n) for ``steps`` steps at ``factor`` x the automatic step.

    Reference: the same time at half the automatic step (free-corner displacement). Above the
    critical step an :class:`InstabilityError` is the right behaviour, if the step it suggests runs.
    """
    from rftstatic.errors import InstabilityError
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions
    from rftstatic.solvers.timestep import stable_time_step

    mod, corner = _hang(n)
    est = stable_time_step(mod, alpha=alpha)
    t_end = steps * est.dt
    out = {"dt_over_estimate": factor, "dt_over_critical": factor * est.dt / est.dt_crit, "estimate_dt": est.dt,
           "nodes": mod.mesh.n_nodes}
    ref = run_explicit(mod, ExplicitOptions(t_end=t_end, dt=0.5 * est.dt, alpha=alpha, progress=False))
    try:
        res = run_explicit(mod, ExplicitOptions(t_end=t_end, dt=factor * est.dt, alpha=alpha, progress=False))
    except InstabilityError as exc:
        out.update(stopped="InstabilityError", message=str(exc), suggested_dt=exc.suggested_dt,
                   suggested_over_estimate=exc.suggested_dt / est.dt, t_stop=exc.t)
        try:  # is the suggestion right? rerun with it
            again = run_explicit(mod, ExplicitOptions(t_end=t_end, dt=exc.suggested_dt, alpha=alpha, progress=False))
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
    from rftstatic.solvers.explicit_options import ExplicitOptions
    from rftstatic.solvers.timestep import stable_time_step

    mod, _ = _hang(n)
    base = stable_time_step(mod, alpha=5.0)
    est = stable_time_step(mod, alpha=5.0, mass_scale=scale)
    # with damping dt_crit = (sqrt(a^2 + 4 w^2) - a) / w^2, w = w1 / sqrt(s): exact sqrt(s) only at a = 0
    from rftstatic.solvers.timestep import critical_step

    expect = 0.9 * critical_step(base.omega_max / math.sqrt(scale), 5.0)
    res = run_explicit(mod, ExplicitOptions(t_end=steps * est.dt, mass_scale=scale, alpha=5.0, progress=False))
    return {"converged": True, "value": est.dt / base.dt, "reference": expect / base.dt,
            "sqrt_s": math.sqrt(scale), "error": abs(est.dt / expect - 1), "iterations": res.steps,
            "nodes": mod.mesh.n_nodes, "omega_ratio": base.omega_max / est.omega_max}
