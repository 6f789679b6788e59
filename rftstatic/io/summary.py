"""The parts of ``summary.json`` every analysis shares, in the scene's units.

- :func:`summary_header`: what ran (scene, its resolved data, element, mesh, software with git commit and
  code fingerprint, warnings, peak memory);
- :func:`drape_summary`: drape coefficient, fold count and the sharp-fold indicator (§3, Figs. 1 and 8);
- :func:`probe_summary`: reference and deformed positions of the scene's probes;
- :func:`self_intersection_summary`: the self-intersection check (crossing triangle pairs, smallest
  distance between non-adjacent triangles) of the final state, and of every saved state of a dynamic run;
- :func:`obstacle_crossing_summary`: the sheet against each triangle-surface obstacle (crossing pairs,
  smallest surface distance, smallest node distance).
"""

from __future__ import annotations

import copy
import logging

import numpy as np

from rftstatic.post.measures.boundary import boundary_loop, outline_surrounds
from rftstatic.post.measures.intersections import self_intersections
from rftstatic.post.measures.obstacle_crossings import obstacle_crossings
from rftstatic.post.measures.summary import drape_measures
from rftstatic.post.probes import probe_positions
from rftstatic.provenance import peak_memory_mb, software
from rftstatic.scenes.material import material_summary

log = logging.getLogger(__name__)


def summary_header(scene, model, analysis: str) -> dict:
    """Keys every summary starts with: scene, title, figure, units, overrides, element, analysis, nodes,
    elements, mesh, ``kernels`` (the model's kernel back end, ``"numpy"`` or ``"compiled"``,
    :func:`rftstatic.compiled.choose_kernels`: the static solves' membrane and every self-contact loop; an
    explicit run's force loop records its own, ``backend``), software, warnings, peak_memory_mb and ``resolved_scene``
    (the scene's data after the overrides, scene units)."""
    return {
        "scene": scene.name,
        "title": scene.get("title", ""),
        "figure": scene.get("figure", ""),
        "units": scene.units.name,
        "overrides": {k: v for k, v in scene.overrides.items() if k != "resume"},
        "element": model.element,
        "analysis": analysis,
        "nodes": model.mesh.n_nodes,
        "elements": model.mesh.n_elements,
        "mesh": model.mesh.summary(),
        "kernels": model.kernels,
        "software": software(),
        "warnings": list(model.warnings),
        "peak_memory_mb": peak_memory_mb(),
        "resolved_scene": copy.deepcopy(scene.data),
        "material": material_summary(scene, model.material),
    }


def drape_summary(scene, model, extras, U) -> dict:
    """Drape coefficient, fold count and sharp-fold indicator (§3, Figs. 1 and 8) at ``U (N, 3)`` [m], scene units."""
    u = scene.units.length
    x = model.positions(U)
    obstacles = extras["obstacles"]
    disc_area, centre = obstacles[0].footprint() if obstacles else (None, np.zeros(2))
    sheet_area = float(model.mesh.area.sum())
    disc = extras.get("disc") if not obstacles else None
    if disc is not None:  # a tester's clamping disc: the specimen includes the part the mesh leaves open
        disc_area, centre, sheet_area = disc.area, disc.centre, sheet_area + disc.open_area
    reason = None
    if not model.mesh.chart_is_flat:
        reason = ("a garment sewn from panels has no flat sheet to project: its hem's drape coefficient is the "
                  "summary's garment table")
    elif disc_area is not None and not sheet_area > disc_area:
        reason = (f"the sheet ({sheet_area / u**2:.4g} square units) is not larger than the obstacle's footprint "
                  f"({disc_area / u**2:.4g}): no drape coefficient")
    elif disc is None and model.mesh.locate(np.asarray(centre, float)[None, :2])[0][0] < 0:
        reason = (f"the obstacle's centre {np.round(np.asarray(centre) / u, 6).tolist()} is not under the sheet: "
                  "the drape measures (coefficient, folds about the centre) do not apply")
    elif not outline_surrounds(x, boundary_loop(model.mesh.tri, x), centre):
        reason = (f"the draped sheet's outline (top view) does not surround the obstacle's centre "
                  f"{np.round(np.asarray(centre) / u, 6).tolist()} (the sheet slid off it): the drape measures "
                  "(coefficient, folds about the centre) do not apply")
    if reason is not None:
        log.warning("drape measures skipped: %s", reason)
        return {"applicable": False, "reason": reason}
    m = drape_measures(x, model.mesh.tri, sheet_area=sheet_area, disc_area=disc_area, centre=centre,
                       curvature=model.curvature(U), h=model.mesh.element_size,
                       fill=None if disc is None else disc.fill, profile=disc is not None)
    m = _scale_lengths(m, u)
    if disc is not None:
        m["disc"] = {"area": disc.area / u**2, "specimen_area": sheet_area / u**2,
                     "centre": (np.asarray(disc.centre) / u).tolist()}
    return m


