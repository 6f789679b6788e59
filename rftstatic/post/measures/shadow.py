"""Shadow area and Cusick's drape coefficient of a draped sheet.

- :func:`shadow_area`: area of the *union* of the vertical (z) projections of the triangles (folds
  overlap in projection, so not the area inside a boundary polygon), by exact scan-line union;
- :func:`drape_coefficient`: DC = (A_shadow − A_disc) / (A_sheet − A_disc).

Lengths in the units of ``x`` (SI inside the package), areas in their square.
"""

from __future__ import annotations

import numpy as np

from rftstatic.post.measures.triangles import check_mesh

__all__ = ["drape_coefficient", "shadow_area"]


def shadow_area(x: np.ndarray, tri: np.ndarray, resolution: int = 2000) -> float:
    """Area of the union of the vertical projections of the triangles.

    Exact scan-line integration in y: on each of ``resolution`` horizontal lines (at the
    mid-points of equal strips spanning the projection's y-range) every triangle that the
    line crosses contributes an interval [x_left, x_right]; the union of the intervals on
    the line is measured exactly (sort, running maximum), and the lengths are summed
    times the strip height (mid-point rule in y).

    Parameters
    ----------
    x : (N, 3) or (N, 2) ndarray
        Node positions [m]; only the first two columns (x, y) are used.
    tri : (E, 3) int ndarray
        Triangles (any orientation; folded-over triangles count once).
    resolution : int, optional
        Number of scan lines.

    Returns
    -------
    float
        A_shadow [m²].

    Notes
    -----
    Accuracy: the covered length L(y) is piecewise linear in y, with kinks only at node
    heights, so the mid-point rule is exact on every strip without a kink; a strip with a
    kink errs by at most |ΔL'|·Δy²/8, Δy = (y_max − y_min)/resolution. The result is exact
    (to rounding) for an axis-aligned rectangle and within Σ|ΔL'|·Δy²/8 for any polygon
    (tested on rotated squares). On a finely polygonised round outline the top and bottom
    strips, where the outline turns horizontal, dominate: a disc comes out within 4e-6
    (relative) at the default 2000 lines and 3e-5 at 500 (measured).

    Cost and memory grow with the number of (triangle, scan line) pairs, about
    A_sheet/(Δy·mean edge): 80 000 triangles at 2000 lines take about 0.7 s.
    """
    x, tri = check_mesh(x, tri, "shadow_area")
    if int(resolution) < 1:
        raise ValueError(f"shadow_area: resolution = {resolution!r}; "
                         "use a positive number of scan lines")
    n = int(resolution)
    p = x[tri][:, :, :2]                                    # (E, 3, 2)
    y0, y1 = p[..., 1].min(), p[..., 1].max()
    if y1 <= y0:
        return 0.0
    dy = (y1 - y0) / n
    ymin, ymax = p[..., 1].min(axis=1), p[..., 1].max(axis=1)
    r0 = np.clip(np.ceil((ymin - y0) / dy - 0.5), 0, n - 1).astype(np.int64)
    r1 = np.clip(np.floor((ymax - y0) / dy - 0.5), 0, n - 1).astype(np.int64)
    cnt = np.maximum(r1 - r0 + 1, 0)
    total = int(cnt.sum())
    if total == 0:
        return 0.0
    e = np.repeat(np.arange(len(tri)), cnt)                 # ragged (triangle, row) pairs
    row = r0[e] + np.arange(total) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    yl = y0 + (row + 0.5) * dy
    pe = p[e]                                               # (P, 3, 2)
    a, b = pe, np.roll(pe, -1, axis=1)                      # edge a→b
    ya, yb = a[..., 1], b[..., 1]
    ylc = yl[:, None]
    cross = (np.minimum(ya, yb) <= ylc) & (ylc <= np.maximum(ya, yb)) & (ya != yb)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cross, (ylc - ya) / np.where(ya != yb, yb - ya, 1.0), 0.0)
    xc = a[..., 0] + t * (b[..., 0] - a[..., 0])
    xl = np.where(cross, xc, np.inf).min(axis=1)
    xr = np.where(cross, xc, -np.inf).max(axis=1)
    ok = xr >= xl
    row, xl, xr = row[ok], xl[ok], xr[ok]
    # union of intervals per row: shift each row by a stride W larger than the x-range so one
    # global sort and one running maximum act row by row
    xmin = p[..., 0].min()
    W = 2.0 * (p[..., 0].max() - xmin) + 1.0
    L = row * W + (xl - xmin)
    R = row * W + (xr - xmin)
    order = np.lexsort((L, row))
    L, R = L[order], R[order]
    reach = np.maximum.accumulate(R)
    prev = np.concatenate(([-np.inf], reach[:-1]))
    covered = np.maximum(R - np.maximum(L, prev), 0.0)
    return float(covered.sum() * dy)


def drape_coefficient(x: np.ndarray, tri: np.ndarray, sheet_area: float, disc_area: float,
                      *, resolution: int = 2000) -> float:
    """Cusick's drape coefficient DC = (A_shadow − A_disc) / (A_sheet − A_disc).

    Parameters
    ----------
    x : (N, 3) ndarray
        Draped node positions [m].
    tri : (E, 3) int ndarray
        Triangles.
    sheet_area : float
        Area of the flat sheet A_sheet [m²].
    disc_area : float
        Area of the supporting disc (pedestal top) A_disc [m²].
    resolution : int, optional
        Scan lines for :func:`shadow_area`.

    Returns
    -------
    float
        DC [-]: 1 for a sheet that stays flat, near 0 for one that hangs straight down.
    """
    if not sheet_area > disc_area >= 0.0:
        raise ValueError(f"drape_coefficient: sheet_area = {sheet_area!r}, disc_area = {disc_area!r};"
                         " need sheet_area > disc_area >= 0 (same units, e.g. m²)")
    a = shadow_area(x, tri, resolution)
    return (a - disc_area) / (sheet_area - disc_area)
