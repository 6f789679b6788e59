"""The model problems that benchmarks and validation reports share (built in code, not from scenes).

- :func:`strip_model`: the clamped wool strip of §4.1 (5 x 1 cm, Kang & Yu's wool) under its weight;
- :func:`sheet_model`: the hanging sheet of §4.6 (two adjacent corners pinned).
"""

from __future__ import annotations

import dataclasses

import numpy as np

STRIP_LENGTH, STRIP_WIDTH = 0.05, 0.01  # the §4.1 strip [m]


def strip_model(nx, ny, *, element="RFT6", pattern="right", warp_angle_deg=0.0, alpha=None, ratio=None):
    """The §4.1 strip clamped at x = 0 under its weight, ``nx`` x ``ny`` nodes; ``alpha`` rescales the
    weight to w = alpha B / L^3 [-]; ``ratio`` scales every membrane rigidity so that C_warp / B_warp =
    ratio [1/cm^2] (the stiff strip cells of the stability matrix)."""
    from rftstatic.material import preset
    from rftstatic.mesh.trimesh import rectangle
    from rftstatic.model.model import Model, Supports, gravity_load

    L, W = STRIP_LENGTH, STRIP_WIDTH
    m = rectangle(L, W, nx, ny, origin=(0.0, -W / 2), pattern=pattern)
    mat = preset("wool-kang-yu", warp_angle_deg=warp_angle_deg)
    if alpha is not None:
        mat = dataclasses.replace(mat, weight=alpha * mat.Db[0, 0] / L**3)
    if ratio is not None:
        mat = dataclasses.replace(mat, Dm=mat.Dm * (ratio * 1e4 / (mat.Dm[0, 0] / mat.Db[0, 0])))
    sup = Supports(m.nodes_in_box(0, 0, -1, 1), np.zeros(0, np.int64), np.zeros((m.n_nodes, 3), bool))
    return Model(m, mat, element=element, supports=sup, load=gravity_load(m, mat.weight), quiet=ratio is not None)


def sheet_model(side: float, n: int, element: str = "RFT6"):
    """The §4.6 sheet: ``side`` [m], n x n nodes, wool, two adjacent corners pinned, own weight."""
    from rftstatic.material import preset
    from rftstatic.mesh.trimesh import rectangle
    from rftstatic.model.model import Model, Supports, gravity_load

    mesh = rectangle(side, side, n, n)
    mat = preset("wool-kang-yu")
    corners = mesh.nearest_node([[0.0, side], [side, side]])
    sup = Supports(np.zeros(0, dtype=np.int64), corners, np.zeros((mesh.n_nodes, 3), bool))
    return Model(mesh, mat, element=element, supports=sup, load=gravity_load(mesh, mat.weight))
