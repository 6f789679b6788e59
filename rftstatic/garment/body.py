"""A parametric dress form: a closed torso surface built from body measurements (a mesh obstacle to dress).

The form is a stack of horizontal elliptical sections, z up (heights above the floor), centred on the z axis,
x across the body and y from back to front. Each measured girth is the perimeter of the ellipse at its
height, with a depth / width ratio per level. The measurements follow ISO 8559-1's definitions:

- bust girth at the height of the bust points;
- waist girth at the natural waist;
- hip girth at the greatest buttock prominence;
- neck girth at the neck base.

Above the bust the section widens to the shoulder breadth at the shoulder height and narrows to the neck
girth at the neck base along a quarter ellipse in each semi-axis (a rounded shoulder top: horizontal at the
neck base, vertical at the shoulder points, where it curves with radius C^2 / (A - rho), C the height from the
shoulder to the neck base, A the half-width it narrows by and rho the neck fillet's radius: 2.9 cm on the size-36
form; the monotone cubic there was a ridge of 4.5 mm radius that a dress's flat triangles cut), which ends
horizontal ``rho`` outside the neck and turns up into it along a concave quarter circle of radius ``rho``
(:data:`NECK_FILLET`; the neck's girth is met ``rho`` above the neck base); the neck is a short upright cylinder. The bottom and the top are closed with half
ellipsoids below the bottom section and above the neck top (depth = the end section's half-depth b), so the
form has no sharp rim: in the vertical plane through the major axis the rim curves with radius b^2 / a, the end
section's own smallest radius (a garment hanging past the bottom of the form slides over it; a flat cap's
90 deg rim cut the flat triangles of a skirt draped past it).

Between two levels each semi-axis is interpolated in height by a monotone cubic (PCHIP), so the girths are
met at their heights and no section bulges past its neighbours. An ellipse of half-width ``a`` and
half-depth ``b`` has the perimeter of Ramanujan's second approximation,
``pi (a + b) (1 + 3 h / (10 + sqrt(4 - 3 h)))`` with ``h = ((a - b) / (a + b))^2``; its relative error is
below 1e-8 for ``b / a`` >= 0.4 (6.3e-9 at 0.4, against quadrature). The sampled section is a polygon of ``around`` vertices, whose perimeter
is short by about ``(pi / around)^2 / 6``: 4e-4 at 64.

:meth:`DressForm.surface` gives the triangles, consistently wound with outward normals and closed. They
pass :func:`rftstatic.mesh.surface.check_triangles` (``oriented=True``). :meth:`DressForm.write_obj` writes
a file that a ``type = "mesh"`` obstacle reads. Lengths in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DressForm", "NECK_FILLET", "ellipse_perimeter", "semi_axes"]

NECK_FILLET = 0.25
"""Radius of the concave fillet between the shoulder's top and the neck, in neck lengths [-] (1.5 cm on a 6 cm
neck): without it the horizontal end of the shoulder's quarter ellipse met the upright neck at a right angle, a
crease of the contact surface where its normal jumps, and a neckline resting in it kept a force jump that no
equilibrium balances (Newton and the relaxation stalled on the dress at 1.45 cm)."""


def ellipse_perimeter(a, b):
    """Perimeter [m] of the ellipse with semi-axes ``a``, ``b`` [m] (Ramanujan's second approximation)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    h = ((a - b) / (a + b)) ** 2
    return np.pi * (a + b) * (1.0 + 3.0 * h / (10.0 + np.sqrt(4.0 - 3.0 * h)))


def semi_axes(girth, ratio):
    """``(a, b)`` [m]: the half-width and half-depth ``b = ratio a`` of the ellipse of perimeter ``girth`` [m]."""
    girth, ratio = np.asarray(girth, float), np.asarray(ratio, float)
    a = girth / ellipse_perimeter(1.0, ratio)
    return a, ratio * a


@dataclass(frozen=True, kw_only=True)
class DressForm:
    """A dress form's measurements [m] (module docstring); the depth ratios are depth / width of each section.

    Attributes
    ----------
    bust_girth, waist_girth, hip_girth, neck_girth : girths [m] (ISO 8559-1)
    bust_height, waist_height, hip_height : heights of those girths above the floor [m]
    shoulder_breadth : across the shoulder points [m], at ``shoulder_height`` [m]
    neck_height : height of the neck base [m]; the neck rises ``neck_length`` [m] above it
    bottom_height : where the form ends below the hip [m]
    bust_depth, waist_depth, hip_depth, shoulder_depth, neck_depth : depth / width ratios [-] of the sections
    """

    bust_girth: float
    waist_girth: float
    hip_girth: float
    bust_height: float
    waist_height: float
    hip_height: float
    shoulder_breadth: float
    shoulder_height: float
    neck_girth: float
    neck_height: float
    neck_length: float = 0.08
    bottom_height: float | None = None
    bust_depth: float = 0.78
    waist_depth: float = 0.74
    hip_depth: float = 0.80
    shoulder_depth: float = 0.45
    neck_depth: float = 0.95

    def __post_init__(self):
        for name in ("bust_girth", "waist_girth", "hip_girth", "neck_girth", "shoulder_breadth", "neck_length",
                     "bust_depth", "waist_depth", "hip_depth", "shoulder_depth", "neck_depth"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise ValueError(f"dress form: {name} must be a finite number > 0 [m], got {value!r}")
        for name in ("bust_depth", "waist_depth", "hip_depth", "shoulder_depth", "neck_depth"):
            if not 0.4 <= getattr(self, name) <= 1.0:
                raise ValueError(f"dress form: {name} = {getattr(self, name)!r} is a depth / width ratio; give one "
                                 "in [0.4, 1]")
        z = self.levels()[0]
        names = ["bottom", "hip", "waist", "bust", "shoulder", "neck base", "neck top"]
        bad = [k for k in range(len(z) - 1) if not z[k + 1] > z[k]]
        if bad:
            k = bad[0]
            raise ValueError(f"dress form: the {names[k + 1]} height ({z[k + 1]:g} m) must lie above the "
                             f"{names[k]} height ({z[k]:g} m); heights are above the floor, in metres")
        if not self.shoulder_breadth > semi_axes(self.neck_girth, self.neck_depth)[0].item() * 2:
            raise ValueError("dress form: the shoulder breadth must be wider than the neck")

    def levels(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(z, a, b)`` (7,) [m]: the heights and semi-axes of the defining sections, bottom to neck top."""
        bottom = self.hip_height - 0.15 if self.bottom_height is None else self.bottom_height
        a_s = 0.5 * self.shoulder_breadth
        girths = [self.hip_girth, self.hip_girth, self.waist_girth, self.bust_girth]
        ratios = [self.hip_depth, self.hip_depth, self.waist_depth, self.bust_depth]
        a, b = semi_axes(girths, ratios)
        an, bn = semi_axes(self.neck_girth, self.neck_depth)
        z = np.array([bottom, self.hip_height, self.waist_height, self.bust_height, self.shoulder_height,
                      self.neck_height, self.neck_height + self.neck_length])
        return (z, np.concatenate([a, [a_s, an, an]]),
                np.concatenate([b, [self.shoulder_depth * a_s, bn, bn]]))

    def section(self, z):
        """``(a, b)`` [m]: the semi-axes of the section at heights ``z`` [m] (within the form): PCHIP between the
        levels; between the shoulder and the neck base a quarter ellipse in each semi-axis (the shoulder's rounded
        top), then the concave fillet into the neck (module docstring)."""
        from scipy.interpolate import PchipInterpolator

        zl, al, bl = self.levels()
        z = np.asarray(z, float)
        a, b = PchipInterpolator(zl, al)(z), PchipInterpolator(zl, bl)(z)
        zs, zn, rho = zl[4], zl[5], self.neck_fillet()
        fa, fb = rho, rho * (bl[4] - bl[5]) / (al[4] - al[5])  # the fillet's run in each semi-axis [m]
        top = (z > zs) & (z < zn)
        if np.any(top):
            s = np.sqrt(1.0 - ((z[top] - zs) / (zn - zs)) ** 2)
            a[top] = al[5] + fa + (al[4] - al[5] - fa) * s
            b[top] = bl[5] + fb + (bl[4] - bl[5] - fb) * s
        fillet = (z >= zn) & (z < zn + rho)
        if np.any(fillet):
            c = 1.0 - np.sqrt(np.clip(1.0 - ((z[fillet] - zn - rho) / rho) ** 2, 0.0, 1.0))
            a[fillet], b[fillet] = al[5] + fa * c, bl[5] + fb * c
        return a, b

    def neck_fillet(self) -> float:
        """Radius [m] of the concave fillet from the shoulder's top into the neck: :data:`NECK_FILLET` neck
        lengths."""
        return NECK_FILLET * self.neck_length

    def shoulder_radius(self) -> float:
        """Radius of curvature [m] of the shoulder's rounded top at the shoulder points, in the vertical plane across
        the body: the quarter ellipse of :meth:`section`, ``C^2 / (A - rho)`` with ``C`` the height from the shoulder
        to the neck base, ``A`` the half-width it narrows by and ``rho`` the neck fillet's radius."""
        zl, al, _ = self.levels()
        return float((zl[5] - zl[4]) ** 2 / (al[4] - al[5] - self.neck_fillet()))

    def surface(self, *, sections: int = 80, around: int = 64, clearance: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """``(P, tri)``: the closed form as points (P, 3) [m] and outward-wound triangles (T, 3).

        ``sections`` rings between the bottom and the neck top (every defining level among them, so each girth
        is met at its height), ``around`` points per ring; each end is a half ellipsoid (module docstring) of rings
        spaced evenly in the angle about its rim, about as far apart as the side's rings, to a centre point.
        ``clearance`` [m] > 0 gives the form grown by that much: every semi-axis and the ends' depths longer by it
        (a surface ``clearance`` outside the form: the contact surface that keeps a coarse garment's flat triangles
        off the curved form, :meth:`chord_clearance`).
        """
        zl = self.levels()[0]
        # the shoulder's top and the neck fillet at even steps along their arcs (their ends are horizontal)
        phi = 0.5 * np.pi * np.linspace(0.0, 1.0, 49)
        arcs = [zl[4] + (zl[5] - zl[4]) * np.sin(phi), zl[5] + self.neck_fillet() * (1.0 - np.cos(phi))]
        z = np.unique(np.concatenate([np.linspace(zl[0], zl[-1], sections), zl, *arcs]))
        a, b = self.section(z)
        depth = np.array([b[0], b[-1]]) + clearance  # the ends' depths [m]
        a, b = a + clearance, b + clearance
        t = 2.0 * np.pi * np.arange(around) / around
        spacing = (z[-1] - z[0]) / sections
        m = [max(2, int(np.ceil(0.5 * np.pi * c / spacing))) for c in depth]  # dome rings (rim excluded) + 1
        th = [0.5 * np.pi * np.arange(1, k) / k for k in m]  # angles of the dome rings above the rim (0, pi/2)
        zs = np.concatenate([z[0] - depth[0] * np.sin(th[0][::-1]), z, z[-1] + depth[1] * np.sin(th[1])])
        f = np.concatenate([np.cos(th[0][::-1]), np.ones(len(z)), np.cos(th[1])])  # the rings' shrink factors
        aa = np.concatenate([np.full(m[0] - 1, a[0]), a, np.full(m[1] - 1, a[-1])]) * f
        bb = np.concatenate([np.full(m[0] - 1, b[0]), b, np.full(m[1] - 1, b[-1])]) * f
        ring = np.stack([aa[:, None] * np.cos(t), bb[:, None] * np.sin(t), np.broadcast_to(zs[:, None], (len(zs), around))],
                        axis=-1)
        P = np.concatenate([ring.reshape(-1, 3), [[0.0, 0.0, z[0] - depth[0]], [0.0, 0.0, z[-1] + depth[1]]]])
        k = np.arange(around)
        rings = len(zs)
        r = np.arange(rings - 1)[:, None] * around
        i0, i1 = r + k, r + (k + 1) % around  # this ring
        j0, j1 = i0 + around, i1 + around  # the next ring (up the side; outwards then inwards on the caps)
        side = np.concatenate([np.stack([i0, i1, j1], -1), np.stack([i0, j1, j0], -1)], axis=0).reshape(-1, 3)
        nb, nt = len(P) - 2, len(P) - 1
        top = (rings - 1) * around
        caps = np.concatenate([np.stack([np.full(around, nb), (k + 1) % around, k], -1),
                               np.stack([np.full(around, nt), top + k, top + (k + 1) % around], -1)])
        return P, np.concatenate([side, caps]).astype(np.int64)

    def smallest_radius(self, top: float | None = None) -> float:
        """The smallest radius of curvature [m] of the form's sections between its bottom and ``top`` [m] (the
        highest point of the garment; default the bust; at most the neck base): ``min b^2 / a`` over the sections
        (semi-axes a >= b), at the ends of each ellipse's major axis, and above the shoulders the
        :meth:`shoulder_radius`. A dress reaches the shoulders, whose flat sections (depth ratio 0.45) curve about
        twice as tightly as the hips'."""
        zl = self.levels()[0]
        top = self.bust_height if top is None else min(max(top, zl[0]), self.neck_height)
        z = np.linspace(zl[0], top, 64)
        a, b = self.section(z)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        radius = float((lo * lo / hi).min())
        return min(radius, self.shoulder_radius()) if top > self.shoulder_height else radius

    def chord_clearance(self, h: float, top: float | None = None) -> float:
        """Depth [m] by which a flat triangle of size ``h`` [m] whose corners touch the form can dip into it: the
        sag of a chord, ``h^2 / (8 R)`` with R the :meth:`smallest_radius` below ``top`` [m]."""
        return h * h / (8.0 * self.smallest_radius(top))

    def girth(self, z, *, around: int = 64) -> float:
        """Perimeter [m] of the form's sampled section at height ``z`` [m] (the polygon of ``around`` points)."""
        a, b = self.section(np.array([z]))
        t = 2.0 * np.pi * np.arange(around + 1) / around
        x, y = a[0] * np.cos(t), b[0] * np.sin(t)
        return float(np.hypot(np.diff(x), np.diff(y)).sum())

    def write_obj(self, path, **surface) -> None:
        """The closed surface (:meth:`surface`) as an OBJ file [m], for a ``type = "mesh"`` obstacle."""
        P, tri = self.surface(**surface)
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(f"# dress form (rftstatic.garment.body), {len(P)} vertices, {len(tri)} triangles, metres\n")
            fh.writelines(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in P)
            fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tri)
