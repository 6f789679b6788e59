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
                   resolution: int = 2000, fill: np.ndarray | None = None, profile: bool = False) -> dict:
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
    fill : (F, 3, 3) ndarray, optional
        Triangles (vertex coordinates [m]) added to the shadow only: a tester's clamping disc where the
        mesh leaves it open (:func:`~rftstatic.post.measures.disc.clamp_disc`).
    profile : bool, optional
        Add the hem's profile ``hem_profile = {"theta_deg", "r"}`` (every second of the 720 rays).

    Returns
    -------
    dict
        ``shadow_area`` [m²], ``drape_coefficient`` [-] (or None), ``fold_count``,
        ``fold_angles_deg`` (list), ``boundary_radius_min/mean/max`` [m], and the keys of
        :func:`sharp_fold_indicator`. Floats, ints and lists only.
    """
    x, tri = check_mesh(x, tri, "drape_measures")
    if fill is not None and len(fill):
        fx = np.asarray(fill, float).reshape(-1, 3)[:, :x.shape[1]]
        a_sh = shadow_area(np.vstack([x, fx]), np.vstack([tri, len(x) + np.arange(len(fx)).reshape(-1, 3)]),
                           resolution)
    else:
        a_sh = shadow_area(x, tri, resolution)
    out: dict = {"shadow_area": a_sh, "drape_coefficient": None}
    if disc_area is not None:
        if not sheet_area > disc_area >= 0.0:
            raise ValueError(f"drape_measures: sheet_area = {sheet_area!r}, disc_area = "
                             f"{disc_area!r}; need sheet_area > disc_area >= 0")
        out["drape_coefficient"] = float((a_sh - disc_area) / (sheet_area - disc_area))
        out["drape_coefficient_percent"] = 100.0 * out["drape_coefficient"]
    prof = fold_count(x, boundary_loop(tri, x), centre)
    out.update(fold_count=prof.count,
               fold_angles_deg=[float(v) for v in np.degrees(prof.peak_theta)],
               boundary_radius_min=float(prof.r.min()),
               boundary_radius_mean=float(prof.r.mean()),
               boundary_radius_max=float(prof.r.max()))
    if profile:
        out["hem_profile"] = {"theta_deg": np.degrees(prof.theta[::2]).tolist(), "r": prof.r[::2].tolist()}
    out.update(sharp_fold_indicator(x, tri, curvature, h))
    return out
