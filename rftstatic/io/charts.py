"""Line charts of the validation reports and runs, in the style of Sze & Zhou (2016).

- :func:`plot_boundary_overlay`: deformed boundaries seen from the top over the obstacle (Fig. 6a);
- :func:`plot_side_profiles`: side profiles of strips against a reference (Fig. 5b);
- :func:`plot_convergence`: errors against nodes, time or h on log axes, with slope triangles and
  fitted rates;
- :func:`plot_history`: quantities against time or iteration (energies, residuals);
- :func:`plot_load_deflection`: load-deflection curves with reference points (Sze, Liu & Lo 2004).

Every function writes one PNG atomically (:func:`rftstatic.io.figure.save_png`) and returns its path;
coordinates are in the scene's units.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rftstatic.io.figure import as_curve, axis_labels, new_figure, save_png, set_2d_limits, set_title

__all__ = ["plot_boundary_overlay", "plot_convergence", "plot_history", "plot_load_deflection",
           "plot_side_profiles"]

_STYLES = ["-", "--", "-.", ":"]


def _closed(curve: np.ndarray) -> np.ndarray:
    return curve if np.allclose(curve[0], curve[-1]) else np.vstack([curve, curve[:1]])


def plot_boundary_overlay(path: str | os.PathLike, curves: Mapping[str, np.ndarray], *, title: str,
                          reference_label: str | None = None, obstacle_outline: np.ndarray | None = None,
                          length_unit: str = "") -> Path:
    """Overlay deformed boundaries seen from the top (the paper's Fig. 6a).

    Parameters
    ----------
    curves : label -> (M, 2) ordered boundary points (x, y) [scene length unit]; closed automatically.
    title : figure title.
    reference_label : key of ``curves`` drawn as the reference (thick black).
    obstacle_outline : (K, 2) outline of the obstacle's top (e.g.
        :func:`rftstatic.io.outlines.outline_square`), filled grey.
    length_unit : axis-label unit.
    """
    if reference_label is not None and reference_label not in curves:
        raise ValueError(f"reference_label {reference_label!r} is not one of the curves {list(curves)}")
    fig = new_figure()
    ax = fig.add_subplot()
    pts = []
    if obstacle_outline is not None:
        ob = _closed(as_curve("obstacle_outline", obstacle_outline))
        ax.fill(ob[:, 0], ob[:, 1], color="0.85", ec="0.5", lw=0.8, zorder=0, label="obstacle")
        pts.append(ob)
    k = 0
    for name, value in curves.items():
        c = _closed(as_curve(name, value))
        pts.append(c)
        if name == reference_label:
            ax.plot(c[:, 0], c[:, 1], color="k", lw=2.0, label=name, zorder=3)
        else:
            ax.plot(c[:, 0], c[:, 1], ls=_STYLES[k % 4], lw=1.3, color=f"C{k % 10}", label=name, zorder=4)
            k += 1
    allp = np.vstack(pts)
    set_2d_limits(ax, allp.min(axis=0), allp.max(axis=0))
    axis_labels(ax, ("x", "y"), length_unit)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")  # the middle holds the obstacle
    set_title(ax, title)
    return save_png(fig, path)


def plot_side_profiles(path: str | os.PathLike, curves: Mapping[str, np.ndarray], *, title: str,
                       reference: Any = None, length_unit: str = "", equal_aspect: bool = True) -> Path:
    """Side-view profiles of strips (the paper's Fig. 5b).

    Parameters
    ----------
    curves : label -> (M, 2) points (x, z) [scene length unit], ordered along the strip.
    title : figure title.
    reference : an (M, 2) array (labelled "reference") or a dict label -> (M, 2), drawn as black
        circles joined by a thin line.
    equal_aspect : keep x and z to the same scale (default, as in the paper).
    """
    if reference is not None and not isinstance(reference, Mapping):
        reference = {"reference": reference}
    fig = new_figure()
    ax = fig.add_subplot()
    pts = []
    for name, value in (reference or {}).items():
        c = as_curve(name, value)
        pts.append(c)
        ax.plot(c[:, 0], c[:, 1], "o-", color="k", ms=4, lw=0.6, mfc="none", label=name, zorder=3)
    for k, (name, value) in enumerate(curves.items()):
        c = as_curve(name, value)
        pts.append(c)
        ax.plot(c[:, 0], c[:, 1], ls=_STYLES[k % 4], lw=1.5, color=f"C{k % 10}", label=name, zorder=4)
    if equal_aspect and pts:
        allp = np.vstack(pts)
        set_2d_limits(ax, allp.min(axis=0), allp.max(axis=0))
    axis_labels(ax, ("x", "z"), length_unit)
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, lw=0.3, alpha=0.5)
    set_title(ax, title)
    return save_png(fig, path)


def _positive_pairs(x, y) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.shape != y.shape:
        raise ValueError(f"x has {x.size} values but the error has {y.size}")
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    return x[ok], y[ok]


def _fit_slope(x, y) -> float:
    x, y = _positive_pairs(x, y)
    if len(np.unique(x)) < 2:
        return float("nan")
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def _slope_triangles(ax, data, slopes, reference_slopes):
    """Draw one slope triangle per reference slope below the data, towards the right end."""
    xs = np.concatenate([d[0] for d in data])
    lx0, lx1 = np.log10(xs.min()), np.log10(xs.max())
    if lx1 - lx0 < 1e-9:
        return
    finite = [s for s in slopes if np.isfinite(s)]
    sign = -1.0 if (not finite or np.median(finite) < 0) else 1.0
    xa, xb = 10 ** (lx0 + 0.55 * (lx1 - lx0)), 10 ** (lx0 + 0.85 * (lx1 - lx0))
    # lowest data value over [xa, xb], so the triangles sit under every series there
    floor = min(float(np.exp(np.interp(np.log(xq), np.log(x), np.log(y))))
                for x, y in data for xq in (xa, xb))
    y_top = floor * 0.5
    for p in reference_slopes:
        s = sign * abs(float(p))
        ratio = (xb / xa) ** s
        # right-angle corner on the low side; the hypotenuse has slope s
        ya, yb = (y_top, y_top * ratio) if s < 0 else (y_top / ratio, y_top)
        corner = (xb, ya) if s < 0 else (xa, yb)
        tri = np.array([[xa, ya], [xb, yb], corner, [xa, ya]])
        ax.plot(tri[:, 0], tri[:, 1], color="0.3", lw=0.9)
        xm = math.sqrt(xa * xb)
        ym = math.sqrt(ya * yb)
        # both corners put the horizontal leg on top, at the corner's height
        ax.text(xm, corner[1] * 1.08, "1", ha="center", va="bottom", fontsize="small", color="0.3")
        ax.text(corner[0] * (1.04 if s < 0 else 0.96), ym, f"{abs(s):g}", ha="left" if s < 0 else "right",
                va="center", fontsize="small", color="0.3")
        y_top = min(ya, yb) * 0.35


def plot_convergence(path: str | os.PathLike, series: Mapping[str, tuple[np.ndarray, np.ndarray]], *,
                     xlabel: str, ylabel: str = "relative error", title: str, loglog: bool = True,
                     reference_slopes: Sequence[float] = (1, 2)) -> tuple[Path, dict[str, float]]:
    """Plot errors against nodes (or wall time, or h) with slope triangles; fit the rates.

    Parameters
    ----------
    series : label -> (x (M,), error (M,)); non-positive or non-finite pairs are left out of the plot
        (on log axes) and of the fit.
    xlabel, ylabel, title : labels.
    loglog : log scales on both axes (the slope triangles are only drawn then).
    reference_slopes : magnitudes of the slope triangles; their sign follows the data (negative when
        the error falls as x grows).

    Returns
    -------
    (path, slopes) with ``slopes[label] = np.polyfit(np.log(x), np.log(err), 1)[0]`` (NaN with fewer
    than two usable points).
    """
    fig = new_figure()
    ax = fig.add_subplot()
    slopes: dict[str, float] = {}
    data = []
    markers = "osd^v<>p"
    for k, (name, (x, err)) in enumerate(series.items()):
        slope = _fit_slope(x, err)
        slopes[name] = slope
        if loglog:
            xp, yp = _positive_pairs(x, err)
            order = np.argsort(xp)
            xp, yp = xp[order], yp[order]
            if len(xp):
                data.append((xp, yp))
        else:
            xp, yp = np.asarray(x, dtype=float).ravel(), np.asarray(err, dtype=float).ravel()
        text = f"{name} (slope {slope:.2f})" if np.isfinite(slope) else name
        ax.plot(xp, yp, marker=markers[k % len(markers)], ls="-", color=f"C{k % 10}", label=text)
    if loglog:
        ax.set_xscale("log")
        ax.set_yscale("log")
        if data and reference_slopes:
            _slope_triangles(ax, data, list(slopes.values()), reference_slopes)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", fontsize="small")
    set_title(ax, title)
    return save_png(fig, path), slopes


def plot_history(path: str | os.PathLike, t: np.ndarray, series: Mapping[str, np.ndarray], *,
                 xlabel: str, ylabel: str, title: str, logy: bool = False) -> Path:
    """Plot quantities against time or iteration (energies against t, residual against iteration).

    Parameters
    ----------
    t : (M,) abscissa shared by all series; ``None`` uses 0..M-1.
    series : label -> (M,) values.
    logy : logarithmic y axis; non-positive values are not drawn.
    """
    fig = new_figure()
    ax = fig.add_subplot()
    for k, (name, y) in enumerate(series.items()):
        y = np.asarray(y, dtype=float).ravel()
        tt = np.arange(len(y)) if t is None else np.asarray(t, dtype=float).ravel()
        if tt.shape != y.shape:
            raise ValueError(f"len(t) = {tt.size}, but series {name!r} has {y.size} values")
        if logy:
            y = np.where(y > 0, y, np.nan)
        ax.plot(tt, y, color=f"C{k % 10}", lw=1.3, label=name)
    if logy:
        ax.set_yscale("log")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if series:
        ax.legend(loc="best", fontsize="small")
    set_title(ax, title)
    return save_png(fig, path)


def plot_load_deflection(path: str | os.PathLike, curves: Mapping[str, tuple[np.ndarray, np.ndarray]],
                         reference: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None, *,
                         xlabel: str, ylabel: str, title: str) -> Path:
    """Load-deflection curves with reference points (Sze, Liu & Lo 2004 benchmarks).

    As in those papers the deflection is on the horizontal axis and the load on the vertical one:
    ``xlabel`` names the deflection, ``ylabel`` the load.

    Parameters
    ----------
    curves : label -> (load (M,), deflection (M,)), drawn as lines.
    reference : label -> (load (K,), deflection (K,)), drawn as open markers.
    """
    fig = new_figure()
    ax = fig.add_subplot()
    markers = "osd^v<>p"
    for k, (name, (load, defl)) in enumerate((reference or {}).items()):
        ax.plot(np.asarray(defl, float), np.asarray(load, float), ls="none", marker=markers[k % len(markers)],
                mfc="none", color="k", ms=5, label=name)
    for k, (name, (load, defl)) in enumerate(curves.items()):
        ax.plot(np.asarray(defl, float), np.asarray(load, float), ls=_STYLES[k % 4], color=f"C{k % 10}",
                lw=1.5, label=name)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", fontsize="small")
    set_title(ax, title)
    return save_png(fig, path)
