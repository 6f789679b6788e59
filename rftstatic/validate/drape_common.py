"""Shared by the drape reports (``drape_sq20``, ``drape_sharp``, ``drape_folds``): cached scene runs.

Each run is a scene of ``cases/`` with ``mesh.nodes`` and ``element`` overridden, solved in a fresh
interpreter by :func:`rftstatic.bench.drape.run_one` (so its wall time and peak memory are its own)
into ``out/validate-drape/<scene>_n<nx>x<ny>_<element>_code-<fingerprint>/`` of the repository:
``record.json``, ``summary.json``, ``state.npz``, ``deformed.vtu`` and the PNG views. The key holds
the code's fingerprint (:func:`rftstatic.bench.drape.run_key`): a finished run there is reused by the
same code only, never after an edit of the package. Set ``RFTSTATIC_DRAPE_REFRESH=1`` to solve again;
folders of other code versions are left in place (delete them by hand).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from rftstatic.bench.drape import cached_dir, run_cached


def cache_root() -> Path:
    """``out/validate-drape`` of the repository."""
    import rftstatic

    return Path(rftstatic.__file__).resolve().parent.parent / "out" / "validate-drape"


def drape_run(scene: str, nodes, element: str, *, figures: bool = True) -> dict:
    """The record of ``scene`` on ``nodes = (n1, n2)`` with ``element`` (see :func:`rftstatic.bench.drape.child`).

    ``figures=False`` skips the PNG views of a new run (the quick reports: they take a third of a
    small run's time).
    With ``RFTSTATIC_DRAPE_CACHED_ONLY=1`` nothing is solved: a run not in the cache gives None
    (the reports then list it as not run).
    """
    overrides = [f"mesh.nodes=[{nodes[0]},{nodes[1]}]", f"element={element}"]
    if os.environ.get("RFTSTATIC_DRAPE_CACHED_ONLY") == "1" and cached_dir(scene, overrides, root=cache_root()) is None:
        return None
    return run_cached(scene, overrides, root=cache_root(), refresh=os.environ.get("RFTSTATIC_DRAPE_REFRESH") == "1",
                      figures=figures)


def mesh_label(nodes) -> str:
    return f"{nodes[0]}x{nodes[1]}"


def copy_views(rec: dict, out: Path, stem: str, views=("top", "iso")) -> list[str]:
    """Copy the run's ``view_<v>.png`` into ``out`` as ``<stem>_<v>.png``; return the names copied."""
    names = []
    for v in views:
        src = Path(rec["dir"]) / f"view_{v}.png"
        if src.exists():
            shutil.copyfile(src, out / f"{stem}_{v}.png")
            names.append(f"{stem}_{v}.png")
    return names


def solve_row(rec: dict, case: str, value, reference, error) -> dict:
    """A row of the report's "All solves" table from a run record."""
    return {"case": case, "element": rec["element"], "mesh": mesh_label(_nodes(rec)), "nodes": rec["nodes"],
            "value": value, "reference": reference, "error": error, "wall_time_s": rec["build_s"] + rec["solve_s"],
            "iterations": rec["newton_iterations"], "converged": rec["converged"],
            "solver_error": rec.get("error", ""), "peak_rss_mb": rec["peak_rss_mb"]}


def _nodes(rec: dict):
    for o in rec["overrides"]:
        if o.startswith("mesh.nodes="):
            return [int(v) for v in o.split("=", 1)[1].strip("[]").split(",")]
    return [rec["nodes"], 1]


def status(rec: dict) -> str:
    """"yes" or "NO (load factor ...)" for the tables."""
    return "yes" if rec["converged"] else f"NO (load factor {rec['load_factor']:.3f})"


def run_cached_only(scene: str, nodes, element: str) -> dict | None:
    """The cached record of a run by this code, or None when it has not been run (nothing is solved)."""
    overrides = [f"mesh.nodes=[{nodes[0]},{nodes[1]}]", f"element={element}"]
    if cached_dir(scene, overrides, root=cache_root()) is None:
        return None
    return run_cached(scene, overrides, root=cache_root())


def free_indicators(rec: dict, scene: str, *, reach: float = 2.0) -> dict:
    """Dihedral-angle indicators on the interior edges farther than ``reach`` mean element sizes from
    every obstacle (the free-hanging fabric), so that the bend over a pedestal's rim -- physical, and
    sharper than one element when the rim radius is below h -- is told apart from folds in free fabric.

    Returns ``free_edges``, ``free_max_dihedral_deg``, ``free_dihedral_p99_deg``, ``free_edges_over_90deg``.
    """
    import numpy as np

    from rftstatic.contact.obstacles import from_spec
    from rftstatic.post.measures.sharp import dihedral_angles
    from rftstatic.scenes.schema import load_scene

    sc = load_scene(scene, rec["overrides"])
    u = sc.units.length
    x, tri = rec["state"]["x"], rec["state"]["tri"]
    edges, ang = dihedral_angles(x, tri)
    mid = 0.5 * (x[edges[:, 0]] + x[edges[:, 1]]) * u
    phi = np.full(len(mid), np.inf)
    for spec in sc.get("obstacles", []):
        phi = np.minimum(phi, from_spec(spec, u).signed_distance(mid)[0])
    free = np.degrees(ang[phi > reach * rec["h_mean"] * u])
    if not free.size:
        return {"free_edges": 0, "free_max_dihedral_deg": float("nan"), "free_dihedral_p99_deg": float("nan"),
                "free_edges_over_90deg": 0}
    return {"free_edges": int(free.size), "free_max_dihedral_deg": float(free.max()),
            "free_dihedral_p99_deg": float(np.percentile(free, 99)), "free_edges_over_90deg": int(np.sum(free > 90))}
