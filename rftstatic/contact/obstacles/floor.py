"""The floor: the plane ``z = height`` with the solid below it (scene type ``floor``)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from rftstatic.contact.obstacles import pedestal_kernels
from rftstatic.contact.obstacles.base import Obstacle, SceneKey, _as_points, _finite
from rftstatic.contact.obstacles.registry import register

__all__ = ["Floor"]


@register
class Floor(Obstacle):
    """Plane ``z = height`` with the solid below it (normal ``+z``).

    Parameters
    ----------
    height : z coordinate of the plane [m]
    """

    type_name = "floor"
    scene_keys: ClassVar[dict[str, SceneKey]] = {"height": SceneKey("height", help="height of the floor plane")}

    def __init__(self, height: float = 0.0):
        self.height = _finite("height", height)

    def signed_distance(self, x):
        x = _as_points(x)
        normal = np.zeros_like(x)
        normal[:, 2] = 1.0
        return x[:, 2] - self.height, normal

    def normal_gradient(self, x):
        x = _as_points(x)
        return np.zeros((x.shape[0], 3, 3))

    def point_kernel(self):
        return pedestal_kernels.FLOOR, (self.height,)

    def bounding_box(self):
        return np.array([-np.inf, -np.inf, -np.inf]), np.array([np.inf, np.inf, self.height])

    def params(self):
        return {"height": self.height}
