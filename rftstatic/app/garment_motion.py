"""The ``garment-motion`` analysis: a garment draped on a dress form, then the form turned (keyframes) and the
garment carried round by friction, swinging and settling (issue 37 item 4).

A scene of this kind is a ``garment`` scene (:mod:`rftstatic.app.garment`) with the form's keyframes and the
moving run's options::

    analysis = "garment-motion"
    [body.motion]                 # rftstatic.scenes.motion: the keys of [obstacles.motion]
    times = [0.2, 1.2]            # [time]
    angles = [0.0, 60.0]          # [deg] about axis through centre
    axis = [0.0, 0.0, 1.0]
    [motion]                      # rftstatic.scenes.motion.GarmentMotionOptions
    t_end = 4.0                   # simulated time on the moving form [time]
    friction = 0.4                # garment on the form
    alpha = 2.0                   # mass damping [1/time]

Stages. (1) The static drape of the ``garment`` analysis on the form at rest (:func:`rftstatic.app.garment.run`,
unchanged: the closing, sewing and the Newton drape with its ``[[supports]]``, e.g. the circle skirt's x-hold),
written to ``drape/`` in the run folder. (2) An explicit run (:mod:`rftstatic.app.dynamic`, its outputs: frames,
``series/*.vtu`` + ``series.pvd``, ``animation.gif``, ``energy.png``, ``checkpoint.npz``) from that equilibrium at
rest (with bending or shear hysteresis, from its frictions' committed slips), on the same sewn mesh and contact
surface, the scene's ``[[supports]]`` released (friction now holds the skirt's turn), with Coulomb friction
``motion.friction`` on the form's surface, which moves by its keyframes: the form is a penalty obstacle evaluated
in its pose (:mod:`rftstatic.contact.motion`, the pose is State, the Model frozen), and a node sticking to it is
carried at the surface's velocity. The form's own surface at every saved state is written as
``series/body_<k>.vtu`` (``body.pvd``).

Measures (``summary.json``, ``garment_motion``, scene units): the form's crossing check (the garment taken into the
form's body frame and checked against ``body.obj``, the form itself: ``body_crossing_pairs`` at every saved state,
0 required), the self-intersections of every saved state (the dynamic summary's ``self_intersections``), the
kinetic energy against time (``kinetic_energy``) and the rest test: **settled** when the kinetic energy has stayed
below ``motion.rest_tolerance`` of its peak from some time after the form stopped to the end (``time_at_rest``);
and the settled garment against the static drape turned with the form (the drape's positions moved by the form's
final pose): hem drape coefficient and hem folds of both, the largest and RMS node distance.
"""

from __future__ import annotations

import copy
import logging
from pathlib import Path

import numpy as np

from rftstatic.app import garment
from rftstatic.app.result import RunResult
from rftstatic.errors import ParameterError
from rftstatic.io.files import to_jsonable, write_json, write_pvd, write_vtu
from rftstatic.optionspec import from_table
from rftstatic.post.measures.boundary import boundary_loop, fold_count
from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
from rftstatic.post.measures.shadow import shadow_area
from rftstatic.scenes.motion import GarmentMotionOptions

__all__ = ["run", "resume_scene", "motion_options", "moving_scene"]

log = logging.getLogger(__name__)

DRAPE = "drape"
"""Sub-folder of the run with the static drape on the form at rest (the ``garment`` analysis' outputs)."""


def motion_options(scene) -> tuple[GarmentMotionOptions, dict]:
    """The scene's ``[motion]`` checked (SI) and as given (scene units); its ``[body.motion]`` must exist."""
    table = scene.get("motion", {})
    try:
        si = from_table((GarmentMotionOptions,), table, "motion", scene.units)[GarmentMotionOptions]
        opts = GarmentMotionOptions(**si)
    except ParameterError as exc:
        raise scene.error(exc.key, exc.detail) from None
    if not isinstance(scene.get("body.motion"), dict):
        raise scene.error("body.motion", 'analysis = "garment-motion" turns the form by keyframes: give [body.motion] '
                          "with times and angles (the keys of obstacles.motion)")
    given = {k: table.get(k, getattr(GarmentMotionOptions, k)) for k in ("t_end", "alpha", "samples",
                                                                       "rest_tolerance")}
    return opts, given


