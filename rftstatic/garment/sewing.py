"""Sewing: the placed panels as one mesh, seam springs that close the seams, and the merge of each seam's two sides.

A garment is solved in two stages (:mod:`rftstatic.app.garment`):

1. *Closing.* The panels, each flat and placed around the body as the pattern says, form one mesh with its
   panels apart (:func:`panel_mesh`): every element keeps its panel's flat shape with the x axis along the
   panel's grain line (the warp; :attr:`rftstatic.mesh.trimesh.TriMesh.element_X`), the placed positions are
   the reference (:attr:`~rftstatic.mesh.trimesh.TriMesh.placed`). Zero-length springs on the seams' node
   pairs (:class:`rftstatic.model.loads.SeamSprings`, stiffness :data:`SEAM_STIFFNESS` times the fabric's
   smallest membrane rigidity) pull the seams shut in a damped explicit run with the body in contact and no
   gravity (:func:`close_seams`), until the largest seam gap is below :data:`SEAM_CLOSED` of the mean element
   size.
2. *Merging.* The two sides of each seam become one node at their midpoint (:func:`sew`): the RF patches of the
   elements along a seam now reach across it (their neighbour unfolded flat about the seam,
   :func:`rftstatic.element.patch.unfolded_opposites`), so the sewn garment bends across its seams like
   cloth, and the garment's static equilibrium on the body is solved from there with the real loads.

The closing may run on a coarser mesh of the same pattern (``garment.closing_h``): its closed positions are then
carried to the garment's mesh through the flat pattern (:func:`carry_closed`: every node of a panel at its panel
coordinates in the coarse panel's closed surface), where a short closing run of the fine mesh's own seam springs
finishes the job. The closing's explicit step is set by the smallest element (membrane and contact frequencies),
so each halving of the element size costs about eight times the explicit steps; the carried start leaves the fine
mesh only the last millimetres.

Seams of kind ``sew`` are closed and merged; ``open`` seams are left open (a slit); ``fold`` seams (a hem turned
back) are closed and merged as ``sew`` seams, and the merged edges along them become the sewn mesh's creases
(:class:`rftstatic.mesh.folds.FoldLines`, :func:`fold_chains`): the RF patches end there and a hinge holds each
at the seam's rest angle (:mod:`rftstatic.element.hinge`), on the side the closed panels turn to (:func:`sew`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np

from rftstatic.garment.pattern import PatternError
from rftstatic.mesh.trimesh import TriMesh

__all__ = ["panel_mesh", "seam_pairs", "fold_chains", "turned_back", "FoldChain", "FOLD_START_TOLERANCE", "sew",
           "close_seams", "carry_closed", "ClosingResult", "CLOSING_RUNS", "SEAM_CLOSED", "SEAM_PULL",
           "SEAM_STIFFENING", "SEAM_STIFFNESS"]

log = logging.getLogger(__name__)

SEAM_CLOSED = 0.05
"""Largest seam gap at which the seams are merged, relative to the mean element size [-]: the merge then
moves each node by at most 2.5 % of an element, a strain the following static solve relaxes."""

SEAM_PULL = 1.0
"""The seam springs' first stiffness, as the pull of all springs together on the open seams over the garment's
weight [-]: k_0 = SEAM_PULL W / (S g_0) for S pairs of largest gap g_0, so the seams close about as fast as the
garment would fall, with no violent snap (a stiffer first pull overshoots and tears the membrane)."""

CLOSING_RUNS = 12
"""Most explicit runs of the closing (:func:`close_seams`): a run that comes to rest short of closing is followed
by one with stiffer springs, a run stopped on a closed gap that springs open again by one at the same stiffness."""

CLOSING_SAMPLE = 10
"""Explicit steps between two looks at the seam gaps in a closing run (each look also evaluates the energy
balance, a second contact query on the body's surface)."""

SEAM_STIFFENING = 3.0
"""Factor on the spring stiffness from one closing run to the next [-] (:func:`close_seams`)."""

SEAM_STIFFNESS = 0.5
"""Largest seam spring stiffness over the fabric's smallest membrane rigidity min(C_warp, C_weft) [-]: a spring on
a seam node then stays below the membrane's own stiffness there, so it does not shorten the explicit step, and
pulls the last millimetres shut against the cloth's bending."""


def panel_mesh(pmesh, placed: np.ndarray, chart: np.ndarray | None = None) -> TriMesh:
    """The garment's panels as one mesh, apart, in their placed positions (stage 1 of the module docstring).

    Parameters
    ----------
    pmesh : :class:`rftstatic.garment.meshing.PatternMesh`
    placed : (N, 3) placed positions of all nodes [m] (global ids of ``pmesh``)
    chart : (N, 2) the mesh's ``X`` [m] (a chart to locate nodes, e.g. the plan view); default ``placed[:, :2]``

    Returns a :class:`TriMesh` whose ``element_X`` gives every element in its panel's coordinates turned so that
    the grain line is the x axis (the material's warp), and whose ``seams`` are the seams to close
    (:func:`seam_pairs`: the self-contact leaves the two sides of a seam alone).
    """
    tri = np.concatenate([m.tri + pmesh.offsets[p] for p, m in enumerate(pmesh.meshes)])
    corners = []
    for p, m in enumerate(pmesh.meshes):
        g = np.radians(pmesh.pattern.panels[p].grain)
        R = np.array([[np.cos(g), np.sin(g)], [-np.sin(g), np.cos(g)]])  # turns the grain direction onto +x
        corners.append(m.X[m.tri] @ R.T)
    X = placed[:, :2] if chart is None else chart
    return TriMesh(X=np.array(X, float), tri=tri, name=f"garment {_stem(pmesh.pattern.source)}",
                   element_X=np.concatenate(corners), placed=np.array(placed, float), seams=seam_pairs(pmesh))


def _stem(source) -> str:
    from pathlib import Path

    return Path(str(source)).stem


def seam_pairs(pmesh) -> np.ndarray:
    """(S, 2) global node pairs of the seams to close and merge (kinds ``sew`` and ``fold``; ``open`` left out).
    A dart tip pairing a node with itself is left out."""
    out = [pairs[pairs[:, 0] != pairs[:, 1]] for s, pairs in zip(pmesh.pattern.seams, pmesh.seam_pairs)
           if s.kind in ("sew", "fold")]
    return np.concatenate(out).astype(np.int64) if out else np.zeros((0, 2), np.int64)


@dataclass(frozen=True)
class FoldChain:
    """A ``fold`` seam's crease before sewing: ``nodes (n + 1,)`` global panel nodes of its side a in order along
    the seam, the rest ``angle`` [rad] (magnitude) and the crease ``width`` [m] (NaN: the elements' height), the
    seam's ``label`` for messages."""

    nodes: np.ndarray
    angle: float
    width: float
    label: str


def fold_chains(pmesh) -> list:
    """The :class:`FoldChain` of every ``fold`` seam of ``pmesh`` (:class:`rftstatic.garment.meshing.PatternMesh`)."""
    return [FoldChain(pairs[:, 0].astype(np.int64), float(np.radians(s.angle)),
                      np.nan if s.width is None else float(s.width), s.label())
            for s, pairs in zip(pmesh.pattern.seams, pmesh.seam_pairs) if s.kind == "fold"]


def turned_back(pmesh) -> np.ndarray:
    """(E,) bool, the elements of the panels turned back at a fold seam (its side b: a hem's facing), which the
    garment's outer measures (hem, drape coefficient's outline) leave out."""
    facing = {s.b_panel for s in pmesh.pattern.seams if s.kind == "fold"}
    return np.repeat([p.name in facing for p in pmesh.pattern.panels], [len(m.tri) for m in pmesh.meshes])


def sew(mesh: TriMesh, pairs: np.ndarray, x: np.ndarray, *, where: str = "pattern",
        folds=()) -> tuple[TriMesh, np.ndarray]:
    """Merge the two sides of every seam into one node (stage 2 of the module docstring).

    Parameters
    ----------
    mesh : the panel mesh (:func:`panel_mesh`)
    pairs : (S, 2) node pairs to merge (chains merge into one node: a corner where two seams meet)
    x : (N, 3) positions [m] at the end of the closing; each merged node takes its group's mean
    where : names the pattern in errors
    folds : the :class:`FoldChain` of the fold seams among ``pairs`` (:func:`fold_chains`): their merged edges
        become the sewn mesh's creases (``TriMesh.folds``), each at its rest angle on the side the merged
        positions turn it to (:func:`_creases`)

    Returns
    -------
    (sewn, node_of) : the sewn :class:`TriMesh` (reference ``placed`` = the merged positions, ``element_X`` kept)
        and ``node_of (N,)``, the sewn node of every panel node.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = mesh.n_nodes
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(g, directed=False)
    first = np.full(label.max() + 1, n)
    np.minimum.at(first, label, np.arange(n))
    order = np.argsort(first, kind="stable")  # sewn nodes numbered in the order of their first panel node
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    node_of = rank[label]
    tri = node_of[mesh.tri]
    bad = (tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 0] == tri[:, 2])
    if bad.any():
        e = int(np.flatnonzero(bad)[0])
        raise PatternError(f"{where}: sewing collapses {bad.sum()} triangle(s) (first: element {e}, nodes "
                           f"{mesh.tri[e].tolist()}): two of its nodes lie on seams sewn to each other (a dart tip or "
                           "a corner sewn to itself); mesh finer (garment.h) or cut the dart wider")
    m = len(order)
    count = np.bincount(node_of, minlength=m).astype(float)
    merged = np.stack([np.bincount(node_of, x[:, i], minlength=m) for i in range(3)], axis=1) / count[:, None]
    chart = mesh.X[first[order]]  # each sewn node's first panel node
    sewn = TriMesh(X=chart, tri=tri, name=mesh.name, element_X=mesh.element_X, placed=merged,
                   info={**mesh.info, "sewn_from_nodes": n})
    if folds:
        sewn = replace(sewn, folds=_creases(sewn, folds, node_of, where))
    return sewn, node_of


FOLD_START_TOLERANCE = 60.0
"""Largest difference [deg] between a fold seam's dihedral angle as closed and its rest angle (:func:`sew`): the
panel turned back is placed turned as folded; a fold much further from its rest would be snapped over by its
hinge, through the cloth around it."""


def _creases(sewn: TriMesh, folds, node_of, where):
    """The :class:`~rftstatic.mesh.folds.FoldLines` of the fold seams ``folds`` on the ``sewn`` mesh: the rest angle
    of each crease edge signed as the merged positions turn it (the hinge's frame, :func:`rftstatic.element.hinge.
    fold_hinges`); :class:`PatternError` naming the seam when a fold as closed is more than
    :data:`FOLD_START_TOLERANCE` from its rest angle."""
    from rftstatic.element.hinge import fold_hinges
    from rftstatic.mesh.folds import FoldLines

    edges, angle, width, seam = [], [], [], []
    for k, f in enumerate(folds):
        chain = node_of[f.nodes]
        e = np.stack([chain[:-1], chain[1:]], axis=1)
        edges.append(e)
        angle += [f.angle] * len(e)
        width += [f.width] * len(e)
        seam += [k] * len(e)
    edges = np.concatenate(edges)
    probe = FoldLines(edges, np.asarray(angle), np.asarray(width))
    hinges = fold_hinges(replace(sewn, folds=probe), np.eye(3))
    theta = hinges.angles(sewn.X3)
    at = hinges.fold
    rest = np.where(theta < 0, -1.0, 1.0) * probe.angle[at]
    off = np.degrees(np.abs(np.abs(theta) - probe.angle[at]))
    worst = int(np.argmax(off))
    if off[worst] > FOLD_START_TOLERANCE:
        f = folds[seam[at[worst]]]
        raise PatternError(f"{where}: the fold seam {f.label} closed at {np.degrees(abs(theta[worst])):.0f} deg, "
                           f"{off[worst]:.0f} deg from its rest angle {np.degrees(f.angle):.0f} deg (more than "
                           f"{FOLD_START_TOLERANCE:g}); place the panel turned back as folded (its side b turned "
                           "onto side a for a 180 deg hem)")
    return FoldLines(hinges.nodes[:, :2], rest, probe.width[at])


def carry_closed(coarse, x, fine) -> np.ndarray:
    """Positions (N_fine, 3) [m] of the nodes of ``fine`` (a :class:`~rftstatic.garment.meshing.PatternMesh` of the
    same pattern) on the closed garment ``x (N_coarse, 3)`` [m] of the mesh ``coarse``: each panel's nodes at their
    panel coordinates on the coarse panel's surface, by the quadratic of its RF patches
    (:func:`rftstatic.remesh.transfer.transfer_fields`, route ``"patch"``: the nodes lie on the curved patch
    surfaces, not on the coarse chords, so the fine triangles are not shortened across the coarse folds; a node
    of a curved edge just outside the coarse panel's polygon takes its nearest triangle's quadratic). Seam nodes
    of the two sides of a seam sit at the same fraction of the seam's arc length on both meshes
    (:mod:`rftstatic.garment.meshing`), so the fine seams open no wider than the coarse ones."""
    from rftstatic.remesh.transfer import transfer_fields

    if len(coarse.meshes) != len(fine.meshes):
        raise ValueError(f"the coarse mesh has {len(coarse.meshes)} panels, the fine one {len(fine.meshes)}")
    out = np.empty((fine.n_nodes, 3))
    for p, (mc, mf) in enumerate(zip(coarse.meshes, fine.meshes)):
        (out[fine.offsets[p]:fine.offsets[p + 1]],) = transfer_fields(
            mc, mf.X, [x[coarse.offsets[p]:coarse.offsets[p + 1]]], method="patch")
    return out


@dataclass
class ClosingResult:
    """The closing stage (:func:`close_seams`): positions, gaps and what it took.

    Attributes
    ----------
    x : (N, 3) positions at the end [m]
    largest_gap_start, largest_gap : the largest seam gap at the start and at the end [m]
    time, steps, wall_time : simulated time [s], explicit steps, wall time [s]
    closed : the gap reached :data:`SEAM_CLOSED` of the mean element size
    """

    x: np.ndarray
    largest_gap_start: float
    largest_gap: float
    time: float
    steps: int
    wall_time: float
    closed: bool


def _closing_step(model, U, alpha) -> float:
    """The closing run's explicit step [s]: the stable step of the cloth and springs at ``U`` (N, 3) [m]
    (:func:`rftstatic.solvers.timestep.stable_time_step`) with the penalty contact's frequency added,
    omega^2 = omega_cloth^2 + k / rho (k the penalty stiffness [N/m^3], rho the mass per area [kg/m^2]): the
    estimate at the start sees no contact, and the body is met later in the run."""
    from rftstatic.solvers.timestep import SAFETY, critical_step, stable_time_step

    est = stable_time_step(model, U, alpha=alpha)
    omega = est.omega_max
    if model.contact is not None:
        omega = float(np.hypot(omega, np.sqrt(model.contact.stiffness / model.material.mass_per_area)))
    return SAFETY * critical_step(omega, alpha)


def close_seams(build, pairs, obstacles, *, weight: float, stiffest: float, t_stage: float, alpha: float,
                progress=False, friction=None) -> ClosingResult:
    """Pull the seams ``pairs (S, 2)`` shut (stage 1 of the module docstring) by damped explicit runs
    (:func:`rftstatic.solvers.explicit.run_explicit`, mass damping ``alpha`` [1/s], the model's penalty contact
    and any ``obstacles`` acting kinematically), each of at most ``t_stage`` [s] and stopped as soon as the
    largest gap is below half of :data:`SEAM_CLOSED` of the mean element size (looked at every
    :data:`CLOSING_SAMPLE` steps; the run takes one more step; the run at the stiffest springs goes to its end). The
    first run's springs pull with :data:`SEAM_PULL` times the garment's ``weight`` [N]; a run that comes to rest
    short of closing is followed by one with springs :data:`SEAM_STIFFENING` times stiffer, up to ``stiffest``
    [N/m], at most :data:`CLOSING_RUNS` runs, each going on from where the last stopped (positions and
    velocities). ``build(springs)`` gives the model of the panel mesh whose only load is the
    :class:`~rftstatic.model.loads.SeamSprings` ``springs``."""
    import time

    from rftstatic.model.loads import SeamSprings
    from rftstatic.solvers.explicit import run_explicit
    from rftstatic.solvers.explicit_options import ExplicitOptions

    t0 = time.perf_counter()
    probe = SeamSprings(pairs, 0.0)
    model = build(probe)
    X3 = model.X3
    tol = SEAM_CLOSED * float(model.mesh.element_size.mean())
    start = float(probe.gaps(X3).max(initial=0.0))
    k = min(SEAM_PULL * weight / (max(len(pairs), 1) * max(start, tol)), stiffest)
    U, V, t, steps = np.zeros_like(X3), np.zeros_like(X3), 0.0, 0
    gap = start
    for _ in range(CLOSING_RUNS):
        springs = SeamSprings(pairs, k)
        model = build(springs)

        def closed(state, sample, springs=springs, last=k >= stiffest):
            # half the tolerance: the run takes one more step; the stiffest springs ring about the closed seam, and
            # their run goes to its end (damped) rather than stop on a passing small gap
            return not last and bool(springs.gaps(X3 + state.U).max(initial=0.0) <= 0.5 * tol)

        opts = ExplicitOptions(t_end=t_stage, alpha=alpha, progress=progress, sample_every=CLOSING_SAMPLE,
                               dt=_closing_step(model, U, alpha))
        run = run_explicit(model, opts, U0=U, V0=V, obstacles=obstacles, callback=closed, friction=friction)
        U, V, t, steps = run.U, run.V, t + float(run.t), steps + int(run.steps)
        gap = float(springs.gaps(X3 + U).max(initial=0.0))
        log.info("seam springs %.3g N/m: largest gap %.4g m after %.3g s", k, gap, float(run.t))
        if gap <= tol:
            break
        if not run.stopped:  # the springs have come to rest short of closing: pull harder
            if k >= stiffest:
                break
            k = min(k * SEAM_STIFFENING, stiffest)
    log.info("seams closed from %.4g m to %.4g m in %.3g s (%d explicit steps)", start, gap, t, steps)
    return ClosingResult(x=X3 + U, largest_gap_start=start, largest_gap=gap, time=t, steps=steps,
                         wall_time=time.perf_counter() - t0, closed=gap <= tol)
