"""The ``cantilever`` analysis: Peirce's cantilever bending tester (Peirce 1930; ASTM D1388, BS 3356).

A strip slides over the edge of a horizontal platform until its tip meets the plane inclined at
theta = 41.5 deg below the horizontal through the edge; the overhang l then gives the bending length
c = l/2 and the flexural rigidity G = W c^3 (W the weight per area). The strip on the platform is flat,
so the platform edge is a clamp (zero slope) and the overhang is a heavy cantilever.

The run finds l by continuation in the overhang: the strip (``[mesh] size = [l0, width]``, clamped at
x = 0) is solved at l0, then at overhangs grown by ``growth`` until the tip's chord angle passes theta,
then by a safeguarded secant (Illinois) root find on ``chord_angle(l) - theta`` inside the bracket; every
solve starts from the previous equilibrium stretched to the new length (same nodes, coordinates scaled
along the strip), so Newton needs a few iterations each.

What the numbers mean. The exact heavy elastica (:func:`~rftstatic.references.elastica.alpha_at_chord_angle`)
meets 41.5 deg at alpha = W l^3 / B = 8.0042: the tester's c = l/2 is the true (B/W)^(1/3) to 0.017 % and
G = W (l/2)^3 is 0.052 % above B (Peirce chose 41.5 deg for this; his closed form
c = l (cos(theta/2) / (8 tan theta))^(1/3) is an approximation that gives 0.5093 l there). The summary gives
both: ``flexural_rigidity`` (the tester's G) and ``rigidity_elastica`` = W l^3 / 8.0042, which is what the
simulation recovers when it reproduces the elastica; its error against the input rigidity is the
simulation's, the tester formula's own is ``tester_formula_error``.

A strip cut on the bias (``material.warp_angle``) bends and twists together: its rigidity lies between
the plate's D_11 (a wide strip, no anticlastic freedom) and the narrow strip's 1 / (D^-1)_11 (free to
twist); both are in the summary, in the strip's axes.
"""

from __future__ import annotations

import copy
import logging
import math
import time
from pathlib import Path

import numpy as np

from rftstatic.app.result import RunResult
from rftstatic.errors import ConvergenceError
from rftstatic.io.files import to_jsonable
from rftstatic.io.results import write_outputs
from rftstatic.io.summary import summary_header
from rftstatic.references.elastica import alpha_at_chord_angle
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import cantilever_options, static_options
from rftstatic.scenes.schema import Scene
from rftstatic.solvers.static import solve_static

log = logging.getLogger(__name__)


def _strip_scene(scene, overhang: float) -> Scene:
    """``scene`` with its strip ``overhang`` [scene length] long (``mesh.size[0]``, origin at x = 0)."""
    data = copy.deepcopy(scene.data)
    m = data.setdefault("mesh", {})
    width = m.get("size", [1.0, 1.0])[1]
    m["size"] = [float(overhang), width]
    m["origin"] = [0.0, m.get("origin", [0.0, -0.5 * width])[1]]
    return Scene(data, scene.path, scene.name, scene.overrides)


class _Tester:
    """Static solves of the strip at given overhangs, each started from the last one."""

    def __init__(self, scene, opts):
        self.scene, self.opts = scene, opts
        self.last = None          # (l, model, U)
        self.history = []

    def angle(self, l: float) -> float:
        """The tip's chord angle below the horizontal [rad] at overhang ``l`` [scene length]."""
        t0 = time.perf_counter()
        sc = _strip_scene(self.scene, l)
        model, extras = build_model(sc)
        opts = self.opts
        U0 = None
        if self.last is not None:
            U0 = self.last[2] * (l / self.last[0])
            opts = opts.replace(initial_increment=1.0, perturbation=0.0)
        res = solve_static(model, U0=U0, options=opts)
        if not res.converged:
            raise ConvergenceError(f"cantilever: overhang {l:.6g}: {res.message}", res)
        x = model.positions(res.U)
        X = model.mesh.X
        tip = np.flatnonzero(np.isclose(X[:, 0], X[:, 0].max()))
        ymid = 0.5 * (X[:, 1].min() + X[:, 1].max())
        mid = tip[np.argmin(np.abs(X[tip, 1] - ymid))]
        root = np.array([0.0, X[mid, 1], model.X3[mid, 2]])
        d = x[tip] - root
        angles = np.arctan2(-d[:, 2], d[:, 0])
        theta = float(angles[tip == mid][0])
        self.last = (l, model, res.U, extras, sc)
        self.history.append({"overhang": l, "angle_deg": math.degrees(theta),
                             "tip_edge_angle_deg": [math.degrees(angles.min()), math.degrees(angles.max())],
                             "iterations": res.iterations, "wall_time_s": time.perf_counter() - t0})
        return theta


