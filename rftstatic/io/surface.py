"""The shaded triangle surface of a drape, as drawn by :mod:`.views` and :mod:`.animation`.

Shading. Each triangle is lit by a light that sits near the viewer (tilted up and to the left), with
the two-sided Lambert factor ``0.35 + 0.65 |n . l|`` (a fabric has no outside), so folds show in the top
view as they do in the paper. The surface is one ``PolyCollection`` (or ``Poly3DCollection``) drawn
back-to-front by a vectorised depth sort, which keeps ~30k triangles fast.

Views: ``side`` is the x-z projection seen from -y, ``top`` the x-y projection seen from +z, ``iso``
3D axes with ``view_init(elev=ELEV, azim=AZIM)``; :data:`CAMERA` holds each view's direction.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from rftstatic.io.figure import padded_limits

__all__ = ["AXES_2D", "AZIM", "CAMERA", "ELEV", "FABRIC_RGB", "SOLID_RGB", "add_solids_2d", "add_surface_2d",
           "add_surface_3d", "check_mesh", "set_3d_limits"]

FABRIC_RGB = np.array([0.85, 0.62, 0.38])  # a warm cloth colour; grey shading alone hides folds less well
SOLID_RGB = np.array([0.62, 0.66, 0.74])   # what the sheet rests on: a cool grey, apart from any colour map
SOLID_ALPHA = 0.35                         # translucent in 3-D, so that the sheet under and behind shows
ELEV, AZIM = 30.0, -60.0                    # iso camera elevation and azimuth [deg]

# Camera direction (towards the viewer) of each view, and the "up" of its image for the light offset:
# view -> ((3,) unit vector, (3,) unit vector).
CAMERA = {
    "side": (np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])),
    "top": (np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])),
}
_e, _a = math.radians(ELEV), math.radians(AZIM)
CAMERA["iso"] = (np.array([math.cos(_e) * math.cos(_a), math.cos(_e) * math.sin(_a), math.sin(_e)]),
                 np.array([-math.sin(_e) * math.cos(_a), -math.sin(_e) * math.sin(_a), math.cos(_e)]))
AXES_2D = {"side": (0, 2), "top": (0, 1)}  # columns of x drawn as (horizontal, vertical) in the 2-D views


def check_mesh(x, tri) -> tuple[np.ndarray, np.ndarray]:
    """``(x, tri)`` as float (N, 3) positions and integer (E, 3) triangles; ``ValueError`` otherwise."""
    x = np.asarray(x, dtype=float)
    tri = np.asarray(tri)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must have shape (N, 3), got {x.shape}")
    if tri.ndim != 2 or tri.shape[1] != 3 or not np.issubdtype(tri.dtype, np.integer):
        raise ValueError(f"tri must be an integer (E, 3) array, got {tri.dtype} {tri.shape}")
    if len(tri) and (tri.min() < 0 or tri.max() >= len(x)):
        raise ValueError(f"tri refers to nodes outside 0..{len(x) - 1}")
    return x, tri


def _light(view: str) -> np.ndarray:
    cam, up = CAMERA[view]
    left = np.cross(cam, up)  # up x cam would point right; this points left in the image
    light = cam + 0.45 * up + 0.35 * left
    return light / np.linalg.norm(light)


def _face_colors(x, tri, view, color_by=None, *, cmap="viridis", clim=None, base=FABRIC_RGB):
    """Per-triangle RGBA (E, 4): ``base`` colour (or colormap of ``color_by``) times the shading factor."""
    from matplotlib import colormaps
    from matplotlib.colors import Normalize

    p = x[tri]                                                     # (E, 3 nodes, 3)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    shade = 0.35 + 0.65 * np.abs(n @ _light(view))
    mappable = None
    if color_by is None:
        rgb = np.broadcast_to(base, (len(tri), 3))
    else:
        c = np.asarray(color_by, dtype=float)
        if c.shape != (len(tri),):
            raise ValueError(f"len(tri) = {len(tri)}, but color_by has shape {c.shape}; "
                             "give one value per triangle")
        finite = c[np.isfinite(c)]
        lo, hi = clim if clim is not None else ((finite.min(), finite.max()) if finite.size else (0.0, 1.0))
        if hi <= lo:
            hi = lo + 1.0
        normalize = Normalize(lo, hi)
        cm = colormaps[cmap]
        rgb = cm(normalize(np.nan_to_num(c, nan=lo)))[:, :3]
        from matplotlib.cm import ScalarMappable

        mappable = ScalarMappable(norm=normalize, cmap=cm)
    rgba = np.ones((len(tri), 4))
    rgba[:, :3] = rgb * shade[:, None]
    return rgba, mappable


def _edges(rgba: np.ndarray) -> dict[str, Any]:
    """Edge colours (E, 4), width [pt] and anti-aliasing for the surface collection.

    Edges are opaque and a darker shade of their own face, only slightly darker on fine meshes, where
    full mesh lines would turn the surface into a blot. Above ~5000 triangles anti-aliasing is off:
    the partly transparent anti-aliased borders of thousands of small faces add up and let the far
    side of the drape show through as a ghost (seen with 30k triangles); at that density the jagged
    borders are invisible.
    """
    n = len(rgba)
    darker = float(np.clip(0.55 + 0.4 * (n / 20000.0) ** 0.5, 0.6, 0.93))
    edge = rgba.copy()
    edge[:, :3] *= darker
    width = float(np.clip(0.4 * math.sqrt(2000.0 / max(n, 1)), 0.25, 0.5))
    return {"edgecolors": edge, "linewidths": width, "antialiased": n <= 5000}


def add_surface_2d(ax, x, tri, view, color_by=None, *, clim=None):
    """Add the shaded surface to a 2-D axes as one depth-sorted ``PolyCollection``.

    Parameters
    ----------
    x : (N, 3) positions [scene length unit]; tri : (E, 3) triangles.
    view : "side" (x-z) or "top" (x-y).
    color_by : (E,) optional per-triangle scalar, coloured with viridis in ``clim`` (default its finite range).

    Returns
    -------
    (collection, mappable): the ``PolyCollection`` and a ``ScalarMappable`` for a colour bar (None
    without ``color_by``).
    """
    from matplotlib.collections import PolyCollection

    i, j = AXES_2D[view]
    cam, _ = CAMERA[view]
    depth = (x @ cam)[tri].mean(axis=1)
    order = np.argsort(depth, kind="stable")                     # far first, near drawn on top
    rgba, mappable = _face_colors(x, tri, view, color_by, clim=clim)
    verts = x[tri[order]][:, :, (i, j)]
    coll = PolyCollection(verts, facecolors=rgba[order], zorder=2, **_edges(rgba[order]))
    ax.add_collection(coll)
    return coll, mappable


def add_surface_3d(ax, x, tri, color_by=None, *, clim=None, solids=()):
    """Add the shaded surface to a 3-D axes as one ``Poly3DCollection`` (lit for the iso view).

    Same arguments and return as :func:`add_surface_2d`, without ``view``; ``solids``: what the sheet rests on,
    :class:`~rftstatic.io.solids.Solid` surfaces drawn translucent (:data:`SOLID_ALPHA`) in the same collection,
    so that matplotlib sorts their triangles and the sheet's together by depth (two collections are sorted as
    wholes: a pedestal would be drawn over the whole sheet or under it).
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    rgba, mappable = _face_colors(x, tri, "iso", color_by, clim=clim)
    edges = _edges(rgba)
    verts, faces = [x[tri]], [rgba]
    edge_rgba = [edges.pop("edgecolors")]
    for solid in solids:
        solid_rgba, _ = _face_colors(solid.vertices, solid.triangles, "iso", base=SOLID_RGB)
        solid_rgba[:, 3] = SOLID_ALPHA
        verts.append(solid.vertices[solid.triangles])
        faces.append(solid_rgba)
        edge_rgba.append(np.zeros_like(solid_rgba))                # no edges: a smooth solid
    coll = Poly3DCollection(np.concatenate(verts), facecolors=np.concatenate(faces),
                            edgecolors=np.concatenate(edge_rgba), **edges)
    ax.add_collection3d(coll)
    return coll, mappable


