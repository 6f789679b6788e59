"""Self-contact law: a C2 penalty on the distances between the sheet's own elements, and a bound on
the Newton or explicit step that keeps any pair from passing through another.

Energy. For every point-triangle pair (a node and a triangle without it) and every edge-edge pair
(edges without a common node) at distance ``delta`` [m] below the thickness ``d`` [m],

    E_s = sum_pairs k / (3 d) (d - delta)^3                                   [J]

(``k`` [N/m]; for a pair closer than ``d / 4`` a log barrier joins it, :func:`pair_law`). Its slope ``-k (d - delta)^2 / d`` and curvature ``2 k (d - delta) / d`` vanish at
``delta = d``, so energy, force and tangent are continuous when a pair enters or leaves (C2), and a
pair pressed by a force ``F`` rests at ``delta = d - sqrt(F d / k)``. The pair's Hessian

    H = e'' grad delta grad delta^T + e' hess delta,
    grad delta = grad s / (2 delta),  hess delta = hess s / (2 delta) - grad s grad s^T / (4 delta^3)

(``s = delta^2`` and its derivatives from :mod:`.distance`) is indefinite in general (``e' < 0`` times
the curvature of the distance); each 12 x 12 block is projected onto the positive semi-definite
matrices (eigenvalues clamped at 0), so that the Newton tangent stays positive semi-definite, the
energy line search sees descent directions and the stable-minimum check (Cholesky of the tangent)
judges the sheet, not the projection. The force and energy are exact; the tangent is exact wherever
every pair's block is already PSD.

Why a penalty first and the IPC log barrier only below ``d / 4`` (:func:`pair_law`): the solvers start
from the flat sheet or from a relaxed or transferred state in which layers may already be closer than
``d`` (a relaxation without self-contact, a remeshed transfer): a barrier over the whole range would be
stiff far from contact and is infinite at contact, the penalty is finite and starts from any state.
:func:`auto_stiffness` makes ``k d`` four times the design load of a pair, so a pair never reaches the
barrier under that load. A pair pressed harder than ``k d`` (a sharp fold, a stiffness lowered by
``contact.self_factor``) would with the cubic alone be closed a little more by every Newton step, each
of which :meth:`SelfContact.max_step_fraction` lets close up to ``1 - min_fraction`` of the gap, and
pass through once at zero distance; the barrier's energy grows without bound on the way, so the pair
rests at a positive distance (and the static route then raises k until it is above ``d / 2``).

Stiffness (:func:`auto_stiffness`): a pair carries the weight of about one node's area ``A``; under a
design pressure ``p`` the pair rests at ``delta = d (1 - sqrt(p A / (k d)) )``; ``k = 4 p_design A / d``
keeps ``delta >= d / 2`` up to ``p_design = pressure_factor * w`` (default 10 layers of the sheet's own
weight ``w``); the sheet's own weight alone rests at ``delta = 0.84 d``. Several pairs per node
(a node over an edge sees two triangles; edges cross edges) only raise the gap.

Step bound (:meth:`SelfContact.max_step_fraction`, additive continuous collision detection after
Li, Kaufman & Jiang, "Codimensional IPC", 2021): along ``x + t dx`` the closest points of a pair move
relative to each other by at most ``l = max |dx_i - dx_j|`` per unit ``t`` (``i`` a node of one
primitive, ``j`` of the other; the closest points are convex combinations), so from a distance
``delta(t)`` the pair stays above ``g`` until ``t + (delta(t) - g) / l`` at least. Advancing by that
bound and re-evaluating the distance converges to the first time the distance reaches
``g = min_fraction * delta(0)``, from below: the step fraction returned never lets any pair come
closer than ``g`` anywhere on the path, i.e. no pair tunnels, however long the step.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from rftstatic.compiled import choose_kernels
from rftstatic.contact.self_contact.broad_phase import PairCache, Pairs, SheetPrimitives, find_pairs
from rftstatic.contact.self_contact.distance import (edge_edge, edge_edge_distance2, point_triangle,
                                                     point_triangle_distance2)
from rftstatic.contact.self_contact.friction import with_friction
from rftstatic.contact.self_contact.law_kernels import additive_ccd_nodes, psd_project
from rftstatic.contact.self_contact.near_pairs import NearPairCache, SelfContactStats, pair_nodes
from rftstatic.model.frozen import Frozen

__all__ = ["SelfContact", "SelfContactState", "auto_stiffness", "pair_law"]

MIN_FRACTION = 0.2
"""Default ``min_fraction`` of the step bound: no pair comes closer than this fraction of its distance
at the start of a step."""

SWEEP_PAIRS = 1_000_000
"""Budget of candidate pairs of one swept broad phase. The swept boxes of a step whose relative motion is
s cover about (s / h)^2 triangles each, so a swept test of the E triangles finds about E (s / h)^2
point-triangle candidates (and as many again edge-edge ones, more where folded layers are stacked):
:attr:`SelfContact.sweep_limit` = h sqrt(budget / E) bounds s. Without it one Newton step of the 80 cm sheet at 201 x 201 nodes (80,000 triangles, h = 4 mm)
from a transferred coarse drape swept ~10 cm and the process ran out of 24 GB."""


@dataclass(frozen=True)
class SelfContactState:
    """Self-contact evaluated at one configuration.

    Attributes
    ----------
    energy : E_s [J]
    force : (N, 3) gradient of E_s [N]
    nodes : (A, 4) nodes of the active pairs (point-triangle: node, triangle; edge-edge: edge, edge)
    blocks : (A, 12, 12) PSD-projected Hessians of the active pairs [N/m] (dof ``3 a + i``), or None
    min_distance : smallest distance over the listed pairs [m] (inf without pairs)
    n_active : pairs closer than the thickness
    """

    energy: float
    force: np.ndarray
    nodes: np.ndarray
    blocks: np.ndarray | None
    min_distance: float
    n_active: int


BARRIER_GAP = 0.25
"""Distance below which the barrier term of :func:`pair_law` acts, as a fraction of the thickness d: below
the d / 2 at which the automatic stiffness rests a pair under its design load, so a scene whose pairs keep
that gap never feels it."""


def pair_law(delta: np.ndarray, d: float, k: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The energy of one pair at distance ``delta (A,)`` [m] and its first and second derivatives in
    ``delta``: ``(e [J], e' [N], e'' [N/m])``, each ``(A,)``, for pairs closer than the thickness ``d``.

    ``e = k / (3 d) (d - delta)^3`` (module docstring), plus below ``dhat = BARRIER_GAP d`` the log
    barrier of IPC (Li et al., "Incremental Potential Contact", SIGGRAPH 2020, Eq. 6) with stiffness k,
    ``-k (delta - dhat)^2 ln(delta / dhat)``, C2 at ``dhat`` (value, slope and curvature vanish there) and
    unbounded as the pair closes: the cubic penalty alone pushes with at most ``k d``, so a fold pressed
    harder than that was driven to zero distance over successive Newton steps, each of which the step
    bound lets close 80 % of the gap, and then passed through (``sphere-floor`` at a fifth of the
    automatic stiffness: 7 crossing pairs); with the barrier its energy grows without bound on the way
    and the pair rests at a positive distance, where the stiffening of the static route opens it.
    """
    gap = d - delta
    e = k / (3.0 * d) * gap**3
    e1 = -k / d * gap**2
    e2 = 2.0 * k / d * gap
    dhat = BARRIER_GAP * d
    near = delta < dhat
    if np.any(near):
        x = delta[near]
        r, log = x - dhat, np.log(x / dhat)
        e[near] -= k * r * r * log
        e1[near] -= k * (2.0 * r * log + r * r / x)
        e2[near] -= k * (2.0 * log + 4.0 * r / x - r * r / (x * x))
    return e, e1, e2


