"""Squared distances between the sheet's own elements: point-triangle and edge-edge, with exact
gradient and Hessian, vectorised over pairs.

Both pair kinds are written as one problem. The four points of a pair are ``X = (X_0, .., X_3)``
(point-triangle: ``p, t_0, t_1, t_2``; edge-edge: ``a_0, a_1, b_0, b_1``) and the difference between
the two closest points is affine in ``X`` and in at most two feature parameters ``u``,

    r(X, u) = sum_k w_k(u) X_k,        s(X) = min_u |r(X, u)|^2,

with the weights ``w`` of the closest feature (classification, :data:`FEATURES`):

* point-triangle, face: ``r = p - (t_0 + u (t_1 - t_0) + v (t_2 - t_0))``, two parameters;
  edge ``t_i t_j``: one parameter; vertex ``t_i``: none;
* edge-edge, interior: ``r = a_0 + s e_a - b_0 - t e_b``, two parameters; an end point against the
  interior of the other edge: one parameter; end point against end point: none.

Within a feature the minimiser ``u*`` is interior, ``ds/du = 0``, and (envelope theorem)

    grad s  = 2 w_k r                                          (12,)
    hess s  = 2 (w w^T) (x) I_3  -  F G^-1 F^T                 (12, 12)
    F_(k i), a = 2 (dw_k/du_a r_i + w_k t_a,i),  G_ab = 2 t_a . t_b,  t_a = sum_k dw_k/du_a X_k,

the second term being the change of the closest points with ``X`` (``du*/dX = -G^-1 F^T``). Only
the active parameters enter ``F`` and ``G``.

The classification takes the smallest of the candidate features' distances (face or interior, then
every edge or end-point candidate with its parameter clamped to [0, 1]); the distance is continuous
across the switches and its gradient too (the closest points move continuously), the Hessian jumps.
Parallel edges: when ``|e_a x e_b|^2 <= PARALLEL_TOL |e_a|^2 |e_b|^2`` the interior candidate is
left out and the end-point candidates give the distance, which for parallel segments is exact (their
distance is attained at an end point of one of them); so ``G`` is never nearly singular. Near
parallel overlapping edges the segment distance has a kink in the tilt of the edges (a known feature
of edge-edge distances, which ipc-toolkit mollifies); on a sheet such pairs are also seen by the
point-triangle pairs of their end points, which are smooth there.

Shapes: pairs on the first axis, ``x4 (P, 4, 3)`` [m] -> ``s (P,)`` [m^2], gradient ``(P, 4, 3)``
[m], Hessian ``(P, 12, 12)`` [-] (dof ``3 k + i``).

Two paths: numpy (this module, all pairs at once) and compiled (numba, one loop over the pairs: the
scalar kernels of :mod:`.kernels`, compiled by :mod:`._kernels_numba`), chosen by :func:`compiled_for`;
they agree to round-off (closest-feature ties, e.g. exactly parallel edges, may pick another of the
equally close points). Measured 2026-12-02 (2 cores shared, load average 3.0) on the 81 x 81 fold of
:mod:`rftstatic.bench.self_contact`: squared distances of the 242,047 listed pairs 0.19 s numpy, 0.009 s
compiled; gradients and Hessians of the 28,360 pairs closer than d 0.26 s and 0.010 s.
"""

from __future__ import annotations

import sys

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.contact.self_contact.kernels import PARALLEL_TOL

__all__ = [
    "FEATURES",
    "PARALLEL_TOL",
    "point_triangle",
    "edge_edge",
    "point_triangle_distance2",
    "edge_edge_distance2",
    "pair_derivatives",
    "compiled_for",
    "COMPILED_MIN_PAIRS",
]

COMPILED_MIN_PAIRS = 2000
"""Fewest pairs (or broad-phase boxes) for which the compiled twins are loaded when they are not yet:
importing numba and loading the cached kernels costs ~0.5 s, what the numpy path spends on ~50,000
pairs' Hessians; once loaded they serve every size."""

