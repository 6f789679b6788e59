"""Figures in the style of Sze & Zhou (2016): shaded drape views, boundary overlays, profiles, curves.

Every function takes coordinates already in the scene's units (the caller converts from SI), writes a
PNG (or a GIF for :func:`animate`) atomically through :func:`rftstatic.output.atomic_write` and returns
the path. matplotlib is imported inside the functions and used without pyplot (a bare
:class:`~matplotlib.figure.Figure` renders with Agg), so nothing here needs or touches a display.

Views of a drape (:func:`plot_views`, as in the paper's Figs. 1, 5-16):

* ``side``: x-z projection seen from -y (Figs. 5a, 11b, 12, 13);
* ``top``: x-y projection seen from +z (Figs. 6b-16);
* ``iso``: 3D axes with ``view_init(elev=30, azim=-60)``.

Shading. Each triangle is lit by a light that sits near the viewer (tilted up and to the left), with
the two-sided Lambert factor ``0.35 + 0.65 |n . l|`` (a fabric has no outside), so folds show in the top
view as they do in the paper. All axes have equal aspect. The surface is one ``PolyCollection`` (or
``Poly3DCollection``) drawn back-to-front by a vectorised depth sort, which keeps ~30k triangles fast.

Obstacles are drawn by callables ``draw(ax, view)`` supplied by the caller (this module knows no
obstacle classes); :func:`outline_drawer` turns an outline from :func:`outline_square` or
:func:`outline_circle` into one.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from rftstatic.io.files import atomic_write

__all__ = [
    "plot_views",
    "plot_boundary_overlay",
    "plot_side_profiles",
    "plot_convergence",
    "plot_history",
    "plot_load_deflection",
    "animate",
    "outline_square",
    "outline_circle",
    "outline_drawer",
]

DPI = 120
FABRIC_RGB = np.array([0.85, 0.62, 0.38])  # a warm cloth colour; grey shading alone hides folds less well
ELEV, AZIM = 30.0, -60.0

# Camera direction (towards the viewer) of each view, and the "up" of its image for the light offset.
_CAMERA = {
    "side": (np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])),
    "top": (np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])),
}
_e, _a = math.radians(ELEV), math.radians(AZIM)
_CAMERA["iso"] = (np.array([math.cos(_e) * math.cos(_a), math.cos(_e) * math.sin(_a), math.sin(_e)]),
                  np.array([-math.sin(_e) * math.cos(_a), -math.sin(_e) * math.sin(_a), math.cos(_e)]))
_AXES2D = {"side": (0, 2), "top": (0, 1)}


def _figure(figsize=(6.4, 4.8)):
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def _save(fig, path: str | os.PathLike) -> Path:
    with atomic_write(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return Path(path)


def _check_mesh(x, tri) -> tuple[np.ndarray, np.ndarray]:
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
    cam, up = _CAMERA[view]
    left = np.cross(cam, up)  # up x cam would point right; this points left in the image
    light = cam + 0.45 * up + 0.35 * left
    return light / np.linalg.norm(light)


def _face_colors(x, tri, view, color_by=None, *, cmap="viridis", clim=None):
    """Per-triangle RGBA (E, 4): base colour (or colormap of ``color_by``) times the shading factor."""
    from matplotlib import colormaps
    from matplotlib.colors import Normalize

    p = x[tri]                                                     # (E, 3 nodes, 3)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    shade = 0.35 + 0.65 * np.abs(n @ _light(view))
    mappable = None
    if color_by is None:
        rgb = np.broadcast_to(FABRIC_RGB, (len(tri), 3))
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


def _padded_limits(lo: np.ndarray, hi: np.ndarray, frac: float = 0.03):
    span = np.maximum(hi - lo, 1e-12 * max(1.0, float(np.abs(np.r_[lo, hi]).max())))
    pad = frac * span.max()
    return lo - pad, hi + pad


def _add_surface_2d(ax, x, tri, view, color_by=None, *, clim=None):
    from matplotlib.collections import PolyCollection

    i, j = _AXES2D[view]
    cam, _ = _CAMERA[view]
    depth = (x @ cam)[tri].mean(axis=1)
    order = np.argsort(depth, kind="stable")                     # far first, near drawn on top
    rgba, mappable = _face_colors(x, tri, view, color_by, clim=clim)
    verts = x[tri[order]][:, :, (i, j)]
    coll = PolyCollection(verts, facecolors=rgba[order], zorder=2, **_edges(rgba[order]))
    ax.add_collection(coll)
    return coll, mappable


def _add_surface_3d(ax, x, tri, color_by=None, *, clim=None):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    rgba, mappable = _face_colors(x, tri, "iso", color_by, clim=clim)
    coll = Poly3DCollection(x[tri], facecolors=rgba, **_edges(rgba))
    ax.add_collection3d(coll)
    return coll, mappable


def _set_3d_limits(ax, lo, hi):
    lo, hi = _padded_limits(lo, hi)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)                                     # equal aspect on all three axes
    ax.view_init(elev=ELEV, azim=AZIM)
    if (hi - lo)[2] < 0.3 * (hi - lo).max():                      # a flat box has room for few z ticks
        from matplotlib.ticker import MaxNLocator

        ax.zaxis.set_major_locator(MaxNLocator(nbins=3))


def _set_2d_limits(ax, lo, hi):
    lo, hi = _padded_limits(lo, hi)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")


def _figsize_2d(lo, hi) -> tuple[float, float]:
    dx, dy = np.maximum(hi - lo, 1e-12)
    height = float(np.clip(5.6 * dy / dx, 2.2, 7.0)) + 0.9      # room for the title and labels
    return 6.4, height


def _axis_labels(ax, names, unit):
    suffix = f" [{unit}]" if unit else ""
    ax.set_xlabel(names[0] + suffix)
    ax.set_ylabel(names[1] + suffix)
    if len(names) == 3:
        ax.set_zlabel(names[2] + suffix)


def plot_views(path_prefix: str | os.PathLike, x: np.ndarray, tri: np.ndarray, *,
               views: Sequence[str] = ("side", "top", "iso"), title: str = "",
               obstacles_draw: Sequence[Callable[[Any, str], Any]] | None = None,
               color_by: np.ndarray | None = None, frame_x0: np.ndarray | None = None,
               color_label: str = "", length_unit: str = "", clim: tuple[float, float] | None = None,
               ) -> dict[str, Path]:
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
    color_by : (E,) optional per-triangle scalar (e.g. relative curvature), coloured with viridis and
        shaded; a colour bar labelled ``color_label`` is added.
    frame_x0 : (N, 3) optional reference positions, drawn as thin grey edges in the side view.
    length_unit : axis-label unit, e.g. "cm".
    clim : colour range for ``color_by`` (default: its finite min and max).

    Returns
    -------
    dict view -> path of the PNG written.
    """
    x, tri = _check_mesh(x, tri)
    bad = [v for v in views if v not in _CAMERA]
    if bad:
        raise ValueError(f"unknown view(s) {bad}; choose among 'side', 'top', 'iso'")
    x0 = None if frame_x0 is None else np.asarray(frame_x0, dtype=float)
    if x0 is not None and x0.shape != x.shape:
        raise ValueError(f"frame_x0 must have the shape of x {x.shape}, got {x0.shape}")
    lo, hi = x.min(axis=0), x.max(axis=0)
    out = {}
    for view in views:
        label = f"{title} ({view} view)" if title else f"{view} view"
        if view == "iso":
            fig = _figure((6.4, 5.6))
            ax = fig.add_subplot(projection="3d")
            for draw in obstacles_draw or ():
                draw(ax, view)
            _, mappable = _add_surface_3d(ax, x, tri, color_by, clim=clim)
            _set_3d_limits(ax, lo, hi)
            _axis_labels(ax, ("x", "y", "z"), length_unit)
        else:
            i, j = _AXES2D[view]
            vlo, vhi = lo[[i, j]], hi[[i, j]]
            if view == "side" and x0 is not None:
                vlo = np.minimum(vlo, x0.min(axis=0)[[i, j]])
                vhi = np.maximum(vhi, x0.max(axis=0)[[i, j]])
            fig = _figure(_figsize_2d(vlo, vhi))
            ax = fig.add_subplot()
            if view == "side" and x0 is not None:
                from matplotlib.collections import PolyCollection

                ax.add_collection(PolyCollection(x0[tri][:, :, (i, j)], facecolors="none",
                                                 edgecolors="0.6", linewidths=0.3, zorder=1))
            for draw in obstacles_draw or ():
                draw(ax, view)
            _, mappable = _add_surface_2d(ax, x, tri, view, color_by, clim=clim)
            _set_2d_limits(ax, vlo, vhi)
            _axis_labels(ax, ("xyz"[i], "xyz"[j]), length_unit)
        if mappable is not None:
            fig.colorbar(mappable, ax=ax, shrink=0.7, pad=0.12 if view == "iso" else 0.02, label=color_label)
        ax.set_title(label)
        out[view] = _save(fig, f"{os.fspath(path_prefix)}_{view}.png")
    return out


