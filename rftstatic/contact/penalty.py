"""Penalty contact of the sheet's nodes with rigid obstacles (the static solver's contact law).

Penalty contact (Sze & Zhou 2016, §4.5; Liu & Sze 2009). Every node ``n`` with nodal area ``A_n`` and
every obstacle with signed distance ``phi`` (``phi < 0`` inside) contribute

    E = sum_n sum_obstacles 1/2 k A_n min(phi(x_n), 0)^2                      [J]

to the total potential energy. Its gradient ``f_n = k A_n min(phi, 0) n`` (``n = grad phi``) is what
:meth:`PenaltyContact.force` returns, i.e. an internal-force term of the residual
``R = f_int + f_contact - P``; the force the obstacle exerts on the sheet is ``-f_n = k A_n |phi| n``
(outward). Its derivative is node-diagonal,

    K_n = d f_n / d x_n = k A_n (n n^T + phi H)     for phi < 0,  0 otherwise,

with ``H`` the Hessian of ``phi`` (:meth:`rftstatic.contact.obstacles.Obstacle.normal_gradient`); the global
tangent only needs these ``(N, 3, 3)`` diagonal blocks. An obstacle with sharp edges (a triangle surface,
``Obstacle.psd_tangent``) has a curvature ``H`` that grows without bound near an edge (``1 / r``): there each
block is projected onto the positive semi-definite matrices (:func:`psd_blocks`); since ``H n = 0``, ``H``
is PSD and the slope ``<= 0``, this keeps ``k A e'' n n^T`` and drops the negative ``e' H`` (exact on the
faces, where ``H = 0``; a Gauss-Newton tangent at the edges and corners). The ``phi H`` term is negative
semi-definite on a convex obstacle (it softens the tangential directions on a sphere or a rounded edge) and is tiny next to
``n n^T`` because ``|phi| << 1 / |H|``.

A node pressed with a contact pressure ``p`` [Pa] penetrates ``p / k`` (:func:`estimate_penetration`);
:func:`auto_penalty` chooses ``k`` from the fabric and the element size so that this stays a small
fraction of the element size.

The kinematic contact of the explicit solver is :mod:`rftstatic.contact.kinematic`.

Nothing here depends on the obstacles' types: only ``signed_distance`` and ``normal_gradient`` are used.

Moving obstacles: the solve's candidate list may carry a rigid pose per obstacle
(:attr:`rftstatic.contact.candidates.CandidateList.poses`, set through
:attr:`rftstatic.model.state.State.obstacle_poses`, or translations only through
:attr:`rftstatic.model.state.State.obstacle_offsets`); obstacle ``m`` is then evaluated in its body frame,
``phi(x) = phi_b(R^T (x - c - s) + c)``, its normal ``R n_b`` and Hessian ``R H_b R^T`` ((P1)-(P2) of
:mod:`rftstatic.contact.motion`), so a route or a keyframed motion (:attr:`PenaltyContact.motion`) moves an
obstacle while the Model stays frozen. Every path that passes the State's candidate list (Newton's energy,
residual and tangent, the explicit force, the friction impulses) sees the same pose.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from rftstatic.contact.candidates import CandidateList
from rftstatic.contact.common import as_list as _as_list, as_points as _as_points, positive as _positive
from rftstatic.contact.friction import friction_terms
from rftstatic.contact.obstacles import Obstacle
from rftstatic.contact.penalty_compiled import compiled_force, point_form
from rftstatic.model.frozen import Frozen

FEATURE_GAP = 0.05
"""Gap ``d`` of the sharp-feature pairs (:mod:`rftstatic.contact.features`), in mean sheet edge lengths (at
least the penalty's onset width): the sheet passes over a sharp obstacle edge this far from it."""

FEATURE_STIFFNESS = 0.1
"""Stiffness of a sharp-feature pair in units of a node's penalty spring ``k A`` (mean node area): a node sees
several pairs at once (the vertices and edges of a fine obstacle near it), and the largest push of one pair,
``k d``, is still about 30 x the weight of the whole 30 cm wool sheet of sphere-30 at 33 x 33 nodes."""

FEATURE_MARGIN = 0.25
"""Broad-phase margin of the sharp-feature pairs, in mean sheet edge lengths: their list is rebuilt once a node
moved half of it (a smaller margin than the nodes' candidate list: a fine obstacle has many features near each
node, and every listed pair's distance bound is computed at every evaluation)."""

__all__ = [
    "PenaltyContact",
    "ContactState",
    "auto_penalty",
    "estimate_penetration",
]


@dataclass(frozen=True)
class ContactState:
    """Penalty contact evaluated at one configuration.

    Attributes
    ----------
    energy : contact energy [J]
    force : (N, 3) gradient of the energy, ``dE/dx`` [N]
    tangent_blocks : (N, 3, 3) node-diagonal blocks of ``d force / dx`` [N/m]
    gap : (N,) smallest signed distance over the obstacles [m]
    active : (N,) node penetrates at least one obstacle
    pair_blocks : the tangent's node-pair blocks of the obstacles' sharp features
        ``(rows (B,), cols (B,), blocks (B, 3, 3))`` [N/m] (:mod:`rftstatic.contact.features`), or None
    """

    energy: float
    force: np.ndarray
    tangent_blocks: np.ndarray
    gap: np.ndarray
    active: np.ndarray
    pair_blocks: tuple | None = None

    @property
    def max_penetration(self) -> float:
        """Largest penetration depth ``max(0, -min gap)`` [m]."""
        return float(max(0.0, -self.gap.min())) if self.gap.size else 0.0

    @property
    def n_active(self) -> int:
        """Number of penetrating nodes."""
        return int(np.count_nonzero(self.active))


class PenaltyContact(Frozen):
    """Node-to-obstacle penalty contact, ``E = sum 1/2 k A_n min(phi, 0)^2`` (read-only once built).

    Parameters
    ----------
    obstacles : an obstacle or a sequence of them (anything with ``signed_distance`` and
        ``normal_gradient``)
    node_area : (N,) area attributed to each node, e.g. a third of its triangles' areas [m^2]
    stiffness : penalty stiffness ``k`` (pressure per penetration depth) [N/m^3]; see :func:`auto_penalty`
    smoothing : width ``eps`` [m] of a C^2 onset of the penalty (0: the plain quadratic penalty).
        With ``eps > 0`` the energy density per node is ``k (eps - phi)^3 / (6 eps)`` for
        ``0 <= phi < eps`` and ``k (eps^2/6 - eps phi/2 + phi^2/2)`` for ``phi < 0``: value, slope and
        curvature are continuous, so the Hessian does not jump when a node touches or leaves the
        obstacle and Newton keeps its quadratic convergence while the contact set settles. A node
        resting under a pressure ``p`` sits at ``phi = eps/2 - p/k``.

    Notes
    -----
    The four methods :meth:`energy`, :meth:`force`, :meth:`tangent_blocks` and :meth:`gaps` each
    evaluate the signed distances once; :meth:`evaluate` returns all of them from one evaluation and is
    what a Newton iteration should call.

    Candidate list: given a :class:`~rftstatic.contact.candidates.CandidateList` (made by
    :meth:`new_candidates`, kept by the solver in its State), :meth:`evaluate` and :meth:`force`
    compute distances only for the nodes that were within ``margin`` of an obstacle when the list was
    last refreshed, and refresh it (one evaluation of every node) once some node has moved more than
    ``margin / 2`` since. A node left out is still more than ``margin / 2 > eps`` away and has no
    contact energy: the result is exact, and an explicit step (which moves nodes a small fraction of
    an element) pays for the few nodes near the obstacle instead of all of them. Without a list every
    node is evaluated; the contact itself holds no state.
    """

    def __init__(self, obstacles: Obstacle | Sequence[Obstacle], node_area, stiffness: float,
                 smoothing: float = 0.0, sheet=None, friction=None, motion=None):
        self.obstacles = _as_list(obstacles)
        self.motion = motion  # a rftstatic.contact.motion.ObstacleMotion (keyframes) or None; the pose is State
        if motion is not None and len(motion.motions) != len(self.obstacles):
            raise ValueError(f"the motion gives {len(motion.motions)} obstacle motions, the contact has "
                             f"{len(self.obstacles)} obstacles: give one (or None) per obstacle")
        self.friction = friction  # a rftstatic.contact.friction.FrictionLaw, lagged through the candidate list
        self.smoothing = _positive("smoothing", smoothing, allow_zero=True)
        area = np.asarray(node_area, dtype=float)
        if area.ndim != 1:
            raise ValueError(f"node_area must have shape (N,), got shape {area.shape}")
        bad = ~np.isfinite(area) | (area < 0)
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"node_area must be finite and >= 0, got node_area[{i}] = {area[i]!r}")
        self.node_area = area
        self.stiffness = _positive("stiffness", stiffness)
        # list margin [m]: a few onset widths, and half a node spacing so explicit runs refresh seldom
        spacing = float(np.sqrt(np.mean(area))) if area.size and np.mean(area) > 0 else 0.0
        self.margin = max(4.0 * self.smoothing, 0.5 * spacing)
        self.point_form = point_form(self.obstacles)  # compiled distances (rftstatic.contact.penalty_compiled) or None
        self.features = None
        if sheet is not None and any(ob.sharp_features() is not None for ob in self.obstacles):
            from rftstatic.contact.features import FeatureContact

            X = np.asarray(sheet.X3, float)
            edges = np.asarray(sheet.topology.edges)
            h = float(np.mean(np.linalg.norm(X[edges[:, 1]] - X[edges[:, 0]], axis=1)))
            self.features = FeatureContact(self.obstacles, sheet.tri, edges, X, gap=max(self.smoothing, FEATURE_GAP * h),
                                           stiffness=FEATURE_STIFFNESS * self.stiffness * float(np.mean(area)),
                                           margin=max(4.0 * self.smoothing, FEATURE_MARGIN * h))
        self._freeze()

    def new_candidates(self) -> CandidateList:
        """An empty candidate list with this contact's margin (for a solver's State)."""
        return CandidateList(self.margin)

    @property
    def n_nodes(self) -> int:
        """Number of nodes ``N``."""
        return self.node_area.shape[0]

    def _distances(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distances ``(M, N)`` [m] and normals ``(M, N, 3)`` for the ``M`` obstacles."""
        return self._distances_of(_as_points(x, self.n_nodes))

    def _distances_of(self, x: np.ndarray, poses=None) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`_distances` for any number of points ``(P, 3)`` [m]; ``poses``: the obstacles' poses in the
        solve (:class:`~rftstatic.contact.motion.Poses`, :attr:`~rftstatic.contact.candidates.CandidateList.poses`),
        None: as built."""
        if not self.obstacles:
            return np.full((0, x.shape[0]), np.inf), np.zeros((0, x.shape[0], 3))
        obstacles = self._shaped(poses)
        if poses is None:
            phis, normals = zip(*(ob.signed_distance(x) for ob in obstacles))
        elif not poses.rotated:  # a translated obstacle: its distance at the point moved back by the translation
            phis, normals = zip(*(ob.signed_distance(x - o) for ob, o in zip(obstacles, poses.translation)))
        else:  # (P2): the distance in the body frame, the normal rotated back to the world
            pairs = [ob.signed_distance(poses.to_body(x, m)) for m, ob in enumerate(obstacles)]
            phis = [p for p, _ in pairs]
            normals = [poses.to_world(n, m) for m, (_, n) in enumerate(pairs)]
        return np.stack(phis), np.stack(normals)

    def _shaped(self, poses):
        """The obstacles as they are shaped at the poses' times: a deforming one
        (:class:`~rftstatic.contact.obstacles.surface_sequence.SurfaceSequence`, a finite ``poses.shape_time``) by
        its ``shape_at``."""
        if poses is None or not poses.deforming:
            return self.obstacles
        return [ob if np.isnan(t) else ob.shape_at(t) for ob, t in zip(self.obstacles, poses.shape_time)]

    def _slack(self, candidates, poses) -> float:
        """Largest surface motion [m] of the deforming obstacles since the candidate list's refresh."""
        ref = getattr(candidates, "shape_times", None)
        if poses is None or not poses.deforming:
            return 0.0 if ref is None or not np.isfinite(ref).any() else np.inf
        if ref is None:
            return np.inf
        out = 0.0
        for ob, t0, t1 in zip(self.obstacles, ref, poses.shape_time):
            if np.isnan(t0) != np.isnan(t1):
                return np.inf
            if not np.isnan(t1):
                out = max(out, ob.drift(float(t0), float(t1)))
        return out

    def _offsets(self, candidates):
        """The obstacles' poses (:class:`~rftstatic.contact.motion.Poses`) the solve's ``candidates`` carry, or None."""
        poses = getattr(candidates, "poses", None)
        if poses is None:
            return None
        if poses.n_obstacles != len(self.obstacles):
            raise ValueError(f"obstacle offsets have shape {(poses.n_obstacles, 3)}, the contact has "
                             f"{len(self.obstacles)} obstacles: give one (x, y, z) translation per obstacle")
        if self.features is not None:
            raise ValueError("obstacle offsets move smooth obstacles only: this contact has sharp features "
                             "(edges of a surface obstacle), whose edge contact does not move with them")
        return poses

    def evaluate(self, x: np.ndarray, *, tangent: bool = True, candidates: CandidateList | None = None
                 ) -> ContactState:
        """Energy, force, tangent blocks and gaps at positions ``x``.

        Parameters
        ----------
        x : (N, 3) current nodal positions [m]
        tangent : also compute the tangent blocks (else they are zeros)
        candidates : the solve's candidate list (refreshed here when needed); None: every node

        Returns
        -------
        ContactState
        """
        x = _as_points(x, self.n_nodes)
        n = x.shape[0]
        offsets = self._offsets(candidates)
        cand, gap = self._near(x, candidates)
        xc = x[cand]
        phi, normal = self._distances_of(xc, offsets)
        e, d1, d2 = self._density(phi)  # energy density, d/dphi, d2/dphi2 per unit k A  (M, C)
        ka = self.stiffness * self.node_area[cand]  # (C,) [N/m]
        energy = float(np.sum(ka * np.sum(e, axis=0)))
        force = np.zeros((n, 3))
        force[cand] = np.einsum("n,mn,mni->ni", ka, d1, normal)
        blocks = np.zeros((n, 3, 3))
        if tangent:
            for m, ob in enumerate(self._shaped(offsets)):
                # touching nodes (phi = 0) get the one-sided Hessian too: a sheet laid on a support
                # then starts with the support's stiffness instead of a singular tangent
                act = phi[m] <= self.smoothing
                if not np.any(act):
                    continue
                if offsets is None:
                    H = ob.normal_gradient(xc[act])
                elif not offsets.rotated:
                    H = ob.normal_gradient(xc[act] - offsets.translation[m])
                else:  # (P2): R H_b R^T at the point in the body frame
                    R = offsets.rotation[m]
                    H = np.einsum("ij,njk,lk->nil", R, ob.normal_gradient(offsets.to_body(xc[act], m)), R)
                nn = np.einsum("ni,nj->nij", normal[m, act], normal[m, act])
                block = d2[m, act, None, None] * nn + d1[m, act, None, None] * H
                if ob.psd_tangent:
                    block = psd_blocks(block)
                blocks[cand[act]] += ka[act, None, None] * block
        active = np.zeros(n, dtype=bool)
        if phi.shape[0]:
            gap[cand] = phi.min(axis=0)
            active[cand] = np.any(phi < 0.0, axis=0)
        pairs = None
        if self.features is not None:
            fs = self.features.evaluate(x, tangent=tangent, cache=candidates)
            energy += fs.energy
            force += fs.force
            pairs = (fs.rows, fs.cols, fs.blocks) if len(fs.rows) else None
        lag = getattr(candidates, "friction", None)
        if lag is not None:
            ef, ff, kf = friction_terms(lag, x, tangent=tangent)
            energy += ef
            force += ff
            if tangent:
                blocks += kf
        return ContactState(energy, force, blocks, gap, active, pairs)

    def _near(self, x, candidates):
        """Indices of the candidate nodes and an ``(N,)`` gap array: exact values are filled in by the caller for the
        candidates; the others hold a lower bound (> margin / 2) [m]."""
        n = x.shape[0]
        if not self.obstacles:
            return np.arange(0), np.full(n, np.inf)
        if candidates is None:
            return np.arange(n), np.full(n, np.inf)
        poses = self._offsets(candidates)
        hit = candidates.lookup(x, self._slack(candidates, poses))
        if hit is not None:
            return hit
        phi, _ = self._distances_of(x, poses)
        gap = phi.min(axis=0)
        return candidates.refresh(x, gap), gap.copy()

    def _density(self, phi):
        eps = self.smoothing
        inside = phi < 0.0
        if eps == 0.0:
            pen = np.where(inside, phi, 0.0)
            return 0.5 * pen**2, pen, np.where(phi <= 0.0, 1.0, 0.0)
        onset = (phi >= 0.0) & (phi < eps)
        a = np.where(onset, eps - phi, 0.0)
        p = np.where(inside, phi, 0.0)
        e = np.where(onset, a**3 / (6 * eps), 0.0) + np.where(inside, eps**2 / 6 - eps * p / 2 + p**2 / 2, 0.0)
        d1 = np.where(onset, -(a**2) / (2 * eps), 0.0) + np.where(inside, p - eps / 2, 0.0)
        d2 = np.where(onset, a / eps, 0.0) + np.where(inside, 1.0, 0.0)
        return e, d1, d2

    def _slope(self, phi):
        """``d1`` of :meth:`_density` alone (the force needs no energy or curvature)."""
        eps = self.smoothing
        if eps == 0.0:
            return np.minimum(phi, 0.0)
        d1 = np.where(phi < 0.0, phi - 0.5 * eps, 0.0)
        onset = (phi >= 0.0) & (phi < eps)
        if np.any(onset):
            a = eps - phi[onset]
            d1[onset] = -(a * a) / (2 * eps)
        return d1

    def energy(self, x: np.ndarray, *, candidates: CandidateList | None = None) -> float:
        """Contact energy ``sum 1/2 k A_n min(phi, 0)^2`` [J] at ``x (N, 3)`` [m]."""
        return self.evaluate(x, tangent=False, candidates=candidates).energy

    def force(self, x: np.ndarray, *, candidates: CandidateList | None = None) -> np.ndarray:
        """Gradient of the contact energy, ``(N, 3)`` [N], at ``x (N, 3)`` [m].

        ``k A_n min(phi, 0) n`` summed over the obstacles; it points into the obstacle, so it is the
        contact term of the residual (the obstacle pushes the sheet with its negative). The explicit
        loop calls this once per step: only the candidates' distances and the slope of the energy density are
        computed (no energy, gaps or tangent blocks), where the distance may be below ``eps``; for rigid analytic
        obstacles at rest in three compiled passes, bit-identical (:mod:`rftstatic.contact.penalty_compiled`).
        """
        x = _as_points(x, self.n_nodes)
        force = compiled_force(self, x, candidates)  # None: not covered, the numpy path (the reference)
        if force is None:
            cand, bound = self._near(x, candidates)
            gap0 = getattr(candidates, "gaps", None)  # distances at the refresh; bound = gap0 - the motion since
            if gap0 is not None and cand.size:  # 2 x motion: room for |grad phi| up to 2 (a smooth surface's: ~1)
                cand = cand[gap0[cand] - 2.0 * (gap0[cand] - bound[cand]) < self.smoothing]
            force = np.zeros((x.shape[0], 3))
            if cand.size:
                phi, normal = self._distances_of(x[cand], self._offsets(candidates))
                d1 = self._slope(phi)
                force[cand] = np.einsum("n,mn,mni->ni", self.stiffness * self.node_area[cand], d1, normal)
        if self.features is not None:
            force += self.features.evaluate(x, tangent=False, cache=candidates).force
        lag = getattr(candidates, "friction", None)
        if lag is not None:
            force += friction_terms(lag, x, tangent=False)[1]
        return force

    def tangent_blocks(self, x: np.ndarray, *, candidates: CandidateList | None = None) -> np.ndarray:
        """Node-diagonal blocks ``(N, 3, 3)`` [N/m] of ``d force / dx`` at ``x (N, 3)`` [m]: ``k A_n (n n^T + phi H)``
        for each obstacle the node penetrates; symmetric."""
        return self.evaluate(x, candidates=candidates).tangent_blocks

    def gaps(self, x: np.ndarray) -> np.ndarray:
        """Smallest signed distance of each node over the obstacles, ``(N,)`` [m] (``inf`` if none)."""
        x = _as_points(x, self.n_nodes)
        phi, _ = self._distances(x)
        return phi.min(axis=0) if phi.shape[0] else np.full(x.shape[0], np.inf)

    def project_out(self, x: np.ndarray, clearance: float = 0.0, rounds: int = 4) -> np.ndarray:
        """``x (N, 3)`` [m] with every node closer than ``clearance`` [m] to an obstacle (or inside it)
        moved along that obstacle's outward normal to the distance ``clearance``, the deepest obstacle
        first, for ``rounds`` rounds (a node between two obstacles). A copy; the nodes outside stay.
        Used to lift a state carried from another mesh out of the obstacles (the new nodes of a coarse
        chord across a rounded edge lie inside it) before Newton starts from it."""
        x = np.array(_as_points(x, self.n_nodes), dtype=float)
        if not self.obstacles:
            return x
        for _ in range(rounds):
            phi, normal = self._distances(x)
            deepest = phi.argmin(axis=0)
            cols = np.arange(x.shape[0])
            depth = phi[deepest, cols]
            inside = depth < clearance
            if not inside.any():
                break
            x[inside] += (clearance - depth[inside])[:, None] * normal[deepest[inside], cols[inside]]
        return x

    def max_penetration(self, x: np.ndarray) -> float:
        """Largest penetration depth ``max(0, -min gap)`` [m] at ``x (N, 3)`` [m]."""
        gap = self.gaps(x)
        return float(max(0.0, -gap.min())) if gap.size else 0.0

    def active(self, x: np.ndarray) -> np.ndarray:
        """``(N,)`` bool: node penetrates at least one obstacle at ``x (N, 3)`` [m]."""
        return self.gaps(x) < 0.0


def psd_blocks(blocks: np.ndarray) -> np.ndarray:
    """Symmetric ``(n, 3, 3)`` blocks with their negative eigenvalues set to 0 (the nearest positive
    semi-definite matrices in the Frobenius norm)."""
    w, Q = np.linalg.eigh(0.5 * (blocks + np.swapaxes(blocks, 1, 2)))
    return np.einsum("nik,nk,njk->nij", Q, np.maximum(w, 0.0), Q)


def auto_penalty(
    *,
    membrane_rigidity: float,
    bending_rigidity: float,
    weight: float,
    h: float,
    factor: float = 1.0,
    target: float = 1e-3,
    pressure_factor: float = 10.0,
) -> float:
    """Penalty stiffness from the fabric and the element size.

    Parameters
    ----------
    membrane_rigidity : tensile rigidity ``C`` (largest of warp/weft) [N/m]
    bending_rigidity : bending rigidity ``B`` [N m]
    weight : weight per unit area ``w`` [N/m^2]
    h : element size (edge length) near the contact [m]
    factor : multiplier on the result (``> 1`` stiffer, less penetration, worse conditioning)
    target : admissible penetration as a fraction of ``h`` under the design pressure
    pressure_factor : design contact pressure in units of ``w``

    Returns
    -------
    k : penalty stiffness [N/m^3]

    Notes
    -----
    A node carries area ``~h^2``, so its penalty spring is ``k h^2`` [N/m] and a contact pressure
    ``p`` makes it penetrate ``d = p / k``. Three conditions are combined,

        k = factor * max(C / h^2,  B / h^4,  pressure_factor * w / (target * h)).

    * ``C / h^2``: the node's penalty spring equals the membrane stiffness of its elements (``~C``), so
      the contact does not dominate the tangent's conditioning, yet is as stiff as the sheet in-plane;
    * ``B / h^4``: the same with the bending stiffness ``B / h^2`` of a node (never the largest for
      fabrics, kept for stiff plates);
    * ``pressure_factor * w / (target * h)``: under the design pressure ``p = pressure_factor * w`` the
      penetration is at most ``target * h``. The default ``p = 10 w`` covers the line load at a pedestal's
      edge: a hanging length ``L`` pulls with tension ``~w L`` spread over one element, ``p ~ w L / h``.

    For the wool of §4 (``C = 1096.6 N/m``, ``B = 8.14e-6 N m``, ``w = 1.863 N/m^2``) at ``h = 5 mm``:
    ``C / h^2 = 4.4e7``, ``B / h^4 = 1.3e4``, ``10 w / (1e-3 h) = 3.7e6`` so ``k = 4.4e7 N/m^3`` and
    ``10 w`` penetrates ``4.2e-7 m = 8.5e-5 h``.
    """
    c = _positive("membrane_rigidity", membrane_rigidity, allow_zero=True)
    b = _positive("bending_rigidity", bending_rigidity, allow_zero=True)
    w = _positive("weight", weight, allow_zero=True)
    h = _positive("h", h)
    factor = _positive("factor", factor)
    target = _positive("target", target)
    pressure_factor = _positive("pressure_factor", pressure_factor, allow_zero=True)
    k = factor * max(c / h**2, b / h**4, pressure_factor * w / (target * h))
    if not k > 0:
        raise ValueError(
            "membrane_rigidity, bending_rigidity and weight (with pressure_factor) are all zero; "
            "give at least one of them > 0"
        )
    return k


def estimate_penetration(pressure, k: float):
    """Penetration ``pressure / k`` [m] of a node pressed with ``pressure`` [Pa] on a penalty ``k`` [N/m^3].

    ``pressure`` may be a number or an array; ``k > 0``.
    """
    k = _positive("k", k)
    p = np.asarray(pressure, dtype=float)
    if np.any(p < 0) or not np.all(np.isfinite(p)):
        raise ValueError(f"pressure must be finite and >= 0, got {pressure!r}")
    out = p / k
    return float(out) if out.ndim == 0 else out