_COMPILED = "rftstatic.contact.self_contact._kernels_numba"


def compiled_for(n: int, compiled: bool | None = None) -> bool:
    """Whether the self-contact loops over ``n`` pairs or boxes run compiled: ``compiled`` when given (the
    run's choice, :attr:`.law.SelfContact.kernels`: a law passes it to every loop it calls), else numba
    installed and ``n >= COMPILED_MIN_PAIRS`` (a call outside a run). Never what ran before in the process."""
    if compiled is not None:
        return compiled
    return numba_available() and n >= COMPILED_MIN_PAIRS


def compiled_loaded() -> bool:
    """Whether the compiled self-contact twins are loaded in this process."""
    return _COMPILED in sys.modules


def _compiled_derivatives(x4, kind, hessian):
    from rftstatic.contact.self_contact._kernels_numba import derivatives_all

    x4 = np.ascontiguousarray(x4)
    P = x4.shape[0]
    s, g, code = np.empty(P), np.empty((P, 4, 3)), np.empty(P, dtype=np.int8)
    H = np.empty((P, 12, 12) if hessian else (1, 12, 12))
    derivatives_all(x4, kind, hessian, s, g, H, code)
    return s, g, (H if hessian else None), code


def _compiled_distance2(x4, kind):
    from rftstatic.contact.self_contact._kernels_numba import distances_all

    x4 = np.ascontiguousarray(x4)
    s, code = np.empty(len(x4)), np.empty(len(x4), dtype=np.int8)
    distances_all(x4, kind, s, code)
    return s

FEATURES = {
    "point_triangle": ("face", "edge", "vertex"),
    "edge_edge": ("interior", "point-edge", "point-point"),
}
"""Names of the closest-feature codes 0, 1, 2 of :func:`point_triangle` and :func:`edge_edge`."""


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _check(x4, name):
    x4 = np.asarray(x4, dtype=float)
    if x4.ndim != 3 or x4.shape[1:] != (4, 3):
        raise ValueError(f"{name}: expected points of shape (P, 4, 3), got {x4.shape}")
    return x4


def _segment_param(p, a, b):
    """Parameter in [0, 1] of the point of segment ``a b`` closest to ``p`` (all ``(P, 3)``)."""
    e = b - a
    ee = _dot(e, e)
    t = np.where(ee > 0, _dot(p - a, e) / np.where(ee > 0, ee, 1.0), 0.0)
    return np.clip(t, 0.0, 1.0)


