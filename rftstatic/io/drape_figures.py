"""Figures of draped sheets in the style of the paper (Sze & Zhou 2016, Figs. 6-11).

- :func:`obstacle_drawers`: the obstacles of a scene as ``draw(ax, view)`` callables for
  :func:`rftstatic.io.views.plot_views` (each obstacle's plan outline, from its signed distance, at its
  top), in the scene's length unit;
- :func:`boundary_xy`: the projected outer boundary of a drape (Fig. 6a);
- :func:`boundary_distance`: the largest distance between two projected boundary curves
  (symmetric Hausdorff distance of the closed polylines);
- :func:`plot_side_by_side`: two drapes (RFT3 and RFT6) in one figure, top and isometric views,
  coloured by the relative curvature |kappa| h on a common scale (Fig. 8).
"""

from __future__ import annotations

import numpy as np

from rftstatic.io.figure import set_title

__all__ = ["boundary_distance", "boundary_xy", "obstacle_drawers", "plot_side_by_side"]


def obstacle_drawers(obstacles, length_scale: float = 1.0) -> list:
    """``draw(ax, view)`` callables for ``views.plot_views(obstacles_draw=...)``, in scene units.

    Each bounded obstacle is drawn from its interface alone (:meth:`Obstacle.plan_outline`, drawn at the height
    where the solid is that wide; :func:`rftstatic.io.outlines.outline_drawer`), whatever its type: a new obstacle
    type is drawn without a line here. Unbounded ones (a floor) are not drawn.

    Parameters
    ----------
    obstacles : sequence of :class:`rftstatic.contact.obstacles.Obstacle` [m]
    length_scale : the scene's length unit [m] (0.01 for cm)
    """
    from rftstatic.io.outlines import outline_drawer

    draws = []
    for ob in obstacles:
        plan = ob.plan_outline()
        if plan is None:
            continue
        outline, height = plan
        draws.append(outline_drawer(outline / length_scale, z=height / length_scale))
    return draws


