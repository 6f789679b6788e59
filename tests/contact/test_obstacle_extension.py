"""The cost of a new obstacle type: one class, declared and registered here, and nothing else edited.

The type is a horizontal rod (an infinite circular cylinder, e.g. the line a sheet is hung over) with a
length key scaled by the scene's unit (``centre``, ``radius``) and one that is not (``angle`` [deg]). It
is registered with the public :func:`rftstatic.contact.obstacles.register`, read from a scene dict by
the scene schema and :func:`rftstatic.scenes.build.build_model`, and its signed distance and normal
gradient are checked by central differences.
"""

from typing import ClassVar

import numpy as np
import pytest

from rftstatic.contact.obstacles import (
    NUMBERS,
    Obstacle,
    SceneKey,
    from_spec,
    obstacle_types,
    register,
    unregister,
)
from rftstatic.errors import SceneError
from rftstatic.scenes.build import build_model
from rftstatic.scenes.schema import scene_from_dict

STEP = 1e-6  # [m], central differences on a rod of radius 1 cm


class Rod(Obstacle):
    """Horizontal rod: the points within ``radius`` of the line through ``centre`` along ``angle``.

    Parameters
    ----------
    centre : (3,) a point of the axis [m]
    radius : rod radius [m]
    angle : direction of the axis in the xy plane, from +x [deg]

    Notes
    -----
    With ``a`` the unit axis and ``d = (x - centre) - ((x - centre) . a) a``: ``phi = |d| - radius``,
    ``normal = d / |d|``, ``H = (I - a a^T - n n^T) / |d|`` (on the axis ``+z`` and 0, one-sided).
    """

    type_name = "rod"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "centre": SceneKey("centre", required=True, kinds=NUMBERS, help="[x, y, z] of a point of a rod's axis"),
        "radius": SceneKey("radius", required=True, help="radius of a rod"),
        "angle": SceneKey("angle", length=False, help="direction of a rod's axis from +x [deg]"),
    }

    def __init__(self, centre, radius, angle=0.0):
        self.centre = np.asarray(centre, float).reshape(3)
        self.radius = float(radius)
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0, got {radius!r}")
        self.angle = float(angle)
        t = np.radians(self.angle)
        self.axis = np.array([np.cos(t), np.sin(t), 0.0])

    def _offset(self, x):
        d = np.asarray(x, float) - self.centre
        d -= (d @ self.axis)[:, None] * self.axis
        rho = np.linalg.norm(d, axis=1)
        on_axis = rho == 0.0
        n = d / np.where(on_axis, 1.0, rho)[:, None]
        n[on_axis] = (0.0, 0.0, 1.0)
        return rho, n, on_axis

    def signed_distance(self, x):
        rho, n, _ = self._offset(x)
        return rho - self.radius, n

    def normal_gradient(self, x):
        rho, n, on_axis = self._offset(x)
        P = np.eye(3) - np.outer(self.axis, self.axis) - np.einsum("ni,nj->nij", n, n)
        return P * np.where(on_axis, 0.0, 1.0 / np.where(on_axis, 1.0, rho))[:, None, None]

    def bounding_box(self):
        lo = np.array([-np.inf, -np.inf, self.centre[2] - self.radius])
        return lo, np.array([np.inf, np.inf, self.centre[2] + self.radius])

    def params(self):
        return {"centre": self.centre.tolist(), "radius": self.radius, "angle": self.angle}


@pytest.fixture(scope="module")
def rod_type():
    register(Rod)
    yield Rod
    unregister(Rod.type_name)
    assert "rod" not in obstacle_types()


def _scene(**rod):
    """A 30 x 30 cm sheet (cm-gf-s) 1 cm above the top of a rod of radius 1 cm."""
    return {
        "units": "cm-gf-s",
        "mesh": {"kind": "rectangle", "size": [30.0, 30.0], "nodes": [9, 9]},
        "material": {"preset": "wool-kang-yu"},
        "obstacles": [{"type": "rod", "centre": [0.0, 2.0, -2.0], "radius": 1.0, "angle": 30.0, **rod}],
    }


def _fd(f, x, step=STEP):
    """Central-difference d f(x)[n, ...] / d x[n, j], shape (N, ..., 3)."""
    cols = []
    for j in range(3):
        e = np.zeros(3)
        e[j] = step
        cols.append((f(x + e) - f(x - e)) / (2 * step))
    return np.stack(cols, axis=-1)


def test_a_new_type_is_built_from_a_scene_and_has_exact_derivatives(rod_type):
    model, extras = build_model(scene_from_dict(_scene()))
    (rod,) = extras["obstacles"]
    assert type(rod) is rod_type and "rod" in obstacle_types()
    # lengths scaled from cm to m, the angle not
    np.testing.assert_allclose(rod.centre, [0.0, 0.02, -0.02])
    assert rod.radius == pytest.approx(0.01) and rod.angle == 30.0
    assert model.contact.obstacles[0] is rod

    # points around the rod (1 to 30 mm from its surface, outside and inside), in metres
    rng = np.random.default_rng(5)
    u = rng.normal(size=(300, 3))
    u -= (u @ rod.axis)[:, None] * rod.axis
    u /= np.linalg.norm(u, axis=1)[:, None]
    x = rod.centre + rng.uniform(-0.1, 0.1, (300, 1)) * rod.axis + rng.uniform(0.002, 0.04, (300, 1)) * u
    phi, n = rod.signed_distance(x)
    assert np.any(phi < 0) and np.any(phi > 0)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(_fd(lambda y: rod.signed_distance(y)[0], x), n, atol=1e-6)
    H = rod.normal_gradient(x)
    np.testing.assert_allclose(H, np.swapaxes(H, 1, 2), atol=1e-12)
    scale = np.maximum(np.abs(H).max(axis=(1, 2)), 1.0)[:, None, None]
    np.testing.assert_allclose(_fd(lambda y: rod.signed_distance(y)[1], x) / scale, H / scale, atol=1e-6)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", H, n), 0.0, atol=1e-9)

    # the penalty contact of the model sees it: the sheet pushed 2 cm down presses on the rod
    U = np.zeros((model.mesh.n_nodes, 3))
    assert model.contact.energy(model.positions(U)) == 0.0
    U[:, 2] = -0.02
    assert model.contact.energy(model.positions(U)) > 0.0


def test_a_new_type_round_trips_and_its_keys_are_checked(rod_type):
    rod = from_spec({"type": "rod", "centre": [1, 2, 3], "radius": 4, "angle": 45}, 0.01)
    again = from_spec(rod.as_dict(), 1.0)
    assert type(again) is rod_type and again.params() == rod.params()
    assert rod.describe().startswith("rod(")
    # the scene schema knows the new keys, and reports the wrong ones
    with pytest.raises(SceneError, match=r"obstacles\.0\.angle: expected int/float"):
        scene_from_dict(_scene(angle="steep"))
    with pytest.raises(SceneError, match=r"obstacles\.0\.radiu.*known keys here: angle, centre"):
        scene_from_dict(_scene(radiu=2.0))
    scene = _scene()
    del scene["obstacles"][0]["radius"]
    with pytest.raises(SceneError, match=r"obstacles\.0.*'rod': missing key\(s\) \['radius'\]"):
        build_model(scene_from_dict(scene))
