"""MEASURE paths: the scalars of a run's ``summary.json`` that a study tabulates and a fit matches.

A MEASURE is a dotted path into the summary (scene units): ``drape.drape_coefficient``,
``drape.fold_count``, ``newton_iterations``, ``wall_time_s``, ... with two shortcuts:

- ``probes.NAME.x`` (``.y``, ``.z``): the deformed coordinate of the scene's probe NAME
  (``summary["probes"][NAME]["deformed"][0..2]``);
- ``cantilever.KEY``: what a cantilever tester run (``analysis = "cantilever"``) writes under
  ``summary["cantilever"]`` (``bending_length``, ``overhang``, ``flexural_rigidity``, ...), read as
  any dotted path; ``cantilever.bending_length`` of a scene without that block (a strip clamped at one
  end, such as ``strip``) is derived from its probe ``tip``: Peirce's c = l (cos(theta/2) / (8 tan
  theta))^(1/3), theta the angle below the horizontal of the chord from the clamped edge to the tip, l
  the overhang (Peirce, J. Text. Inst. 21, 1930, the cantilever test of ASTM D1388; exact for the
  elastica only at theta = 41.5 deg, and a smooth, monotonic function of the bending rigidity B at any
  angle).
"""

from __future__ import annotations

import math

from rftstatic.study.space import StudyError

AXES = {"x": 0, "y": 1, "z": 2}
ROOTS = ("drape", "probes", "cantilever")
KNOWN_SCALARS = ("converged", "load_steps", "newton_iterations", "wall_time_s", "build_time_s", "nodes",
                 "elements", "load_factor", "max_relative_curvature", "peak_memory_mb")
DRAPE = ("drape_coefficient", "fold_count", "shadow_area", "boundary_radius_min", "boundary_radius_mean",
         "boundary_radius_max")


def standard_columns(scene) -> list[str]:
    """The measures every row of ``results.csv`` holds for ``scene``: drape coefficient, fold count and
    the deformed coordinates of each of its probes."""
    cols = ["drape.drape_coefficient", "drape.fold_count"]
    for probe in scene.get("probes", []) or []:
        cols += [f"probes.{probe['name']}.{a}" for a in AXES]
    return cols


def check_measure(path: str, scene, arg: str = "--target") -> None:
    """A :class:`StudyError` when ``path`` cannot name a scalar of ``scene``'s summary."""
    parts = path.split(".")
    probes = [p["name"] for p in scene.get("probes", []) or []]
    problem = None
    if parts[0] == "probes":
        if len(parts) != 3 or parts[2] not in AXES:
            problem = "a probe measure is probes.NAME.x, .y or .z"
        elif parts[1] not in probes:
            problem = f'the scene has no probe "{parts[1]}" (its probes: {", ".join(probes) or "none"})'
    elif parts[0] == "cantilever":
        tester = scene.get("analysis") == "cantilever"
        if len(parts) != 2 or not parts[1]:
            problem = "a cantilever measure is cantilever.KEY, e.g. cantilever.bending_length"
        elif not tester and parts[1] != "bending_length":
            problem = f'{path} needs a cantilever tester scene (analysis = "cantilever")'
        elif not tester and "tip" not in probes:
            problem = ('cantilever.bending_length needs a cantilever tester scene (analysis = "cantilever") or '
                       'a probe named "tip" at the free end of a clamped strip')
    elif parts[0] == "drape":
        if len(parts) != 2 or parts[1] not in DRAPE:
            problem = f"a drape measure is drape.{' / drape.'.join(DRAPE)}"
    elif len(parts) != 1 or parts[0] not in KNOWN_SCALARS:
        problem = ("known measures: probes.NAME.x/y/z, cantilever.KEY, drape.KEY ("
                   + ", ".join(DRAPE) + "), " + ", ".join(KNOWN_SCALARS))
    if problem:
        raise StudyError(f'{arg} "{path}": unknown MEASURE path: {problem}')


def measure(summary: dict, path: str) -> float | int | None:
    """The value of MEASURE ``path`` in ``summary`` (None when the run has none, e.g. no drape)."""
    parts = path.split(".")
    if parts[0] == "probes" and len(parts) == 3:
        probe = (summary.get("probes") or {}).get(parts[1])
        return None if probe is None else float(probe["deformed"][AXES[parts[2]]])
    if parts == ["cantilever", "bending_length"] and "cantilever" not in summary:  # derived (module docstring)
        return bending_length(summary)
    node = summary
    for part in parts:
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    if isinstance(node, bool):
        return float(node)
    if isinstance(node, int):  # a count (fold_count, newton_iterations) stays an integer in results.csv
        return node
    return float(node) if isinstance(node, float) else None


def clamped_edge_x(summary: dict) -> float:
    """x of the first clamped support's box in the resolved scene (0 without one) [length]."""
    for s in summary.get("resolved_scene", {}).get("supports", []):
        if s.get("kind") == "clamped" and "box" in s:
            return float(s["box"][0])
    return 0.0


def bending_length(summary: dict) -> float | None:
    """Peirce's bending length c [length] from the probe ``tip`` (module docstring); None without it."""
    tip = (summary.get("probes") or {}).get("tip")
    if tip is None:
        return None
    x0 = clamped_edge_x(summary)
    overhang = tip["reference"][0] - x0
    reach, drop = tip["deformed"][0] - x0, -(tip["deformed"][2] - tip["reference"][2])
    theta = math.atan2(drop, reach)
    if not 0 < theta < math.pi / 2:
        return None
    return overhang * (math.cos(theta / 2) / (8 * math.tan(theta))) ** (1 / 3)


def flat_measures(summary: dict, paths) -> dict:
    """``{path: value}`` for each path (None where the run has none)."""
    return {p: measure(summary, p) for p in paths}