def boundary_xy(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(B, 2) projected outer boundary of a draped sheet, in the order of the loop.

    Parameters
    ----------
    x : (N, 3) node positions [any length unit]
    tri : (E, 3) triangles
    """
    from rftstatic.post.measures.boundary import boundary_loop

    loop = boundary_loop(tri, x)
    return np.asarray(x, float)[loop, :2]


def _densify(c: np.ndarray, step: float) -> np.ndarray:
    """Points along the closed polyline ``c`` (M, 2) no farther apart than ``step``."""
    a, b = c, np.roll(c, -1, axis=0)
    seg = np.linalg.norm(b - a, axis=1)
    k = np.maximum(1, np.ceil(seg / step).astype(int))
    idx = np.repeat(np.arange(len(c)), k)
    frac = (np.arange(k.sum()) - np.repeat(np.cumsum(k) - k, k)) / np.repeat(k, k)
    return a[idx] + frac[:, None] * (b[idx] - a[idx])


def boundary_distance(c1: np.ndarray, c2: np.ndarray, *, step: float | None = None) -> float:
    """Largest distance between two closed curves (symmetric Hausdorff distance) [their unit].

    Both curves are sampled at ``step`` (default 1/2000 of the larger extent); the distance is
    exact to within ``step / 2``.
    """
    from scipy.spatial import cKDTree

    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    if step is None:
        step = max(np.ptp(c1, axis=0).max(), np.ptp(c2, axis=0).max()) / 2000.0
    p1, p2 = _densify(c1, step), _densify(c2, step)
    d12 = cKDTree(p2).query(p1)[0].max()
    d21 = cKDTree(p1).query(p2)[0].max()
    return float(max(d12, d21))


def plot_side_by_side(path, drapes: dict, *, title: str, obstacles_draw=None, length_unit: str = "cm",
                      clim=None, views=("top", "iso")):
    """One row per view, one column per drape; shaded and coloured by |kappa| h on a common scale.

    Parameters
    ----------
    drapes : label -> (x (N, 3) [length_unit], tri (E, 3), color (E,) relative curvature [-])
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors
    from matplotlib.collections import PolyCollection
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    labels = list(drapes)
    if clim is None:
        clim = (0.0, max(float(np.max(c)) for _, _, c in drapes.values()))
    norm = colors.Normalize(*clim)
    cmap = matplotlib.colormaps["viridis"]
    fig = plt.figure(figsize=(5.0 * len(labels), 4.6 * len(views)))
    lo = np.min([d[0].min(axis=0) for d in drapes.values()], axis=0)
    hi = np.max([d[0].max(axis=0) for d in drapes.values()], axis=0)
    for r, view in enumerate(views):
        for k, lb in enumerate(labels):
            x, tri, col = drapes[lb]
            p = x[tri]
            nrm = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
            rgba = cmap(norm(col))
            idx = r * len(labels) + k + 1
            if view == "iso":
                light = np.array([-0.4, -0.6, 0.7]) / np.linalg.norm([-0.4, -0.6, 0.7])
                shade = 0.45 + 0.55 * np.abs(nrm @ light)
                rgba[:, :3] *= shade[:, None]
                ax = fig.add_subplot(len(views), len(labels), idx, projection="3d")
                for draw in obstacles_draw or ():
                    draw(ax, view)
                ax.add_collection3d(Poly3DCollection(p, facecolors=rgba, edgecolors=rgba, linewidths=0.1))
                span = (hi - lo).max() / 2
                mid = (hi + lo) / 2
                ax.set_xlim(mid[0] - span, mid[0] + span)
                ax.set_ylim(mid[1] - span, mid[1] + span)
                ax.set_zlim(mid[2] - span, mid[2] + span)
                ax.view_init(elev=30, azim=-60)
                ax.set_box_aspect((1, 1, 1))
            else:
                order = np.argsort(p[:, :, 2].mean(axis=1))  # painter's order: highest drawn last
                shade = 0.45 + 0.55 * np.abs(nrm[:, 2])
                rgba[:, :3] *= shade[:, None]
                ax = fig.add_subplot(len(views), len(labels), idx)
                for draw in obstacles_draw or ():
                    draw(ax, view)
                ax.add_collection(PolyCollection(p[order][:, :, :2], facecolors=rgba[order], edgecolors="k",
                                                 linewidths=0.05, zorder=2))
                ax.set_xlim(lo[0], hi[0])
                ax.set_ylim(lo[1], hi[1])
                ax.set_aspect("equal")
                ax.set_xlabel(f"x [{length_unit}]")
                ax.set_ylabel(f"y [{length_unit}]")
            set_title(ax, f"{lb} ({view})", fontsize="small")
    set_title(fig, title, figure_title=True)
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), ax=fig.axes, shrink=0.6, label="|kappa| h")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_shadow(path, x: np.ndarray, tri: np.ndarray, *, fill: np.ndarray, centre, specimen_radius: float,
                disc_radius: float, title: str, unit: str = ""):
    """The drape tester's photograph: the shadow of the draped specimen seen from above (the union of the
    projected triangles, black), the disc (grey) and the flat specimen's and disc's outlines (dashed).

    Parameters
    ----------
    x : (N, 3) draped positions [scene length]; tri : (E, 3) triangles
    fill : (F, 3, 3) the clamping disc as triangles [scene length] (:class:`~rftstatic.post.measures.disc.Disc`)
    centre : (2,) the disc's centre; specimen_radius, disc_radius : [scene length]
    """
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Circle

    from rftstatic.io.figure import axis_labels, new_figure, save_png, set_2d_limits

    fig = new_figure((5.6, 6.0))
    ax = fig.add_subplot()
    ax.add_collection(PolyCollection(np.asarray(x)[np.asarray(tri)][:, :, :2], facecolors="0.08", edgecolors="0.08",
                                     linewidths=0.3))
    ax.add_collection(PolyCollection(np.asarray(fill)[:, :, :2], facecolors="0.55", edgecolors="0.55", linewidths=0.3))
    for r, style in ((specimen_radius, "--"), (disc_radius, ":")):
        ax.add_patch(Circle(tuple(np.asarray(centre)[:2]), r, fill=False, linestyle=style, color="tab:red", lw=1.0))
    c = np.asarray(centre, float)[:2]
    set_2d_limits(ax, c - specimen_radius, c + specimen_radius)
    axis_labels(ax, ("x (warp)", "y (weft)"), unit)
    set_title(ax, title)
    return save_png(fig, path)