def _pt_classify(x4):
    """Weights ``W (P, 4)``, parameter derivatives ``D (P, 4, 2)``, active parameters ``(P, 2)``,
    squared distance ``(P,)`` and feature code ``(P,)`` of the point-triangle pairs."""
    P = x4.shape[0]
    p, t0, t1, t2 = x4[:, 0], x4[:, 1], x4[:, 2], x4[:, 3]
    e1, e2, w = t1 - t0, t2 - t0, p - t0
    a11, a12, a22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    b1, b2 = _dot(w, e1), _dot(w, e2)
    det = a11 * a22 - a12 * a12
    ok = det > 1e-14 * a11 * a22
    sdet = np.where(ok, det, 1.0)
    u = (a22 * b1 - a12 * b2) / sdet
    v = (a11 * b2 - a12 * b1) / sdet
    inside = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    rf = w - u[:, None] * e1 - v[:, None] * e2
    best = np.where(inside, _dot(rf, rf), np.inf)
    W = np.zeros((P, 4))
    D = np.zeros((P, 4, 2))
    act = np.zeros((P, 2), dtype=bool)
    code = np.zeros(P, dtype=np.int8)
    W[inside] = np.stack([np.ones_like(u), -(1 - u - v), -u, -v], axis=1)[inside]
    D[inside] = np.array([[0.0, 0.0], [1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    act[inside] = True
    for i, j in ((1, 2), (2, 3), (3, 1)):
        s = _segment_param(p, x4[:, i], x4[:, j])
        r = p - x4[:, i] - s[:, None] * (x4[:, j] - x4[:, i])
        d2 = _dot(r, r)
        take = d2 < best
        if not np.any(take):
            continue
        best = np.where(take, d2, best)
        st = s[take]
        Wt = np.zeros((st.size, 4))
        Wt[:, 0], Wt[:, i], Wt[:, j] = 1.0, -(1 - st), -st
        W[take] = Wt
        interior = (st > 0) & (st < 1)
        Dt = np.zeros((st.size, 4, 2))
        Dt[interior, i, 0], Dt[interior, j, 0] = 1.0, -1.0
        D[take] = Dt
        act[take] = np.stack([interior, np.zeros_like(interior)], axis=1)
        code[take] = np.where(interior, 1, 2)
    return W, D, act, best, code


def _ee_classify(x4):
    """As :func:`_pt_classify` for the edge-edge pairs ``(a_0, a_1, b_0, b_1)``."""
    P = x4.shape[0]
    a0, a1, b0, b1 = x4[:, 0], x4[:, 1], x4[:, 2], x4[:, 3]
    ea, eb, w0 = a1 - a0, b1 - b0, a0 - b0
    aa, ab, bb = _dot(ea, ea), _dot(ea, eb), _dot(eb, eb)
    ad, bd = _dot(ea, w0), _dot(eb, w0)
    det = aa * bb - ab * ab
    ok = det > PARALLEL_TOL * aa * bb
    sdet = np.where(ok, det, 1.0)
    s = (ab * bd - bb * ad) / sdet
    t = (aa * bd - ab * ad) / sdet
    inside = ok & (s > 0) & (s < 1) & (t > 0) & (t < 1)
    r = w0 + s[:, None] * ea - t[:, None] * eb
    best = np.where(inside, _dot(r, r), np.inf)
    S = np.where(inside, s, 0.0)
    T = np.where(inside, t, 0.0)
    act = np.zeros((P, 2), dtype=bool)
    act[inside] = True
    code = np.zeros(P, dtype=np.int8)
    # end point of one edge against the other segment: (which parameter is fixed, its value)
    for fixed, value in (("s", 0.0), ("s", 1.0), ("t", 0.0), ("t", 1.0)):
        if fixed == "s":
            pt = a0 + value * ea
            q = _segment_param(pt, b0, b1)
            s_c, t_c = np.full(P, value), q
        else:
            pt = b0 + value * eb
            q = _segment_param(pt, a0, a1)
            s_c, t_c = q, np.full(P, value)
        rc = w0 + s_c[:, None] * ea - t_c[:, None] * eb
        d2 = _dot(rc, rc)
        take = d2 < best
        if not np.any(take):
            continue
        best = np.where(take, d2, best)
        S, T = np.where(take, s_c, S), np.where(take, t_c, T)
        interior = (q > 0) & (q < 1)
        col = 1 if fixed == "s" else 0
        act[take] = False
        act[take, col] = interior[take]
        code[take] = np.where(interior[take], 1, 2)
    W = np.stack([1 - S, S, -(1 - T), -T], axis=1)
    D = np.zeros((P, 4, 2))
    D[:, :, 0] = [-1.0, 1.0, 0.0, 0.0]
    D[:, :, 1] = [0.0, 0.0, 1.0, -1.0]
    D *= act[:, None, :]
    return W, D, act, best, code


def pair_derivatives(x4, W, D, act, *, hessian=True):
    """Squared distance ``(P,)`` [m^2], gradient ``(P, 4, 3)`` [m] and Hessian ``(P, 12, 12)`` [-] of
    ``|sum_k W_k X_k|^2`` minimised over the active parameters (module docstring).

    Parameters
    ----------
    x4 : (P, 4, 3) the pairs' points [m]
    W : (P, 4) weights of the closest points
    D : (P, 4, 2) their derivatives by the feature parameters (zero for inactive ones)
    act : (P, 2) bool, active (interior) parameters
    hessian : also return the Hessian (else None)
    """
    r = np.einsum("pk,pki->pi", W, x4)
    s = _dot(r, r)
    grad = 2.0 * W[:, :, None] * r[:, None, :]
    if not hessian:
        return s, grad, None
    P = x4.shape[0]
    eye3 = np.eye(3)
    H = 2.0 * np.einsum("pk,pl,ij->pkilj", W, W, eye3).reshape(P, 12, 12)
    if np.any(act):
        tv = np.einsum("pka,pki->pai", D, x4)  # (P, 2, 3)
        G = 2.0 * np.einsum("pai,pbi->pab", tv, tv)
        F = 2.0 * (np.einsum("pka,pi->pkia", D, r) + np.einsum("pk,pai->pkia", W, tv))
        F = F.reshape(P, 12, 2) * act[:, None, :]
        mask = act[:, :, None] & act[:, None, :]
        G = np.where(mask, G, np.eye(2))
        H -= np.einsum("pma,pab,pnb->pmn", F, np.linalg.inv(G), F)
    return s, grad, H


def point_triangle(x4, *, hessian=True, compiled=None):
    """Point-triangle squared distance, gradient, Hessian and closest feature.

    Parameters
    ----------
    x4 : (P, 4, 3) rows ``(p, t_0, t_1, t_2)`` [m]: a point and a triangle that does not contain it
    hessian : also compute the Hessian
    compiled : the compiled twin or the numpy path (None: :func:`compiled_for` by size)

    Returns
    -------
    s : (P,) squared distance [m^2]
    grad : (P, 4, 3) ``ds/dX`` [m]
    hess : (P, 12, 12) ``d^2 s/dX^2`` [-], or None
    feature : (P,) int8, 0 face, 1 edge, 2 vertex (:data:`FEATURES`)
    """
    return _derivatives(x4, 0, hessian, "point_triangle", compiled)


def edge_edge(x4, *, hessian=True, compiled=None):
    """Edge-edge (segment-segment) squared distance, gradient, Hessian and closest feature.

    Parameters
    ----------
    x4 : (P, 4, 3) rows ``(a_0, a_1, b_0, b_1)`` [m]: two edges that share no node
    hessian : also compute the Hessian
    compiled : as for :func:`point_triangle`

    Returns
    -------
    s : (P,) squared distance [m^2]
    grad : (P, 4, 3) ``ds/dX`` [m]
    hess : (P, 12, 12) ``d^2 s/dX^2`` [-], or None
    feature : (P,) int8, 0 interior-interior, 1 end point-edge, 2 end point-end point
    """
    return _derivatives(x4, 1, hessian, "edge_edge", compiled)


def _derivatives(x4, kind: int, hessian: bool, who: str, compiled: bool | None):
    """:func:`point_triangle` (``kind`` 0) or :func:`edge_edge` (1): compiled, or classified and derived in numpy."""
    x4 = _check(x4, who)
    if compiled_for(len(x4), compiled):
        return _compiled_derivatives(x4, kind, hessian)
    W, D, act, _, code = (_pt_classify if kind == 0 else _ee_classify)(x4)
    s, g, H = pair_derivatives(x4, W, D, act, hessian=hessian)
    return s, g, H, code


def point_triangle_distance2(x4, *, compiled=None) -> np.ndarray:
    """Point-triangle squared distance ``(P,)`` [m^2] only (the continuous-collision loop's call); ``compiled``
    as for :func:`point_triangle`."""
    x4 = _check(x4, "point_triangle_distance2")
    if compiled_for(len(x4), compiled):
        return _compiled_distance2(x4, 0)
    return _pt_classify(x4)[3]


def edge_edge_distance2(x4, *, compiled=None) -> np.ndarray:
    """Edge-edge squared distance ``(P,)`` [m^2] only; ``compiled`` as for :func:`point_triangle`."""
    x4 = _check(x4, "edge_edge_distance2")
    if compiled_for(len(x4), compiled):
        return _compiled_distance2(x4, 1)
    return _ee_classify(x4)[3]
