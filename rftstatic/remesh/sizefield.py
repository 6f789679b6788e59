"""Target element size from the curvature of the present mesh (Sze & Zhou 2016, §5.1, Eq. 28-29).

For every RF triangle of the present mesh the new size follows from

    |kappa| h_new^2 = const,   h_target = clip(h_new, h_lower, h_upper)            (Eq. 29)

with the curvature vector of Eq. 7, ``kappa = (k_xx, k_yy, 2 k_xy)`` as returned by
:meth:`rftstatic.model.model.Model.curvature`. Its magnitude is the Frobenius norm of the curvature tensor,

    |kappa| = sqrt(k_xx^2 + k_yy^2 + 2 k_xy^2),   k_xy = (2 k_xy) / 2,

:func:`rftstatic.element.curvature.curvature_norm`, the same measure as
:meth:`~rftstatic.model.model.Model.relative_curvature` (``|kappa| h``), so it does not depend on the
orientation of the in-plane axes. ``const`` is a
length [m] (Eq. 28 compares ``|kappa| h^2`` with it): a triangle of the new mesh of size h_new has
``|kappa| h_new = const / h_new``.
A flat triangle (|kappa| = 0) takes h_upper.

Step f of §5.2: the per-triangle h_target is put on the square background grid of the mesher
(:meth:`rftstatic.mesh.mesher.BackgroundGrid.from_samples`, sampled at the triangle centroids in
reference coordinates, each grid node keeping the smallest nearby sample) with a gradation limit,
which the advancing front of step g reads.
"""

from __future__ import annotations

import numpy as np

from rftstatic.element.curvature import curvature_norm
from rftstatic.errors import ParameterError
from rftstatic.mesh import GRADATION

__all__ = ["check_size_bounds", "size_field", "target_sizes"]


def check_size_bounds(*, const, h_lower, h_upper, extent=None) -> None:
    """Raise :class:`~rftstatic.errors.ParameterError` (a ``ValueError``) naming the parameter if the Eq. 29
    parameters are unusable.

    Parameters
    ----------
    const : |kappa| h^2 target [m], > 0
    h_lower, h_upper : size bounds [m], 0 < h_lower <= h_upper
    extent : smaller side of the sheet's bounding box [m]; sizes above it cannot be meshed
    """
    for name, v in (("const", const), ("h_lower", h_lower), ("h_upper", h_upper)):
        if not (isinstance(v, (int, float, np.floating, np.integer)) and np.isfinite(v) and v > 0):
            raise ParameterError(name, f"{name} = {v!r} must be a positive finite number [m] (Eq. 29)")
    if h_lower > h_upper:
        raise ParameterError("h_lower", f"h_lower = {h_lower!r} m is larger than h_upper = {h_upper!r} m; "
                         "Eq. 29 clips h_target to [h_lower, h_upper]: swap them")
    if extent is not None:
        for name, v in (("h_lower", h_lower), ("h_upper", h_upper)):
            if v > extent:
                raise ParameterError(name, f"{name} = {v!r} m is larger than the sheet (smaller side {extent:.6g} "
                                     f"m); a flat region would get elements bigger than the domain: use {name} < "
                                     f"{extent:.6g}")


def target_sizes(kappa, *, const, h_lower, h_upper) -> np.ndarray:
    """Eq. 29: (E,) h_target = clip(sqrt(const / |kappa|), h_lower, h_upper) [m].

    Parameters
    ----------
    kappa : (E, 3) element curvature (k_xx, k_yy, 2 k_xy) [1/m] (Eq. 7)
    const : |kappa| h_new^2 [m]
    h_lower, h_upper : bounds on the new size [m]
    """
    check_size_bounds(const=const, h_lower=h_lower, h_upper=h_upper)
    mag = curvature_norm(kappa)
    with np.errstate(divide="ignore"):
        h_new = np.sqrt(const / mag)          # inf where flat, clipped to h_upper below
    return np.clip(h_new, h_lower, h_upper)


def size_field(mesh, kappa, *, const, h_lower, h_upper, gradation=GRADATION, spacing=None, region=None):
    """Steps e-f of §5.2: the background grid of h_target for a new mesh of ``mesh``'s sheet.

    Parameters
    ----------
    mesh : :class:`rftstatic.mesh.trimesh.TriMesh`, the present mesh (reference coordinates [m])
    kappa : (E, 3) its element curvature (k_xx, k_yy, 2 k_xy) [1/m]
    const, h_lower, h_upper : Eq. 29 [m]
    gradation : ratio >= 1; neighbouring grid sizes obey ``h_q <= h_p + (gradation - 1) |x_q - x_p|``
        (:mod:`rftstatic.mesh.mesher.sizefield`); ``None`` stores the clipped samples as they are
    spacing : grid spacing [m]; default ``max(h_lower / 2, longest side / 500)``
    region : Domain or (xmin, ymin, xmax, ymax) [m] to cover (default: the mesh's bounding box)

    Returns
    -------
    :class:`rftstatic.mesh.mesher.BackgroundGrid`; its values lie in [h_lower, h_upper].
    """
    from rftstatic.mesh.mesher import BackgroundGrid

    X = mesh.X
    lo, hi = X.min(axis=0), X.max(axis=0)
    check_size_bounds(const=const, h_lower=h_lower, h_upper=h_upper, extent=float((hi - lo).min()))
    kappa = np.asarray(kappa, dtype=float)
    if kappa.shape != (mesh.n_elements, 3):
        raise ValueError(f"kappa must have shape ({mesh.n_elements}, 3), one curvature per triangle, got {kappa.shape}")
    h = target_sizes(kappa, const=const, h_lower=h_lower, h_upper=h_upper)
    if region is None:
        region = (lo[0], lo[1], hi[0], hi[1])
    if spacing is None:
        spacing = max(0.5 * h_lower, float((hi - lo).max()) / 500.0)
    centroids = X[mesh.tri].mean(axis=1)
    return BackgroundGrid.from_samples(centroids, h, region, spacing=spacing, gradation=gradation,
                                       h_lower=h_lower, h_upper=h_upper)
