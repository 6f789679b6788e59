"""Rigid analytic obstacles described by exact signed distance functions.

Every obstacle answers, for a batch of points ``x (N, 3) [m]``:

* ``signed_distance(x) -> (phi (N,) [m], normal (N, 3) [-])`` with ``phi > 0`` outside, ``phi < 0``
  inside and ``normal = grad phi`` (unit, outward);
* ``normal_gradient(x) -> (N, 3, 3) [1/m]``, the Hessian of ``phi`` (``d normal / dx``), which makes the
  penalty tangent exact (:mod:`rftstatic.contact`);
* ``project(x)``: penetrated points moved to their closest surface point ``x - phi * normal``, others
  unchanged (the projection onto the admissible set ``phi >= 0``).

The obstacles of the paper (Sze & Zhou 2016, §4-6) are a floor plane, a sphere (§4.5, §6.3, Ø10 cm), a
square pedestal (§4.2-4.3, 10-40 cm wide) and a circular pedestal (§4.4, §6.2, Ø20 cm). The pedestals
are boxes / cylinders whose edges are rounded by a small radius ``r`` so that the contact normal is
continuous. Their signed distance is the exact one of a rounded box: with ``q = |p| - (b - r)`` per axis
(``p`` relative to the centre, ``b`` the half sizes),

    phi = |max(q, 0)| + min(max_i q_i, 0) - r,

i.e. the distance to the box shrunk by ``r``, minus ``r``. The circular pedestal uses the same formula in
the two coordinates ``(rho, z)``, ``rho`` the distance from its axis. A pedestal is infinitely tall by
default (``height=None``): only its top face and rounded top edge are ever met by a sheet that starts
flat above it.

Where the signed distance is not twice differentiable (the sphere's centre, the pedestal axis, the medial
surfaces inside a box where two faces are equally near, the boundaries between the face and edge regions
outside) the methods return a one-sided value: the gradient of the face picked first by ``argmax`` and
the Hessian of the region the point is assigned to. These sets have zero measure and lie deep inside the
obstacle (medial surfaces) or carry only a jump in curvature (region boundaries outside).

:func:`from_spec` builds an obstacle from a scene table; it is the only place that knows the type names.
"""

from __future__ import annotations

import abc
from typing import Any, Mapping

import numpy as np

__all__ = [
    "Obstacle",
    "Floor",
    "Sphere",
    "SquarePedestal",
    "RoundPedestal",
    "from_spec",
    "obstacle_types",
]

_TINY = 1e-300


def _as_points(x: Any) -> np.ndarray:
    """Return ``x`` as a float ``(N, 3)`` array or raise a ``ValueError`` naming its shape."""
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


class Obstacle(abc.ABC):
    """Rigid obstacle with an exact signed distance; all lengths in metres.

    Subclasses implement :meth:`signed_distance`, :meth:`normal_gradient`, :meth:`bounding_box` and
    :meth:`params`; contact code uses only this interface and never the concrete type.
    """

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

    def footprint(self) -> tuple[float | None, np.ndarray]:
        """Area [m^2] and centre ``(2,)`` [m] of the support in top view (the "disc" of the drape
        coefficient); area ``None`` for an unbounded obstacle (a floor)."""
        return None, np.zeros(2)

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
        return {"type": _type_name(self), **self.params()}

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
        return f"{_type_name(self)}({', '.join(parts)}) [m]"

    def __repr__(self) -> str:
        return self.describe()


class Floor(Obstacle):
    """Plane ``z = height`` with the solid below it (normal ``+z``).

    Parameters
    ----------
    height : z coordinate of the plane [m]
    """

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

    def bounding_box(self):
        return np.array([-np.inf, -np.inf, -np.inf]), np.array([np.inf, np.inf, self.height])

    def params(self):
        return {"height": self.height}


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

    def bounding_box(self):
        return self.centre - self.radius, self.centre + self.radius

    def params(self):
        return {"centre": self.centre.tolist(), "radius": self.radius}

    def footprint(self):
        return float(np.pi * self.radius**2), self.centre[:2].copy()


def _check_height(height, edge_radius: float, what: str) -> float:
    """Validate a pedestal height [m] (``None`` or ``inf`` = infinitely tall)."""
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
    """Shifted vertical coordinate ``q_z`` of a pedestal and its derivative ``dq_z/dz`` (+-1)."""
    if np.isfinite(height):
        dz = z - (top_z - 0.5 * height)
        sign = np.where(dz >= 0.0, 1.0, -1.0)
        return np.abs(dz) - (0.5 * height - r), sign
    return z - (top_z - r), np.ones_like(z)


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
    ``phi`` is the rounded-box distance of the module notes with ``q_i = |p_i| - (b_i - r)``; its
    gradient and Hessian follow by the chain rule through ``dq_i/dx_i = sign(p_i)``.
    """

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
                f"edge_radius = {edge_radius!r} is larger than the half width {half.min()!r}; "
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

    def signed_distance(self, x):
        q, sign = self._q(x)
        phi, g, _ = _rounded_box(q, self.edge_radius, hessian=False)
        return phi, g * sign

    def normal_gradient(self, x):
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
        return float(4 * hx * hy), self.centre_xy.copy()


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
    term is dropped (one-sided choice; the axis is inside the solid).
    """

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

    def signed_distance(self, x):
        phi, g, _, J, *_ = self._parts(x, hessian=False)
        return phi, np.einsum("na,nai->ni", g, J)

    def normal_gradient(self, x):
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
        return float(np.pi * self.radius**2), self.centre_xy.copy()