def find_overhang(tester: _Tester, l0: float, opts) -> float:
    """The overhang at which the chord angle is ``opts.angle``: growth to a bracket, then Illinois."""
    f = lambda l: tester.angle(l) - opts.angle  # noqa: E731
    a, fa = l0, f(l0)
    step = opts.growth if fa < 0 else 1.0 / opts.growth
    b, fb = a * step, f(a * step)
    while fa * fb > 0:
        if len(tester.history) >= opts.max_solves:
            raise ConvergenceError(f"cantilever: no overhang from {l0:g} to {b:g} brings the tip to the plane in "
                                   f"{opts.max_solves} solves; raise cantilever.growth or start nearer", None)
        a, fa, b, fb = b, fb, b * step, f(b * step)
    side = 0
    while True:
        c = b - fb * (b - a) / (fb - fa)
        fc = f(c)
        if abs(c - b) <= opts.tolerance * abs(c) or fc == 0.0:
            return c
        if len(tester.history) >= opts.max_solves:
            raise ConvergenceError(f"cantilever: the overhang root find did not settle in {opts.max_solves} solves "
                                   f"(last {c:.8g}, angle error {math.degrees(fc):.3g} deg); raise cantilever.max_solves "
                                   "or cantilever.tolerance", None)
        if fc * fb < 0:
            a, fa = b, fb
            side = 0
        else:
            fa = fa / 2.0 if side == -1 else fa      # Illinois: halve the stale end's value
            side = -1
        b, fb = c, fc


def strip_rigidities(material) -> dict:
    """The strip's bending rigidities along x [N m]: the plate's D_11 and the narrow strip's 1/(D^-1)_11."""
    Db = np.asarray(material.Db)
    return {"plate_D11": float(Db[0, 0]), "narrow_strip": float(1.0 / np.linalg.inv(Db)[0, 0])}


def run(scene, out: Path, *, progress=True, figures=True) -> RunResult:
    """Find the tester's overhang for ``scene``; write the final strip and the summary into ``out``."""
    t0 = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    opts = cantilever_options(scene)
    sopts = static_options(scene, progress=False)
    tester = _Tester(scene, sopts)
    l0 = float(scene.get("mesh.size", [1.0, 1.0])[0])
    error = None
    try:
        l = find_overhang(tester, l0, opts)
    except ConvergenceError as exc:
        error, l = exc, (tester.last[0] if tester.last else l0)
        if tester.last is None:
            raise
    _, model, U, extras, sc = tester.last
    u = scene.units
    W = model.material.weight
    alpha = alpha_at_chord_angle(opts.angle)
    rig = strip_rigidities(model.material)
    L = l * u.length
    c = 0.5 * L
    G = W * c**3
    B_el = W * L**3 / alpha
    peirce = L * (math.cos(opts.angle / 2) / (8 * math.tan(opts.angle))) ** (1 / 3)
    summary = summary_header(sc, model, "cantilever")
    summary.update({
        "converged": error is None, "message": "" if error is None else str(error),
        "wall_time_s": time.perf_counter() - t0,
        "cantilever": {
            "overhang": l, "bending_length": c / u.length, "flexural_rigidity": G / u.moment,
            "angle_deg": math.degrees(opts.angle),
            "given_bending_rigidity": rig["plate_D11"] / u.moment,
            "narrow_strip_rigidity": rig["narrow_strip"] / u.moment,
            "alpha_elastica": alpha, "rigidity_elastica": B_el / u.moment,
            "error_elastica_vs_given": B_el / rig["plate_D11"] - 1.0,
            "error_tester_vs_given": G / rig["plate_D11"] - 1.0,
            "tester_formula_error": alpha / 8.0 - 1.0,
            "peirce_bending_length": peirce / u.length, "peirce_rigidity": W * peirce**3 / u.moment,
            "solves": tester.history,
        },
    })
    write_outputs(sc, model, extras, U, out, summary, figures=figures)
    if error is not None:
        raise error
    return RunResult(to_jsonable(summary), model, U, extras, out)
