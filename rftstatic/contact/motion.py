"""Rigid motion of obstacles: poses (rotation about an axis through a point, and a translation) and keyframes in time.

A pose maps a point ``y`` of obstacle ``m`` as built (its *body frame*) to the world,

    x = R (y - c) + c + s,        y = R^T (x - c - s) + c,                                        (P1)

with ``R`` a rotation about the axis through the centre ``c`` and ``s`` a translation. The contact law evaluates
the obstacle in its body frame: ``phi(x) = phi_b(y)``, so its normal and Hessian are rotated back,

    grad phi(x) = R n_b(y),        d^2 phi / dx^2 = R H_b(y) R^T                                   (P2)

(:mod:`rftstatic.contact.penalty`). A point fixed on the moving surface has the velocity ``v(x) = A x + b``
(:attr:`Poses.rate_matrix`, :attr:`Poses.rate_offset`); for the explicit solver's step ``t -> t + dt`` it is the
chord of the step, ``A = (R_1 R_0^T - I) / dt`` and ``b = (c + s_1 - R_1 R_0^T (c + s_0)) / dt``, so that a node
carried at that velocity lands exactly where the body took its material point (a sticking node follows the body
without drift), and friction acts on the velocity relative to it (:func:`rftstatic.contact.friction.penalty_impulses`).

Keyframes (:class:`Keyframes`): times ``t_0 < t_1 < ... < t_K``, rotation angles ``theta_k`` about a fixed axis and
translations ``s_k``; between two keys the pose goes by the *smooth step* ``u -> 3 u^2 - 2 u^3`` (default) or
linearly in ``u = (t - t_k) / (t_(k+1) - t_k)``; before the first key the pose is the first key's, after the last
the last key's. The smooth step starts and stops every segment at rest (velocity continuous, 0 at the keys, peak
speed 1.5 x the segment's mean): a garment on a turning body is not struck by a jump of the body's velocity, which
a stick friction cannot pass on in one step (it needs ``mu lambda dt / m`` per step); the linear law is for a
constant speed (a turntable at a steady rate), its velocity jumps at the keys.

The keyframes belong to the scene (frozen with the contact law,
:attr:`rftstatic.contact.penalty.PenaltyContact.motion`); the pose at the current time is State
(:attr:`rftstatic.model.state.State.obstacle_poses`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Poses", "Keyframes", "ObstacleMotion", "ShapeClock", "rotation", "INTERPOLATIONS"]

INTERPOLATIONS = ("smooth", "linear")
"""How the pose goes between two keyframes (module docstring)."""


def rotation(axis, angle):
    """Rotation matrices ``(..., 3, 3)`` by ``angle (...)`` [rad] about the unit ``axis (3,)`` (Rodrigues:
    ``R = I + sin(a) K + (1 - cos(a)) K^2``, ``K`` the cross-product matrix of the axis; right-handed)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    th = np.asarray(angle, dtype=float)[..., None, None]
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


@dataclass(frozen=True)
class ShapeClock:
    """The entry of :class:`ObstacleMotion` for a deforming obstacle
    (:class:`~rftstatic.contact.obstacles.surface_sequence.SurfaceSequence`): its shape follows the run's time;
    ``end`` [s] the time of its last frame."""

    end: float


