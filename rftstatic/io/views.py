"""Shaded views of a drape in the style of Sze & Zhou (2016), Figs. 1, 5-16: :func:`plot_views`.

* ``side``: x-z projection seen from -y (Figs. 5a, 11b, 12, 13);
* ``top``: x-y projection seen from +z (Figs. 6b-16);
* ``iso``: 3D axes with ``view_init(elev=30, azim=-60)``.

All axes have equal aspect; the surface and its shading are those of :mod:`rftstatic.io.surface`.
What the sheet rests on is drawn from ``solids``, triangulated surfaces (:mod:`rftstatic.io.solids`): shaded grey
under the sheet in the 2-D views, translucent in the 3-D view; the axes' limits include them. Other obstacle
drawings are callables ``draw(ax, view)`` supplied by the caller (this module knows no obstacle classes);
:func:`rftstatic.io.outlines.outline_drawer` turns an outline into one.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rftstatic.io.figure import axis_labels, figsize_2d, new_figure, save_png, set_2d_limits, set_title
from rftstatic.io.surface import (AXES_2D, CAMERA, add_solids_2d, add_surface_2d, add_surface_3d, check_mesh,
                                  set_3d_limits)

__all__ = ["plot_views"]


def plot_views(path_prefix: str | os.PathLike, x: np.ndarray, tri: np.ndarray, *,
               views: Sequence[str] = ("side", "top", "iso"), title: str = "",
               obstacles_draw: Sequence[Callable[[Any, str], Any]] | None = None,
               color_by: np.ndarray | None = None, frame_x0: np.ndarray | None = None,
               color_label: str = "", length_unit: str = "", clim: tuple[float, float] | None = None,
               solids: Sequence[Any] = ()) -> dict[str, Path]:
    """Draw the shaded drape in side, top and isometric views, one PNG per view.

    Parameters
    ----------
    path_prefix : files are ``<prefix>_side.png``, ``<prefix>_top.png``, ``<prefix>_iso.png``.
    x : (N, 3) current positions [scene length unit].
    tri : (E, 3) triangles.
    views : any of "side" (x-z), "top" (x-y), "iso" (3D, elev 30, azim -60).
    title : figure title; the view name is appended.
    obstacles_draw : callables ``draw(ax, view)`` called before the surface is added (so the surface
        covers them in the 2D views); they draw in scene units.
    solids : :class:`~rftstatic.io.solids.Solid` surfaces the sheet rests on (obstacles, a tester's disc) [scene
        length unit], drawn under the sheet (2-D) or translucent among its triangles (3-D).
    color_by : (E,) optional per-triangle scalar (e.g. relative curvature), coloured with viridis and
        shaded; a colour bar labelled ``color_label`` (the field and its unit, e.g. "|kappa| h [-]") is added.
    frame_x0 : (N, 3) optional reference positions, drawn as thin grey edges in the side view.
    length_unit : axis-label unit, e.g. "cm".
    clim : colour range for ``color_by`` (default: its finite min and max).

    Returns
    -------
    dict view -> path of the PNG written.
    """
    x, tri = check_mesh(x, tri)
    bad = [v for v in views if v not in CAMERA]
    if bad:
        raise ValueError(f"unknown view(s) {bad}; choose among 'side', 'top', 'iso'")
    x0 = None if frame_x0 is None else np.asarray(frame_x0, dtype=float)
    if x0 is not None and x0.shape != x.shape:
        raise ValueError(f"frame_x0 must have the shape of x {x.shape}, got {x0.shape}")
    lo, hi = x.min(axis=0), x.max(axis=0)
    for solid in solids:                                           # equal scales over the sheet and its supports
        lo, hi = np.minimum(lo, solid.vertices.min(axis=0)), np.maximum(hi, solid.vertices.max(axis=0))
    out = {}
    for view in views:
        label = f"{title} ({view} view)" if title else f"{view} view"
        if view == "iso":
            fig = new_figure((6.4, 5.6))
            ax = fig.add_subplot(projection="3d")
            for draw in obstacles_draw or ():
                draw(ax, view)
            _, mappable = add_surface_3d(ax, x, tri, color_by, clim=clim, solids=solids)
            set_3d_limits(ax, lo, hi)
            axis_labels(ax, ("x", "y", "z"), length_unit)
        else:
            i, j = AXES_2D[view]
            vlo, vhi = lo[[i, j]], hi[[i, j]]
            if view == "side" and x0 is not None:
                vlo = np.minimum(vlo, x0.min(axis=0)[[i, j]])
                vhi = np.maximum(vhi, x0.max(axis=0)[[i, j]])
            fig = new_figure(figsize_2d(vlo, vhi))
            ax = fig.add_subplot()
            if view == "side" and x0 is not None:
                from matplotlib.collections import PolyCollection

                ax.add_collection(PolyCollection(x0[tri][:, :, (i, j)], facecolors="none",
                                                 edgecolors="0.6", linewidths=0.3, zorder=1))
            add_solids_2d(ax, solids, view)
            for draw in obstacles_draw or ():
                draw(ax, view)
            _, mappable = add_surface_2d(ax, x, tri, view, color_by, clim=clim)
            set_2d_limits(ax, vlo, vhi)
            axis_labels(ax, ("xyz"[i], "xyz"[j]), length_unit)
        if mappable is not None:
            fig.colorbar(mappable, ax=ax, shrink=0.7, pad=0.12 if view == "iso" else 0.02, label=color_label)
        set_title(ax, label)
        out[view] = save_png(fig, f"{os.fspath(path_prefix)}_{view}.png")
    return out
