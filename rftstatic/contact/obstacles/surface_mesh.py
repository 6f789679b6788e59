"""A rigid obstacle given as a triangle surface file (scene type ``mesh``): a user's own object.

Scene keys: ``path`` (any surface meshio reads: OBJ, STL, PLY, VTU, ...; relative to the scene file, or
absolute), ``units`` of the file (``m``, ``cm``, ``mm``, ``in``, ``ft``; default: the scene's length unit),
``scale`` (a factor), ``rotate`` ``[rx, ry, rz]`` [deg] (about x, then y, then z, about the file's origin),
``translate`` ``[x, y, z]`` (scene lengths), applied in that order. The file is checked on the way in
(:func:`rftstatic.mesh.surface.check_triangles`: degenerate or duplicate triangles, non-manifold edges,
orientation), quads are split into triangles (said in :attr:`SurfaceObstacle.notes`), coincident nodes
are merged.

A closed surface is a solid: inside and outside come from its winding (an inward-wound file is turned
round, said in the notes). An open one (a table top, a shell) needs either ``side = "front"`` (the solid
lies behind the side its triangles' right-hand normals face; ``"back"`` the other way: a point whose
closest surface point is on the open boundary is outside) or ``thickness`` (a two-sided shell: ``phi =
r - thickness / 2``). A closed or one-sided surface may be ``rounding`` [length] > 0: the solid grown by a ball of
that radius (a Minkowski sum; ``phi = d - rounding`` with ``d`` the signed distance to the triangles), whose
contact surface is smooth (C1): a facet edge or corner becomes a cylinder or sphere of radius at least
``rounding``, so the distance's curvature is bounded (``|H| <= 1 / rounding``) and the penalty's tangent is kept
exact instead of clamped (:attr:`SurfaceObstacle.psd_tangent`; :mod:`rftstatic.contact.penalty`). A body given by
a finely tessellated smooth surface (a dress form) is best described so: Newton then converges quadratically where
nodes rest over facet edges, where the clamped tangent converges linearly.

The signed distance and its derivatives are those of :mod:`.surface_geometry`, exact for the points
within ``band`` of the surface. The closest triangle is sought among each point's nearest triangle centroids
(a ``cKDTree`` of them, built once: :data:`~.surface_query.WIDER` with the compiled kernel of :mod:`.surface_kernels`,
:data:`~.surface_query.NEAREST` with its numpy twin), kept between calls for the same number of points (a static obstacle's
triangles never move: :data:`~.surface_query.HELD_SETS`); the nearest of them is the nearest of all when every other centroid
lies farther than its distance plus ``R`` (the largest centroid-to-corner radius; the centroid distances where
the set was found minus how far the point moved since), else the set is sought again where the point is, and
a point still unproven searches every triangle whose centroid lies within its distance plus ``R``. A point
farther than ``band`` from every triangle gets a lower bound of its distance (the nearest centroid minus
``R``): 1-Lipschitz and never above the true distance, which is all the contact candidate lists need
(:mod:`rftstatic.contact.candidates`); its side comes from the winding number (a closed surface, a point
inside its bounding box), and its Hessian is 0. The Hessian is 0 inside too: inside a convex edge or corner
the closest point is on a face (phi linear), except for a point on the surface itself, where the edge's
``1 / r`` is round-off (a sheet node laid exactly on a box's edge); at a reflex (concave) edge the face value
is a one-sided choice, a softer PSD tangent (the penalty's slope is negative there).

A step of the explicit analyses' kinematic contact through the surface (a thin table top) is caught by
:meth:`SurfaceObstacle.segment_crossings` (:mod:`.surface_ccd`).

Sharp features (:meth:`SurfaceObstacle.sharp_features`): the convex edges whose faces meet at more than
``feature_angle`` (:data:`FEATURE_ANGLE`) from flat and the open boundary, and their end corners: the contact
law keeps the sheet's edges and triangles off them (:mod:`rftstatic.contact.features`).
"""

from __future__ import annotations

from itertools import chain
from pathlib import Path
from typing import ClassVar

import numpy as np

from rftstatic.compiled import numba_available
from rftstatic.contact.obstacles.base import NUMBER, NUMBERS, Obstacle, SceneKey, SharpFeatures, _as_points
from rftstatic.contact.obstacles.registry import register
from rftstatic.contact.obstacles.surface_query import HELD_SETS, NEAREST, WIDER, WIDEST
from rftstatic.contact.obstacles.surface_geometry import (EDGE, FACE, VERTEX, closest_on_triangles, merge_nodes,
                                                          plan_hull, polygon_area_centre, pseudo_normals, rotation,
                                                          sharp_edges, winding_number)

