"""The stability matrix's cells, their budgets and tolerances, and how an outcome is judged.

:func:`cells` lists the matrix (:class:`Cell`: a function of
:mod:`rftstatic.validate.stability.cell_functions` with its keywords, a wall-time budget and a
tolerance);
:func:`verdict` turns a cell's record into its outcome (see :mod:`rftstatic.validate.stability`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rftstatic.validate.report import fmt_err
from rftstatic.validate.stability.cell_functions import L


@dataclass
class Cell:
    """One cell of the matrix: ``func(**kw)`` in a child process, at most ``budget`` seconds.

    ``func``: the name of a function of :mod:`rftstatic.validate.stability.cell_functions`;
    ``kw``: its keywords (JSON values); ``budget`` [s]: wall time of the child process, interpreter start-up
    included; ``tolerance``: the largest ``error`` that passes (None: no reference).
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


def strip_tolerance(nx) -> float:
    """Tip tolerance for a strip with nx nodes along: 3 x the measured O(h^2) error of RFT3, >= 0.5 %.

    (validation/strip.md: 1.28 % at 11 x 3, 0.36 % at 21 x 5, 0.10 % at 41 x 9.)
    """
    return max(0.005, 3 * 0.013 * (10.0 / (nx - 1)) ** 2)


def plate_tolerance(n) -> float:
    """3 x the measured O(h^2) error of the clamped plate (12.2 % at 11 x 11), >= 1 %, <= 100 %."""
    return float(np.clip(3 * 0.122 * (10.0 / (n - 1)) ** 2, 0.01, 1.0))


