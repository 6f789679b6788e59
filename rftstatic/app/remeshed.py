"""Run a scene with a ``[remesh]`` table: global adaptive remeshing (Sze & Zhou 2016, §5.2 and §6).

``analysis = "static"``
    :func:`rftstatic.remesh.remesh_static`: Newton solve, size a new mesh from the converged
    curvature by Eq. 28-29 (|kappa| h_new^2 = const, h clipped to [h_lower, h_upper]), transfer U,
    solve again, until the node count changes by less than ``tol`` (and max |kappa| h <= ``kappa_h_max``
    when the scene sets it).
``analysis = "relax"`` (§6, Figs. 14-16)
    :func:`rftstatic.remesh.remesh_relax`: the damped explicit motion (Eq. 16-22, damping Eq. 27
    with ``[dynamics] alpha``) with the mass scaled by ``[dynamics] mass_scale`` (§6: 100; the weight
    is not scaled), remeshed every ``every`` steps or when max |kappa| h^2 > ``kappa_h2_max``, U and V
    transferred, until the sheet rests on a mesh that no longer changes, or ``[dynamics] t_end``.
    Obstacles act kinematically (§6.3): the static solver's penalty contact is dropped.

Outputs in the run folder, every number in the scene's units:

* ``summary.json``: scene, element, route, final node and triangle counts, converged flag, wall
  time, the ``[remesh]`` settings, one record per mesh (cycle, time and step, reason, node and
  triangle counts, mesher quality, largest |kappa| h and |kappa| h^2, node-count change, wall time),
  the drape measures of the final state (:func:`rftstatic.run.drape_summary`) and the probes;
* ``mesh_<k>_{top,iso}.png``: the deformed sheet with its mesh edges at each successive mesh
  (relax: the transferred state just after remesh k; static: the equilibrium on mesh k is only
  known for the last mesh, so the earlier ones are drawn flat in the top view), ``remesh.gif``
  (the isometric frames), ``nodes.png`` (node count against time or cycle);
* ``deformed.vtu`` and ``view_{side,top,iso}.png`` of the final state (:func:`rftstatic.run.write_outputs`).
"""

from __future__ import annotations

import logging
import platform
import time
from pathlib import Path

import numpy as np

from rftstatic.provenance import __version__
from rftstatic.remesh.adapt import DAMPING
from rftstatic.remesh.transfer import METHODS

log = logging.getLogger(__name__)

__all__ = ["remesh_options", "run_remesh_scene", "solve_remesh_scene", "summarize"]

SAFETY = 0.5
_LENGTH_KEYS = ("const", "h_lower", "h_upper", "kappa_h2_max")
_DEFAULTS = {"gradation": 1.3, "max_cycles": 5, "tol": 0.05, "kappa_h_max": None, "transfer": "mesh",
             "every": None, "kappa_h2_max": None, "damping": "fixed"}


def remesh_options(scene) -> dict:
    """The scene's ``[remesh]`` table with defaults, checked, lengths in SI [m]."""
    r = {**_DEFAULTS, **dict(scene.get("remesh", {}))}
    for key in ("const", "h_lower", "h_upper"):
        if key not in r:
            raise scene.error(f"remesh.{key}", f"a [remesh] table needs {key} (Eq. 29, scene length units)")
    for key in ("const", "h_lower", "h_upper", "gradation", "tol", "kappa_h_max"):
        if key == "kappa_h_max" and r[key] is None:
            continue
        if not (isinstance(r[key], (int, float)) and r[key] > 0):
            raise scene.error(f"remesh.{key}", f"must be a positive number, got {r[key]!r}")
    if r["gradation"] < 1:
        raise scene.error("remesh.gradation", f"must be >= 1 (a size ratio), got {r['gradation']!r}")
    if r["h_lower"] > r["h_upper"]:
        raise scene.error("remesh.h_lower", f"h_lower = {r['h_lower']} exceeds h_upper = {r['h_upper']}")
    if r["transfer"] not in METHODS:
        raise scene.error("remesh.transfer", f'"{r["transfer"]}" is unknown; use one of {", ".join(METHODS)}')
    if r["damping"] not in DAMPING:
        raise scene.error("remesh.damping", f'"{r["damping"]}" is unknown; use one of {", ".join(DAMPING)}')
    for key in ("every", "max_cycles"):
        if r[key] is not None and not (isinstance(r[key], int) and r[key] >= (1 if key == "every" else 0)):
            raise scene.error(f"remesh.{key}", f"must be a {'positive' if key == 'every' else 'non-negative'} "
                              f"integer, got {r[key]!r}")
    if r["kappa_h2_max"] is not None and not r["kappa_h2_max"] > 0:
        raise scene.error("remesh.kappa_h2_max", f"must be a positive length, got {r['kappa_h2_max']!r}")
    u = scene.units.length
    return {k: (v * u if k in _LENGTH_KEYS and v is not None else v) for k, v in r.items()}


