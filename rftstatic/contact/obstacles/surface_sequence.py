"""A body given as a sequence of triangle surfaces of one topology, interpolated in time (scene type
``mesh-sequence``, a deforming obstacle).

Scene keys: ``paths`` (the frame files, each as the ``mesh`` type reads it: any surface meshio reads, relative to
the scene), ``times`` (one per frame [s], strictly increasing), ``units`` of the files (default the scene's length
unit), ``feature_angle`` [deg] (default 100: a deforming surface may have no sharp features, whose edge contact
does not follow it). It acts in ``analysis = "dynamic"`` runs only (by the penalty contact,
:mod:`rftstatic.scenes.motion`); before its first time it is its first frame.

Frames ``V_0, ..., V_(F-1)`` (each ``(n, 3)`` [m], the same triangles) at times ``t_0 < ... < t_(F-1)``: the surface
at time ``t`` has the vertices

    V(t) = (1 - u) V_k + u V_(k+1),      u = (t - t_k) / (t_(k+1) - t_k),    t_k <= t <= t_(k+1)        (S1)

(linear in time between frames; the first frame before ``t_0``, the last after ``t_(F-1)``). At a fixed time the
surface is a :class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle` (its exact signed distance,
normal and Hessian: :meth:`SurfaceSequence.shape_at`), so the penalty contact's force and tangent stay the exact
derivatives of the contact energy at that time. The time the shape is taken at is State (the obstacle poses'
:attr:`~rftstatic.contact.motion.Poses.shape_time`, set at every explicit step by
:class:`~rftstatic.contact.motion.ObstacleMotion` through a :class:`ShapeClock`); the sequence itself is built
once (Model). Between the evaluations of one time the shape is cached; a new time rebuilds its search structures
(a k-d tree of the triangle centroids, about 10 ms for 10,000 triangles).

Friction on a deforming surface acts on the velocity relative to the surface's material point nearest the node,
taken at the nearest vertex: ``(V(t + dt) - V(t)) / dt`` there (:meth:`SurfaceSequence.surface_velocity`; exact
for a rigid translation, first order in the vertex spacing otherwise). The contact candidate list adds the largest
vertex motion since its refresh to the nodes' own (:meth:`SurfaceSequence.drift`), so it stays exact.
"""

from __future__ import annotations

import copy
from typing import ClassVar

import numpy as np

from rftstatic.contact.obstacles.base import NUMBERS, Obstacle, SceneKey
from rftstatic.contact.obstacles.registry import register
from rftstatic.contact.obstacles.surface_geometry import pseudo_normals
from rftstatic.contact.obstacles.surface_mesh import SurfaceObstacle

__all__ = ["SurfaceSequence"]


