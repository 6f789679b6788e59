"""The near-pair cache of self-contact: the broad phase's pairs cut to those whose exact distance is
below the list radius ``r = d + margin`` at the build, the node motion since the build, and the
cost counters of a run.

Why cut the list. The broad phase (:func:`~.broad_phase.find_pairs`) keeps every pair whose boxes
overlap; on a flat or gently curved sheet those are the neighbours one ring of elements away, whose
distance is an element size, far above ``r``: 12,800 point-triangle and 31,229 edge-edge pairs of the
81 x 81 sheet, none of them within ``r``. A pair farther than ``r`` at the build cannot come closer
than ``d`` before the next one (its two primitives each move less than ``margin / 2``), so dropping
it changes no force: the list the law and the step filter see is the exact one within ``r``, and its
build distances ``delta_0 (P,)`` give every pair a lower bound at any later state,

    delta(x) >= delta_0 - 2 max_(k in pair) |u_k - c|,       u = x - x_build,   c = midrange of u,   (1)

since the closest points are convex combinations of the pair's nodes on each side and a distance
does not change under a translation ``c`` of the whole sheet (so a falling sheet does not rebuild).
The same translation-free motion decides the rebuild: after a motion of ``margin / 2`` (largest
``|u_k - c|``). Pairs not in the list are farther than ``r - 2 max |u - c|`` (:meth:`unlisted_distance`).

All counters (:class:`SelfContactStats`) are diagnostics: results never depend on them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from rftstatic.contact.self_contact.broad_phase import PairCache, Pairs, SheetPrimitives, find_pairs
from rftstatic.contact.self_contact import distance
from rftstatic.contact.self_contact.distance import edge_edge_distance2, point_triangle_distance2

__all__ = ["NearPairCache", "SelfContactStats", "pair_nodes"]


@dataclass
class SelfContactStats:
    """Cost and size counters of the self-contact of one model, summed over its solves.

    Attributes
    ----------
    rebuilds : broad-phase builds
    broad_phase_s : wall time of the builds, with the exact-distance cut [s]
    listed : box pairs of the last build (point-triangle + edge-edge)
    pairs : near pairs of the last build (within ``d + margin``); max_pairs : the most of any build
    force_s : wall time of the self-contact energy and force (and tangent, static) evaluations [s]
    force_calls : those evaluations
    filter_s : wall time of the explicit step filter [s]; filter_steps : steps that filtered
    filter_work_steps : steps where the per-pair test found pairs to filter
    impulses : pair impulses applied by the velocity filter; rejected_solves : its active-set solves that
        would have added kinetic energy (dropped for the Jacobi sweeps)
    ccd_limited : steps whose motion the CCD fail-safe had to shorten; ccd_min_fraction : the smallest factor
    swept : steps that needed a swept broad phase (a step longer than ``margin / 2``)
    sweeps_limited : static steps too long to sweep within the pair budget, bounded to
        :attr:`~rftstatic.contact.self_contact.law.SelfContact.sweep_limit` of relative motion
    """

    rebuilds: int = 0
    broad_phase_s: float = 0.0
    listed: int = 0
    pairs: int = 0
    max_pairs: int = 0
    force_s: float = 0.0
    force_calls: int = 0
    filter_s: float = 0.0
    filter_steps: int = 0
    filter_work_steps: int = 0
    impulses: int = 0
    rejected_solves: int = 0
    ccd_limited: int = 0
    ccd_min_fraction: float = 1.0
    swept: int = 0
    sweeps_limited: int = 0

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def pair_nodes(prims: SheetPrimitives, pairs: Pairs) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ``(Q, 4)`` of the point-triangle pairs (node, triangle) and ``(R, 4)`` of the edge-edge
    pairs (edge, edge), the rows of the distance functions of :mod:`.distance`."""
    npt = np.concatenate([pairs.pt[:, :1], prims.tri[pairs.pt[:, 1]]], axis=1)
    nee = prims.edges[pairs.ee].reshape(-1, 4)
    return npt, nee


