"""The self-contact law's two loops over pairs, compiled when numba is there: the PSD projection of the
12 x 12 pair blocks and the additive continuous collision detection of the step bound (:mod:`.law`
gives the equations). Drop-in twins of ``law._psd`` and ``law._additive_ccd`` (same arguments and
results, to round-off); their numpy paths are kept here for machines without numba.
"""

from __future__ import annotations

import numpy as np

from rftstatic.contact.self_contact import distance

__all__ = ["psd_project", "additive_ccd", "additive_ccd_nodes"]

_SIDES = (((0,), (1, 2, 3)), ((0, 1), (2, 3)))


def psd_project(H: np.ndarray, *, compiled: bool | None = None) -> np.ndarray:
    """Symmetric ``(A, n, n)`` matrices projected onto the PSD cone (eigenvalues clamped at 0).

    Compiled: a range basis and Jacobi rotations per block (:mod:`.kernels`); numpy: ``eigh``; ``compiled``:
    which (None: :func:`.distance.compiled_for` by size)."""
    H = np.asarray(H, dtype=float)
    if not len(H):
        return H
    if distance.compiled_for(len(H), compiled):
        from rftstatic.contact.self_contact._kernels_numba import psd_project_all

        out = np.empty_like(H)
        psd_project_all(np.ascontiguousarray(H), out)
        return out
    H = 0.5 * (H + H.transpose(0, 2, 1))
    lam, Q = np.linalg.eigh(H)
    return np.einsum("aij,aj,akj->aik", Q, np.maximum(lam, 0.0), Q)


def additive_ccd(x4: np.ndarray, dx4: np.ndarray, kind: int, eta: float, max_rounds: int,
                 floor: float = 0.0, *, compiled: bool | None = None) -> float:
    """Smallest safe time in [0, 1] over pairs ``x4, dx4 (P, 4, 3)`` [m] (``kind`` 0 point-triangle,
    1 edge-edge): the first time any pair comes within its target ``g`` (``eta`` times its starting
    distance ``delta_0``, raised to ``floor`` [m] for a pair that starts above it), found by advancing
    each pair by ``(delta - g) / l`` (``l`` its relative speed bound) for at most ``max_rounds`` rounds;
    1 if none (:mod:`.law`); ``compiled`` as for :func:`psd_project`."""
    if not len(x4):
        return 1.0
    if distance.compiled_for(len(x4), compiled):
        from rftstatic.contact.self_contact._kernels_numba import ccd_all

        P = len(x4)
        return float(ccd_all(np.ascontiguousarray(x4, dtype=float).reshape(4 * P, 3),
                             np.ascontiguousarray(dx4, dtype=float).reshape(4 * P, 3),
                             np.arange(4 * P, dtype=np.int64).reshape(P, 4), kind, float(eta), int(max_rounds),
                             float(floor)))
    d2 = distance.point_triangle_distance2 if kind == 0 else distance.edge_edge_distance2

    def dist2(y4):
        return d2(y4, compiled=compiled)
    a, b = _SIDES[kind]
    rel = dx4[:, list(a)][:, :, None, :] - dx4[:, list(b)][:, None, :, :]
    ell = np.sqrt(np.max(np.einsum("pabi,pabi->pab", rel, rel), axis=(1, 2)))  # (P,) relative speed bound
    d0 = np.sqrt(dist2(x4))
    g = np.where(d0 > floor, np.maximum(eta * d0, floor), eta * d0)
    keep = (ell > 0) & (ell * 1.0 > d0 - g)  # the others cannot reach g by t = 1
    if not np.any(keep):
        return 1.0
    x4, dx4, ell, d0, g = x4[keep], dx4[keep], ell[keep], d0[keep], g[keep]
    t = np.zeros(len(d0))
    dcur = d0.copy()
    live = np.ones(len(d0), dtype=bool)
    for _ in range(max_rounds):
        tau = (dcur[live] - g[live]) / ell[live]
        tn = t[live] + tau
        done = tn >= 1.0
        idx = np.flatnonzero(live)
        t[idx[done]] = 1.0
        live[idx[done]] = False
        idx, tn = idx[~done], tn[~done]
        if not len(idx):
            break
        t[idx] = tn
        dcur[idx] = np.sqrt(dist2(x4[idx] + tn[:, None, None] * dx4[idx]))
        # close to the target: the pair is about to reach eta d0; keep the time reached
        stuck = dcur[idx] - g[idx] <= 1e-3 * (d0[idx] - g[idx])
        live[idx[stuck]] = False
    return float(t.min())


def additive_ccd_nodes(x: np.ndarray, dx: np.ndarray, nodes: np.ndarray, kind: int, eta: float,
                       max_rounds: int, floor: float = 0.0, *, compiled: bool | None = None) -> float:
    """:func:`additive_ccd` of the pairs ``nodes (P, 4)`` of positions ``x (N, 3)`` [m] and step
    ``dx (N, 3)`` [m], without gathering ``x[nodes]`` (the compiled loop reads the nodes itself: on the
    824,000 swept pairs of a 1 cm step of the 81 x 81 fold the gather cost as much as the loop)."""
    nodes = np.asarray(nodes, dtype=np.int64)
    if not len(nodes):
        return 1.0
    if distance.compiled_for(len(nodes), compiled):
        from rftstatic.contact.self_contact._kernels_numba import ccd_all

        return float(ccd_all(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(dx, dtype=float),
                             np.ascontiguousarray(nodes), kind, float(eta), int(max_rounds), float(floor)))
    return additive_ccd(x[nodes], dx[nodes], kind, eta, max_rounds, floor, compiled=compiled)


def load_compiled() -> bool:
    """Load the compiled self-contact twins now (numba compiles them on their first use in a checkout,
    about half a minute, then loads them from its cache in about a second) by running each once on a
    sheet folded onto itself; False when numba is not installed. For callers that time what follows
    (a study, the property test's per-scene bound), so that the one-time compile falls outside."""
    from rftstatic.compiled import numba_available
    from rftstatic.contact.self_contact.broad_phase import SheetPrimitives, find_pairs
    from rftstatic.mesh.trimesh import rectangle

    if not numba_available():
        return False
    mesh = rectangle(2.0, 1.0, 5, 3)
    x = mesh.X3.copy()
    fold = x[:, 0] > 1.0
    x[fold, 0], x[fold, 2] = 2.0 - x[fold, 0], 0.1  # the right half laid over the left one
    dx = np.zeros_like(x)
    dx[fold, 2] = -0.2  # and pushed through it
    pairs = find_pairs(SheetPrimitives.of_mesh(mesh), x, 0.2, compiled=True)
    find_pairs(SheetPrimitives.of_mesh(mesh), x, 0.2, x + dx, compiled=True)
    tri, edges = mesh.tri, mesh.topology.edges
    npt = np.column_stack([pairs.pt[:, 0], tri[pairs.pt[:, 1]]]).astype(np.int64)
    nee = np.column_stack([edges[pairs.ee[:, 0]], edges[pairs.ee[:, 1]]]).astype(np.int64)
    for kind, nodes, full, d2 in ((0, npt, distance.point_triangle, distance.point_triangle_distance2),
                                  (1, nee, distance.edge_edge, distance.edge_edge_distance2)):
        H = full(x[nodes], hessian=True, compiled=True)[2]
        d2(x[nodes], compiled=True)
        psd_project(H, compiled=True)
        additive_ccd(x[nodes], dx[nodes], kind, 0.2, 10, compiled=True)
        additive_ccd_nodes(x, dx, nodes, kind, 0.2, 10, compiled=True)
    return True
