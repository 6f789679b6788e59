"""A GIF of the shaded drape over time (the paper's Figs. 12-16 as a movie): :func:`animate`."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rftstatic.io.figure import DPI, axis_labels, figsize_2d, new_figure, set_2d_limits, set_title
from rftstatic.io.files import atomic_write
from rftstatic.io.surface import (AXES_2D, CAMERA, add_solids_2d, add_surface_2d, add_surface_3d, check_mesh,
                                  set_3d_limits)

__all__ = ["animate"]


def animate(path: str | os.PathLike, frames: Sequence[np.ndarray], tri: np.ndarray, *,
            times: Sequence[float], view: str = "iso", fps: int = 10, title: str = "",
            time_unit: str = "s", length_unit: str = "", solids: Sequence = ()) -> Path:
    """Write a GIF of the shaded surface over time (the paper's Figs. 12-16 as a movie).

    Parameters
    ----------
    frames : list of (N, 3) positions [scene length unit], one per frame.
    tri : (E, 3) triangles (the same for all frames).
    times : one time per frame [scene time unit], shown in the title.
    view : "iso", "top" or "side".
    fps : frames per second of the GIF.
    solids : :class:`~rftstatic.io.solids.Solid` surfaces the sheet rests on [scene length unit], drawn as in
        :func:`rftstatic.io.views.plot_views` (translucent among the sheet's triangles in the iso view).

    The axis limits are those of all frames together, so the motion is not hidden by rescaling.
    """
    from matplotlib.animation import PillowWriter

    if view not in CAMERA:
        raise ValueError(f"unknown view {view!r}; choose among 'side', 'top', 'iso'")
    if len(frames) == 0:
        raise ValueError("animate needs at least one frame")
    if len(times) != len(frames):
        raise ValueError(f"len(frames) = {len(frames)}, but len(times) = {len(times)}")
    frames = [check_mesh(f, tri)[0] for f in frames]
    tri = np.asarray(tri)
    lo = np.min([f.min(axis=0) for f in frames] + [s.vertices.min(axis=0) for s in solids], axis=0)
    hi = np.max([f.max(axis=0) for f in frames] + [s.vertices.max(axis=0) for s in solids], axis=0)
    if view == "iso":
        fig = new_figure((6.4, 5.6))
        ax = fig.add_subplot(projection="3d")
        set_3d_limits(ax, lo, hi)
        axis_labels(ax, ("x", "y", "z"), length_unit)
    else:
        i, j = AXES_2D[view]
        fig = new_figure(figsize_2d(lo[[i, j]], hi[[i, j]]))
        ax = fig.add_subplot()
        set_2d_limits(ax, lo[[i, j]], hi[[i, j]])
        axis_labels(ax, ("xyz"[i], "xyz"[j]), length_unit)
        add_solids_2d(ax, solids, view)
    set_title(ax, f"{title}: t = 0" if title else "t = 0")
    fig.get_layout_engine().execute(fig)
    fig.set_layout_engine("none")  # lay out once, then keep it fixed: the frames must not jitter
    writer = PillowWriter(fps=fps)
    with atomic_write(path) as tmp, writer.saving(fig, os.fspath(tmp), dpi=DPI):
        coll = None
        for x, t in zip(frames, times):
            if coll is not None:
                coll.remove()
            if view == "iso":
                coll, _ = add_surface_3d(ax, x, tri, solids=solids)
            else:
                coll, _ = add_surface_2d(ax, x, tri, view)
            head = f"{title}: " if title else ""
            set_title(ax, f"{head}t = {float(t):.3g} {time_unit}".strip())
            writer.grab_frame()
    return Path(path)