def _distances(prims: SheetPrimitives, x: np.ndarray, pairs: Pairs,
               compiled: bool | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Distances ``(Q,)`` and ``(R,)`` [m] of the point-triangle and edge-edge ``pairs`` at ``x (N, 3)`` [m].
    Compiled: read from ``x`` by index (:func:`.geometry.distances_by_index`; the gather ``x[nodes]`` of
    the ~14,000 box pairs of hang-20's 41 x 41 sheet cost as much as the distances, 700 times a run)."""
    if distance.compiled_for(len(pairs), compiled):
        from rftstatic.contact.self_contact._kernels_numba import distances_by_index

        out = []
        for kind, rows in ((0, pairs.pt), (1, pairs.ee)):
            s = np.empty(len(rows))
            distances_by_index(x, np.ascontiguousarray(rows, dtype=np.int64), prims.tri, prims.edges, kind, s)
            out.append(np.sqrt(s))
        return out[0], out[1]
    npt, nee = pair_nodes(prims, pairs)
    dpt = np.sqrt(point_triangle_distance2(x[npt], compiled=compiled)) if len(npt) else np.zeros(0)
    dee = np.sqrt(edge_edge_distance2(x[nee], compiled=compiled)) if len(nee) else np.zeros(0)
    return dpt, dee


def translation_free_motion(a: np.ndarray, c: np.ndarray, *, b: np.ndarray | None = None,
                            s: float = 0.0, compiled: bool | None = None) -> tuple[np.ndarray, float]:
    """``|w_k - m| (N,)`` [m] and its largest value for ``w = a + s b - c`` (``a, b, c (N, 3)`` [m]) and
    ``m`` the midrange of ``w`` (Eq. 1): the motion since a build (``a = x``, ``c = x_build``), at the
    end of a step (``b = dx``, ``s = 1``), or a step's own spread (``a = dx``, ``c = 0``). Compiled
    (:func:`.kernels.midrange_motion`, two passes, no temporaries) when the self-contact twins are chosen
    (``compiled``; None: by size, :func:`.distance.compiled_for`):
    numpy's axis reductions of ``(N, 3)`` arrays took 130 us for the 1,681 nodes of hang-20, twice a step."""
    out = np.empty(len(a))
    if distance.compiled_for(len(a), compiled):
        from rftstatic.contact.self_contact._kernels_numba import midrange_motion

        big = midrange_motion(a, a if b is None else b, float(s), c, out)
        return out, float(big)
    return _motion_numpy(a, c, b, s, out)


def _motion_numpy(a, c, b, s, out):
    w = a - c if b is None or s == 0.0 else a + s * b - c
    w -= 0.5 * (w.max(axis=0) + w.min(axis=0))
    np.sqrt(np.einsum("ni,ni->n", w, w), out=out)
    return out, float(out.max(initial=0.0))


class NearPairCache(PairCache):
    """A :class:`~.broad_phase.PairCache` whose list holds the pairs within the radius by exact
    distance (module docstring), rebuilt after a translation-free motion of ``margin / 2``.

    Parameters
    ----------
    margin : [m], > 0
    stats : counters to add to (shared by the caches of one model), or None
    compiled : the kernels of its loops (the law's choice; None: by size)

    Attributes (after a build)
    --------------------------
    npt : (Q, 4) nodes of the near point-triangle pairs; nee : (R, 4) of the near edge-edge pairs
    dist_pt : (Q,) and dist_ee : (R,) their distances at the build [m]
    """

    def __init__(self, margin: float, stats: SelfContactStats | None = None, *, compiled: bool | None = None):
        super().__init__(margin, compiled=compiled)
        self.stats = stats if stats is not None else SelfContactStats()

    def _moved(self, x) -> float:
        if self._x is None or self._x.shape != x.shape:
            return np.inf
        return translation_free_motion(x, self._x, compiled=self.compiled)[1]

    def motion(self, x: np.ndarray, dx: np.ndarray | None = None) -> tuple[np.ndarray, float]:
        """``|u_k - c| (N,)`` [m], the translation-free motion of every node since the build (Eq. 1) at
        ``x (N, 3)`` [m] (or at ``x + dx``), and its largest value [m]."""
        return translation_free_motion(x, self._x, b=dx, s=0.0 if dx is None else 1.0, compiled=self.compiled)

    def pairs(self, prims: SheetPrimitives, x: np.ndarray, thickness: float) -> Pairs:
        """The near pairs for positions ``x (N, 3)`` [m], rebuilt when needed."""
        if self._moved(x) <= 0.5 * self.margin:
            return self._pairs
        return self.rebuild(prims, x, thickness)

    def current(self, prims: SheetPrimitives, x: np.ndarray, thickness: float) -> tuple[np.ndarray, float]:
        """The list made valid for ``x (N, 3)`` [m] (rebuilt when needed, as :meth:`pairs`) and the
        translation-free motion ``(N,)`` [m] since its build and its largest value (:meth:`motion`),
        computed once."""
        if self._x is None or self._x.shape != x.shape:
            self.rebuild(prims, x, thickness)
            return np.zeros(len(x)), 0.0
        m, big = self.motion(x)
        if big > 0.5 * self.margin:
            self.rebuild(prims, x, thickness)
            return np.zeros(len(x)), 0.0
        return m, big

    def step_motions(self, prims: SheetPrimitives, x: np.ndarray, dx: np.ndarray, thickness: float):
        """For an explicit step ``x -> x + dx`` (``(N, 3)`` [m]): the list made valid for ``x`` as :meth:`current`,
        and ``(m_max, end_max, spread_max)`` [m], the largest translation-free motions since its build at ``x``
        (:meth:`current`'s) and at ``x + dx`` (:meth:`motion`'s), and of the step itself
        (:func:`translation_free_motion` of ``dx``), the same values; compiled, one two-pass loop without a root per
        node (:func:`.kernels.step_motions`) instead of three (a step filter's test at every step: the per-node
        motions are wanted only by the steps that test pairs)."""
        if self._x is None or self._x.shape != x.shape or not distance.compiled_for(len(x), self.compiled):
            m_max = self.current(prims, x, thickness)[1]
            spread_max = translation_free_motion(dx, np.zeros_like(dx), compiled=self.compiled)[1]
            return m_max, self.motion(x, dx)[1], spread_max
        from rftstatic.contact.self_contact._kernels_numba import step_motions

        m_max, end_max, spread_max = step_motions(x, self._x, dx)
        if m_max > 0.5 * self.margin:
            self.rebuild(prims, x, thickness)
            m_max, end_max = 0.0, self.motion(x, dx)[1]
        return float(m_max), float(end_max), float(spread_max)

    def rebuild(self, prims: SheetPrimitives, x: np.ndarray, thickness: float) -> Pairs:
        """Build the list at ``x (N, 3)`` [m] now."""
        t0 = time.perf_counter()
        radius = thickness + self.margin
        raw = find_pairs(prims, x, radius, compiled=self.compiled)
        dpt, dee = _distances(prims, x, raw, self.compiled)
        kp, ke = dpt < radius, dee < radius
        self._pairs = Pairs(raw.pt[kp], raw.ee[ke])
        self.npt, self.nee = pair_nodes(prims, self._pairs)
        self.dist_pt, self.dist_ee = dpt[kp], dee[ke]
        self.nodes = np.concatenate([self.npt, self.nee])  # (P, 4), point-triangle first
        self.dist = np.concatenate([self.dist_pt, self.dist_ee])  # (P,)
        self.min_dist = float(self.dist.min(initial=np.inf))
        self._x = np.array(x, dtype=float, copy=True)
        self._radius = radius
        self.builds += 1
        s = self.stats
        s.rebuilds += 1
        s.listed = len(raw)
        s.pairs = len(self._pairs)
        s.max_pairs = max(s.max_pairs, s.pairs)
        s.broad_phase_s += time.perf_counter() - t0
        return self._pairs

    def lower_bounds(self, m: np.ndarray) -> np.ndarray:
        """Lower bounds ``(P,)`` [m] of the near pairs' distances (Eq. 1), ``m (N,)`` from :meth:`motion`."""
        return self.dist - 2.0 * m[self.nodes].max(axis=1)
