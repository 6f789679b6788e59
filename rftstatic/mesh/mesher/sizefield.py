"""Target element size stored on a square background grid (Lee & Lo 1995).

Sze & Zhou (2016), section 5.2 b/f/g: the target size h_target of Eq. (29) is
transferred from the old mesh to a square background grid, and the advancing
front reads it from there.  :class:`BackgroundGrid` is that grid: node values
``values[i, j]`` sit at ``origin + spacing * (i, j)`` and are interpolated
bilinearly.

Gradation limit
---------------
With ``gradation = g`` (a ratio, default :data:`rftstatic.mesh.GRADATION`) the stored field is lowered
(never raised) to the largest field not above the input that satisfies, for
every pair of 8-neighbouring grid nodes p, q::

    h[q] <= h[p] + (g - 1) * |x_q - x_p|

i.e. the size is Lipschitz with slope ``g - 1``.  Two elements of size h lying
one element length apart therefore differ in size by at most the factor g,
independently of the grid spacing.  The limiting is exact and costs two
raster passes, vectorised along the rows (see :func:`limit_gradation`).
"""

from __future__ import annotations

import numpy as np

from rftstatic.errors import MeshingError
from rftstatic.mesh import GRADATION

__all__ = ["BackgroundGrid", "limit_gradation"]

_DEFAULT_CELLS = 200


def _bbox_of(region):
    """(xmin, ymin, xmax, ymax) [m] of a Domain-like object or a 4-sequence."""
    bbox = getattr(region, "bbox", region)
    bbox = np.asarray(bbox, dtype=float).reshape(-1)
    if bbox.shape != (4,) or not np.all(np.isfinite(bbox)):
        raise MeshingError(f"bbox must be (xmin, ymin, xmax, ymax) with finite values, got {bbox!r}")
    if bbox[2] <= bbox[0] or bbox[3] <= bbox[1]:
        raise MeshingError(f"bbox {tuple(bbox)} is empty: need xmax > xmin and ymax > ymin")
    return bbox


