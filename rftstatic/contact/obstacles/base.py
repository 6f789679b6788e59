"""The :class:`Obstacle` interface, the declaration of its scene keys (:class:`SceneKey`) and shared helpers.

Every obstacle answers, for a batch of points ``x (N, 3) [m]``:

* ``signed_distance(x) -> (phi (N,) [m], normal (N, 3) [-])`` with ``phi > 0`` outside, ``phi < 0``
  inside and ``normal = grad phi`` (unit, outward);
* ``normal_gradient(x) -> (N, 3, 3) [1/m]``, the Hessian of ``phi`` (``d normal / dx``), which makes the
  penalty tangent exact (:mod:`rftstatic.contact`);
* ``project(x)``: penetrated points moved to their closest surface point ``x - phi * normal``, others
  unchanged (the projection onto the admissible set ``phi >= 0``).

A concrete type also declares, as class attributes, its scene ``type_name`` (e.g. ``"sphere"``) and its
``scene_keys``: scene key -> :class:`SceneKey` (the constructor argument it feeds, whether it is
required, whether it is a length that :func:`~rftstatic.contact.obstacles.from_spec` scales, the value
types and help text the scene schema checks).

The pedestals are boxes / cylinders whose edges are rounded by a small radius ``r`` so that the contact
normal is continuous. Their signed distance is the exact one of a rounded box (:func:`_rounded_box`):
with ``q = |p| - (b - r)`` per axis (``p`` relative to the centre, ``b`` the half sizes),

    phi = |max(q, 0)| + min(max_i q_i, 0) - r,

i.e. the distance to the box shrunk by ``r``, minus ``r``. The circular pedestal uses the same formula in
the two coordinates ``(rho, z)``, ``rho`` the distance from its axis.

Where the signed distance is not twice differentiable (the sphere's centre, the pedestal axis, the medial
surfaces inside a box where two faces are equally near, the boundaries between the face and edge regions
outside) the methods return a one-sided value: the gradient of the face picked first by ``argmax`` and
the Hessian of the region the point is assigned to. These sets have zero measure and lie deep inside the
obstacle (medial surfaces) or carry only a jump in curvature (region boundaries outside).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

__all__ = ["NUMBER", "NUMBERS", "Obstacle", "SceneKey", "SharpFeatures", "type_name_of"]

NUMBER = (int, float)  # scene value types of a number
NUMBERS = (list,)      # ... of a list of numbers


@dataclass(frozen=True)
class SceneKey:
    """One key of an obstacle's scene table.

    Attributes
    ----------
    arg : constructor argument the value is passed as
    required : the key must be given
    length : the value is a length (or a list of lengths) in scene units, multiplied by the length
        scale [m / scene unit] before it reaches the constructor; else passed unchanged
    kinds : Python types the scene schema accepts for the value (:data:`NUMBER`, :data:`NUMBERS`, ...)
    help : what the key means, for the schema
    default : passed as ``arg`` [m] when the key is absent; ``None``: the constructor's own default
    """

    arg: str
    required: bool = False
    length: bool = True
    kinds: tuple[type, ...] = NUMBER
    help: str = ""
    default: Any = None


def _as_points(x: Any) -> np.ndarray:
    """Return ``x`` as a float ``(N, 3)`` array [m] or raise a ``ValueError`` naming its shape."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"x must have shape (N, 3), got shape {arr.shape}")
    return arr


def _finite(name: str, value: Any, shape: tuple[int, ...] = ()) -> np.ndarray | float:
    """Return ``value`` as a finite float (array of ``shape``) or raise naming ``name``."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number{'' if not shape else ' array'}, got {value!r}") from None
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {value!r} with shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return float(arr) if shape == () else arr.copy()


def _positive(name: str, value: Any, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float > 0 (>= 0 with ``allow_zero``) or raise naming ``name``."""
    v = _finite(name, value)
    if v < 0 or (v == 0 and not allow_zero):
        raise ValueError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return v


