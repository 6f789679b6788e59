"""The round pedestal, a vertical cylinder with a rounded rim (Sze & Zhou 2016, §4.4, §6.2: Ø20 cm)
(scene type ``round-pedestal``)."""

from __future__ import annotations

import math
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

__all__ = ["RoundPedestal"]


@register
class RoundPedestal(Obstacle):
    """Vertical circular cylinder (pedestal) whose top (and bottom) rim is rounded by ``edge_radius``.

    Parameters
    ----------
    centre_xy : (2,) axis position in the plane [m]
    radius : cylinder radius, > 0 [m]
    top_z : height of the top face [m]
    edge_radius : radius of the rounded rim, ``0 <= edge_radius <= radius`` [m]
    height : height below the top face [m]; ``None`` (default) makes it infinitely tall

    Notes
    -----
    The 2D rounded-box distance in ``q = (rho - (R - r), q_z)``, ``rho = |x_xy - centre_xy|``. With
    ``e = (x_xy - centre_xy) / rho`` and ``g = dphi/dq``, ``G = d^2phi/dq^2``:
    ``normal = g_0 e + g_1 s_z e_z`` and ``H = J^T G J + g_0 (P_xy - e e^T) / rho`` where the rows of
    ``J`` are ``e`` and ``s_z e_z``. On the axis (``rho = 0``) ``e`` is taken as ``+x`` and the curvature
    term is dropped (one-sided choice; the axis is inside the solid). Calls on many points run the compiled
    twin (:mod:`rftstatic.contact.obstacles.pedestal_kernels`), equal to round-off.
    """

    type_name = "round-pedestal"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "centre": SceneKey("centre_xy", kinds=NUMBERS, help="[x, y] of a pedestal's axis", default=(0.0, 0.0)),
        "radius": SceneKey("radius", required=True, help="radius of a round pedestal"),
        "top": SceneKey("top_z", help="height of a pedestal's top face"),
        "edge_radius": SceneKey("edge_radius", help="rounding of a pedestal's edges"),
        "height": SceneKey("height", help="height of a pedestal below its top (default infinitely tall)"),
    }

    def __init__(self, centre_xy, radius: float, top_z: float = 0.0, edge_radius: float = 0.0,
                 height: float | None = None):
        self.centre_xy = _finite("centre_xy", centre_xy, (2,))
        self.radius = _positive("radius", radius)
        self.top_z = _finite("top_z", top_z)
        self.edge_radius = _positive("edge_radius", edge_radius, allow_zero=True)
        if self.edge_radius > self.radius:
            raise ValueError(
                f"edge_radius = {edge_radius!r} is larger than radius = {radius!r}; use edge_radius <= radius"
            )
        self.height = _check_height(height, self.edge_radius, "round pedestal")

    def _parts(self, x, hessian=True):
        x = _as_points(x)
        r = self.edge_radius
        p = x[:, :2] - self.centre_xy
        rho = np.linalg.norm(p, axis=1)
        on_axis = rho == 0.0
        e = np.zeros_like(x)
        e[:, :2] = p / np.where(on_axis, 1.0, rho)[:, None]
        e[on_axis, 0] = 1.0
        qz, sz = _vertical_q(x[:, 2], self.top_z, self.height, r)
        q = np.column_stack([rho - (self.radius - r), qz])
        J = np.zeros((x.shape[0], 2, 3))
        J[:, 0, :] = e
        J[:, 1, 2] = sz
        phi, g, G = _rounded_box(q, r, hessian)
        return phi, g, G, J, e, rho, on_axis

    def point_kernel(self):
        cx, cy = self.centre_xy
        return pedestal_kernels.ROUND, (float(cx), float(cy), self.radius, self.top_z, float(self.height),
                                        self.edge_radius)

    def _compiled(self, x, hessian):
        from rftstatic.contact.obstacles._pedestal_numba import round_all

        return pedestal_kernels.run(round_all, x, self.point_kernel()[1], hessian)

    def signed_distance(self, x):
        x = _as_points(x)
        if pedestal_kernels.compiled_for(len(x)):
            return self._compiled(x, False)[:2]
        phi, g, _, J, *_ = self._parts(x, hessian=False)
        return phi, np.einsum("na,nai->ni", g, J)

    def normal_gradient(self, x):
        x = _as_points(x)
        if pedestal_kernels.compiled_for(len(x)):
            return self._compiled(x, True)[2]
        _, g, G, J, e, rho, on_axis = self._parts(x)
        H = np.einsum("nai,nab,nbj->nij", J, G, J)
        pxy = np.diag([1.0, 1.0, 0.0])
        # d e / d x = (P_xy - e e^T) / rho: the wall's curvature around the axis, dropped on the axis.
        coef = np.where(on_axis, 0.0, g[:, 0] / np.where(on_axis, 1.0, rho))
        return H + coef[:, None, None] * (pxy - np.einsum("ni,nj->nij", e, e))

    def bounding_box(self):
        lo = np.array([*(self.centre_xy - self.radius), self.top_z - self.height])
        hi = np.array([*(self.centre_xy + self.radius), self.top_z])
        return lo, hi

    def params(self):
        return {
            "centre": self.centre_xy.tolist(),
            "radius": self.radius,
            "top": self.top_z,
            "edge_radius": self.edge_radius,
            "height": None if np.isinf(self.height) else self.height,
        }

    def footprint(self):
        return math.pi * float(self.radius) * float(self.radius), self.centre_xy.copy()  # inf for a huge one