_LENGTH_KEYS = ("boundary_radius_min", "boundary_radius_mean", "boundary_radius_max", "max_dihedral_at",
                "max_relative_curvature_at")


def _scale_lengths(m: dict, u: float) -> dict:
    """Drape measures from SI to the scene's length unit ``u`` [m]."""
    out = dict(m)
    if "shadow_area" in out:
        out["shadow_area"] = out["shadow_area"] / u**2
    if "hem_profile" in out:
        out["hem_profile"] = {"theta_deg": out["hem_profile"]["theta_deg"],
                              "r": (np.asarray(out["hem_profile"]["r"]) / u).tolist()}
    for key in _LENGTH_KEYS:
        if key in out and out[key] is not None:
            out[key] = (np.asarray(out[key], float) / u).tolist()
    return out


def probe_summary(scene, model, probes: dict, U) -> dict:
    """``{name: {"reference": [x, y, z], "deformed": [x, y, z]}}`` in scene length units."""
    u = scene.units.length
    return {name: {"reference": (p["reference"] / u).tolist(), "deformed": (p["deformed"] / u).tolist()}
            for name, p in probe_positions(model, probes, U).items()}


def self_contact_summary(scene, model, *, scale: float = 1.0) -> dict | None:
    """The self-contact's settings and counters (:class:`~rftstatic.contact.self_contact.near_pairs.SelfContactStats`,
    summed over the run's solves), lengths in scene units; None without self-contact. ``stiffness``: the one the
    result holds with, the law's times ``scale`` (the solve's ``self_contact_scale``, raised after convergence
    by the static route; ``stiffness_scale`` gives it). ``pairs``: the near
    pairs (within thickness + margin) of the last broad phase, ``max_pairs`` the most of any;
    ``broad_phase_s`` the builds' wall time, ``force_s`` that of the energy/force/tangent evaluations,
    ``filter_s`` that of the explicit step filter."""
    sc = getattr(model, "self_contact", None)
    if sc is None:
        return None
    u = scene.units
    out = {"thickness": sc.thickness / u.length, "margin": sc.margin / u.length,
           "stiffness": sc.stiffness * scale / (u.force / u.length), "stiffness_scale": scale}
    out.update(sc.stats.as_dict())
    return out


def self_intersection_summary(scene, model, U, *, states=()) -> dict:
    """Self-intersection check (:func:`~rftstatic.post.measures.intersections.self_intersections`) of
    the state ``U (N, 3)`` [m] of ``model``, lengths in the scene's unit.

    ``states``: a dynamic run's saved states, ``(t [s], U (N, 3) [m])`` pairs, each checked for crossings too
    (the smallest distance of the final state only: it costs 4 x the crossing count, 5 % of a hang-20 run
    for its 33 states): the record then adds ``saved_states``, ``pairs_saved`` (one count per state),
    ``max_pairs_saved`` and ``max_pairs_at`` (the first state time with the most pairs, scene time unit).
    ``seconds`` is the wall time of all the checks; ``smallest_distance`` is ``None``
    (JSON null) when no two non-adjacent triangles are within ``within``. A non-finite state is not checked
    (``applicable: false`` for the final one; left out of the saved ones, counted in ``saved_skipped``).
    """
    u = scene.units
    tri = model.mesh.tri
    seconds = 0.0

    def check(V, distance=False):
        nonlocal seconds
        x = model.positions(V)
        if not np.isfinite(x).all():
            return None
        r = self_intersections(x, tri, distance=distance)
        seconds += r["seconds"]
        return r

    last = check(U, distance=True)
    if last is None:
        out = {"applicable": False, "reason": "non-finite positions"}
    else:
        out = {"pairs": last["pairs"], "triangles": last["triangles"], "area_fraction": last["area_fraction"],
               "smallest_distance": last["smallest_distance"] / u.length,
               "smallest_distance_pair": last["smallest_distance_pair"],
               "within": last["within"] / u.length, "tol": last["tol"] / u.length}
    if len(states):
        times, pairs, skipped = [], [], 0
        for t, V in states:
            same = last is not None and (V is U or np.array_equal(V, U))   # the final state, saved
            r = last if same else check(V)
            if r is None:
                skipped += 1
                continue
            times.append(t / u.time)
            pairs.append(r["pairs"])
        out.update(saved_states=len(pairs), saved_skipped=skipped, pairs_saved=pairs)
        if pairs:
            k = int(np.argmax(pairs))
            out.update(max_pairs_saved=pairs[k], max_pairs_at=times[k])
    out["seconds"] = seconds
    return out