def _check_bounds(h_lower, h_upper):
    for name, v in (("h_lower", h_lower), ("h_upper", h_upper)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise MeshingError(f"{name} = {v!r} must be a positive finite size [m]")
    if h_lower is not None and h_upper is not None and h_lower > h_upper:
        raise MeshingError(
            f"h_lower = {h_lower!r} is larger than h_upper = {h_upper!r}; "
            "swap them or lower h_lower (Eq. 29 clamps h_target to [h_lower, h_upper])"
        )


def _clamp(values, h_lower, h_upper):
    if h_lower is not None:
        values = np.maximum(values, h_lower)
    if h_upper is not None:
        values = np.minimum(values, h_upper)
    return values


def _row_sweep(r, ramp):
    """Exact in-row limiting r[j] <= r[k] + slope |j - k| via cumulative minima."""
    r = np.minimum(r, np.minimum.accumulate(r - ramp) + ramp)
    return np.minimum(r, np.minimum.accumulate((r + ramp)[::-1])[::-1] - ramp)


def limit_gradation(values, spacing, gradation):
    """Lower a grid size field until neighbouring sizes obey the gradation.

    Two raster passes (top-down then bottom-up), each row first relaxed from
    its three neighbours in the previous row and then swept exactly along the
    row; as for chamfer distance transforms this is exact, because a shortest
    8-neighbour path is monotone in both grid directions.

    Parameters
    ----------
    values : (nx, ny) node sizes [m]
    spacing : grid spacing [m]
    gradation : ratio g >= 1; enforces ``h[q] <= h[p] + (g - 1) |x_q - x_p|``
        for 8-neighbours (see the module docstring).

    Returns
    -------
    (nx, ny) limited sizes [m]: the largest field <= ``values`` obeying the limit.
    """
    if not (np.isfinite(gradation) and gradation >= 1.0):
        raise MeshingError(f"gradation = {gradation!r} must be a ratio >= 1 (e.g. 1.3)")
    h = np.array(values, dtype=float, copy=True)
    a = (gradation - 1.0) * spacing
    d = np.sqrt(2.0) * a
    ramp = a * np.arange(h.shape[1])
    nx = h.shape[0]
    h[0] = _row_sweep(h[0], ramp)
    for rows in (range(1, nx), range(nx - 2, -1, -1)):
        for i in rows:
            prev = h[i - 1] if rows.step == 1 else h[i + 1]
            r = np.minimum(h[i], prev + a)
            r[1:] = np.minimum(r[1:], prev[:-1] + d)
            r[:-1] = np.minimum(r[:-1], prev[1:] + d)
            h[i] = _row_sweep(r, ramp)
    return h


class BackgroundGrid:
    """Square background grid holding the target element size.

    Parameters
    ----------
    origin : (2,) coordinates of node (0, 0) [m]
    spacing : grid spacing [m], > 0
    values : (nx, ny) target sizes at the nodes [m], positive and finite;
        ``values[i, j]`` is at ``origin + spacing * (i, j)``
    gradation : optional ratio >= 1; when given the values are limited as
        described in the module docstring (default: stored as given).

    Notes
    -----
    ``size_at`` interpolates bilinearly and clamps points outside the grid to
    its border, so the grid should cover the domain's bounding box (the
    constructors below do).
    """

    def __init__(self, origin, spacing, values, *, gradation=None):
        origin = np.asarray(origin, dtype=float).reshape(-1)
        if origin.shape != (2,) or not np.all(np.isfinite(origin)):
            raise MeshingError(f"origin must be a finite (2,) point [m], got {origin!r}")
        spacing = float(spacing)
        if not (np.isfinite(spacing) and spacing > 0):
            raise MeshingError(f"spacing = {spacing!r} must be positive and finite [m]")
        values = np.array(values, dtype=float)
        if values.ndim != 2 or min(values.shape) < 2:
            raise MeshingError(f"values must be an (nx, ny) array with nx, ny >= 2, got shape {values.shape}")
        bad = ~(np.isfinite(values) & (values > 0))
        if bad.any():
            i, j = np.argwhere(bad)[0]
            raise MeshingError(
                f"target size values[{i}, {j}] = {values[i, j]!r} at "
                f"({origin[0] + i * spacing:g}, {origin[1] + j * spacing:g}) must be positive and finite"
            )
        if gradation is not None:
            values = limit_gradation(values, spacing, gradation)
        self.origin = origin
        self.spacing = spacing
        self.values = values
        self.gradation = gradation

    # ------------------------------------------------------------------ constructors
    @staticmethod
    def _layout(bbox, spacing):
        x0, y0, x1, y1 = bbox
        if spacing is None:
            spacing = max(x1 - x0, y1 - y0) / _DEFAULT_CELLS
        spacing = float(spacing)
        if not (np.isfinite(spacing) and spacing > 0):
            raise MeshingError(f"spacing = {spacing!r} must be positive and finite [m]")
        nx = int(np.ceil((x1 - x0) / spacing - 1e-9)) + 1
        ny = int(np.ceil((y1 - y0) / spacing - 1e-9)) + 1
        return np.array([x0, y0]), spacing, max(nx, 2), max(ny, 2)

    @classmethod
    def uniform(cls, h, region, *, spacing=None):
        """Constant size ``h`` [m] on a grid covering ``region`` (a Domain or bbox)."""
        _check_bounds(h, None)
        bbox = _bbox_of(region)
        if spacing is None:
            spacing = max(bbox[2] - bbox[0], bbox[3] - bbox[1])
        origin, spacing, nx, ny = cls._layout(bbox, spacing)
        return cls(origin, spacing, np.full((nx, ny), float(h)))

    @classmethod
    def from_function(cls, func, region, *, spacing=None, gradation=GRADATION, h_lower=None, h_upper=None):
        """Sample a vectorised ``func(x, y) -> h`` [m] at the grid nodes.

        Parameters
        ----------
        func : callable taking two (M,) coordinate arrays [m], returning (M,) sizes [m]
        region : Domain or (xmin, ymin, xmax, ymax) [m] to cover
        spacing : grid spacing [m] (default: longest bbox side / 200)
        gradation : ratio >= 1 or None (no limiting)
        h_lower, h_upper : optional clamp of the sizes [m] (Eq. 29)
        """
        _check_bounds(h_lower, h_upper)
        origin, spacing, nx, ny = cls._layout(_bbox_of(region), spacing)
        x = origin[0] + spacing * np.arange(nx)
        y = origin[1] + spacing * np.arange(ny)
        gx, gy = np.meshgrid(x, y, indexing="ij")
        values = np.broadcast_to(np.asarray(func(gx.ravel(), gy.ravel()), dtype=float), (nx * ny,))
        values = _clamp(values.reshape(nx, ny), h_lower, h_upper)
        return cls(origin, spacing, values, gradation=gradation)

    @classmethod
    def from_samples(cls, points, sizes, region, *, spacing=None, gradation=GRADATION, h_lower=None, h_upper=None):
        """Grid from scattered size samples, e.g. per-triangle h_target of an old mesh.

        Each sample goes to its nearest grid node, which keeps the minimum of
        its samples; nodes without a sample take the value of the nearest
        node that has one; then clamping to [h_lower, h_upper] and gradation.

        Parameters
        ----------
        points : (M, 2) sample locations [m] (e.g. old triangle centroids)
        sizes : (M,) target sizes [m]
        region : Domain or (xmin, ymin, xmax, ymax) [m] to cover
        spacing, gradation, h_lower, h_upper : as in :meth:`from_function`
        """
        from scipy.ndimage import distance_transform_edt

        _check_bounds(h_lower, h_upper)
        points = np.asarray(points, dtype=float)
        sizes = np.asarray(sizes, dtype=float).reshape(-1)
        if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
            raise MeshingError(f"points must be a non-empty (M, 2) array, got shape {points.shape}")
        if len(sizes) != len(points):
            raise MeshingError(f"len(points) = {len(points)}, but len(sizes) = {len(sizes)}")
        bad = ~(np.isfinite(sizes) & (sizes > 0)) | ~np.isfinite(points).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise MeshingError(f"sample {k}: size {sizes[k]!r} at {points[k]} must be positive and finite")
        origin, spacing, nx, ny = cls._layout(_bbox_of(region), spacing)
        ij = np.rint((points - origin) / spacing).astype(np.int64)
        ij[:, 0] = np.clip(ij[:, 0], 0, nx - 1)
        ij[:, 1] = np.clip(ij[:, 1], 0, ny - 1)
        values = np.full((nx, ny), np.inf)
        np.minimum.at(values, (ij[:, 0], ij[:, 1]), sizes)
        empty = np.isinf(values)
        if empty.any():
            _, (ii, jj) = distance_transform_edt(empty, return_distances=True, return_indices=True)
            values = values[ii, jj]
        values = _clamp(values, h_lower, h_upper)
        return cls(origin, spacing, values, gradation=gradation)

    # ------------------------------------------------------------------ queries
    @property
    def shape(self):
        """(nx, ny) number of grid nodes."""
        return self.values.shape

    @property
    def bbox(self):
        """(xmin, ymin, xmax, ymax) covered by the grid [m]."""
        nx, ny = self.values.shape
        return np.array([*self.origin, self.origin[0] + (nx - 1) * self.spacing,
                         self.origin[1] + (ny - 1) * self.spacing])

    @property
    def h_min(self):
        """Smallest stored size [m]."""
        return float(self.values.min())

    @property
    def h_max(self):
        """Largest stored size [m]."""
        return float(self.values.max())

    def size_at(self, points):
        """Bilinear target size at ``points``.

        Parameters
        ----------
        points : (M, 2) coordinates [m]; points outside the grid are clamped to it

        Returns
        -------
        (M,) target sizes [m]
        """
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        nx, ny = self.values.shape
        u = np.clip((p[:, 0] - self.origin[0]) / self.spacing, 0.0, nx - 1.0)
        v = np.clip((p[:, 1] - self.origin[1]) / self.spacing, 0.0, ny - 1.0)
        i = np.minimum(u.astype(np.int64), nx - 2)
        j = np.minimum(v.astype(np.int64), ny - 2)
        fu = u - i
        fv = v - j
        f = self.values
        return ((1 - fu) * ((1 - fv) * f[i, j] + fv * f[i, j + 1])
                + fu * ((1 - fv) * f[i + 1, j] + fv * f[i + 1, j + 1]))

    def __repr__(self):
        nx, ny = self.values.shape
        return (f"BackgroundGrid(origin={tuple(self.origin)}, spacing={self.spacing:g}, shape=({nx}, {ny}), "
                f"h in [{self.h_min:g}, {self.h_max:g}])")