__all__ = ["FILE_UNITS", "SurfaceObstacle"]

FILE_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}
"""Length units a mesh file may be in [m]."""

BAND = 0.25
"""Exact-distance band, in bounding-box diagonals of the obstacle (module docstring)."""

SIZE_RANGE = (1e-6, 1e4)
"""Sizes [m] (bounding-box diagonal after scale and units) a mesh obstacle may have: a scale that makes it
smaller or larger is a mistake (its triangles would be degenerate, or its coordinates overflow)."""

HESSIAN_CAP = 0.5
"""The rounded surface's curvature ``1 / d`` is taken at ``d = HESSIAN_CAP * rounding`` where the point lies
closer to the triangles (deeper than half the rounding into the contact surface: never in a sound run)."""

FEATURE_ANGLE = 30.0
"""Default angle [deg] between two faces' normals above which their common (convex) edge is a sharp feature: a
box's or a table's edges (90 deg) are, the edges of a tessellated curved body (an icosphere of 1,280
triangles: 7.5 deg) are not. On a curved body the sheet's flat triangles then dip into the obstacle between
their nodes by about the chord sagitta ``h^2 / (8 R)``, as they do into an analytic sphere; ``feature_angle =
1`` keeps every convex edge and vertex off the sheet (0 crossing pairs) at the cost measured in
validation/mesh_obstacles.md."""