def _rounded_box(q: np.ndarray, r: float, hessian: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Signed distance of a rounded box in terms of the shifted coordinates ``q``.

    Parameters
    ----------
    q : (N, d) ``|p| - (b - r)`` per axis [m]
    r : edge radius [m]
    hessian : also return ``G`` (else ``None``: the explicit loop needs only ``phi`` and ``g``)

    Returns
    -------
    phi : (N,) signed distance [m]
    g : (N, d) derivative of ``phi`` with respect to ``q`` (unit vector)
    G : (N, d, d) second derivative of ``phi`` with respect to ``q`` [1/m], or ``None``

    Notes
    -----
    Outside the inner box (some ``q_i > 0``) ``phi = |q+| - r`` with ``q+ = max(q, 0)``, so
    ``g = q+ / |q+|`` and ``G = (D - g g^T) / |q+|`` with ``D = diag(q > 0)``. Inside it
    ``phi = max_i q_i - r``: ``g`` is the unit vector of the (first) largest component and ``G = 0``.
    """
    n, d = q.shape
    qp = np.maximum(q, 0.0)
    length = np.linalg.norm(qp, axis=1)
    outside = length > 0.0
    inv = 1.0 / np.where(outside, length, 1.0)
    k = np.argmax(q, axis=1)
    qmax = q[np.arange(n), k]

    phi = np.where(outside, length, np.minimum(qmax, 0.0)) - r
    g = qp * inv[:, None]
    g_in = np.zeros((n, d))
    g_in[np.arange(n), k] = 1.0
    g = np.where(outside[:, None], g, g_in)
    if not hessian:
        return phi, g, None

    pos = (q > 0.0).astype(float)
    G = (np.einsum("ni,ij->nij", pos, np.eye(d)) - np.einsum("ni,nj->nij", g, g)) * inv[:, None, None]
    G *= outside[:, None, None]
    return phi, g, G


def _check_height(height, edge_radius: float, what: str) -> float:
    """Validate a pedestal height [m] (``None`` or ``inf`` = infinitely tall); ``edge_radius`` [m]."""
    if height is None:
        return np.inf
    try:
        h = float(height)
    except (TypeError, ValueError):
        raise ValueError(f"height must be a number or None, got {height!r}") from None
    if not h > 0:
        raise ValueError(f"height must be > 0 (or None for an infinitely tall {what}), got {height!r}")
    if h < 2 * edge_radius:
        raise ValueError(
            f"height = {height!r} is smaller than 2 * edge_radius = {2 * edge_radius!r}; the {what} "
            "needs room for its rounded top and bottom edges"
        )
    return h


def _vertical_q(z: np.ndarray, top_z: float, height: float, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Shifted vertical coordinate ``q_z`` (N,) [m] of a pedestal and its derivative ``dq_z/dz`` (N,) (+-1).

    ``z`` (N,) [m]; ``top_z``, ``height`` (``inf``: infinitely tall) and the edge radius ``r`` [m].
    """
    if np.isfinite(height):
        dz = z - (top_z - 0.5 * height)
        sign = np.where(dz >= 0.0, 1.0, -1.0)
        return np.abs(dz) - (0.5 * height - r), sign
    return z - (top_z - r), np.ones_like(z)


@dataclass(frozen=True)
class SharpFeatures:
    """An obstacle's sharp features (:meth:`Obstacle.sharp_features`, :mod:`rftstatic.contact.features`).

    Attributes
    ----------
    points : (n, 3) [m]
    edges : (f, 2) sharp edges, into ``points``
    corners : (c,) corners, into ``points``
    edge_normals : (f, 3) outward unit normal of each edge (its faces' normals summed)
    corner_normals : (c, 3) outward unit normal of each corner (angle-weighted pseudo-normal)
    """

    points: np.ndarray
    edges: np.ndarray
    corners: np.ndarray
    edge_normals: np.ndarray
    corner_normals: np.ndarray


def type_name_of(obstacle: Obstacle) -> str:
    """The scene type name declared by the obstacle's own class (not inherited), else its class name."""
    return vars(type(obstacle)).get("type_name") or type(obstacle).__name__


class Obstacle(abc.ABC):
    """Rigid obstacle with an exact signed distance; all lengths in metres.

    Subclasses implement :meth:`signed_distance`, :meth:`normal_gradient`, :meth:`bounding_box` and
    :meth:`params`; contact code uses only this interface and never the concrete type. A type that
    scenes can name sets ``type_name`` and ``scene_keys`` and is registered with
    :func:`rftstatic.contact.obstacles.register`.
    """

    type_name: ClassVar[str] = ""                  # scene name, e.g. "round-pedestal"
    scene_keys: ClassVar[dict[str, SceneKey]] = {}  # scene key -> SceneKey

    @abc.abstractmethod
    def signed_distance(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance and outward unit normal.

        Parameters
        ----------
        x : (N, 3) points [m]

        Returns
        -------
        phi : (N,) signed distance, > 0 outside, < 0 inside [m]
        normal : (N, 3) ``grad phi``, unit outward normal of the nearest surface point [-]
        """

    @abc.abstractmethod
    def normal_gradient(self, x: np.ndarray) -> np.ndarray:
        """Hessian of the signed distance, ``d normal / dx``.

        Parameters
        ----------
        x : (N, 3) points [m]

        Returns
        -------
        (N, 3, 3) symmetric ``H[n, i, j] = d^2 phi / dx_i dx_j`` [1/m]; one-sided where ``phi`` is not
        twice differentiable (see the module notes).
        """

    @abc.abstractmethod
    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds ``(lo (3,), hi (3,))`` of the solid [m]; unbounded sides are ``inf``."""

    @abc.abstractmethod
    def params(self) -> dict[str, Any]:
        """Defining parameters in metres, keyed as in a scene table (without ``type``)."""

    def point_kernel(self) -> tuple[int, tuple[float, ...]] | None:
        """The obstacle as a compiled per-point distance: ``(kind, params)`` of
        :func:`rftstatic.contact.obstacles.pedestal_kernels.distance_one` (lengths [m]), which computes exactly what
        :meth:`signed_distance` does; None: no such kernel (the penalty contact's explicit force then calls
        :meth:`signed_distance`). Read only from the class that defines it (``vars(type(obstacle))``): a subclass
        that changes the distance does not inherit its parent's kernel."""
        return None

    psd_tangent: ClassVar[bool] = False
    """The curvature of ``phi`` is unbounded (sharp edges and corners, a triangle surface): the penalty
    contact projects each node's tangent block onto the positive semi-definite matrices
    (:class:`rftstatic.contact.penalty.PenaltyContact`) instead of using ``normal_gradient`` as it is."""

    def surface(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The triangles bounding the solid, ``(V (n, 3) [m], T (t, 3))``, for an independent crossing check
        of the sheet against them; None for an analytic obstacle."""
        return None

    def segment_crossings(self, x0: np.ndarray, x1: np.ndarray):
        """Continuous collision detection of a step: the points moved along straight segments ``x0 -> x1``
        (``(n, 3)`` [m]) that passed through a thin part of the obstacle, where a projection of the end point
        would put them on the wrong side. None when nothing can be stepped through (an analytic solid: a node
        inside it is projected back out the way it came); else ``(hit (n,) bool, stop (n, 3) [m], normal (n, 3))``,
        where each hit point stops and the outward normal there (towards its start)."""
        return None

    def sharp_features(self) -> SharpFeatures | None:
        """Sharp edges and corners that must not cut the sheet between its nodes (:class:`SharpFeatures`);
        None: the obstacle has none (its normal is continuous, e.g. the rounded pedestals), the node penalty
        is all its contact needs."""
        return None

    def footprint(self) -> tuple[float | None, np.ndarray]:
        """Area [m^2] and centre ``(2,)`` [m] of the support in top view (the "disc" of the drape
        coefficient); area ``None`` for an unbounded obstacle (a floor)."""
        return None, np.zeros(2)

    def plan_outline(self, n: int = 128) -> tuple[np.ndarray, float] | None:
        """The solid's outline seen from above, ``(n, 2)`` [m], and the height [m] where it is that wide,
        for drawing it; None when unbounded (a floor).

        Found from the signed distance alone (any obstacle type): along ``n`` rays from the footprint's
        centre, the farthest point whose vertical line enters the solid (phi < 0 at one of 33 heights
        over its top part), by bisection to 1e-9 of the box size; the height is the median over the rays
        of the highest height of least phi there (the top of a vertical side). Exact for solids that are
        star-shaped about that centre in plan (every type here); a type may give its own.
        """
        lo, hi = (np.asarray(b, float) for b in self.bounding_box())
        if not (np.isfinite(lo[:2]).all() and np.isfinite(hi[:2]).all() and np.isfinite(hi[2])):
            return None
        _, centre = self.footprint()
        centre = np.asarray(centre, float)[:2]
        size = float(np.max(hi[:2] - lo[:2]))
        z = np.linspace(max(lo[2], hi[2] - size), hi[2], 33)
        theta = 2.0 * np.pi * np.arange(n) / n
        d = np.column_stack([np.cos(theta), np.sin(theta)])

        def columns(radius):  # (n, 2) points at ``radius`` along the rays, (n, 33) phi up their columns
            xy = centre + radius[:, None] * d
            pts = np.concatenate([np.repeat(xy, len(z), axis=0), np.tile(z, n)[:, None]], axis=1)
            return xy, self.signed_distance(pts)[0].reshape(n, len(z))

        inner, outer = np.zeros(n), np.full(n, float(np.hypot(*(hi[:2] - lo[:2]))))
        while np.max(outer - inner) > 1e-9 * size:
            mid = 0.5 * (inner + outer)
            inside = columns(mid)[1].min(axis=1) < 0.0
            inner, outer = np.where(inside, mid, inner), np.where(inside, outer, mid)
        xy, phi = columns(inner)
        widest = phi <= phi.min(axis=1, keepdims=True) + 1e-6 * size  # a vertical side: all of it
        height = float(np.median(np.max(np.where(widest, z[None, :], -np.inf), axis=1)))  # its top
        return xy, height

    def closest_point(self, x: np.ndarray) -> np.ndarray:
        """Closest surface point ``x - phi * normal`` of every point.

        Parameters
        ----------
        x : (N, 3) points [m]

        Returns
        -------
        (N, 3) points on the surface [m] (exact for exact signed distances, away from the medial set).
        """
        x = _as_points(x)
        phi, normal = self.signed_distance(x)
        return x - phi[:, None] * normal

    def project(self, x: np.ndarray) -> np.ndarray:
        """Project onto the admissible set ``phi >= 0``.

        Parameters
        ----------
        x : (N, 3) points [m]

        Returns
        -------
        (N, 3) penetrated points (``phi < 0``) moved to their closest surface point, others unchanged [m].
        """
        x = _as_points(x)
        phi, normal = self.signed_distance(x)
        return x - np.minimum(phi, 0.0)[:, None] * normal

    def as_dict(self) -> dict[str, Any]:
        """Scene-table form in metres, ``from_spec(obstacle.as_dict(), 1.0)`` rebuilds the obstacle."""
        return {"type": type_name_of(self), **self.params()}

    def describe(self) -> str:
        """One-line human summary, lengths in metres."""
        parts = []
        for key, value in self.params().items():
            if value is None:
                continue
            if np.ndim(value):
                value = "[" + ", ".join(f"{v:.6g}" for v in value) + "]"
            else:
                value = f"{value:.6g}"
            parts.append(f"{key}={value}")
        return f"{type_name_of(self)}({', '.join(parts)}) [m]"

    def __repr__(self) -> str:
        return self.describe()
