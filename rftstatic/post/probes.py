"""Probes: named reference points of the flat sheet, followed through the deformation.

A probe at reference point ``p`` is the barycentric combination of the three nodes of the element
that contains ``p``; on the boundary, where the point location may miss, the nearest node.
"""

from __future__ import annotations

import numpy as np


def probe_interpolation(mesh, probes: dict) -> tuple[list, np.ndarray, np.ndarray]:
    """Names, ``(P, 3)`` node indices and ``(P, 3)`` barycentric weights of the probes.

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.trimesh.TriMesh`
    probes : ``{name: (2,) reference point [m]}``
    """
    names = list(probes)
    if not names:
        return [], np.zeros((0, 3), np.int64), np.zeros((0, 3))
    pts = np.array([probes[n] for n in names], float)
    elem, bary = mesh.locate(pts)
    nodes = np.empty((len(names), 3), np.int64)
    w = np.zeros((len(names), 3))
    inside = elem >= 0
    nodes[inside] = mesh.tri[elem[inside]]
    w[inside] = bary[inside]
    if (~inside).any():  # on the boundary the trifinder may miss: the nearest node
        nodes[~inside] = mesh.nearest_node(pts[~inside])[:, None]
        w[~inside] = [1.0, 0.0, 0.0]
    return names, nodes, w


def probe_positions(model, probes: dict, U: np.ndarray) -> dict:
    """``{name: {"reference": (3,), "deformed": (3,)}}`` positions [m] of the probes at displacements
    ``U (N, 3)`` [m] of ``model`` (:func:`probe_interpolation`)."""
    names, nodes, w = probe_interpolation(model.mesh, probes)
    ref = np.einsum("pa,pai->pi", w, model.X3[nodes])
    disp = np.einsum("pa,pai->pi", w, U[nodes])
    return {name: {"reference": ref[k], "deformed": ref[k] + disp[k]} for k, name in enumerate(names)}