class _TimeUp(Exception):
    """Raised by the stepper when the simulated time reaches ``[dynamics] t_end``."""


class _Tracker:
    """Wraps the explicit stepper: snapshots each new mesh (model, U, t, steps) and stops at t_end."""

    def __init__(self, advance, t_end):
        self.advance, self.t_end = advance, t_end
        self.t, self.steps, self.meshes, self.last = 0.0, 0, [], None

    def __call__(self, model, U, V, n):
        if not self.meshes or self.meshes[-1]["model"] is not model:
            self.meshes.append({"model": model, "U": U.copy(), "t": self.t, "step": self.steps})
        if self.t >= self.t_end:
            self.last = (model, U, V)
            raise _TimeUp
        U, V, dt = self.advance(model, U, V, n)
        self.t += float(dt)
        self.steps += n
        self.last = (model, U, V)
        return U, V, dt


def run_remesh_scene(scene, out, *, progress=True, figures=True) -> dict:
    """Run a scene that has a ``[remesh]`` table and write its outputs into ``out`` (module docstring).

    Returns the summary as written to ``summary.json`` (plain Python types, scene units).
    """
    from rftstatic.io.files import to_jsonable

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    opts = remesh_options(scene)
    run = solve_remesh_scene(scene, opts)
    summary = summarize(scene, opts, run)
    _write(scene, run, out, summary, figures=figures)
    return to_jsonable(summary)


def solve_remesh_scene(scene, opts=None) -> dict:
    """Run the remeshing route of ``scene``; return the final ``model``, ``U`` [m], ``extras``,
    ``records``, ``converged``, ``meshes`` (the snapshots drawn as frames) and ``wall_time_s``."""
    opts = remesh_options(scene) if opts is None else opts
    analysis = scene.get("analysis", "static")
    t0 = time.perf_counter()
    if analysis == "static":
        run = _static(scene, opts)
    elif analysis == "relax":
        run = _relax(scene, opts)
    else:
        raise scene.error("analysis", f'"{analysis}" cannot be remeshed; use "static" or "relax" with [remesh]')
    run["wall_time_s"] = time.perf_counter() - t0
    return run


def _static(scene, opts) -> dict:
    from rftstatic.remesh.adapt import remesh_static
    from rftstatic.scenes.build import build_model

    meshes = []

    def factory(mesh=None):
        model, extras = build_model(scene, mesh=mesh)
        meshes.append({"model": model, "U": None, "t": 0.0, "step": 0})
        return model, extras

    res = remesh_static(factory, const=opts["const"], h_lower=opts["h_lower"], h_upper=opts["h_upper"],
                        max_cycles=opts["max_cycles"], tol=opts["tol"], kappa_h_max=opts["kappa_h_max"],
                        gradation=opts["gradation"], transfer=opts["transfer"], options=_static_opts(scene))
    meshes[-1]["U"] = res.result.U
    return {"route": "remesh_static", "model": res.model, "extras": res.extras, "U": res.result.U,
            "records": res.records, "converged": bool(res.converged and res.result.converged),
            "meshes": meshes, "t": None, "steps": None, "skipped": 0}


