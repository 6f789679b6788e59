"""Squared distances between the sheet's own elements: point-triangle and edge-edge, with exact
gradient and Hessian and the closest feature, over all pairs at once (the equations, the closest-feature
rules and the parallel-edge tolerance: :mod:`.geometry`).

Shapes: pairs on the first axis, ``x4 (P, 4, 3)`` [m] -> ``s (P,)`` [m^2], gradient ``(P, 4, 3)``
[m], Hessian ``(P, 12, 12)`` [-] (dof ``3 k + i``).

Two back ends run the one source of :mod:`.geometry`: numpy (all pairs at once, pair axis last:
:func:`.geometry.derivatives_numpy`) and compiled (numba, one loop over the pairs,
:mod:`._kernels_numba`), chosen by :func:`compiled_for`; they do the same arithmetic in the same order
(equal to the last bit on the bench's pairs and the tests' random ones)."""

from __future__ import annotations

import sys

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.contact.self_contact.geometry import PARALLEL_TOL, derivatives_numpy, distances_numpy

__all__ = [
    "FEATURES",
    "PARALLEL_TOL",
    "point_triangle",
    "edge_edge",
    "point_triangle_distance2",
    "edge_edge_distance2",
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


def _check(x4, name):
    x4 = np.asarray(x4, dtype=float)
    if x4.ndim != 3 or x4.shape[1:] != (4, 3):
        raise ValueError(f"{name}: expected points of shape (P, 4, 3), got {x4.shape}")
    return x4


FEATURES = {
    "point_triangle": ("face", "edge", "vertex"),
    "edge_edge": ("interior", "point-edge", "point-point"),
}
"""Names of the closest-feature codes 0, 1, 2 of :func:`point_triangle` and :func:`edge_edge`."""


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
    return derivatives_numpy(x4, kind, hessian)


def point_triangle_distance2(x4, *, compiled=None) -> np.ndarray:
    """Point-triangle squared distance ``(P,)`` [m^2] only (the continuous-collision loop's call); ``compiled``
    as for :func:`point_triangle`."""
    x4 = _check(x4, "point_triangle_distance2")
    if compiled_for(len(x4), compiled):
        return _compiled_distance2(x4, 0)
    return distances_numpy(x4, 0)


def edge_edge_distance2(x4, *, compiled=None) -> np.ndarray:
    """Edge-edge squared distance ``(P,)`` [m^2] only; ``compiled`` as for :func:`point_triangle`."""
    x4 = _check(x4, "edge_edge_distance2")
    if compiled_for(len(x4), compiled):
        return _compiled_distance2(x4, 1)
    return distances_numpy(x4, 1)