def obstacle_crossing_summary(scene, model, extras, U, poses=None) -> list | None:
    """For each obstacle with a triangle surface (:meth:`~rftstatic.contact.obstacles.Obstacle.surface`), the
    independent crossing check of the state ``U (N, 3)`` [m]
    (:func:`~rftstatic.post.measures.obstacle_crossings.obstacle_crossings`: ``pairs`` of sheet and obstacle
    triangles that cross, ``smallest_distance`` between the surfaces) and ``smallest_node_distance``, the least
    signed distance of a node to it (the obstacle's own distance: negative inside) and ``deepest_chord``, the
    least signed distance (0 if none is negative) of a sheet triangle's centroid or edge midpoint (how far the
    flat triangles dip into it between their nodes), lengths in scene units; None when no obstacle has a
    surface. ``poses``: the obstacles' poses (:class:`rftstatic.contact.motion.Poses`) the state is checked
    against (the sheet taken into each obstacle's body frame: a rigid motion keeps every distance); None: as
    built."""
    u = scene.units.length
    x = model.positions(U)
    out = []
    for i, ob in enumerate(extras.get("obstacles", ())):
        surface = ob.surface()
        if surface is None:
            continue
        if not np.isfinite(x).all():
            out.append({"obstacle": i, "applicable": False, "reason": "non-finite positions"})
            continue
        if poses is not None:
            x = poses.to_body(model.positions(U), i)
        r = obstacle_crossings(x, model.mesh.tri, *surface)
        mids = np.concatenate([x[model.mesh.tri].mean(axis=1), 0.5 * (x[model.mesh.topology.edges].sum(axis=1))])
        out.append({"obstacle": i, "pairs": r["pairs"], "first": r["first"],
                    "smallest_distance": r["smallest_distance"] / u,
                    "smallest_node_distance": float(ob.signed_distance(x)[0].min()) / u,
                    "deepest_chord": float(min(0.0, ob.signed_distance(mids)[0].min())) / u,
                    "within": r["within"] / u, "tol": r["tol"] / u, "seconds": r["seconds"]})
    return out or None


def warn_crossings(summary: dict, *, self_contact: bool) -> None:
    """Add to ``summary["warnings"]`` (and the log) that the final state crosses itself, when its
    ``self_intersections`` count pairs: a converged flag beside a sheet that passed through itself is not a
    physical equilibrium. The fix named depends on ``self_contact`` (on: its stiffness or the mesh; off: turn
    it on)."""
    pairs = (summary.get("self_intersections") or {}).get("pairs", 0)
    if not pairs:
        return
    if self_contact:
        text = (f"{pairs} triangle pairs of the final state cross although self-contact is on: the "
                "layers passed through each other, so this equilibrium is not physical; raise "
                "contact.self_factor (or refine the mesh at the fold)")
    else:
        text = (f"{pairs} triangle pairs of the final state cross: the sheet passed through itself (this scene has "
                "no self-contact), so this equilibrium is not physical; set contact.self = true (--set "
                "contact.self=true), or take a gentler route (solver.start)")
    log.warning(text)
    summary.setdefault("warnings", []).append(text)