def _static_opts(scene):
    from rftstatic.app.static import static_options

    return static_options(scene, progress=False)


def _relax(scene, opts) -> dict:
    from rftstatic.app.dynamic import dynamic_model, dynamics_options
    from rftstatic.remesh.adapt import (
        RemeshRecord,
        _curvature_figures,
        explicit_advance,
        refinable_maxima,
        remesh_relax,
    )
    from rftstatic.scenes.build import build_model

    d = dynamics_options(scene)

    def factory(mesh=None):
        model, extras = build_model(scene, mesh=mesh)
        return _with_contact_reaction(dynamic_model(scene, model, extras), extras.get("obstacles", ())), extras

    model0, extras0 = factory(None)
    stepper = explicit_advance(alpha=d["alpha"], mass_scale=d["mass_scale"], dt=d["dt"], safety=SAFETY,
                               obstacles=tuple(extras0.get("obstacles", ())), damping=opts["damping"])
    track = _Tracker(stepper, d["t_end"])
    first = [(model0, extras0)]

    def make(mesh=None):  # hand the already built initial model to the driver
        return first.pop() if mesh is None and first else factory(mesh)

    try:
        res = remesh_relax(make, const=opts["const"], h_lower=opts["h_lower"], h_upper=opts["h_upper"],
                           advance=track, mass_scale=d["mass_scale"], every=opts["every"],
                           kappa_h2_max=opts["kappa_h2_max"], max_steps=10**9, tol=opts["tol"],
                           tol_force=d["force_tolerance"], tol_kinetic=d["rest_tolerance"],
                           gradation=opts["gradation"], transfer=opts["transfer"])
        model, U, records, converged, skipped = res.model, res.U, res.records, res.converged, res.skipped
        t, steps = res.t, res.steps
    except _TimeUp:
        # the driver keeps its records to itself; rebuild them from the meshes the stepper saw
        model, U, _ = track.last
        records = []
        for k, m in enumerate(track.meshes):
            mm = m["model"]
            records.append(RemeshRecord(k, mm.mesh.n_nodes, mm.mesh.n_elements,
                                        dict(mm.mesh.info.get("quality", {})), time=m["t"], step=m["step"],
                                        reason="initial" if k == 0 else "remesh"))
        kappa, records[-1].max_kappa_h, records[-1].max_kappa_h2 = _curvature_figures(model, U)
        records[-1].refinable_kappa_h, records[-1].refinable_kappa_h2 = refinable_maxima(
            model.mesh, kappa, const=opts["const"], h_lower=opts["h_lower"])
        converged, skipped, t, steps = False, 0, track.t, track.steps
        log.warning("remesh relax: t_end = %.4g s reached before the sheet came to rest on a settled mesh",
                    d["t_end"])
    meshes = track.meshes
    meshes.append({"model": model, "U": U, "t": t, "step": steps, "final": True})
    extras = extras0  # probes and obstacles are defined in reference coordinates: the same on every mesh
    return {"route": "remesh_relax", "model": model, "extras": extras, "U": U, "records": records,
            "converged": bool(converged), "meshes": meshes, "t": t, "steps": steps, "skipped": skipped,
            "dynamics": d, "alphas": list(stepper.alphas)}