def add_solids_2d(ax, solids, view) -> None:
    """Draw ``solids`` (:class:`~rftstatic.io.solids.Solid`) in a 2-D view, shaded, depth-sorted and under the
    sheet (``zorder`` 1): the sheet covers them where it lies in front."""
    from matplotlib.collections import PolyCollection

    i, j = AXES_2D[view]
    cam, _ = CAMERA[view]
    for solid in solids:
        x, tri = solid.vertices, solid.triangles
        order = np.argsort((x @ cam)[tri].mean(axis=1), kind="stable")
        rgba, _ = _face_colors(x, tri[order], view, base=SOLID_RGB)
        ax.add_collection(PolyCollection(x[tri[order]][:, :, (i, j)], facecolors=rgba, edgecolors=rgba,
                                         linewidths=0.2, zorder=1))


def set_3d_limits(ax, lo, hi):
    """Padded limits of a 3-D axes from (3,) data bounds ``lo``, ``hi``, equal aspect, the iso camera.

    The camera is ``view_init(elev=ELEV, azim=AZIM)``; a flat box gets few z ticks (``MaxNLocator(nbins=3)``).
    """
    lo, hi = padded_limits(lo, hi)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)                                     # equal aspect on all three axes
    ax.view_init(elev=ELEV, azim=AZIM)
    if (hi - lo)[2] < 0.3 * (hi - lo).max():                      # a flat box has room for few z ticks
        from matplotlib.ticker import MaxNLocator

        ax.zaxis.set_major_locator(MaxNLocator(nbins=3))