def _drape_scene(scene):
    """The ``garment`` scene of stage 1: the same garment and form, at rest."""
    data = copy.deepcopy(scene.data)
    data["analysis"] = "garment"
    data.pop("motion", None)
    data["body"].pop("motion", None)
    return type(scene)(data, scene.path, scene.name, scene.overrides)


def moving_scene(scene, body_obj: Path, given: dict, opts: GarmentMotionOptions, smooth: float = 0.0):
    """The ``dynamic`` scene of stage 2: the form's contact surface ``body_obj`` (an OBJ in metres, its smooth
    surface's support ``smooth`` in scene lengths: the drape's ``garment.contact_smoothing``) as a mesh obstacle with
    the friction and the keyframes; no supports, no static solver; ``[dynamics]`` from ``[motion]`` (``given``: its
    values in scene units)."""
    data = copy.deepcopy(scene.data)
    for key in ("garment", "solver", "supports", "motion"):
        data.pop(key, None)
    body = data.pop("body")
    data["analysis"] = "dynamic"
    data["obstacles"] = [{"type": "mesh", "path": str(Path(body_obj).resolve()), "units": "m",
                          "smooth": smooth,
                          "feature_angle": garment.BODY_FEATURE_ANGLE, "friction": opts.friction,
                          "motion": body["motion"]}]
    t_end = given["t_end"]
    keys = body["motion"].get("times", []) if isinstance(body["motion"], dict) else []
    frames = sorted({0.0, float(t_end), *(float(t) for t in keys if isinstance(t, (int, float)) and 0 <= t <= t_end)})
    data["dynamics"] = {"t_end": t_end, "alpha": given["alpha"], "samples": int(given["samples"]),
                        "rest_tolerance": given["rest_tolerance"], "frames": frames}
    return type(scene)(data, scene.path, scene.name, scene.overrides)


def _stage(scene, out, opts, given):
    """The moving stage's scene, its keyframes checked (before the drape is run: a bad key fails at once)."""
    from rftstatic.scenes.motion import obstacle_motion

    stage = moving_scene(scene, out / DRAPE / "body-m.obj", given, opts)
    try:
        motion = obstacle_motion(stage, 1)
    except Exception as exc:  # the stage's keys are the scene's [body.motion]: name them so
        raise type(exc)(str(exc).replace("obstacles.0.motion", "body.motion")) from None
    if not motion.end < opts.t_end:
        raise scene.error("motion.t_end", f"{given['t_end']!r} ends before the form stops (body.motion.times end at "
                          f"{motion.end / scene.units.time:g}): give a t_end after the last keyframe, with time to "
                          "settle")
    return stage


def run(scene, out: Path, *, progress=True, figures=True, resume=False):
    """Drape the garment on the form at rest, then turn the form and let the garment settle (module docstring);
    returns the :class:`~rftstatic.app.result.RunResult` of the moving run (its summary with ``garment_motion``
    and the drape's ``garment`` measures)."""
    from rftstatic.app import dynamic

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    from rftstatic.scenes.build import build_model

    opts, given = motion_options(scene)
    stage = _stage(scene, out, opts, given)
    drape = garment.run(_drape_scene(scene), out / DRAPE, progress=progress, figures=figures)
    stage = moving_scene(scene, out / DRAPE / "body-m.obj", given, opts, drape.summary["garment"]["contact_smoothing"])
    model, extras = build_model(stage, mesh=drape.model.mesh, contact="penalty", start_check=False)
    summary, explicit = dynamic._run(stage, model, extras, out, progress=progress, figures=figures, resume=resume,
                                     U0=drape.U, slip=drape.slip)
    form = garment.dress_form(scene)
    summary["analysis"] = "garment-motion"
    summary["garment"] = drape.summary.get("garment")
    summary["garment_motion"] = to_jsonable(_measures(scene, model, drape, explicit, form, opts, out))
    write_json(out / "summary.json", summary)
    log.info("garment-motion: settled %s, body crossings %s", summary["garment_motion"]["settled"],
             summary["garment_motion"]["max_body_crossing_pairs"])
    return RunResult(summary, model, explicit.U, extras, out, slip=explicit.state.slip)