def _closed(curve: np.ndarray) -> np.ndarray:
    return curve if np.allclose(curve[0], curve[-1]) else np.vstack([curve, curve[:1]])


def _as_curve(name: str, value: Any) -> np.ndarray:
    c = np.asarray(value, dtype=float)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 2:
        raise ValueError(f"curve {name!r} must be an (M, 2) array with M >= 2, got shape {c.shape}")
    return c


_STYLES = ["-", "--", "-.", ":"]


def plot_boundary_overlay(path: str | os.PathLike, curves: Mapping[str, np.ndarray], *, title: str,
                          reference_label: str | None = None, obstacle_outline: np.ndarray | None = None,
                          length_unit: str = "") -> Path:
    """Overlay deformed boundaries seen from the top (the paper's Fig. 6a).

    Parameters
    ----------
    curves : label -> (M, 2) ordered boundary points (x, y) [scene length unit]; closed automatically.
    title : figure title.
    reference_label : key of ``curves`` drawn as the reference (thick black).
    obstacle_outline : (K, 2) outline of the obstacle's top (e.g. :func:`outline_square`), filled grey.
    length_unit : axis-label unit.
    """
    if reference_label is not None and reference_label not in curves:
        raise ValueError(f"reference_label {reference_label!r} is not one of the curves {list(curves)}")
    fig = _figure()
    ax = fig.add_subplot()
    pts = []
    if obstacle_outline is not None:
        ob = _closed(_as_curve("obstacle_outline", obstacle_outline))
        ax.fill(ob[:, 0], ob[:, 1], color="0.85", ec="0.5", lw=0.8, zorder=0, label="obstacle")
        pts.append(ob)
    k = 0
    for name, value in curves.items():
        c = _closed(_as_curve(name, value))
        pts.append(c)
        if name == reference_label:
            ax.plot(c[:, 0], c[:, 1], color="k", lw=2.0, label=name, zorder=3)
        else:
            ax.plot(c[:, 0], c[:, 1], ls=_STYLES[k % 4], lw=1.3, color=f"C{k % 10}", label=name, zorder=4)
            k += 1
    allp = np.vstack(pts)
    _set_2d_limits(ax, allp.min(axis=0), allp.max(axis=0))
    _axis_labels(ax, ("x", "y"), length_unit)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")  # the middle holds the obstacle
    ax.set_title(title)
    return _save(fig, path)


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
    fig = _figure()
    ax = fig.add_subplot()
    pts = []
    for name, value in (reference or {}).items():
        c = _as_curve(name, value)
        pts.append(c)
        ax.plot(c[:, 0], c[:, 1], "o-", color="k", ms=4, lw=0.6, mfc="none", label=name, zorder=3)
    for k, (name, value) in enumerate(curves.items()):
        c = _as_curve(name, value)
        pts.append(c)
        ax.plot(c[:, 0], c[:, 1], ls=_STYLES[k % 4], lw=1.5, color=f"C{k % 10}", label=name, zorder=4)
    if equal_aspect and pts:
        allp = np.vstack(pts)
        _set_2d_limits(ax, allp.min(axis=0), allp.max(axis=0))
    _axis_labels(ax, ("x", "z"), length_unit)
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.set_title(title)
    return _save(fig, path)


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
    fig = _figure()
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
    ax.set_title(title)
    return _save(fig, path), slopes


