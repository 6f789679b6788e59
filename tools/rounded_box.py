"""Write a box with rounded edges as a closed triangle surface: the square pedestal of the scenes as a mesh file.

The analytic ``square-pedestal`` (:class:`rftstatic.contact.obstacles.SquarePedestal`) is the box of half sides
``b`` shrunk by the edge radius ``r`` and grown again by ``r`` (every edge and corner rounded). Here each face of
the outer box is a structured grid whose lines lie at uniform spacing (at most ``spacing``) over the flat part
and at ``(b - r) + r tan(alpha_j)``, ``alpha_j`` uniform in (0, 45 deg] (``arc`` per 45 deg), over the rounding
zone; each grid point ``v`` goes to ``c + r (v - c) / |v - c|``, ``c`` its closest point on the shrunk box:
flat faces stay flat, the rounding zone lands on the rounded edges and corners at uniform angles (the facets'
sagitta ``r (1 - cos(pi / (8 arc)))``). Nodes shared by two faces are merged; triangles wound outward.

    PYTHONPATH=$PWD python tools/rounded_box.py OUT.obj [--size 10 10 10] [--radius 0.2] [--spacing 0.5]
        [--arc 4] [--top 0]

Sizes in the file's unit (the scenes': cm); the top face at ``--top``, the box below it.
"""

from __future__ import annotations

import argparse

import meshio
import numpy as np

from rftstatic.contact.obstacles.surface_geometry import merge_nodes


def _axis(b, r, spacing, arc):
    """Grid coordinates along one axis of half size ``b``: flat part, then the rounding zone, both sides."""
    n = max(1, int(np.ceil(2 * (b - r) / spacing)))
    flat = np.linspace(-(b - r), b - r, n + 1)
    zone = (b - r) + r * np.tan(np.linspace(0.0, np.pi / 4, arc + 1)[1:])
    return np.concatenate([-zone[::-1], flat, zone]) if r > 0 else flat


def rounded_box(size=(10.0, 10.0, 10.0), radius=0.2, spacing=0.5, arc=4, top=0.0):
    """``(V (n, 3), T (t, 3))`` of the rounded box ``size`` (full sides) with top face at ``top`` (module
    docstring)."""
    b = 0.5 * np.asarray(size, float)
    r = float(radius)
    if not (0 <= r <= b.min()):
        raise ValueError(f"radius {r} must lie in [0, {b.min()}]")
    axes = [_axis(b[k], r, spacing, arc) for k in range(3)]
    pts, tris, offset = [], [], 0
    for k in range(3):  # the faces normal to axis k, at -b_k and +b_k
        i, j = [m for m in range(3) if m != k]
        U, W = np.meshgrid(axes[i], axes[j], indexing="ij")
        nu, nw = U.shape
        for sign in (-1.0, 1.0):
            P = np.zeros((U.size, 3))
            P[:, i], P[:, j], P[:, k] = U.ravel(), W.ravel(), sign * b[k]
            a = (np.arange(nu - 1)[:, None] * nw + np.arange(nw - 1)[None, :]).ravel()
            quads = np.column_stack([a, a + nw, a + nw + 1, a + 1])  # counter-clockwise about +k for (i, j, k) cyclic
            t = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
            cyclic = (j - i) % 3 == 1
            if (sign > 0) != cyclic:
                t = t[:, [0, 2, 1]]
            pts.append(P)
            tris.append(t + offset)
            offset += len(P)
    V, T = merge_nodes(np.vstack(pts), np.vstack(tris))
    c = np.clip(V, -(b - r), b - r)
    d = V - c
    n = np.linalg.norm(d, axis=1, keepdims=True)
    V = c + r * d / np.where(n > 0, n, 1.0) if r > 0 else V
    V[:, 2] += top - b[2]
    return V, T


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--size", type=float, nargs=3, default=(10.0, 10.0, 10.0))
    ap.add_argument("--radius", type=float, default=0.2)
    ap.add_argument("--spacing", type=float, default=0.5)
    ap.add_argument("--arc", type=int, default=4)
    ap.add_argument("--top", type=float, default=0.0)
    a = ap.parse_args(argv)
    V, T = rounded_box(a.size, a.radius, a.spacing, a.arc, a.top)
    meshio.write(a.out, meshio.Mesh(V, [("triangle", T)]))
    print(f"{a.out}: {len(V)} vertices, {len(T)} triangles")


if __name__ == "__main__":
    main()