def _with_contact_reaction(model, obstacles):
    """``model`` whose ``residual(U)`` counts the kinematic contact's reaction.

    :func:`rftstatic.remesh.remesh_relax` tests rest with ``model.residual(U)`` = F(U) - P, which
    knows nothing of the kinematic obstacles: the weight carried by a pedestal stays in it and the
    sheet never counts as at rest. At a node touching an obstacle (phi below 1e-3 of the smallest
    element size) a frictionless reaction lam n (n the outward normal, lam >= 0) acts; lam is the one
    that best balances the node's free dofs, lam = max(0, r_f . n_f / |n_f|^2) with r_f, n_f the
    residual and the normal on the free components (on a fully free node lam = max(r . n, 0); on
    a node whose x and y are held, e.g. the in-plane hold on top of a sphere, the support takes
    the in-plane part of lam n), and r -> r - lam n there. The instance's class is swapped for a
    subclass with that ``residual``; everything else (forces, mass, step) is the model's own.
    """
    if not obstacles:
        return model
    base = type(model)
    tol = 1e-3 * float(model.mesh.element_size.min())

    class KinematicContactModel(base):
        def residual(self, U, lam=1.0):
            r = base.residual(self, U, lam)
            x = self.X3 + U
            for ob in obstacles:
                phi, n = ob.signed_distance(x)
                touch = phi <= tol
                nf = n[touch] * self.free[touch]
                nn = np.einsum("ni,ni->n", nf, nf)
                rn = np.einsum("ni,ni->n", r[touch] * self.free[touch], nf)
                reaction = np.where(nn > 0, np.maximum(rn, 0.0) / np.where(nn > 0, nn, 1.0), 0.0)
                r[touch] -= reaction[:, None] * n[touch]
            return r

    KinematicContactModel.__name__ = f"KinematicContact{base.__name__}"
    model.__class__ = KinematicContactModel
    return model


def summarize(scene, opts, run) -> dict:
    """The summary (scene units) of a :func:`solve_remesh_scene` run."""
    from rftstatic.app.static import drape_summary
    from rftstatic.scenes.build import probe_positions

    u = scene.units
    model, U = run["model"], run["U"]
    records = []
    for r in run["records"]:
        d = r.as_dict()
        d["time"] = d["time"] / u.time
        d["max_kappa_h2"] = d["max_kappa_h2"] / u.length
        d["refinable_kappa_h2"] = d["refinable_kappa_h2"] / u.length
        records.append(d)
    settings = {k: (v / u.length if k in _LENGTH_KEYS and v is not None else v) for k, v in opts.items()}
    summary = {
        "scene": scene.name, "title": scene.get("title", ""), "figure": scene.get("figure", ""),
        "units": u.name, "overrides": scene.overrides, "element": model.element,
        "analysis": scene.get("analysis", "static"), "route": run["route"],
        "nodes": model.mesh.n_nodes, "elements": model.mesh.n_elements, "initial_nodes": records[0]["nodes"],
        "remeshes": len(records) - 1, "converged": run["converged"], "wall_time_s": run["wall_time_s"],
        "remesh": settings, "records": records,
        "max_relative_curvature": float(model.relative_curvature(U).max()),
    }
    if run["route"] == "remesh_relax":
        d = run["dynamics"]
        summary.update(t=run["t"] / u.time, steps=run["steps"], skipped_remeshes=run["skipped"],
                       t_end=d["t_end"] / u.time, alpha=d["alpha"] * u.time, mass_scale=d["mass_scale"],
                       damping=settings["damping"],
                       alpha_final=(run["alphas"][-1] if run.get("alphas") else d["alpha"]) * u.time)
        P = np.where(model.free, model.load, 0.0)
        r = np.where(model.free, model.residual(U), 0.0)
        summary["residual_relative"] = float(np.linalg.norm(r) / max(np.linalg.norm(P), 1e-300))
    else:
        summary["newton_iterations"] = int(run["records"][-1].solve.get("iterations", 0))
    if run["extras"].get("obstacles"):
        summary["drape"] = drape_summary(scene, model, run["extras"], U)
    summary["probes"] = {name: {"reference": (p["reference"] / u.length).tolist(),
                                "deformed": (p["deformed"] / u.length).tolist()}
                         for name, p in probe_positions(model, run["extras"].get("probes", {}), U).items()}
    summary["software"] = {"rftstatic": __version__, "python": platform.python_version()}
    return summary


