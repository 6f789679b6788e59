"""The sphere (Sze & Zhou 2016, §4.5, §6.3: Ø10 cm) (scene type ``sphere``)."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from rftstatic.contact.obstacles import pedestal_kernels
from rftstatic.contact.obstacles.base import NUMBERS, Obstacle, SceneKey, _as_points, _finite, _positive
from rftstatic.contact.obstacles.registry import register

__all__ = ["Sphere"]


@register
class Sphere(Obstacle):
    """Solid sphere, ``phi = |x - centre| - radius``.

    Parameters
    ----------
    centre : (3,) centre [m]
    radius : radius, > 0 [m]

    Notes
    -----
    ``normal = d / |d|`` and ``H = (I - n n^T) / |d|`` with ``d = x - centre``. At the centre itself the
    normal is taken as ``+z`` and ``H = 0`` (one-sided choice).
    """

    type_name = "sphere"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "centre": SceneKey("centre", required=True, kinds=NUMBERS, help="[x, y, z] of a sphere"),
        "radius": SceneKey("radius", required=True, help="radius of a sphere"),
    }

    def __init__(self, centre, radius: float):
        self.centre = _finite("centre", centre, (3,))
        self.radius = _positive("radius", radius)

    def _offset(self, x):
        d = _as_points(x) - self.centre
        dist = np.linalg.norm(d, axis=1)
        at_centre = dist == 0.0
        normal = d / np.where(at_centre, 1.0, dist)[:, None]
        normal[at_centre] = (0.0, 0.0, 1.0)
        return dist, normal, at_centre

    def signed_distance(self, x):
        dist, normal, _ = self._offset(x)
        return dist - self.radius, normal

    def normal_gradient(self, x):
        dist, normal, at_centre = self._offset(x)
        H = np.eye(3) - np.einsum("ni,nj->nij", normal, normal)
        return H * np.where(at_centre, 0.0, 1.0 / np.where(at_centre, 1.0, dist))[:, None, None]

    def point_kernel(self):
        return pedestal_kernels.SPHERE, (*(float(c) for c in self.centre), self.radius)

    def bounding_box(self):
        return self.centre - self.radius, self.centre + self.radius

    def params(self):
        return {"centre": self.centre.tolist(), "radius": self.radius}

    def footprint(self):
        return math.pi * float(self.radius) * float(self.radius), self.centre[:2].copy()  # inf for a huge one