@register
class SurfaceSequence(Obstacle):
    """Triangle surfaces of one topology at increasing times, linearly interpolated (S1).

    Parameters
    ----------
    paths : F >= 2 surface files of one mesh (the ``mesh`` type's :class:`SurfaceObstacle`)
    times : (F,) frame times [s], strictly increasing
    units, feature_angle, scene_length, base_dir : as :class:`SurfaceObstacle`'s, for every frame
    """

    type_name = "mesh-sequence"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "paths": SceneKey("paths", required=True, length=False, kinds=(list,),
                          help="the frames' surface files, one topology (relative to the scene)"),
        "times": SceneKey("times", required=True, length=False, kinds=NUMBERS,
                          help="time of each frame [s], strictly increasing; linear in time between frames"),
        "units": SceneKey("units", length=False, kinds=(str,), help="length unit of the files (default the scene's)"),
        "feature_angle": SceneKey("feature_angle", length=False, kinds=(int, float),
                                  help="as for type = mesh (default 100: no sharp features)"),
    }
    psd_tangent = True

    def __init__(self, paths, times, units=None, feature_angle=100.0, *, scene_length=1.0, base_dir=None):
        if not isinstance(paths, (list, tuple)) or not all(isinstance(p, str) for p in paths):
            raise ValueError(f"paths must be a list of surface files, got {paths!r}")
        frames = [SurfaceObstacle(p, units=units, feature_angle=feature_angle, scene_length=scene_length,
                                  base_dir=base_dir) for p in paths]
        self._setup(frames, times)
        self.units, self.feature_angle = units, float(feature_angle)

    @classmethod
    def from_frames(cls, frames, times) -> SurfaceSequence:
        """A sequence of built :class:`SurfaceObstacle` frames (same triangles, metres) at ``times (F,)`` [s]."""
        seq = cls.__new__(cls)
        seq._setup(list(frames), times)
        seq.units, seq.feature_angle = "m", float(frames[0].feature_angle)
        return seq

    def _setup(self, frames, times):
        self.frames = list(frames)
        t = np.asarray(times, dtype=float).ravel()
        bad = len(self.frames) < 2 or t.shape != (len(self.frames),) or not np.isfinite(t).all()
        if bad or np.any(np.diff(t) <= 0):
            raise ValueError(f"a surface sequence needs two or more frames at strictly increasing times, one per "
                             f"frame; got {len(self.frames)} frames at times {np.asarray(times).tolist()!r}")
        base = self.frames[0]
        for k, f in enumerate(self.frames[1:], 1):
            if f.V.shape != base.V.shape or not np.array_equal(f.T, base.T):
                raise ValueError(f"frame {k} ({getattr(f, 'path', '?')}) has another topology than frame 0 "
                                 f"({len(f.V)} nodes, {len(f.T)} triangles against {len(base.V)}, {len(base.T)}): "
                                 "give frames of one mesh")
            if f.sharp_features() is not None:
                raise ValueError(f"frame {k} has sharp features, whose edge contact does not follow a deforming "
                                 "surface: give a feature_angle above its edges' angles")
        if base.sharp_features() is not None:
            raise ValueError("frame 0 has sharp features, whose edge contact does not follow a deforming surface: "
                             "give a feature_angle above its edges' angles")
        self.times = t
        self.V = np.stack([f.V for f in self.frames])  # (F, n, 3) [m]
        self._cache = {}

    # --- the shape in time --------------------------------------------------------------------------------------
    def vertices_at(self, t: float) -> np.ndarray:
        """Vertices ``(n, 3)`` [m] at time ``t`` [s] (S1)."""
        times = self.times
        if t <= times[0]:
            return self.V[0]
        if t >= times[-1]:
            return self.V[-1]
        k = int(np.searchsorted(times, t, side="right") - 1)
        u = (t - times[k]) / (times[k + 1] - times[k])
        return (1.0 - u) * self.V[k] + u * self.V[k + 1]

    def shape_at(self, t: float):
        """The surface at time ``t`` [s]: a :class:`~rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle` with
        the vertices (S1) (frame 0's topology, normals and search rebuilt; the last two times kept)."""
        t = float(t)
        hit = self._cache.get(t)
        if hit is not None:
            return hit
        V = self.vertices_at(t)
        base = self.frames[0]
        if np.array_equal(V, base.V):
            shape = base
        else:
            shape = copy.copy(base)
            shape.V = V
            shape.nf, shape.ne, shape.nv = pseudo_normals(V, base.T, base.edge_of, len(base.edges))
            shape._build_search()
            shape._features()
        if len(self._cache) >= 2:
            self._cache.pop(next(iter(self._cache)))
        self._cache[t] = shape
        return shape

    def surface_velocity(self, x: np.ndarray, t: float, dt: float) -> np.ndarray:
        """Velocity ``(P, 3)`` [m/s] of the surface near the points ``x (P, 3)`` [m] over the step ``t -> t + dt``
        [s]: the chord velocity of the nearest vertex of the shape at ``t``."""
        if not dt > 0:
            return np.zeros_like(x)
        _, i = self.shape_at(t)._vtree.query(x)
        return (self.vertices_at(t + dt)[i] - self.vertices_at(t)[i]) / dt

    def drift(self, t0: float, t1: float) -> float:
        """Largest vertex motion [m] between the shapes at ``t0`` and ``t1`` [s] (piecewise linear in time: the
        largest over the frames between and the two ends)."""
        if t0 == t1:
            return 0.0
        lo, hi = min(t0, t1), max(t0, t1)
        inner = self.times[(self.times > lo) & (self.times < hi)]
        pts = [self.vertices_at(lo), *(self.vertices_at(s) for s in inner), self.vertices_at(hi)]
        ref = pts[0]
        return float(max(np.sqrt(np.max(np.einsum("ni,ni->n", p - ref, p - ref))) for p in pts[1:]))

    @property
    def end(self) -> float:
        """Time of the last frame [s]."""
        return float(self.times[-1])

    # --- the Obstacle interface (at the first frame: the body as built) -----------------------------------------
    def signed_distance(self, x):
        return self.frames[0].signed_distance(x)

    def normal_gradient(self, x):
        return self.frames[0].normal_gradient(x)

    def bounding_box(self):
        lo = self.V.min(axis=(0, 1))
        hi = self.V.max(axis=(0, 1))
        return lo, hi

    def params(self):
        return {"paths": [str(f.path) for f in self.frames], "times": self.times.tolist(), "units": "m",
                "feature_angle": self.feature_angle}

    def as_dict(self):
        out = super().as_dict()
        out["units"] = "m"  # the frames' coordinates in metres (each file's own unit applied)
        return out

    def describe(self):
        return (f"mesh-sequence({len(self.frames)} frames of {len(self.frames[0].V)} nodes, {len(self.frames[0].T)} "
                f"triangles, t = {self.times[0]:g}..{self.times[-1]:g} s)")

    def surface(self):
        return self.frames[0].surface()

    def sharp_features(self):
        return None
