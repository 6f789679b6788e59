"""Obstacle outlines seen from the top, and callables drawing them in the views.

- :func:`outline_square`, :func:`outline_circle`: closed counter-clockwise (K, 2) outlines;
- :func:`outline_drawer`: ``draw(ax, view)`` for :func:`rftstatic.io.views.plot_views` from such an
  outline (filled in the top view, the top face in the side view, the rim in 3-D).

Lengths are in the scene's units.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from rftstatic.io.figure import as_curve

__all__ = ["outline_circle", "outline_drawer", "outline_square"]


def outline_square(cx: float, cy: float, half: float, *, corner_radius: float = 0.0, n: int = 16
                   ) -> np.ndarray:
    """Closed (K, 2) outline of a square of half width ``half`` centred at (cx, cy), counter-clockwise.

    With ``corner_radius > 0`` the corners are rounded (``n`` points per corner), as the pedestals of
    :mod:`rftstatic.contact.obstacles`. The last point repeats the first.
    """
    if corner_radius <= 0:
        pts = np.array([[1, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]], dtype=float) * half
        return pts + (cx, cy)
    r = min(float(corner_radius), float(half))
    c = half - r
    parts = []
    for k, (sx, sy) in enumerate([(1, 1), (-1, 1), (-1, -1), (1, -1)]):  # corners in CCW order
        a = np.linspace(k * np.pi / 2, (k + 1) * np.pi / 2, n)
        parts.append(np.column_stack([sx * c + r * np.cos(a), sy * c + r * np.sin(a)]))
    pts = np.vstack(parts)
    return np.vstack([pts, pts[:1]]) + (cx, cy)


def outline_circle(cx: float, cy: float, r: float, n: int = 128) -> np.ndarray:
    """Closed (n + 1, 2) outline of the circle of radius ``r`` about (cx, cy), counter-clockwise."""
    a = np.linspace(0.0, 2.0 * np.pi, n + 1)
    a[-1] = 0.0
    return np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)])


def outline_drawer(outline: np.ndarray, *, z: float | None = None, color: str = "0.55",
                   label: str | None = None) -> Callable[[Any, str], None]:
    """Return ``draw(ax, view)`` drawing an obstacle's top outline (K, 2) in scene units.

    Top view: the filled outline under the fabric. Side view (when the top height ``z`` is given):
    the top face as a thick horizontal segment at ``z``. Iso view (with ``z``): the outline at height z.
    """
    outline = as_curve("outline", outline)

    def draw(ax, view: str) -> None:
        if view == "top":
            ax.fill(outline[:, 0], outline[:, 1], color=color, alpha=0.6, zorder=1, label=label)
        elif view == "side" and z is not None:
            ax.plot([outline[:, 0].min(), outline[:, 0].max()], [z, z], color=color, lw=3, zorder=1,
                    label=label)
        elif view == "iso" and z is not None:
            ax.plot(outline[:, 0], outline[:, 1], np.full(len(outline), z), color=color, lw=1.5)

    return draw