@dataclass(frozen=True)
class Poses:
    """The rigid poses of the ``M`` obstacles of a contact law at one time (P1) and their surfaces' velocity.

    Attributes
    ----------
    rotation : (M, 3, 3) rotation ``R`` of each obstacle from its built pose [-]
    centre : (M, 3) point ``c`` the rotation turns about [m]
    translation : (M, 3) translation ``s`` [m]
    rate_matrix : (M, 3, 3) ``A`` of the surface velocity ``v(x) = A x + b`` [1/s]
    rate_offset : (M, 3) ``b`` of that velocity [m/s]
    shape_time : (M,) time [s] a deforming obstacle's shape is taken at
        (:class:`rftstatic.contact.obstacles.surface_sequence.SurfaceSequence`), NaN for a rigid one (None: all
        rigid)
    step : the step [s] the surface velocities are the chord of (0: at rest)
    """

    rotation: np.ndarray
    centre: np.ndarray
    translation: np.ndarray
    rate_matrix: np.ndarray
    rate_offset: np.ndarray
    shape_time: np.ndarray | None = None
    step: float = 0.0

    def __post_init__(self):
        m = np.asarray(self.rotation).shape[0] if np.ndim(self.rotation) == 3 else -1
        st = np.full(max(m, 0), np.nan) if self.shape_time is None else np.array(self.shape_time, dtype=float)
        if st.shape != (m,) or np.isinf(st).any():
            raise ValueError(f"Poses.shape_time must be (M,) = ({m},) times or NaN, got {self.shape_time!r}")
        st.setflags(write=False)
        object.__setattr__(self, "shape_time", st)
        object.__setattr__(self, "step", float(self.step))
        for name, shape in (("rotation", (m, 3, 3)), ("centre", (m, 3)), ("translation", (m, 3)),
                            ("rate_matrix", (m, 3, 3)), ("rate_offset", (m, 3))):
            v = np.array(getattr(self, name), dtype=float)
            if v.shape != shape or not np.isfinite(v).all():
                raise ValueError(f"Poses.{name} must be a finite array of shape (M, ...) = {shape}, got shape "
                                 f"{v.shape}")
            v.setflags(write=False)
            object.__setattr__(self, name, v)

    @classmethod
    def translations(cls, offsets) -> Poses:
        """Translation-only poses at rest: ``offsets (M, 3)`` [m] (what a route that lowers a support sets)."""
        s = np.asarray(offsets, dtype=float)
        m = s.shape[0]
        return cls(np.broadcast_to(np.eye(3), (m, 3, 3)), np.zeros((m, 3)), s, np.zeros((m, 3, 3)), np.zeros((m, 3)))

    @property
    def n_obstacles(self) -> int:
        """Number of obstacles ``M``."""
        return self.rotation.shape[0]

    @property
    def rotated(self) -> bool:
        """True if some obstacle is turned (not only translated)."""
        return not np.array_equal(self.rotation, np.broadcast_to(np.eye(3), self.rotation.shape))

    @property
    def at_rest(self) -> bool:
        """True if no obstacle is moved from its built pose and none moves or deforms."""
        return not (self.rotated or self.translation.any() or self.rate_matrix.any() or self.rate_offset.any()
                    or self.deforming)

    @property
    def deforming(self) -> bool:
        """True if some obstacle's shape follows time (:attr:`shape_time`)."""
        return bool(np.isfinite(self.shape_time).any())

    def to_body(self, x: np.ndarray, m: int) -> np.ndarray:
        """Points ``x (P, 3)`` [m] in obstacle ``m``'s body frame, ``R^T (x - c - s) + c`` (P1)."""
        c = self.centre[m]
        return (x - c - self.translation[m]) @ self.rotation[m] + c

    def to_world(self, v: np.ndarray, m: int) -> np.ndarray:
        """Body-frame vectors ``v (P, 3)`` of obstacle ``m`` in the world, ``R v``."""
        return v @ self.rotation[m].T

    def body_frames(self, x: np.ndarray) -> np.ndarray:
        """``(M, P, 3)``: the points ``x (P, 3)`` [m] in every obstacle's body frame."""
        c = self.centre[:, None, :]
        return np.einsum("mpi,mij->mpj", x[None] - c - self.translation[:, None, :], self.rotation) + c

    def velocity(self, x: np.ndarray, m: int) -> np.ndarray:
        """Velocity ``(P, 3)`` [m/s] of obstacle ``m``'s surface (its material point) at the points ``x (P, 3)`` [m]."""
        return x @ self.rate_matrix[m].T + self.rate_offset[m]


