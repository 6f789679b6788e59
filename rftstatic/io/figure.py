"""What every figure of :mod:`rftstatic.io` shares: a bare figure, its atomic PNG, limits and labels.

The figures are in the style of Sze & Zhou (2016). Every plotting function takes coordinates already
in the scene's units (the caller converts from SI), writes a PNG (or a GIF, :mod:`.animation`)
atomically through :func:`rftstatic.io.files.atomic_write` and returns the path. matplotlib is
imported inside the functions and used without pyplot (a bare :class:`~matplotlib.figure.Figure`
renders with Agg), so importing these modules stays light and nothing needs or touches a display.

Figure modules: :mod:`.views` (shaded drape views), :mod:`.surface` (the shaded triangle surface they
draw), :mod:`.charts` (boundary overlays, profiles, convergence, histories, load-deflection),
:mod:`.animation` (GIF over time), :mod:`.outlines` (obstacle outlines and their drawers).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from rftstatic.io.files import atomic_write

__all__ = ["DPI", "LENGTH_UNITS", "as_curve", "axis_labels", "figsize_2d", "new_figure", "padded_limits", "save_png",
           "set_2d_limits", "set_title", "wrap_title"]

DPI = 120
"""Resolution of every PNG and GIF frame [dots per inch]."""

LENGTH_UNITS = {"cm-gf-s": "cm", "cm-dyn-s": "cm", "mm-N-s": "mm", "SI": "m"}
"""The length unit of a scene's unit system (its name), for axis labels and colour bars."""


def new_figure(figsize=(6.4, 4.8)):
    """A bare :class:`matplotlib.figure.Figure` with constrained layout (Agg, no pyplot, no display).

    ``figsize`` is (width, height) [inch]; matplotlib is imported here, not when the module is.
    """
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def save_png(fig, path: str | os.PathLike) -> Path:
    """Write ``fig`` as a PNG at :data:`DPI` through :func:`rftstatic.io.files.atomic_write`; return the path."""
    with atomic_write(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return Path(path)


def as_curve(name: str, value: Any) -> np.ndarray:
    """``value`` as a float (M, 2) curve with M >= 2; ``ValueError`` naming the curve ``name`` otherwise."""
    c = np.asarray(value, dtype=float)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 2:
        raise ValueError(f"curve {name!r} must be an (M, 2) array with M >= 2, got shape {c.shape}")
    return c


def padded_limits(lo: np.ndarray, hi: np.ndarray, frac: float = 0.03):
    """Axis limits (lo, hi) widened on every side by ``frac`` of the largest span [data units].

    ``lo``, ``hi`` : (D,) lower and upper data bounds; a zero span is treated as a tiny positive one.
    """
    span = np.maximum(hi - lo, 1e-12 * max(1.0, float(np.abs(np.r_[lo, hi]).max())))
    pad = frac * span.max()
    return lo - pad, hi + pad


def set_2d_limits(ax, lo, hi):
    """Padded x-y limits of a 2-D axes from (2,) data bounds ``lo``, ``hi``, with equal aspect."""
    lo, hi = padded_limits(lo, hi)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")


def figsize_2d(lo, hi) -> tuple[float, float]:
    """(width, height) [inch] of a 2-D view of the (2,) data bounds ``lo``, ``hi``.

    6.4 wide; the height follows the aspect ratio (clipped to 2.2-7.0) plus room for the title and labels.
    """
    dx, dy = np.maximum(hi - lo, 1e-12)
    height = float(np.clip(5.6 * dy / dx, 2.2, 7.0)) + 0.9      # room for the title and labels
    return 6.4, height


def axis_labels(ax, names, unit):
    """Label the axes ``names`` (2 or 3 of them, e.g. ("x", "z")) with ``" [unit]"`` when ``unit`` is given."""
    suffix = f" [{unit}]" if unit else ""
    ax.set_xlabel(names[0] + suffix)
    ax.set_ylabel(names[1] + suffix)
    if len(names) == 3:
        ax.set_zlabel(names[2] + suffix)


TITLE_CHAR_WIDTH = 0.55
"""Mean width of a title character over its font size (DejaVu Sans, mixed text; measured 0.52-0.58)."""


def wrap_title(text: str, width_inch: float, fontsize_pt: float, *, max_lines: int = 3) -> str:
    """``text`` broken into lines that fit ``width_inch`` at ``fontsize_pt`` (at most ``max_lines``; a longer
    title is cut with an ellipsis), so that no title runs off the figure's edges."""
    import textwrap

    chars = max(int(width_inch * 72.0 / (TITLE_CHAR_WIDTH * fontsize_pt)), 20)
    out = []
    for part in str(text).split("\n"):
        out += textwrap.wrap(part, chars, break_long_words=True, break_on_hyphens=False) or [""]
    if len(out) > max_lines:
        out = out[:max_lines]
        out[-1] = out[-1][: max(chars - 3, 1)].rstrip() + "..."
    return "\n".join(out)


def set_title(ax, text: str, *, fontsize=None, figure_title: bool = False):
    """Set the title of ``ax`` (or the figure's suptitle, ``figure_title``), wrapped to the width it has:
    the figure's for a suptitle or a figure's only plot (whose title becomes the figure's), else the axes'
    (:func:`wrap_title`)."""
    import matplotlib
    from matplotlib.font_manager import FontProperties

    fig = ax if figure_title else ax.figure
    key = "figure.titlesize" if figure_title else "axes.titlesize"
    size = FontProperties(size=fontsize if fontsize is not None else matplotlib.rcParams[key]).get_size_in_points()
    plots = [a for a in fig.axes if not hasattr(a, "_colorbar")]
    # a lone plot's title is the figure's, centred on the figure and as wide: an equal-aspect view is often far
    # narrower than its title, and a colour bar moves it off the centre
    whole = figure_title or len(plots) <= 1
    width = fig.get_figwidth() * (0.95 if whole else ax.get_position().width)
    kw = {} if fontsize is None else {"fontsize": fontsize}
    text = wrap_title(text, max(width, 1.0), size)
    return fig.suptitle(text, **kw) if whole else ax.set_title(text, **kw)