def cells(quick: bool) -> list[Cell]:
    """The cells of the matrix, in report order (``quick``: the coarse subset of ``validate --quick``)."""
    c = []
    ratios = [1e2, 1e4, 1e6, 1e9] if quick else [1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9]
    nx, ny = (11, 3) if quick else (21, 5)
    for element in (["RFT6"] if quick else ["RFT3", "RFT6"]):
        for r in ratios:
            c.append(Cell("stiffness ratio: strip", f"C/B = {r:.0e} /cm^2, {element} {nx}x{ny}", "strip_cell",
                          {"nx": nx, "ny": ny, "element": element, "ratio": r}, 120, strip_tolerance(nx)))
    for r in ([1e2, 1e9] if quick else [1e2, 1e4, 1e6, 1e9]):
        c.append(Cell("stiffness ratio: pedestal", f"C/B = {r:.0e} /cm^2, pedestal-square-20 9x9" if quick else
                      f"C/B = {r:.0e} /cm^2, pedestal-square-20 17x17", "pedestal_cell",
                      {"n": 9 if quick else 17, "ratio": r}, 240))
    c.append(Cell("stiffness ratio: pedestal", "scene preset + override material.C_warp", "scene_override_cell",
                  {}, 30, 1e-9))

    sizes = [(5, 5), (11, 3)] + ([] if quick else [(21, 5), (41, 9), (81, 17)])
    for sx, sy in sizes:
        c.append(Cell("mesh: strip size", f"strip {sx}x{sy} RFT6", "strip_cell", {"nx": sx, "ny": sy}, 300,
                      strip_tolerance(sx)))
    for n in [5, 11, 41] + ([] if quick else [121, 241]):
        c.append(Cell("mesh: sheet size", f"clamped plate {n}x{n} (bending only)", "plate_cell", {"n": n}, 300,
                      plate_tolerance(n)))
    for aspect in ([10, 25] if quick else [1, 5, 10, 25, 50]):
        sx = 1 + 10 * aspect  # dy / dx = (nx - 1) / (5 (ny - 1)) with ny = 3
        c.append(Cell("mesh: sliver", f"strip {sx}x3, element aspect {aspect}", "strip_cell", {"nx": sx, "ny": 3},
                      120, strip_tolerance(21)))
    for hh in ([0.0025] if quick else [0.0025, 0.00125]):
        c.append(Cell("mesh: unstructured", f"advancing front h = {hh * 100:g} cm", "strip_cell",
                      {"mesh_kind": "unstructured", "h": hh}, 120, strip_tolerance(round(L / hh) + 1)))
    for seed in ([0] if quick else [0, 1, 2]):
        c.append(Cell("mesh: unstructured", f"jittered 21x5, 0.3 h, seed {seed}", "strip_cell",
                      {"nx": 21, "ny": 5, "jitter": 0.3, "seed": seed}, 120, strip_tolerance(21)))
    for eps in ([1e-3, 1e-12] if quick else [1e-1, 1e-3, 1e-6, 1e-9, 1e-12]):
        c.append(Cell("mesh: near-degenerate patch", f"21x5, opposite node at {eps:g} of its distance to the edge",
                      "strip_cell", {"nx": 21, "ny": 5, "degenerate": eps}, 120, strip_tolerance(21),
                      expected=("PatchError", "MeshError")))

    for a in ([0.1, 1e4] if quick else [0.1, 1.0, 1e2, 1e3, 1e4]):
        sx, sy = (21, 5) if a < 1e3 else (81, 5)  # the clamp boundary layer is L / sqrt(alpha) long
        c.append(Cell("load: strip alpha", f"alpha = {a:g}, RFT6 {sx}x{sy}", "strip_cell",
                      {"nx": sx, "ny": sy, "alpha": a}, 240, strip_tolerance(sx)))
    c.append(Cell("load: end moment", "full roll-up 25x3 RFT6", "end_moment_cell", {"nx": 25, "ny": 3}, 120, 0.03))
    if not quick:
        c.append(Cell("load: end moment", "full roll-up 49x3 RFT3", "end_moment_cell",
                      {"nx": 49, "ny": 3, "element": "RFT3"}, 240, 0.03))
        c.append(Cell("load: end moment", "full roll-up 25x3 RFT6, 1 step per table fraction", "end_moment_cell",
                      {"nx": 25, "ny": 3, "steps_per_table": 1}, 120, 0.03))
    c.append(Cell("load: one increment", "strip 21x5 RFT6, alpha 28.6", "strip_cell", {"one_step": True}, 120,
                  strip_tolerance(21)))
    if not quick:
        c.append(Cell("load: one increment", "strip 21x5 RFT3, alpha 28.6", "strip_cell",
                      {"one_step": True, "element": "RFT3"}, 120, strip_tolerance(21)))
        c.append(Cell("load: one increment", "strip 81x5 RFT6, alpha 1000", "strip_cell",
                      {"nx": 81, "ny": 5, "alpha": 1e3, "one_step": True}, 240, strip_tolerance(81)))
        c.append(Cell("load: one increment", "pedestal-square-20 17x17", "pedestal_cell", {"one_step": True}, 240))
        c.append(Cell("load: one increment", "clamped plate 41x41 (linear)", "plate_cell", {"n": 41}, 60,
                      plate_tolerance(41)))

    for f in ([1.0, 1.2] if quick else [0.5, 0.8, 1.0, 1.1, 1.2]):
        c.append(Cell("explicit: time step", f"hang-20 11x11, dt = {f:g} x estimate", "explicit_dt_cell",
                      {"factor": f}, 120, 0.02, expected=("InstabilityError",)))
    for s in ([1.0, 1e4] if quick else [1.0, 10.0, 100.0, 1e3, 1e4]):
        c.append(Cell("explicit: mass scaling", f"hang-20 11x11, s = {s:g}", "mass_scale_cell", {"scale": s}, 120,
                      1e-3))
    return c


def verdict(cell: Cell, rec: dict) -> tuple[str, str]:
    """(outcome, why) of a cell's record: ``pass``, ``converged``, ``expected stop``, ``limitation`` or ``FAIL``.

    ``rec["exception"]`` is the exception's type name, ``"timeout"`` (no result within the budget)
    or ``"process died"`` (the child crashed without reporting); see the package docstring.
    """
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
                                  f"about: {short(rec['warnings'][0], 90)}")
        return "FAIL", f"wrong answer reported as converged: error {fmt_err(err)} > {fmt_err(cell.tolerance)}"
    return "pass", f"error {fmt_err(err)} <= {fmt_err(cell.tolerance)}"


def short(text, n=160) -> str:
    """``text`` on one line, table-safe (``|`` replaced), at most ``n`` characters."""
    text = " ".join(str(text).split()).replace("|", "/")
    return text if len(text) <= n else text[: n - 3] + "..."