@dataclass(frozen=True)
class Keyframes:
    """The rigid motion of one obstacle: keyframe times, angles about a fixed axis through a centre, translations.

    Attributes
    ----------
    times : (K,) keyframe times [s], strictly increasing
    angles : (K,) rotation angle at each key [rad] (right-handed about ``axis``)
    axis : (3,) rotation axis (normalised here), nonzero
    centre : (3,) point of the axis [m]
    translations : (K, 3) translation at each key [m]
    interpolation : ``"smooth"`` or ``"linear"`` (module docstring)
    """

    times: np.ndarray
    angles: np.ndarray
    axis: np.ndarray
    centre: np.ndarray
    translations: np.ndarray
    interpolation: str = "smooth"

    def __post_init__(self):
        t = np.array(self.times, dtype=float).ravel()
        if t.size < 1 or not np.isfinite(t).all():
            raise ValueError(f"times must be one or more finite numbers, got {self.times!r}")
        if np.any(np.diff(t) <= 0):
            k = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise ValueError(f"times must increase strictly: times[{k}] = {t[k]:g} >= times[{k + 1}] = {t[k + 1]:g}")
        ang = np.array(self.angles, dtype=float).ravel()
        if ang.shape != t.shape or not np.isfinite(ang).all():
            raise ValueError(f"angles must be {t.size} finite numbers (one per time), got {len(ang)}: {self.angles!r}")
        axis = np.array(self.axis, dtype=float).ravel()
        if axis.shape != (3,) or not np.isfinite(axis).all() or not np.linalg.norm(axis) > 0:
            raise ValueError(f"axis must be a nonzero vector [x, y, z], got {self.axis!r}")
        centre = np.array(self.centre, dtype=float).ravel()
        if centre.shape != (3,) or not np.isfinite(centre).all():
            raise ValueError(f"centre must be a point [x, y, z], got {self.centre!r}")
        s = np.array(self.translations, dtype=float)
        if s.shape != (t.size, 3) or not np.isfinite(s).all():
            raise ValueError(f"translations must be {t.size} finite vectors [x, y, z] (one per time), got shape "
                             f"{s.shape}")
        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f'interpolation "{self.interpolation}" is unknown; use one of {", ".join(INTERPOLATIONS)}')
        for name, v in (("times", t), ("angles", ang), ("axis", axis / np.linalg.norm(axis)), ("centre", centre),
                        ("translations", s)):
            v.setflags(write=False)
            object.__setattr__(self, name, v)

    def _share(self, t: float) -> tuple[int, float]:
        """Segment ``k`` and the share ``w`` of the way from key ``k`` to key ``k + 1`` at time ``t`` [s]."""
        times = self.times
        if times.size == 1 or t <= times[0]:
            return 0, 0.0
        if t >= times[-1]:
            return times.size - 2, 1.0
        k = int(np.searchsorted(times, t, side="right") - 1)
        u = (t - times[k]) / (times[k + 1] - times[k])
        return k, (3.0 * u * u - 2.0 * u**3) if self.interpolation == "smooth" else u

    def angle_translation(self, t: float) -> tuple[float, np.ndarray]:
        """Angle [rad] and translation ``(3,)`` [m] at time ``t`` [s]."""
        if self.times.size == 1:
            return float(self.angles[0]), self.translations[0].copy()
        k, w = self._share(float(t))
        ang = (1.0 - w) * self.angles[k] + w * self.angles[k + 1]
        return float(ang), (1.0 - w) * self.translations[k] + w * self.translations[k + 1]

    @property
    def end(self) -> float:
        """Time of the last key [s]: the pose holds from then on."""
        return float(self.times[-1])


class ObstacleMotion:
    """The keyframed motions of the ``M`` obstacles of a contact law (None for an obstacle that stays put; a
    :class:`ShapeClock` for a surface sequence, whose shape follows the time).

    Parameters
    ----------
    motions : sequence of ``M`` :class:`Keyframes`, ShapeClock or None
    """

    def __init__(self, motions):
        self.motions = tuple(motions)
        if not all(m is None or isinstance(m, (Keyframes, ShapeClock)) for m in self.motions):
            raise TypeError("ObstacleMotion takes one Keyframes, ShapeClock or None per obstacle")
        self._clock = np.array([not (m is None or isinstance(m, Keyframes)) for m in self.motions], bool)

    @property
    def end(self) -> float:
        """Time [s] from which every obstacle holds its pose and shape."""
        return max((m.end for m in self.motions if m is not None), default=0.0)

    def _pose(self, t):
        m = len(self.motions)
        R = np.broadcast_to(np.eye(3), (m, 3, 3)).copy()
        c = np.zeros((m, 3))
        s = np.zeros((m, 3))
        for i, km in enumerate(self.motions):  # one entry per obstacle (a handful)
            if isinstance(km, Keyframes):
                ang, s[i] = km.angle_translation(t)
                R[i] = rotation(km.axis, ang)
                c[i] = km.centre
        return R, c, s

    def poses(self, t: float, dt: float | None = None) -> Poses:
        """The poses at time ``t`` [s], with the surface velocity of the step to ``t + dt`` [s] (its chord, module
        docstring; ``dt`` None: at rest, a static pose)."""
        R0, c, s0 = self._pose(t)
        m = len(self.motions)
        A, b = np.zeros((m, 3, 3)), np.zeros((m, 3))
        if dt is not None and dt > 0:
            R1, _, s1 = self._pose(t + dt)
            Q = np.einsum("mij,mkj->mik", R1, R0)  # R_1 R_0^T
            A = (Q - np.eye(3)) / dt
            b = (c + s1 - np.einsum("mij,mj->mi", Q, c + s0)) / dt
        shape = np.where(self._clock, float(t), np.nan)
        return Poses(R0, c, s0, A, b, shape, dt if dt is not None and dt > 0 else 0.0)