@register
class SurfaceObstacle(Obstacle):
    """Rigid obstacle bounded by a triangle surface (module docstring); lengths in metres.

    Parameters
    ----------
    path : the surface file
    units : the file's length unit (:data:`FILE_UNITS`), or None: ``scene_length``
    scale : factor on the file's coordinates
    rotate : (3,) angles [deg] about x, y, z
    translate : (3,) offset [m]
    side : ``"front"`` or ``"back"`` for an open surface (module docstring)
    thickness : of a two-sided open shell [m]
    rounding : radius [m] of the ball the solid is grown by (module docstring); 0: the triangles themselves
    feature_angle : [deg] (:data:`FEATURE_ANGLE`)
    scene_length : metres per scene length unit (the file's unit when ``units`` is None)
    base_dir : directory a relative ``path`` is taken from (the scene file's)
    """

    type_name = "mesh"
    scene_keys: ClassVar[dict[str, SceneKey]] = {
        "path": SceneKey("path", required=True, length=False, kinds=(str,),
                         help="surface file meshio reads (OBJ, STL, PLY, VTU, ...), relative to the scene file"),
        "units": SceneKey("units", length=False, kinds=(str,),
                          help="length unit of a mesh file: " + ", ".join(FILE_UNITS) + " (default: the scene's)"),
        "scale": SceneKey("scale", length=False, help="factor on a mesh file's coordinates (default 1)"),
        "rotate": SceneKey("rotate", length=False, kinds=NUMBERS,
                           help="[rx, ry, rz] rotation of a mesh [deg] about x, then y, then z"),
        "translate": SceneKey("translate", kinds=NUMBERS, help="[x, y, z] offset of a mesh, after scale and rotate"),
        "side": SceneKey("side", length=False, kinds=(str,),
                         help='open mesh: "front" (solid behind the side its normals face) or "back"'),
        "thickness": SceneKey("thickness", kinds=NUMBER, help="open mesh: two-sided shell of this thickness"),
        "smooth": SceneKey("smooth", kinds=NUMBER,
                           help="closed mesh: the smooth implicit (IMLS) surface of its facets, of this support radius "
                                "(at least 2.5 facet radii; default 0: the triangles)"),
        "rounding": SceneKey("rounding", kinds=NUMBER,
                             help="closed or one-sided mesh: the solid grown by a ball of this radius (a smooth contact "
                                  "surface, an exact contact tangent; default 0)"),
        "feature_angle": SceneKey("feature_angle", length=False,
                                  help=f"mesh edges bent more than this [deg] are sharp features (default {FEATURE_ANGLE:g})"),
    }

    def __init__(self, path, units=None, scale=1.0, rotate=(0.0, 0.0, 0.0), translate=(0.0, 0.0, 0.0),
                 side=None, thickness=None, feature_angle=FEATURE_ANGLE, rounding=0.0, smooth=0.0, *,
                 scene_length=1.0, base_dir=None):
        from rftstatic.errors import MeshError
        from rftstatic.mesh.surface import check_triangles, read_triangles

        self.path = Path(path) if base_dir is None or Path(path).is_absolute() else Path(base_dir) / path
        if units is not None and units not in FILE_UNITS:
            raise ValueError(f"units {units!r} is not a length unit; use one of {list(FILE_UNITS)}")
        self.units = units
        self.scale = float(scale)
        if not (np.isfinite(self.scale) and self.scale > 0):
            raise ValueError(f"scale must be a finite number > 0, got {scale!r}")
        self.rotate = np.asarray(rotate, float).reshape(3)
        self.translate = np.asarray(translate, float).reshape(3)
        self.side = side
        self.thickness = None if thickness is None else float(thickness)
        self.feature_angle = float(feature_angle)
        self.rounding, self.smooth = float(rounding), float(smooth)
        self.scene_length = float(scene_length)
        if side not in (None, "front", "back"):
            raise ValueError(f'side must be "front" or "back", got {side!r}')
        if self.thickness is not None and not (np.isfinite(self.thickness) and self.thickness > 0):
            raise ValueError(f"thickness must be a finite number > 0, got {thickness!r}")
        if side is not None and self.thickness is not None:
            raise ValueError("thickness and side are exclusive: a shell of a thickness has two sides; give one")
        if not (np.isfinite(self.rounding) and self.rounding >= 0):
            raise ValueError(f"rounding must be a finite length >= 0, got {rounding!r}")
        if not (np.isfinite(self.smooth) and self.smooth >= 0):
            raise ValueError(f"smooth must be a finite length >= 0, got {smooth!r}")
        if self.rounding > 0 and self.thickness is not None:
            raise ValueError("rounding and thickness are exclusive: a shell is rounded by half its thickness; give one")
        if not (0.0 < self.feature_angle < 180.0):
            raise ValueError(f"feature_angle must lie in (0, 180) deg, got {feature_angle!r}")
        if not self.path.is_file():
            raise MeshError(f"{self.path}: no such file; give path relative to the scene file, or absolute")
        P, tri, notes = read_triangles(self.path, quads="triangulate")
        P, tri = merge_nodes(P, tri)
        unit = FILE_UNITS[units] if units is not None else self.scene_length
        if not (np.isfinite(self.rotate).all() and np.isfinite(self.translate).all()):
            raise ValueError(f"rotate and translate must be finite, got {rotate!r} and {translate!r}")
        with np.errstate(over="ignore", invalid="ignore"):
            V = (P * (unit * self.scale)) @ rotation(self.rotate).T + self.translate
            size = float(np.linalg.norm(np.ptp(V, axis=0)))
        if not (np.isfinite(V).all() and SIZE_RANGE[0] <= size <= SIZE_RANGE[1]):
            raise ValueError(f"scale = {scale!r} (file units {units or 'of the scene'}) makes the obstacle {size:.3g} m "
                             f"across; give a scale (and units) that make it {SIZE_RANGE[0]:g} m to {SIZE_RANGE[1]:g} m")
        info = check_triangles(V, tri, where=str(self.path), oriented=self.thickness is None)
        self.closed = info["closed"]
        if self.closed and (side is not None or self.thickness is not None):
            raise MeshError(f"{self.path}: the surface is closed (a solid, inside by its winding); side and "
                            "thickness are for open surfaces: remove them")
        if not self.closed and side is None and self.thickness is None:
            open_edges = int(np.sum(info["count"] == 1))
            raise MeshError(f'{self.path}: the surface is open ({open_edges} boundary edges): say which side is solid '
                            '(side = "front" or "back") or make it a two-sided shell (thickness = ...)')
        if self.closed:
            a, b, c = V[tri[:, 0]], V[tri[:, 1]], V[tri[:, 2]]
            volume = float(np.einsum("ti,ti->", a, np.cross(b, c))) / 6.0
            if volume < 0:
                tri = tri[:, [0, 2, 1]]
                notes.append("the surface was wound inward (negative volume): turned round")
                info = check_triangles(V, tri, where=str(self.path), oriented=True)
        elif side == "back":
            tri = tri[:, [0, 2, 1]]
            info = check_triangles(V, tri, where=str(self.path), oriented=True)
        self.notes = notes
        self.V, self.T = V, tri
        self.edges, self.edge_of, count = info["edges"], info["edge_of"], info["count"]
        self.nf, self.ne, self.nv = pseudo_normals(V, tri, self.edge_of, len(self.edges))
        boundary_edge = count == 1
        self.boundary_edge = boundary_edge
        self.boundary_vertex = np.zeros(len(V), bool)
        self.boundary_vertex[self.edges[boundary_edge].ravel()] = True
        self._build_search()
        if self.smooth:
            from rftstatic.contact.obstacles.surface_smooth import MIN_SUPPORT, SmoothSurface

            if not self.closed:
                raise MeshError(f"{self.path}: smooth needs a closed surface (a solid); this one is open: leave it out")
            if self.smooth < MIN_SUPPORT * self.radius * (1.0 - 1e-6):
                raise ValueError(f"smooth = {smooth!r} is below {MIN_SUPPORT:g} facet radii of {self.path.name} "
                                 f"({MIN_SUPPORT * self.radius:.3g} m): give at least that (in the scene's lengths)")
            self._smooth = SmoothSurface(V, tri, self.smooth, tree=self._ctree)  # the same centroids
        self._features()

    # --- geometry ---------------------------------------------------------------------------------
    def _build_search(self):
        from scipy.spatial import cKDTree

        V, T = self.V, self.T
        self.centroid = V[T].mean(axis=1)
        self.radius = float(np.max(np.linalg.norm(V[T] - self.centroid[:, None, :], axis=2)))
        self.lo, self.hi = V.min(axis=0), V.max(axis=0)
        self.band = BAND * float(np.linalg.norm(self.hi - self.lo))
        self._ctree = cKDTree(self.centroid)
        self._vtree = cKDTree(V)
        self._sets = {}  # candidate sets of the last calls, by their number of points (_candidates)
        self._wider, self.widest = WIDER, WIDEST  # their size, doubled while fresh sets fail to prove (surface_query)
        self._surface = tuple(np.ascontiguousarray(a) for a in (
            V, T.astype(np.int64), self.centroid, self.nf, self.ne, self.nv, self.edge_of.astype(np.int64),
            self.edges.astype(np.int64), self.boundary_edge, self.boundary_vertex))
        mode = 0 if self.closed else (2 if self.thickness is not None else 1)
        self._consts = np.array([self.radius, self.band, self.offset, mode, *self.lo, *self.hi, 0.0,
                                 HESSIAN_CAP * self.rounding], float)
        # the compiled query pays off where the numpy twin searches subsets; a box's 12 triangles are all tested
        # at once in numpy, without importing numba (0.5 s)
        self.compiled = numba_available() and len(T) > NEAREST

    def _candidates(self, x, K):
        """Each point's ``K`` candidate triangles ``ik (n, K)``, nearest centroid first, their centroid distances
        ``dk (n, K)`` [m] where they were found and how far the point moved since, ``moved (n,)`` [m]: the
        previous call's sets (same number of points) kept, else the ``K`` nearest centroids now (``moved = 0``).
        ``dk - moved`` bounds the centroids' distances from below (the distance is 1-Lipschitz)."""
        held = self._sets.get(len(x))
        if held is None or held[1].shape[1] != K:
            dk, ik = self._ctree.query(x, k=K)
            dk, ik = dk.reshape(len(x), K), ik.reshape(len(x), K)
            if len(self._sets) >= HELD_SETS and len(x) not in self._sets:
                self._sets.pop(next(iter(self._sets)))
            self._sets[len(x)] = (x.copy(), ik, dk)
            return ik, dk, np.zeros(len(x))
        x_ref, ik, dk = held
        return ik, dk, np.linalg.norm(x - x_ref, axis=1)

    def _nearest_in(self, x, ik, dk, moved):
        """Per point, the nearest of its candidate triangles ``ik (n, K)``: ``(q, kind, local, tri, r, dc)``,
        ``dc`` the least distance to the centroids of those it tested (:func:`.surface_kernels.nearest_in_sets`:
        the compiled twin stops at the first candidate that cannot be nearer, ``dk - moved - R > r``)."""
        n, K = ik.shape
        if self.compiled:
            from rftstatic.contact.obstacles._surface_numba import nearest_in_sets

            q, feature, dist = np.empty((n, 3)), np.empty((n, 3), np.int64), np.empty((n, 2))
            nearest_in_sets(np.ascontiguousarray(x), self.V, self.T, self.centroid, np.ascontiguousarray(ik),
                            np.ascontiguousarray(dk), moved, self.radius, q, feature, dist)
            return (q, feature[:, 0].astype(np.int8), feature[:, 1].astype(np.int8), feature[:, 2], dist[:, 0],
                    dist[:, 1])
        q, kind, local, tri = self._nearest_of(np.repeat(x, K, axis=0), ik.ravel(), np.full(n, K))
        dc = np.sqrt(np.min(np.einsum("pki,pki->pk", x[:, None] - self.centroid[ik], x[:, None] - self.centroid[ik]),
                            axis=1))
        return q, kind, local, tri, np.linalg.norm(x - q, axis=1), dc

    def _closest(self, x):
        """Closest features of the points ``x (n, 3)`` [m]: ``(q (n, 3), kind (n,), gid (n,), exact (n,), lower
        (n,))``, ``gid`` the global face, edge or vertex index, ``exact`` where it is proven (the others: the
        nearest of their candidates) and ``lower`` a lower bound of each point's distance [m]. The nearest of a
        point's candidates is the nearest of all when every other centroid is farther than its distance plus
        ``R`` (``d_K - moved - R >= r``); candidate sets that fail that are sought again at ``x``; the points
        still unproven and within ``band`` search every triangle within ``r + R``."""
        K = min(WIDER if self.compiled else NEAREST, len(self.T))
        ik, dk, moved = self._candidates(x, K)
        q, kind, local, tri, r, dc = self._nearest_in(x, ik, dk, moved)
        whole = len(self.T) <= K
        far = np.flatnonzero((moved > 0) & (dk[:, 0] - moved - self.radius >= self.band))
        if far.size:  # beyond the band whatever its held set: its nearest centroid now as its set (FAR)
            dk, moved = dk.copy(), moved.copy()
            dkf, ikf = self._ctree.query(x[far], k=1)
            dk[far], moved[far] = dkf[:, None], 0.0  # the set of one: its first and farthest centroid
            q[far], kind[far], local[far], tri[far], r[far], dc[far] = self._nearest_in(
                x[far], ikf.reshape(-1, 1), dkf.reshape(-1, 1), np.zeros(len(far)))
        beyond = dk[:, -1] - moved
        proven = whole | (beyond - self.radius >= r)
        again = np.flatnonzero(~proven & (moved > 0))
        if again.size:  # sets kept from the last call that no longer prove the nearest: the K nearest now
            dka, ika = self._ctree.query(x[again], k=K)
            dka, ika = dka.reshape(len(again), K), ika.reshape(len(again), K)
            x_ref, ik_held, dk_held = self._sets[len(x)]
            x_ref[again], ik_held[again], dk_held[again] = x[again], ika, dka
            q[again], kind[again], local[again], tri[again], r[again], dc[again] = self._nearest_in(
                x[again], ika, dka, np.zeros(len(again)))
            beyond[again] = dka[:, -1]
            proven[again] = beyond[again] - self.radius >= r[again]
        # every centroid not tested is farther than r + R or than beyond: the distance is at least this
        lower = np.maximum(np.minimum(np.minimum(dc, beyond) - self.radius, r), 0.0)
        open_ = np.flatnonzero(~proven & (lower < self.band))
        if open_.size:
            q[open_], kind[open_], local[open_], tri[open_] = self._ball(x[open_], r[open_])
            proven[open_] = True
        return q, kind, self._gid(kind, local, tri), proven, lower

    def _ball(self, xo, reach=None):
        """The nearest triangle of each point ``xo (m, 3)`` among all whose centroid lies within ``reach + R``
        (``reach (m,)`` [m], a distance to the surface some triangle attains; default: to the nearest vertex):
        ``(q, kind, local, tri)``."""
        if reach is None:
            reach, _ = self._vtree.query(xo)
        lists = self._ctree.query_ball_point(xo, reach + self.radius * (1 + 1e-12) + 1e-300)
        counts = np.fromiter(map(len, lists), np.int64, len(lists))
        tris = np.fromiter(chain.from_iterable(lists), np.int64, int(counts.sum()))
        return self._nearest_of(np.repeat(xo, counts, axis=0), tris, counts)

    def _gid(self, kind, local, tri):
        """The global face, edge or vertex index of a closest feature."""
        return np.where(kind == FACE, tri, np.where(kind == EDGE, self.edge_of[tri, local], self.T[tri, local]))

    def _nearest_of(self, xp, tri, counts):
        """Per point, the nearest of its ``counts`` consecutive candidate pairs ``(xp (P, 3), tri (P,))``."""
        T = self.T[tri]
        q, kind, local = closest_on_triangles(xp, self.V[T[:, 0]], self.V[T[:, 1]], self.V[T[:, 2]])
        d2 = np.einsum("pi,pi->p", xp - q, xp - q)
        if not len(counts):  # no point asked about
            return q, kind, local, tri
        if np.all(counts == counts[0]):  # K each: the nearest along the rows
            best = np.argmin(d2.reshape(len(counts), -1), axis=1) + counts[0] * np.arange(len(counts))
        else:
            pt = np.repeat(np.arange(len(counts)), counts)
            best = np.lexsort((d2, pt))[np.r_[0, np.cumsum(counts)[:-1]]]  # per point, the nearest pair first
        return q[best], kind[best], local[best], tri[best]

    def _evaluate(self, x, hessian):
        x = _as_points(x)
        if self.smooth:  # the IMLS surface wherever a facet's support reaches
            from rftstatic.contact.obstacles.surface_smooth import evaluate_smooth

            return evaluate_smooth(self, x, hessian)
        return self._evaluate_faceted(x, hessian)

    def _evaluate_faceted(self, x, hessian):
        if self.compiled:
            return self._evaluate_compiled(x, hessian)
        q, kind, gid, exact, lower = self._closest(x)
        return self._signed(x, q, kind, gid, exact & (lower < self.band), lower, hessian)

    def _evaluate_compiled(self, x, hessian):
        from rftstatic.contact.obstacles.surface_query import evaluate_compiled

        return evaluate_compiled(self, x, hessian)

    def _signed(self, x, q, kind, gid, near, lower, hessian):
        """Signed distance, normal and Hessian (or None) at ``x (n, 3)`` [m] from each point's closest feature
        ``q (n, 3)`` [m], ``kind, gid``, exact where ``near``, else the lower bound ``lower (n,)`` [m] (module
        docstring)."""
        n = len(x)
        near = near.copy()
        if self.closed:
            box = ~near & np.all((x >= self.lo) & (x <= self.hi), axis=1)
            if box.any():  # a point deep inside (none in a sound run) gets its exact distance too
                deep = np.flatnonzero(box)[winding_number(x[box], self.V, self.T) > 0.5]
                if deep.size:
                    qd, kd, ld, td = self._ball(x[deep])
                    q[deep], kind[deep], gid[deep] = qd, kd, self._gid(kd, ld, td)
                    near[deep] = True
        half = self.offset
        phi = lower - half
        away = x - q
        normal = away / np.maximum(np.linalg.norm(away, axis=1, keepdims=True), 1e-300)
        H = np.zeros((n, 3, 3)) if hessian else None
        idx = np.flatnonzero(near)
        if idx.size:
            xn = x[idx]
            q, kind, gid = q[idx], kind[idx], gid[idx]
            d = xn - q
            r = np.linalg.norm(d, axis=1)
            pn = np.where((kind == FACE)[:, None], self.nf[np.where(kind == FACE, gid, 0)],
                          np.where((kind == EDGE)[:, None], self.ne[np.where(kind == EDGE, gid, 0)],
                                   self.nv[np.where(kind == VERTEX, gid, 0)]))
            if self.thickness is not None:
                s = np.ones(len(idx))
            else:
                s = np.where(np.einsum("pi,pi->p", d, pn) < 0.0, -1.0, 1.0)
                if not self.closed:  # closest point on the open boundary: outside
                    on_rim = ((kind == EDGE) & self.boundary_edge[np.where(kind == EDGE, gid, 0)]) | (
                        (kind == VERTEX) & self.boundary_vertex[np.where(kind == VERTEX, gid, 0)])
                    s = np.where(on_rim, 1.0, s)
            tiny = r <= 1e-12 * self.band
            u = np.where(tiny[:, None], pn, d / np.where(tiny, 1.0, r)[:, None])
            phi[idx] = s * r - half
            normal[idx] = s[:, None] * u
            if hessian:
                P = np.eye(3) - np.einsum("pi,pj->pij", u, u)
                e = self.edges[np.where(kind == EDGE, gid, 0)]
                t = self.V[e[:, 1]] - self.V[e[:, 0]]
                t /= np.linalg.norm(t, axis=1, keepdims=True)
                P = P - (kind == EDGE)[:, None, None] * np.einsum("pi,pj->pij", t, t)
                # inside (s < 0) the closest point is on a face except at a reflex edge or exactly on the surface
                # (r ~ 0, where 1 / r would be round-off): 0 there (module docstring)
                scale = np.where((kind == FACE) | tiny | (s < 0), 0.0,
                                 s / np.where(tiny, 1.0, np.maximum(r, HESSIAN_CAP * self.rounding)))
                H[idx] = scale[:, None, None] * P
        return phi, normal, H

    # --- the Obstacle interface -------------------------------------------------------------------
    def signed_distance(self, x):
        phi, normal, _ = self._evaluate(x, False)
        return phi, normal

    def normal_gradient(self, x):
        return self._evaluate(x, True)[2]

    def segment_crossings(self, x0, x1):
        """Steps ``x0 -> x1`` ``(n, 3)`` [m] through the surface (:mod:`.surface_ccd`): a point whose step is
        longer than its end's distance to the surface (the mid-surface of a shell) is tested."""
        from rftstatic.contact.obstacles.surface_ccd import first_crossings

        x0, x1 = _as_points(x0), _as_points(x1)
        half = self.offset
        r = np.abs(self.signed_distance(x1)[0] + half)
        return first_crossings(self, x0, x1, np.flatnonzero(np.linalg.norm(x1 - x0, axis=1) >= r), half)

    @property
    def offset(self) -> float:
        """How far [m] the contact surface lies outside the triangles: half the thickness of a shell, or the
        rounding."""
        return 0.5 * self.thickness if self.thickness is not None else self.rounding

    @property
    def psd_tangent(self) -> bool:
        """The penalty clamps the contact tangent (PSD) where the distance's curvature is unbounded (sharp edges, no
        rounding or smoothing); a rounded or smooth surface's curvature is bounded: its tangent stays exact."""
        return self.rounding == 0.0 and self.smooth == 0.0

    def bounding_box(self):
        half = self.offset
        return self.lo - half, self.hi + half

    def params(self):
        out = {"path": str(self.path), "scale": self.scale, "rotate": self.rotate.tolist(),
               "translate": self.translate.tolist(), "feature_angle": self.feature_angle}
        if self.units is not None:
            out["units"] = self.units
        if self.side is not None:
            out["side"] = self.side
        if self.thickness is not None:
            out["thickness"] = self.thickness
        if self.rounding > 0:
            out["rounding"] = self.rounding
        if self.smooth > 0:
            out["smooth"] = self.smooth
        return out

    def as_dict(self):
        out = super().as_dict()
        out["units"] = "m"  # as_dict is in metres: the file's coordinates scaled to them
        out["scale"] = self.scale * (FILE_UNITS[self.units] if self.units else self.scene_length)
        return out

    def describe(self):
        return (f"mesh({self.path.name}: {len(self.V)} nodes, {len(self.T)} triangles, "
                f"{'closed' if self.closed else 'open'}, box {np.round(self.lo, 6).tolist()}.."
                f"{np.round(self.hi, 6).tolist()}) [m]")

    def surface(self):
        """The triangles ``(V (n, 3) [m], T (t, 3))`` bounding the solid."""
        return self.V, self.T

    def footprint(self):
        """Area [m^2] and centre of the convex hull of the contact surface seen from above."""
        return polygon_area_centre(plan_hull(self.V, self.offset)[0])

    def plan_outline(self, n: int = 128):
        """The convex hull of the contact surface seen from above and the mean height of its corners [m]."""
        return plan_hull(self.V, self.offset)

    # --- sharp features ---------------------------------------------------------------------------
    def _features(self):
        self.feature_edges, self.feature_normals, self.feature_corners = sharp_edges(
            self.V, self.T, self.edges, self.edge_of, self.nf, self.ne, self.boundary_edge, self.feature_angle,
            two_sided=self.thickness is not None)

    def sharp_features(self):
        """The sharp edges and their end or junction corners, with their pseudo-normals."""
        if not len(self.feature_edges):
            return None
        return SharpFeatures(self.V, self.feature_edges, self.feature_corners, self.feature_normals,
                             self.nv[self.feature_corners])
