"""Meshing domains: an outer boundary loop with optional holes.

A :class:`Domain` is a tuple of closed :class:`Loop` objects.  ``loops[0]`` is
the outer boundary, normalised to counter-clockwise; the others are holes,
normalised to clockwise, so the domain always lies to the left of every
boundary edge (the orientation the advancing front needs).  A loop is either a
polygon (its vertices are "corners", kept exactly by the discretisation) or a
circle (its boundary nodes are placed on the circle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import MeshingError

__all__ = ["Loop", "Domain"]

_CHECK_SEGMENTS = 256   # circle -> polygon resolution used only for the validity checks


@dataclass(frozen=True, eq=False)
class Loop:
    """One closed boundary loop.

    Attributes
    ----------
    vertices : (M, 2) polygon corners in order [m] (None for a circle); the
        loop closes from the last vertex back to the first.
    center : (2,) circle centre [m] (None for a polygon)
    radius : circle radius [m] (0 for a polygon)
    orientation : +1 counter-clockwise, -1 clockwise
    """

    vertices: np.ndarray | None = None
    center: np.ndarray | None = None
    radius: float = 0.0
    orientation: int = 1

    @property
    def is_circle(self):
        return self.vertices is None

    def polyline(self, n_circle=_CHECK_SEGMENTS):
        """(M, 2) vertices in loop order [m]; a circle is sampled with ``n_circle`` points."""
        if not self.is_circle:
            return self.vertices
        t = 2 * np.pi * np.arange(n_circle) / n_circle * self.orientation
        return self.center + self.radius * np.column_stack([np.cos(t), np.sin(t)])

    @property
    def signed_area(self):
        """Signed area [m²], > 0 for counter-clockwise loops."""
        if self.is_circle:
            return self.orientation * np.pi * self.radius**2
        return _signed_area(self.vertices)

    def reversed(self):
        """The same loop traversed the other way."""
        if self.is_circle:
            return Loop(center=self.center, radius=self.radius, orientation=-self.orientation)
        return Loop(vertices=self.vertices[::-1].copy(), orientation=-self.orientation)

    def discretise(self, size_at, spacing):
        """Boundary nodes of this loop following a size field.

        Every polygon side gets ``n = max(1, round(integral ds / h))`` segments,
        placed so that each spans an equal share of that integral; corners are
        kept exactly.  A circle gets ``max(3, round(integral))`` nodes on the
        circle, equidistributed the same way in angle.

        Parameters
        ----------
        size_at : callable (M, 2) points [m] -> (M,) sizes [m]
        spacing : background-grid spacing [m], sets the sampling resolution

        Returns
        -------
        nodes : (B, 2) nodes in loop order [m] (the loop closes back to node 0)
        count : float, the loop integral of ds / h (ideal number of segments)
        """
        if self.is_circle:
            k = int(min(max(512, 4 * 2 * np.pi * self.radius / spacing), 200_000))
            t = np.linspace(0.0, 2 * np.pi, k + 1) * self.orientation
            pts = self.center + self.radius * np.column_stack([np.cos(t), np.sin(t)])
            arc = self.radius * 2 * np.pi / k
            cum = np.concatenate([[0.0], np.cumsum(0.5 * arc * (1 / size_at(pts[:-1]) + 1 / size_at(pts[1:])))])
            n = max(3, int(round(cum[-1])))
            tt = np.interp(np.arange(n) * cum[-1] / n, cum, t)
            return self.center + self.radius * np.column_stack([np.cos(tt), np.sin(tt)]), float(cum[-1])
        v = self.vertices
        w = np.roll(v, -1, axis=0)
        out, total = [], 0.0
        for a, b in zip(v, w):
            length = float(np.hypot(*(b - a)))
            k = int(min(max(32, 4 * length / spacing), 100_000))
            s = np.linspace(0.0, 1.0, k + 1)
            pts = a + s[:, None] * (b - a)
            inv = 1.0 / size_at(pts)
            cum = np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * length / k)])
            n = max(1, int(round(cum[-1])))
            total += cum[-1]
            ss = np.interp(np.arange(n) * cum[-1] / n, cum, s)
            out.append(a + ss[:, None] * (b - a))
            out[-1][0] = a          # the corner exactly
        return np.concatenate(out, axis=0), float(total)


def _signed_area(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _as_vertices(name, pts):
    pts = np.array(pts, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise MeshingError(f"{name} must be an (M, 2) array of vertices [m], got shape {pts.shape}")
    if not np.isfinite(pts).all():
        raise MeshingError(f"{name} has non-finite coordinates")
    if len(pts) > 1 and np.array_equal(pts[0], pts[-1]):
        pts = pts[:-1]          # explicitly closed: drop the repeated vertex
    if len(pts) < 3:
        raise MeshingError(f"{name} has {len(pts)} distinct vertices; a closed loop needs at least 3")
    d = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)
    scale = np.ptp(pts, axis=0).max()
    if (d <= 1e-12 * scale).any():
        k = int(np.flatnonzero(d <= 1e-12 * scale)[0])
        raise MeshingError(f"{name}: vertices {k} and {(k + 1) % len(pts)} coincide at {pts[k]}; remove the duplicate")
    return pts


def segments_cross(p1, p2, q1, q2, *, tol=0.0):
    """(n, m) bool: segment p1p2 (n, 2) touches or crosses segment q1q2 (m, 2) [m].

    ``tol`` > 0 [m] asks for a proper crossing: each segment's ends on opposite sides of the other's
    line and farther than ``tol`` from it (touching and collinear overlap excluded). With ``tol`` = 0,
    touching counts, collinear segments only when they overlap.
    """
    def orient(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])

    P1, P2, Q1, Q2 = p1[:, None], p2[:, None], q1[None], q2[None]
    o1, o2 = orient(P1, P2, Q1), orient(P1, P2, Q2)
    o3, o4 = orient(Q1, Q2, P1), orient(Q1, Q2, P2)
    if tol > 0:
        lp = tol * np.hypot(*(p2 - p1).T)[:, None]
        lq = tol * np.hypot(*(q2 - q1).T)[None, :]
        return ((o1 * o2 < 0) & (np.minimum(abs(o1), abs(o2)) > lp)
                & (o3 * o4 < 0) & (np.minimum(abs(o3), abs(o4)) > lq))
    hit = (o1 * o2 <= 0) & (o3 * o4 <= 0)
    collinear = (o1 == 0) & (o2 == 0)
    if collinear.any():
        lo = np.minimum(P1, P2) <= np.maximum(Q1, Q2)
        hi = np.minimum(Q1, Q2) <= np.maximum(P1, P2)
        hit &= ~collinear | (lo & hi).all(axis=-1)
    return hit


def _point_in_polygon(p, v):
    """Even-odd test of point p (2,) against polygon v (M, 2)."""
    a, b = v, np.roll(v, -1, axis=0)
    cond = (a[:, 1] > p[1]) != (b[:, 1] > p[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = a[:, 0] + (p[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(cond & (p[0] < xs)) % 2)


class Domain:
    """A polygonal/circular domain with holes.

    Parameters
    ----------
    loops : sequence of :class:`Loop`; the first is the outer boundary and the
        rest are holes.  Orientation is normalised (outer CCW, holes CW).

    Raises
    ------
    MeshingError
        If a loop is degenerate, loops cross themselves or each other, or a
        hole is not inside the outer loop (or inside another hole).
    """

    def __init__(self, loops):
        loops = list(loops)
        if not loops:
            raise MeshingError("a Domain needs at least the outer loop")
        for k, lp in enumerate(loops):
            if lp.is_circle and not (np.isfinite(lp.radius) and lp.radius > 0):
                raise MeshingError(f"loop {k}: circle radius {lp.radius!r} must be positive [m]")
        self.loops = tuple(loops)
        self._check_crossings()
        norm = []
        for k, lp in enumerate(loops):
            want = 1 if k == 0 else -1
            if abs(lp.signed_area) <= 0:
                raise MeshingError(f"loop {k} has zero area; give at least 3 non-collinear vertices")
            if np.sign(lp.signed_area) != want:
                lp = lp.reversed()
            if not lp.is_circle:
                lp = Loop(vertices=lp.vertices, orientation=want)
            norm.append(lp)
        self.loops = tuple(norm)
        self._check_nesting()

    # ------------------------------------------------------------------ constructors
    @classmethod
    def polygon(cls, outer, holes=()):
        """Polygon ``outer`` (M, 2) [m] with polygonal ``holes`` (each (M_k, 2)); any orientation."""
        loops = [Loop(vertices=_as_vertices("outer loop", outer))]
        loops += [Loop(vertices=_as_vertices(f"hole {k}", h)) for k, h in enumerate(holes)]
        return cls(loops)

    @classmethod
    def rectangle(cls, x0, y0, lx, ly):
        """Rectangle with corner (x0, y0) and side lengths lx, ly [m]."""
        if not (lx > 0 and ly > 0):
            raise MeshingError(f"rectangle sides lx = {lx!r}, ly = {ly!r} must be positive [m]")
        return cls.polygon([[x0, y0], [x0 + lx, y0], [x0 + lx, y0 + ly], [x0, y0 + ly]])

    @classmethod
    def disc(cls, cx, cy, r):
        """Disc of radius r [m] centred at (cx, cy) [m]; boundary nodes lie on the circle."""
        return cls([Loop(center=np.array([cx, cy], dtype=float), radius=float(r))])

    @classmethod
    def annulus(cls, cx, cy, r_in, r_out):
        """Annulus r_in < |x - c| < r_out [m]; both circles are meshed exactly."""
        if not (0 < r_in < r_out):
            raise MeshingError(f"annulus needs 0 < r_in < r_out, got r_in = {r_in!r}, r_out = {r_out!r}")
        c = np.array([cx, cy], dtype=float)
        return cls([Loop(center=c, radius=float(r_out)), Loop(center=c, radius=float(r_in), orientation=-1)])

    @classmethod
    def from_segments(cls, points, segments, *, collinear_tol=1e-9):
        """Domain from closed boundary segments, e.g. the boundary edges of an old mesh.

        Parameters
        ----------
        points : (N, 2) node coordinates [m]
        segments : (S, 2) node index pairs; every node used must have exactly
            two segments (closed loops).  The loop of largest area is the
            outer boundary, the others are holes.
        collinear_tol : vertices whose turn |sin| is below this are dropped, so
            straight runs are re-discretised from the size field.
        """
        points = np.asarray(points, dtype=float)
        seg = np.asarray(segments, dtype=np.int64)
        if seg.ndim != 2 or seg.shape[1] != 2 or len(seg) < 3:
            raise MeshingError(f"segments must be an (S, 2) index array with S >= 3, got shape {seg.shape}")
        if seg.min() < 0 or seg.max() >= len(points):
            raise MeshingError(f"segments index nodes outside 0..{len(points) - 1}")
        deg = np.bincount(seg.ravel(), minlength=len(points))
        bad = np.flatnonzero((deg != 0) & (deg != 2))
        if len(bad):
            k = int(bad[0])
            raise MeshingError(
                f"non-closed boundary: node {k} at {points[k]} has {deg[k]} boundary segments, "
                "each node of a closed loop needs exactly 2; close the loop or remove stray segments")
        nbr = {}
        for a, b in seg.tolist():
            nbr.setdefault(a, []).append(b)
            nbr.setdefault(b, []).append(a)
        seen = set()
        loops = []
        for start in sorted(nbr):
            if start in seen:
                continue
            order, prev, cur = [start], -1, start
            seen.add(start)
            while True:
                n0, n1 = nbr[cur]
                nxt = n1 if n0 == prev else n0
                if nxt == start:
                    break
                order.append(nxt)
                seen.add(nxt)
                prev, cur = cur, nxt
            v = points[order]
            a, b = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
            e1, e2 = v - a, b - v
            cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            keep = np.abs(cross) > collinear_tol * np.hypot(*e1.T) * np.hypot(*e2.T)
            if keep.sum() < 3:
                raise MeshingError(f"boundary loop through node {start} is degenerate (collinear)")
            v = v[keep]
            loops.append(Loop(vertices=v, orientation=int(np.sign(_signed_area(v)))))
        loops.sort(key=lambda lp: -abs(lp.signed_area))
        return cls(loops)

    # ------------------------------------------------------------------ properties
    @property
    def n_holes(self):
        return len(self.loops) - 1

    @property
    def area(self):
        """Domain area [m²]."""
        return float(sum(lp.signed_area for lp in self.loops))

    @property
    def bbox(self):
        """(xmin, ymin, xmax, ymax) [m] of the outer loop."""
        lp = self.loops[0]
        if lp.is_circle:
            c, r = lp.center, lp.radius
            return np.array([c[0] - r, c[1] - r, c[0] + r, c[1] + r])
        v = lp.vertices
        return np.array([*v.min(axis=0), *v.max(axis=0)])

    def __repr__(self):
        kinds = ["circle" if lp.is_circle else f"polygon[{len(lp.vertices)}]" for lp in self.loops]
        return f"Domain(outer={kinds[0]}, holes={kinds[1:]})"

    # ------------------------------------------------------------------ checks
    def _check_crossings(self):
        polys = [lp.polyline() for lp in self.loops]
        p1 = np.concatenate(polys)
        p2 = np.concatenate([np.roll(v, -1, axis=0) for v in polys])
        loop_id = np.concatenate([np.full(len(v), k) for k, v in enumerate(polys)])
        local = np.concatenate([np.arange(len(v)) for v in polys])
        size = np.concatenate([np.full(len(v), len(v)) for v in polys])
        n = len(p1)
        chunk = max(1, 4_000_000 // max(n, 1))
        for s in range(0, n, chunk):
            sl = slice(s, min(n, s + chunk))
            same = loop_id[sl, None] == loop_id[None, :]
            d = (local[sl, None] - local[None, :]) % size[None, :]
            skip = same & ((d == 0) | (d == 1) | (d == size[None, :] - 1))
            hit = segments_cross(p1[sl], p2[sl], p1, p2) & ~skip
            if hit.any():
                i, j = np.argwhere(hit)[0]
                i += s
                raise MeshingError(
                    f"self-intersecting boundary: segment {local[i]} of loop {loop_id[i]} "
                    f"({p1[i][0]:g}, {p1[i][1]:g})-({p2[i][0]:g}, {p2[i][1]:g}) touches or crosses segment "
                    f"{local[j]} of loop {loop_id[j]} ({p1[j][0]:g}, {p1[j][1]:g})-({p2[j][0]:g}, {p2[j][1]:g}); "
                    "fix the coordinates so that loops are simple and disjoint")

    def _check_nesting(self):
        polys = [lp.polyline() for lp in self.loops]
        outer = polys[0]
        for k in range(1, len(polys)):
            p = polys[k][0]
            if not _point_in_polygon(p, outer):
                raise MeshingError(f"hole {k - 1} (loop {k}) lies outside the outer loop; remove it or enlarge the outer loop")
            for m in range(1, len(polys)):
                if m != k and _point_in_polygon(p, polys[m]):
                    raise MeshingError(f"hole {k - 1} lies inside hole {m - 1}; nested islands are not supported")

    # ------------------------------------------------------------------ discretisation
    def discretise(self, size_field):
        """Boundary nodes and edges following the size field.

        Parameters
        ----------
        size_field : :class:`~rftstatic.mesh.mesher.BackgroundGrid`

        Returns
        -------
        points : (B, 2) boundary nodes [m], loop by loop
        edges : (B, 2) int64 node pairs, domain on the left of each edge
        loop_of_edge : (B,) int64 loop index of each edge

        Raises
        ------
        MeshingError
            If the size field is too large for a loop (fewer than 3 segments).
        """
        pts, edges, owner = [], [], []
        offset = 0
        for k, lp in enumerate(self.loops):
            v, count = lp.discretise(size_field.size_at, size_field.spacing)
            if count < 3.0:
                name = "outer loop" if k == 0 else f"hole {k - 1}"
                raise MeshingError(
                    f"the target size (~{size_field.size_at(v).max():g} m) is larger than the {name}: its perimeter "
                    f"holds only {count:.2f} target sizes, at least 3 are needed; reduce the size field there "
                    "(h_upper) or enlarge the domain")
            idx = offset + np.arange(len(v))
            pts.append(v)
            edges.append(np.column_stack([idx, np.roll(idx, -1)]))
            owner.append(np.full(len(v), k))
            offset += len(v)
        return np.concatenate(pts), np.concatenate(edges).astype(np.int64), np.concatenate(owner).astype(np.int64)