def auto_stiffness(*, weight: float, node_area: float, thickness: float, pressure_factor: float = 10.0,
                   factor: float = 1.0) -> float:
    """Penalty stiffness ``k = factor * 4 pressure_factor w A / d`` [N/m] (module docstring).

    Parameters
    ----------
    weight : weight per area ``w`` [N/m^2]
    node_area : area per node ``A`` (the mean) [m^2]
    thickness : ``d`` [m]
    pressure_factor : design pressure in units of ``w`` at which a pair rests at ``d / 2``
    factor : multiplier
    """
    for name, v in (("weight", weight), ("node_area", node_area), ("thickness", thickness),
                    ("pressure_factor", pressure_factor), ("factor", factor)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
    return float(factor * 4.0 * pressure_factor * weight * node_area / thickness)


MARGIN_EDGES = 0.5
"""Default broad-phase margin in mean edge lengths: the list is rebuilt after a motion of half of it. Measured
(2026-12-05, 22:45-22:56 UTC, load 1.1-1.5, whole runs one after the other) against a quarter edge: rebuilds and
the time of the pair lists and the step filter about halved, the near list 3-5 x longer; whole run
pedestal-square-80 41.7 -> 38.7 s, drop-floor 12.8 -> 11.8 s, hang-100 6.8 -> 5.5 s, skirt-circle 88.5 -> 79.8 s."""


class SelfContact(Frozen):
    """Penalty self-contact of a sheet (module docstring), read-only once built: a solve that raises the
    stiffness does so through its pair cache (``cache.stiffness_scale``, ``State.self_contact_scale``).

    Parameters
    ----------
    mesh : the reference :class:`~rftstatic.mesh.trimesh.TriMesh` [m]; no pair of a flat reference may lie closer
        than ``d``; a sewn mesh's (``element_X``: the closed garment) may, down to the barrier gap
    thickness : ``d`` [m], below half the smallest edge of the mesh
    stiffness : ``k`` [N/m] (:func:`auto_stiffness`), the stiffness at scale 1
    margin : broad-phase margin [m] (default ``max(2 d, MARGIN_EDGES h)``, h the mean edge length): pairs are
        listed within ``d + margin`` and the list is rebuilt once a node moved ``margin / 2``
    min_fraction : of the step bound, in (0, 1)
    sweep_limit : longest relative motion of a step that one swept broad phase covers [m] (default from the
        :data:`SWEEP_PAIRS` budget)
    kernels : ``"numpy"`` or ``"compiled"``, the kernels of every loop of the law and its pair caches
        (:func:`rftstatic.compiled.choose_kernels`; default: its choice for a self-contact run on this mesh)
    friction : Coulomb friction between the layers (a :class:`rftstatic.contact.friction.FrictionLaw` with one
        coefficient pair), lagged by the static route (:mod:`.friction`); None: frictionless

    Attributes
    ----------
    stats : :class:`~.near_pairs.SelfContactStats`, counts and timings of the law's work, added to by every
        solve (shared with the pair caches it makes) and summed over a run in its summary; no evaluation
        reads them. The one part of the law that changes after it is built: its attributes cannot be set.
    """

    def __init__(self, mesh, thickness: float, stiffness: float, *, margin: float | None = None,
                 min_fraction: float = MIN_FRACTION, sweep_limit: float | None = None, kernels: str | None = None,
                 friction=None):
        self.friction = friction
        self.prims = SheetPrimitives.of_mesh(mesh)
        X = mesh.X3
        e = self.prims.edges
        length = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
        self.smallest_edge = float(length.min())
        if not (np.isfinite(thickness) and thickness > 0):
            raise ValueError(f"self-contact thickness must be a finite number > 0, got {thickness!r}")
        if thickness > 0.5 * self.smallest_edge:
            raise ValueError(f"self-contact thickness {thickness:.6g} m is above half the smallest edge "
                             f"({self.smallest_edge:.6g} m / 2): the law would push apart neighbours that are "
                             "not in contact; use a thinner thickness or a coarser mesh")
        if not (np.isfinite(stiffness) and stiffness > 0):
            raise ValueError(f"self-contact stiffness must be a finite number > 0, got {stiffness!r}")
        if not 0.0 < min_fraction < 1.0:
            raise ValueError(f"min_fraction must be in (0, 1), got {min_fraction!r}")
        self.thickness = float(thickness)
        self.stiffness = float(stiffness)
        self.min_fraction = float(min_fraction)
        self.margin = float(margin) if margin is not None else max(2.0 * thickness, MARGIN_EDGES * float(length.mean()))
        self.sweep_limit = (float(sweep_limit) if sweep_limit is not None
                            else float(length.mean()) * float(np.sqrt(SWEEP_PAIRS / max(len(mesh.tri), 1))))
        self.stats = SelfContactStats()
        self.kernels = choose_kernels(len(mesh.tri), self_contact=True, requested=kernels)
        self.compiled = self.kernels == "compiled"
        ref = self.evaluate(X, tangent=False)
        if ref.n_active and getattr(mesh, "element_X", None) is not None:
            # a sewn mesh's reference is the closed garment, whose layers may rest in contact (a hem's facing on
            # the skirt, at d / 2 under the design load), but not inside the barrier
            if ref.min_distance < BARRIER_GAP * thickness:
                raise ValueError(f"the sewn garment's start has self-contact pairs {ref.min_distance:.6g} m apart, "
                                 f"inside the barrier gap {BARRIER_GAP:g} x the thickness {thickness:.6g} m: its "
                                 "layers were pressed together in the closing; place the panels further apart or "
                                 "use a thinner thickness")
        elif ref.n_active:
            raise ValueError(f"the flat reference mesh has {ref.n_active} self-contact pairs closer than the "
                             f"thickness {thickness:.6g} m (smallest distance {ref.min_distance:.6g} m, e.g. a "
                             "skinny triangle's height); use a thinner thickness")
        self._freeze()

    @property
    def n_nodes(self) -> int:
        return self.prims.n_nodes

    def new_pairs(self) -> NearPairCache:
        """A fresh pair cache for a solve (kept in :attr:`rftstatic.model.state.State.self_pairs`): the
        pairs within ``d + margin`` by exact distance (:mod:`.near_pairs`), counted in :attr:`stats`."""
        return NearPairCache(self.margin, self.stats, compiled=self.compiled)

    def pairs(self, x, cache: PairCache | None = None) -> Pairs:
        """Pairs within ``d + margin`` of ``x (N, 3)`` [m] (from ``cache`` when still valid)."""
        if cache is not None:
            return cache.pairs(self.prims, x, self.thickness)
        return find_pairs(self.prims, x, self.thickness + self.margin, compiled=self.compiled)

    def _x4(self, x, pairs: Pairs):
        """Nodes ``(Q, 4)`` of the point-triangle and ``(R, 4)`` of the edge-edge pairs."""
        return pair_nodes(self.prims, pairs)

    def _check_x(self, x):
        x = np.asarray(x, dtype=float)
        if x.shape != (self.n_nodes, 3):
            raise ValueError(f"x must have shape ({self.n_nodes}, 3), got {x.shape}")
        return x

    def evaluate(self, x, *, tangent: bool = True, cache: PairCache | None = None,
                 project: bool = True) -> SelfContactState:
        """Energy, force and pair blocks at positions ``x (N, 3)`` [m] over the pairs within ``d + margin``
        (:meth:`pairs`), the stiffness times the solve's ``cache.stiffness_scale`` (1 without a cache), with the
        solve's lagged friction between layers ``cache.friction`` (:mod:`.friction`) added when it has one;
        ``project``: the blocks projected to PSD (False: the exact Hessian blocks, for tests)."""
        x = self._check_x(x)
        pairs = self.pairs(x, cache)
        if isinstance(cache, NearPairCache):
            npt, nee = cache.npt, cache.nee
        else:
            npt, nee = self._x4(x, pairs)
        state = self.evaluate_pairs(x, npt, nee, tangent=tangent, project=project, scale=_scale(cache))
        lag = getattr(cache, "friction", None)  # the solve's lagged friction between layers, if any
        return state if lag is None else with_friction(state, lag, x, tangent)

    def normal_force(self, delta, scale: float = 1.0) -> np.ndarray:
        """The push ``-e'(delta) (A,)`` [N] of pairs at distances ``delta (A,)`` [m] below the thickness
        (:func:`pair_law`), the stiffness times ``scale``."""
        d = self.thickness
        return -pair_law(np.maximum(np.asarray(delta, dtype=float), 1e-12 * d), d, self.stiffness * scale)[1]

    def evaluate_pairs(self, x, npt, nee, *, tangent: bool = True, project: bool = True,
                       scale: float = 1.0) -> SelfContactState:
        """The law (module docstring) summed over the given pairs: ``npt (Q, 4)`` point-triangle rows
        (node, triangle), ``nee (R, 4)`` edge-edge rows (edge, edge), at ``x (N, 3)`` [m]. The one source
        of the energy ``sum e(delta)`` [J] (:func:`pair_law`), its gradient ``(N, 3)`` [N] and the pair blocks,
        for the static solver (:meth:`evaluate`) and the explicit one
        (:meth:`near_force`); the stiffness times ``scale`` [-]."""
        t0 = time.perf_counter()
        d, k = self.thickness, self.stiffness * scale
        s_pt = point_triangle_distance2(x[npt], compiled=self.compiled) if len(npt) else np.zeros(0)
        s_ee = edge_edge_distance2(x[nee], compiled=self.compiled) if len(nee) else np.zeros(0)
        smin = min(float(s_pt.min(initial=np.inf)), float(s_ee.min(initial=np.inf)))
        nodes_list, grads, hess, dist = [], [], [], []
        for nodes, s, fun in ((npt, s_pt, point_triangle), (nee, s_ee, edge_edge)):
            act = s < d * d
            if not np.any(act):
                continue
            s2, g, H, _ = fun(x[nodes[act]], hessian=tangent, compiled=self.compiled)
            nodes_list.append(nodes[act])
            grads.append(g.reshape(-1, 12))
            hess.append(H)
            dist.append(np.sqrt(s2))
        force = np.zeros((self.n_nodes, 3))
        if not nodes_list:
            self._count(t0)
            return SelfContactState(0.0, force, np.zeros((0, 4), np.int64),
                                    np.zeros((0, 12, 12)) if tangent else None, float(np.sqrt(smin)), 0)
        nodes = np.concatenate(nodes_list)
        gs = np.concatenate(grads)
        delta = np.maximum(np.concatenate(dist), 1e-12 * d)
        e, e1, e2 = pair_law(delta, d, k)
        energy = float(np.sum(e))
        gd = gs / (2.0 * delta[:, None])  # grad delta (A, 12)
        idx = (3 * nodes[:, :, None] + np.arange(3)).ravel()
        force = np.bincount(idx, (e1[:, None] * gd).ravel(), minlength=3 * self.n_nodes).reshape(-1, 3)
        blocks = None
        if tangent:
            Hs = np.concatenate(hess)
            hd = Hs / (2.0 * delta[:, None, None]) - np.einsum("am,an->amn", gs, gs) / (4.0 * delta[:, None, None] ** 3)
            blocks = e2[:, None, None] * np.einsum("am,an->amn", gd, gd) + e1[:, None, None] * hd
            if project:
                blocks = psd_project(blocks, compiled=self.compiled)
        self._count(t0)
        return SelfContactState(energy, force, nodes, blocks, float(np.sqrt(smin)), len(nodes))

    def _count(self, t0):
        self.stats.force_s += time.perf_counter() - t0
        self.stats.force_calls += 1

    def near_force(self, x, cache: NearPairCache | None, *, energy: bool = False):
        """The force ``(N, 3)`` [N] (gradient of ``E_s``) at ``x (N, 3)`` [m] and, with ``energy``, ``E_s`` [J],
        for the explicit solver: only the near pairs of ``cache`` (the solve's :class:`NearPairCache`; None:
        a fresh broad phase) whose lower bound (Eq. 1 of :mod:`.near_pairs`) is below the thickness are
        evaluated, and none when even the smallest bound is above it (an O(N) test)."""
        x = self._check_x(x)
        if cache is None:
            st = self.evaluate(x, tangent=False)
            return (st.force, st.energy) if energy else st.force
        m, m_max = cache.current(self.prims, x, self.thickness)
        d = self.thickness
        if cache.min_dist - 2.0 * m_max >= d:
            f = np.zeros_like(x)
            return (f, 0.0) if energy else f
        live = cache.lower_bounds(m) < d
        q = len(cache.npt)
        st = self.evaluate_pairs(x, cache.npt[live[:q]], cache.nee[live[q:]], tangent=False, scale=_scale(cache))
        return (st.force, st.energy) if energy else st.force

    def energy(self, x, *, cache: PairCache | None = None) -> float:
        """E_s [J] at ``x (N, 3)`` [m]."""
        return self.evaluate(x, tangent=False, cache=cache).energy

    def force(self, x, *, cache: PairCache | None = None) -> np.ndarray:
        """Gradient of E_s, ``(N, 3)`` [N], at ``x (N, 3)`` [m] (the repulsion on the sheet is its negative)."""
        return self.evaluate(x, tangent=False, cache=cache).force

    def min_distance(self, x) -> float:
        """Smallest distance [m] over the pairs within ``d + margin`` (inf if none) at ``x (N, 3)`` [m]."""
        return self.evaluate(self._check_x(x), tangent=False).min_distance

    # --- continuous collision: the step bound ----------------------------------------------------
    def max_step_fraction(self, x, dx, *, cache: PairCache | None = None, max_rounds: int = 200) -> float:
        """Largest ``alpha`` in (0, 1] such that on the path ``x + t dx``, ``0 <= t <= alpha``, no pair
        comes closer than ``min_fraction`` times its distance at ``x`` (module docstring).

        Parameters
        ----------
        x : (N, 3) positions at the start of the step [m]
        dx : (N, 3) step [m]
        cache : the solve's pair cache (the pairs near ``x``), or None
        max_rounds : advancing rounds of the additive CCD; a pair still approaching after them keeps
            the time it reached (conservative)

        The pairs checked are those listed near ``x``; when the step's relative motion
        ``2 max_n |dx_n - c|`` (``c`` the midrange of ``dx``) could bring an unlisted pair (farther than
        ``r``, :meth:`PairCache.unlisted_distance`) below ``min_fraction r``, also those of a swept
        broad phase over ``x -> x + dx`` (radius ``d``: the pairs it leaves out stay farther than ``d``
        on the whole path). A step whose relative motion exceeds :attr:`sweep_limit` (the
        :data:`SWEEP_PAIRS` budget) is tested, and bounded, over its first ``sweep_limit / spread``.
        """
        x = self._check_x(x)
        dx = self._check_x(dx)
        if not np.all(np.isfinite(dx)):
            raise ValueError("dx has non-finite entries")
        eta, d = self.min_fraction, self.thickness
        c = 0.5 * (dx.max(axis=0) + dx.min(axis=0))
        spread = 2.0 * float(np.sqrt(np.max(np.einsum("ni,ni->n", dx - c, dx - c), initial=0.0)))
        if spread == 0.0:
            return 1.0
        listed = self.pairs(x, cache)
        far = cache.unlisted_distance(x) if cache is not None else d + self.margin
        npt, nee = self._x4(x, listed)
        scale = 1.0
        if spread > (1.0 - eta) * far:
            if spread > self.sweep_limit:  # a step too long to sweep within the pair budget: test its start
                scale = self.sweep_limit / spread
                self.stats.sweeps_limited += 1
            swept = find_pairs(self.prims, x, d, x + scale * dx, compiled=self.compiled)
            s_pt, s_ee = self._x4(x, swept)
            npt, nee = np.concatenate([npt, s_pt]), np.concatenate([nee, s_ee])
        t_pt = additive_ccd_nodes(x, scale * dx, npt, 0, eta, max_rounds, compiled=self.compiled)
        t_ee = additive_ccd_nodes(x, scale * dx, nee, 1, eta, max_rounds, compiled=self.compiled)
        return float(scale * min(1.0, t_pt, t_ee))


def _scale(cache) -> float:
    """The solve's factor on the stiffness carried by its pair cache (:attr:`.broad_phase.PairCache.stiffness_scale`),
    1 without a cache."""
    return 1.0 if cache is None else cache.stiffness_scale