def resume_scene(scene, out_dir, *, progress=True, figures=True) -> dict:
    """Run the drape again (deterministic) and continue the moving run from ``out_dir/checkpoint.npz``."""
    return run(scene, Path(out_dir), progress=progress, figures=figures, resume=True).summary


def _measures(scene, model, drape, explicit, form, opts, out) -> dict:
    """The ``garment_motion`` table (module docstring), and the form's surface at every saved state."""
    u = scene.units
    motion = model.contact.motion
    P, T = form.surface()
    tri = model.mesh.tri
    crossings, bodies = [], []
    (out / "series").mkdir(exist_ok=True)
    for k, (t, U) in enumerate(explicit.frames):
        pose = motion.poses(t)
        x = model.positions(U)
        crossings.append(int(obstacle_crossings(pose.to_body(x, 0), tri, P, T)["pairs"]))
        name = f"series/body_{k:04d}.vtu"
        moved = (P - pose.centre[0]) @ pose.rotation[0].T + pose.centre[0] + pose.translation[0]
        write_vtu(out / name, P, moved - P, T, length_unit_scale=u.length)
        bodies.append((t / u.time, name))
    write_pvd(out / "body.pvd", bodies)
    h = explicit.history
    end_pose = motion.poses(explicit.t)
    x_end = model.positions(explicit.U)
    x_static = drape.model.positions(drape.U)
    c, R, s = end_pose.centre[0], end_pose.rotation[0], end_pose.translation[0]
    turned = (x_static - c) @ R.T + c + s
    d = np.linalg.norm(x_end - turned, axis=1)
    peak = float(h["kinetic"].max())
    after = h["time"] >= motion.end
    settled_from = explicit.time_at_rest
    return {
        "friction": opts.friction, "form_stops_at": motion.end / u.time,
        "final_angle_deg": float(np.degrees(np.arccos(np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0)))),
        "body_crossing_pairs": crossings, "max_body_crossing_pairs": int(max(crossings, default=0)),
        "saved_states": len(crossings), "body_series": "body.pvd",
        "kinetic_energy": {"time": h["time"] / u.time, "kinetic": h["kinetic"] / u.energy},
        "peak_kinetic": peak / u.energy,
        "peak_kinetic_after_stop": float(h["kinetic"][after].max()) / u.energy if after.any() else None,
        "final_kinetic_share": float(h["kinetic"][-1]) / max(peak, 1e-300),
        "rest_test": f"kinetic energy <= {opts.rest_tolerance:g} x its peak from time_at_rest to the end, "
                     "time_at_rest after the form stopped",
        "time_at_rest": None if settled_from is None else settled_from / u.time,
        "settled": bool(settled_from is not None and settled_from >= motion.end),
        "compared_with_static_turned": {
            "max_node_distance": float(d.max()) / u.length,
            "rms_node_distance": float(np.sqrt(np.mean(d**2))) / u.length,
            "hem_drape_coefficient": _dc(model, x_end), "hem_drape_coefficient_static": _dc(model, turned),
            "hem_folds": _folds(model, x_end), "hem_folds_static": _folds(model, turned)},
    }


def _dc(model, x) -> float:
    """Hem drape coefficient ``A_shadow / A_flat`` (:mod:`rftstatic.app.garment`) at positions ``x (N, 3)`` [m]."""
    return float(shadow_area(x, model.mesh.tri) / model.mesh.area.sum())


def _folds(model, x):
    """Hem folds about the form's axis (:func:`rftstatic.post.measures.boundary.fold_count`), or None."""
    try:
        return int(fold_count(x, boundary_loop(model.mesh.tri, x), (0.0, 0.0)).count)
    except ValueError:
        return None
