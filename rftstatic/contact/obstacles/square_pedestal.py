"""The square (or rectangular) pedestal with rounded edges (Sze & Zhou 2016, §4.2-4.3: 10-40 cm wide)
(scene type ``square-pedestal``)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from rftstatic.contact.obstacles.base import (
    NUMBERS,
    Obstacle,
    SceneKey,
    _as_points,
    _check_height,
    _finite,
    _positive,
    _rounded_box,
    _vertical_q,
)
from rftstatic.contact.obstacles import pedestal_kernels
from rftstatic.contact.obstacles.registry import register

__all__ = ["SquarePedestal"]


@register
class SquarePedestal(Obstacle):
    """Axis-aligned rectangular pedestal (box) whose edges are rounded by ``edge_radius``.

    Parameters
    ----------
    centre_xy : (2,) centre of the top face in the plane [m]
    half_width : half side [m], a number (square) or ``(hx, hy)`` (rectangle); give this or ``size``
    top_z : height of the top face [m]
    edge_radius : radius of the rounded edges, ``0 <= edge_radius <= min(hx, hy)`` [m]
    height : height of the box below its top face [m]; ``None`` (default) makes it infinitely tall
    size : full side ``2 * half_width`` [m], a number or ``(lx, ly)``; alternative to ``half_width``

    Notes
    -----
    ``phi`` is the rounded-box distance (:mod:`rftstatic.contact.obstacles.base`) with
    ``q_i = |p_i| - (b_i - r)``; its gradient and Hessian follow by the chain rule through
    ``dq_i/dx_i = sign(p_i)``. Infinitely tall by default: only its top face and rounded top edge are
    ever met by a sheet that starts flat above it. Calls on many points run the compiled twin
    (:mod:`rftstatic.contact.obstacles.pedestal_kernels`), equal to round-off.
    """

    type_name = "square-pedestal"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "centre": SceneKey("centre_xy", kinds=NUMBERS, help="[x, y] of a pedestal's axis", default=(0.0, 0.0)),
        "half_width": SceneKey("half_width", help="half side of a square pedestal"),
        "size": SceneKey("size", kinds=NUMBERS, help="sides [lx, ly] of a square pedestal"),
        "top": SceneKey("top_z", help="height of a pedestal's top face"),
        "edge_radius": SceneKey("edge_radius", help="rounding of a pedestal's edges"),
        "height": SceneKey("height", help="height of a pedestal below its top (default infinitely tall)"),
    }

    def __init__(self, centre_xy, half_width=None, top_z: float = 0.0, edge_radius: float = 0.0,
                 height: float | None = None, *, size=None):
        self.centre_xy = _finite("centre_xy", centre_xy, (2,))
        if (half_width is None) == (size is None):
            raise ValueError(
                f"give exactly one of half_width and size, got half_width={half_width!r}, size={size!r}"
            )
        name, value, scale = ("half_width", half_width, 1.0) if size is None else ("size", size, 0.5)
        shape = () if np.ndim(value) == 0 else (2,)
        half = scale * np.broadcast_to(_finite(name, value, shape), (2,)).astype(float)
        if np.any(half <= 0):
            raise ValueError(f"{name} must be > 0, got {value!r}")
        self.half_width = half
        self.top_z = _finite("top_z", top_z)
        self.edge_radius = _positive("edge_radius", edge_radius, allow_zero=True)
        if self.edge_radius > half.min():
            raise ValueError(
                f"edge_radius = {edge_radius!r} is larger than the half width {float(half.min())!r}; "
                "use edge_radius <= half_width"
            )
        self.height = _check_height(height, self.edge_radius, "square pedestal")

    def _q(self, x):
        x = _as_points(x)
        r = self.edge_radius
        p = x[:, :2] - self.centre_xy
        sign = np.empty_like(x)
        sign[:, :2] = np.where(p >= 0.0, 1.0, -1.0)
        qz, sign[:, 2] = _vertical_q(x[:, 2], self.top_z, self.height, r)
        q = np.column_stack([np.abs(p) - (self.half_width - r), qz])
        return q, sign

    def point_kernel(self):
        (cx, cy), (hx, hy) = self.centre_xy, self.half_width
        params = (float(cx), float(cy), float(hx), float(hy), self.top_z, float(self.height), self.edge_radius)
        return pedestal_kernels.SQUARE, params

    def _compiled(self, x, hessian):
        from rftstatic.contact.obstacles._pedestal_numba import square_all

        return pedestal_kernels.run(square_all, x, self.point_kernel()[1], hessian)

    def signed_distance(self, x):
        x = _as_points(x)
        if pedestal_kernels.compiled_for(len(x)):
            return self._compiled(x, False)[:2]
        q, sign = self._q(x)
        phi, g, _ = _rounded_box(q, self.edge_radius, hessian=False)
        return phi, g * sign

    def normal_gradient(self, x):
        x = _as_points(x)
        if pedestal_kernels.compiled_for(len(x)):
            return self._compiled(x, True)[2]
        q, sign = self._q(x)
        _, _, G = _rounded_box(q, self.edge_radius)
        return G * sign[:, :, None] * sign[:, None, :]

    def bounding_box(self):
        lo = np.array([*(self.centre_xy - self.half_width), self.top_z - self.height])
        hi = np.array([*(self.centre_xy + self.half_width), self.top_z])
        return lo, hi

    def params(self):
        hx, hy = self.half_width
        return {
            "centre": self.centre_xy.tolist(),
            "half_width": float(hx) if hx == hy else [float(hx), float(hy)],
            "top": self.top_z,
            "edge_radius": self.edge_radius,
            "height": None if np.isinf(self.height) else self.height,
        }

    def footprint(self):
        hx, hy = self.half_width
        return 4.0 * float(hx) * float(hy), self.centre_xy.copy()  # Python floats: inf, no warning, for a huge one
