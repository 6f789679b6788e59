"""All drape measures of one configuration as plain values, the record of ``summary.json``."""

from __future__ import annotations

import numpy as np

from rftstatic.post.measures.boundary import boundary_loop, fold_count
from rftstatic.post.measures.shadow import shadow_area
from rftstatic.post.measures.sharp import sharp_fold_indicator
from rftstatic.post.measures.triangles import check_mesh

__all__ = ["drape_measures"]


def drape_measures(x: np.ndarray, tri: np.ndarray, *, sheet_area: float,
                   disc_area: float | None = None, centre=(0.0, 0.0),
                   curvature: np.ndarray | None = None, h: np.ndarray | None = None,
                   resolution: int = 2000) -> dict:
    """All drape measures of one configuration, as plain values for ``summary.json``.

    Parameters
    ----------
    x : (N, 3) ndarray
        Draped node positions [m].
    tri : (E, 3) int ndarray
        Triangles (counter-clockwise in the flat sheet).
    sheet_area : float
        Flat sheet area [m²].
    disc_area : float, optional
        Support disc area [m²]; without it the drape coefficient is not computed.
    centre : (2,) array_like, optional
        Support axis in the xy-plane [m], for the fold count.
    curvature : (E, 3) ndarray, optional
        Element curvature vectors [1/m], for the relative-curvature indicator.
    h : (E,) ndarray, optional
        Element sizes [m] (mean side length, ``mesh.element_size``), with ``curvature``.
    resolution : int, optional
        Scan lines for the shadow area.

    Returns
    -------
    dict
        ``shadow_area`` [m²], ``drape_coefficient`` [-] (or None), ``fold_count``,
        ``fold_angles_deg`` (list), ``boundary_radius_min/mean/max`` [m], and the keys of
        :func:`sharp_fold_indicator`. Floats, ints and lists only.
    """
    x, tri = check_mesh(x, tri, "drape_measures")
    a_sh = shadow_area(x, tri, resolution)
    out: dict = {"shadow_area": a_sh, "drape_coefficient": None}
    if disc_area is not None:
        if not sheet_area > disc_area >= 0.0:
            raise ValueError(f"drape_measures: sheet_area = {sheet_area!r}, disc_area = "
                             f"{disc_area!r}; need sheet_area > disc_area >= 0")
        out["drape_coefficient"] = float((a_sh - disc_area) / (sheet_area - disc_area))
    prof = fold_count(x, boundary_loop(tri, x), centre)
    out.update(fold_count=prof.count,
               fold_angles_deg=[float(v) for v in np.degrees(prof.peak_theta)],
               boundary_radius_min=float(prof.r.min()),
               boundary_radius_mean=float(prof.r.mean()),
               boundary_radius_max=float(prof.r.max()))
    out.update(sharp_fold_indicator(x, tri, curvature, h))
    return out