# Scene tables: type name -> (class, {scene key: (constructor argument, required)}). Every value is a
# length (or a list of lengths) in scene units.
_SPECS: dict[str, tuple[type, dict[str, tuple[str, bool]]]] = {
    "floor": (Floor, {"height": ("height", False)}),
    "sphere": (Sphere, {"centre": ("centre", True), "radius": ("radius", True)}),
    "square-pedestal": (SquarePedestal, {
        "centre": ("centre_xy", False),
        "half_width": ("half_width", False),
        "size": ("size", False),
        "top": ("top_z", False),
        "edge_radius": ("edge_radius", False),
        "height": ("height", False),
    }),
    "round-pedestal": (RoundPedestal, {
        "centre": ("centre_xy", False),
        "radius": ("radius", True),
        "top": ("top_z", False),
        "edge_radius": ("edge_radius", False),
        "height": ("height", False),
    }),
}
_DEFAULTS = {"centre_xy": (0.0, 0.0)}


def obstacle_types() -> list[str]:
    """Type names accepted by :func:`from_spec`."""
    return sorted(_SPECS)


def _type_name(obstacle: Obstacle) -> str:
    for name, (cls, _) in _SPECS.items():
        if type(obstacle) is cls:
            return name
    return type(obstacle).__name__


def _scale(key: str, value: Any, factor: float, where: str) -> Any:
    if value is None:
        return None
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"{where}: key {key!r} must be a number or a list of numbers, got {value!r}"
        ) from None
    scaled = arr * factor
    return float(scaled) if scaled.ndim == 0 else scaled


def from_spec(spec: Mapping[str, Any], length_scale: float = 1.0) -> Obstacle:
    """Build an obstacle from a scene table.

    Parameters
    ----------
    spec : table such as ``{"type": "round-pedestal", "centre": [0, 0], "radius": 10, "top": 0,
        "edge_radius": 0.5}``; lengths in scene units. Types and keys:

        - ``floor``: ``height`` (default 0);
        - ``sphere``: ``centre`` (3 numbers), ``radius``;
        - ``square-pedestal``: ``centre`` (2 numbers, default origin), ``half_width`` or ``size``
          (number or 2 numbers), ``top`` (default 0), ``edge_radius`` (default 0), ``height``
          (default infinitely tall);
        - ``round-pedestal``: ``centre``, ``radius``, ``top``, ``edge_radius``, ``height`` as above.

        Underscores in the type name are accepted for dashes (``round_pedestal``).
    length_scale : metres per scene length unit [m] (0.01 for ``cm-gf-s``)

    Returns
    -------
    Obstacle with all lengths in metres.

    Raises
    ------
    ValueError
        Naming the type and the offending key (missing, unknown or invalid value).
    """
    if not isinstance(spec, Mapping):
        raise ValueError(f"obstacle spec must be a table, got {spec!r}")
    factor = float(length_scale)
    if not np.isfinite(factor) or factor <= 0:
        raise ValueError(f"length_scale must be a finite number > 0, got {length_scale!r}")
    if "type" not in spec:
        raise ValueError(f"obstacle spec {dict(spec)!r} has no key 'type'; use one of {obstacle_types()}")
    kind = str(spec["type"]).strip().lower().replace("_", "-")
    if kind not in _SPECS:
        raise ValueError(f"obstacle key 'type' = {spec['type']!r} is unknown; use one of {obstacle_types()}")
    cls, keys = _SPECS[kind]
    where = f"obstacle {kind!r}"
    unknown = sorted(set(spec) - set(keys) - {"type"})
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {unknown}; allowed keys are {sorted(keys)}")
    missing = [key for key, (_, required) in keys.items() if required and key not in spec]
    if missing:
        raise ValueError(f"{where}: missing key(s) {missing}")
    kwargs = {}
    for key, (arg, _) in keys.items():
        if key in spec:
            kwargs[arg] = _scale(key, spec[key], factor, where)
        elif arg in _DEFAULTS:
            kwargs[arg] = _DEFAULTS[arg]
    try:
        return cls(**kwargs)
    except ValueError as err:
        message = str(err)
        first = message.split(" ", 1)[0]
        for key, (arg, _) in keys.items():
            if first == arg and key in spec:
                raise ValueError(
                    f"{where}: key {key!r} = {spec[key]!r} is invalid: {message} "
                    f"(in metres, after length_scale = {factor:g})"
                ) from None
        raise ValueError(f"{where}: {message}") from None