def _write(scene, run, out: Path, summary: dict, *, figures=True) -> None:
    from rftstatic.app.static import write_outputs
    from rftstatic.io.files import write_json

    write_outputs(scene, run["model"], run["extras"], run["U"], out, summary, figures=figures)
    if not figures:
        return
    summary["frames"] = _frames(scene, run, out)
    _node_plot(scene, summary, out)
    summary["node_plot"] = "nodes.png"
    write_json(out / "summary.json", summary)


def _frames(scene, run, out: Path) -> list:
    """``mesh_<k>_{top,iso}.png`` per mesh (edges drawn) and their GIF ``remesh.gif``."""
    from rftstatic.io.views import plot_views

    u = scene.units
    lu = {"cm-gf-s": "cm", "mm-N-s": "mm", "SI": "m"}.get(u.name, "")
    frames, lo, hi = [], None, None
    states = []
    for k, m in enumerate(run["meshes"]):
        model = m["model"]
        U = m["U"] if m["U"] is not None else np.zeros_like(model.X3)
        x = (model.X3 + U) / u.length
        states.append((k, m, model, x))
        lo = x.min(axis=0) if lo is None else np.minimum(lo, x.min(axis=0))
        hi = x.max(axis=0) if hi is None else np.maximum(hi, x.max(axis=0))
    for k, m, model, x in states:
        label = "final" if m.get("final") else f"mesh {k}"
        when = (f"t = {m['t'] / u.time:.3g} s" if run["route"] == "remesh_relax" else
                ("equilibrium" if m["U"] is not None else "flat reference"))
        title = f"{scene.name}: {label}, {model.mesh.n_nodes} nodes, {when}"
        name = f"mesh_{k:02d}" if not m.get("final") else "mesh_final"
        files = plot_views(str(out / name), x, model.mesh.tri, views=("top", "iso"), title=title, length_unit=lu)
        frames.append({"mesh": label, "nodes": model.mesh.n_nodes, "triangles": model.mesh.n_elements,
                       "time": None if run["route"] != "remesh_relax" else m["t"] / u.time,
                       "files": {v: p.name for v, p in files.items()}})
    _gif(out / "remesh.gif", [out / f["files"]["iso"] for f in frames])
    return frames


def _gif(path: Path, pngs: list) -> None:
    """A GIF of PNG frames (each shown 1 s, the last 3 s), resized to the first frame."""
    from PIL import Image

    from rftstatic.io.files import atomic_write

    imgs = [Image.open(p).convert("RGB") for p in pngs]
    size = imgs[0].size
    imgs = [im if im.size == size else im.resize(size) for im in imgs]
    durations = [1000] * (len(imgs) - 1) + [3000]
    with atomic_write(path) as tmp:
        imgs[0].save(tmp, format="GIF", save_all=True, append_images=imgs[1:], duration=durations, loop=0)


def _node_plot(scene, summary, out: Path) -> None:
    from rftstatic.io.figure import new_figure as _figure
    from rftstatic.io.figure import save_png as _save

    recs = summary["records"]
    relax = summary["route"] == "remesh_relax"
    x = [r["time"] for r in recs] + ([summary["t"]] if relax else [])
    n = [r["nodes"] for r in recs] + ([recs[-1]["nodes"]] if relax else [])
    if not relax:
        x = [r["cycle"] for r in recs]
    fig = _figure((6.4, 4.0))
    ax = fig.add_subplot()
    ax.step(x, n, where="post", marker="o")
    ax.set_xlabel(f"time [{scene.units.name.split('-')[-1] if '-' in scene.units.name else 's'}]" if relax
                  else "remesh cycle")
    ax.set_ylabel("nodes")
    ax.set_title(f"{scene.name}: node count ({summary['element']})")
    ax.grid(alpha=0.3)
    _save(fig, out / "nodes.png")