def plot_history(path: str | os.PathLike, t: np.ndarray, series: Mapping[str, np.ndarray], *,
                 xlabel: str, ylabel: str, title: str, logy: bool = False) -> Path:
    """Plot quantities against time or iteration (energies against t, residual against iteration).

    Parameters
    ----------
    t : (M,) abscissa shared by all series; ``None`` uses 0..M-1.
    series : label -> (M,) values.
    logy : logarithmic y axis; non-positive values are not drawn.
    """
    fig = _figure()
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
    ax.set_title(title)
    return _save(fig, path)


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
    fig = _figure()
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
    ax.set_title(title)
    return _save(fig, path)


def animate(path: str | os.PathLike, frames: Sequence[np.ndarray], tri: np.ndarray, *,
            times: Sequence[float], view: str = "iso", fps: int = 10, title: str = "",
            time_unit: str = "s", length_unit: str = "") -> Path:
    """Write a GIF of the shaded surface over time (the paper's Figs. 12-16 as a movie).

    Parameters
    ----------
    frames : list of (N, 3) positions [scene length unit], one per frame.
    tri : (E, 3) triangles (the same for all frames).
    times : one time per frame [scene time unit], shown in the title.
    view : "iso", "top" or "side".
    fps : frames per second of the GIF.

    The axis limits are those of all frames together, so the motion is not hidden by rescaling.
    """
    from matplotlib.animation import PillowWriter

    if view not in _CAMERA:
        raise ValueError(f"unknown view {view!r}; choose among 'side', 'top', 'iso'")
    if len(frames) == 0:
        raise ValueError("animate needs at least one frame")
    if len(times) != len(frames):
        raise ValueError(f"len(frames) = {len(frames)}, but len(times) = {len(times)}")
    frames = [_check_mesh(f, tri)[0] for f in frames]
    tri = np.asarray(tri)
    lo = np.min([f.min(axis=0) for f in frames], axis=0)
    hi = np.max([f.max(axis=0) for f in frames], axis=0)
    if view == "iso":
        fig = _figure((6.4, 5.6))
        ax = fig.add_subplot(projection="3d")
        _set_3d_limits(ax, lo, hi)
        _axis_labels(ax, ("x", "y", "z"), length_unit)
    else:
        i, j = _AXES2D[view]
        fig = _figure(_figsize_2d(lo[[i, j]], hi[[i, j]]))
        ax = fig.add_subplot()
        _set_2d_limits(ax, lo[[i, j]], hi[[i, j]])
        _axis_labels(ax, ("xyz"[i], "xyz"[j]), length_unit)
    ax.set_title(f"{title}: t = 0" if title else "t = 0")
    fig.get_layout_engine().execute(fig)
    fig.set_layout_engine("none")  # lay out once, then keep it fixed: the frames must not jitter
    writer = PillowWriter(fps=fps)
    with atomic_write(path) as tmp:
        with writer.saving(fig, os.fspath(tmp), dpi=DPI):
            coll = None
            for x, t in zip(frames, times):
                if coll is not None:
                    coll.remove()
                if view == "iso":
                    coll, _ = _add_surface_3d(ax, x, tri)
                else:
                    coll, _ = _add_surface_2d(ax, x, tri, view)
                head = f"{title}: " if title else ""
                ax.set_title(f"{head}t = {float(t):.3g} {time_unit}".strip())
                writer.grab_frame()
    return Path(path)


def outline_square(cx: float, cy: float, half: float, *, corner_radius: float = 0.0, n: int = 16
                   ) -> np.ndarray:
    """Closed (K, 2) outline of a square of half width ``half`` centred at (cx, cy), counter-clockwise.

    With ``corner_radius > 0`` the corners are rounded (``n`` points per corner), as the pedestals of
    :mod:`rftstatic.obstacles`. The last point repeats the first.
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
    outline = _as_curve("outline", outline)

    def draw(ax, view: str) -> None:
        if view == "top":
            ax.fill(outline[:, 0], outline[:, 1], color=color, alpha=0.6, zorder=1, label=label)
        elif view == "side" and z is not None:
            ax.plot([outline[:, 0].min(), outline[:, 0].max()], [z, z], color=color, lw=3, zorder=1,
                    label=label)
        elif view == "iso" and z is not None:
            ax.plot(outline[:, 0], outline[:, 1], np.full(len(outline), z), color=color, lw=1.5)

    return draw
