"""Rigid analytic obstacles described by exact signed distance functions.

The obstacles of the paper (Sze & Zhou 2016, §4-6) are a floor plane (:class:`Floor`), a sphere
(:class:`Sphere`, §4.5, §6.3, Ø10 cm), a square pedestal (:class:`SquarePedestal`, §4.2-4.3, 10-40 cm
wide) and a circular pedestal (:class:`RoundPedestal`, §4.4, §6.2, Ø20 cm), the pedestals with rounded
edges so that the contact normal is continuous; and a user's own object given as a triangle surface file
(:class:`SurfaceObstacle`, scene type ``mesh``). The interface every obstacle answers (signed distance
``phi (N,) [m]``, outward unit normal ``(N, 3)``, its gradient ``(N, 3, 3) [1/m]``, closest point,
projection) and the notes on the exact rounded-box distance are in :mod:`.base`.

Layout: :mod:`.base` (the :class:`Obstacle` interface, :class:`SceneKey`, shared helpers), one module per
type, :mod:`.registry` (:func:`register`, :func:`from_spec`, :func:`obstacle_types`, :func:`scene_schema`).

Adding an obstacle type is one class in one module (imported below, or anywhere before the scene is
read)::

    @register
    class Cone(Obstacle):
        type_name = "cone"                                    # the scene's type = "cone"
        scene_keys: ClassVar[dict[str, SceneKey]] = {         # scene key -> constructor argument
            "apex": SceneKey("apex", required=True, kinds=NUMBERS, help="[x, y, z] of the apex"),
            "angle": SceneKey("half_angle", length=False, help="half opening angle [deg]"),
        }
        def __init__(self, apex, half_angle=30.0): ...
        # signed_distance, normal_gradient, bounding_box, params (as the scene keys, in metres)

:func:`from_spec` scales the length keys to metres, the scene schema (:mod:`rftstatic.scenes.schema`)
checks the declared keys, and the contact code uses only the :class:`Obstacle` interface.
"""

from rftstatic.contact.obstacles.base import NUMBER, NUMBERS, Obstacle, SceneKey, SharpFeatures
from rftstatic.contact.obstacles.floor import Floor
from rftstatic.contact.obstacles.registry import (
    from_spec,
    obstacle_class,
    obstacle_types,
    register,
    scene_schema,
    unregister,
)
from rftstatic.contact.obstacles.round_pedestal import RoundPedestal
from rftstatic.contact.obstacles.sphere import Sphere
from rftstatic.contact.obstacles.surface_mesh import SurfaceObstacle
from rftstatic.contact.obstacles.square_pedestal import SquarePedestal
from rftstatic.contact.obstacles.surface_sequence import SurfaceSequence

__all__ = [
    "NUMBER",
    "NUMBERS",
    "Floor",
    "Obstacle",
    "RoundPedestal",
    "SceneKey",
    "SharpFeatures",
    "Sphere",
    "SquarePedestal",
    "SurfaceObstacle",
    "SurfaceSequence",
    "from_spec",
    "obstacle_class",
    "obstacle_types",
    "register",
    "scene_schema",
    "unregister",
]
