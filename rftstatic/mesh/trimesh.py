"""Triangle meshes of the flat reference configuration, and their generators.

A :class:`TriMesh` holds the flat reference coordinates ``X (N, 2)`` [m], counter-clockwise
triangles ``tri (E, 3)`` and the height ``z0`` [m] of the reference plane. The fabric's reference
configuration is flat (§2.1), so every mesh -- structured, polar or read from a file -- lives in
the plane z = z0. Edge topology (which triangle lies across which edge) is computed once, with
vectorised numpy, and cached.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import math

import numpy as np

from rftstatic.errors import MeshError
from rftstatic.mesh.folds import FoldLines, fold_edge_mask
from rftstatic.mesh.topology import EdgeTopology, edge_topology

PATTERNS = ("right", "left", "alternate", "union-jack")



BRUTE_LOCATE_POINTS = 64
BRUTE_LOCATE_PAIRS = 4_000_000
"""For a few points (supports, probes: up to :data:`BRUTE_LOCATE_POINTS`, and this many point-triangle
pairs) :meth:`TriMesh.locate` tests every triangle (no matplotlib import: 0.5 s of a strip run's
1.5 s start-up); for more (a remesh transfer), matplotlib's trapezoid map, whose choice of triangle for
a point on a shared edge the transferred fields (and the remeshed relaxation's fold branch) depend on."""


@dataclass(frozen=True, eq=False)
class TriMesh:
    """A triangle mesh of the flat reference configuration.

    Parameters
    ----------
    X : (N, 2) reference coordinates [m]
    tri : (E, 3) node indices; reoriented to counter-clockwise if needed (a flat mesh)
    z0 : height of the reference plane [m]
    name : label for summaries
    element_X : (E, 3, 2) flat reference coordinates of every element's corners [m], for a mesh sewn from
        panels (:mod:`rftstatic.garment.sewing`): no single flat chart holds it, each element keeps the shape
        it has in its panel (its x axis along the panel's grain line, the warp); counter-clockwise, as ``tri``.
        None: ``X[tri]``, the flat mesh of §2.1. Given, ``X`` is only a chart for locating nodes (the pattern
        layout), and areas, sizes, the RF patches (:func:`rftstatic.element.patch.build_patches`, neighbours
        unfolded across their shared edge) and the membrane come from ``element_X``
    placed : (N, 3) reference positions in space [m] that displacements are measured from, with
        ``element_X``: the panels as placed around the body, or a sewn garment's state where a stage starts
        (:attr:`X3`). None: ``(X, z0)``
    folds : creased edges (:class:`rftstatic.mesh.folds.FoldLines`): the RF patches end there and hinges hold
        the crease (:mod:`rftstatic.element.hinge`); None: the sheet is smooth across every interior edge
    seams : (S, 2) node pairs of seams still open (a garment's panels being sewn, :mod:`rftstatic.garment.sewing`):
        the self-contact does not act between primitives that will share a node once they are sewn
        (:class:`rftstatic.contact.self_contact.broad_phase.SheetPrimitives`); None: none
    """

    X: np.ndarray
    tri: np.ndarray
    z0: float = 0.0
    name: str = "mesh"
    info: dict = field(default_factory=dict)
    element_X: np.ndarray | None = None
    placed: np.ndarray | None = None
    folds: FoldLines | None = None
    seams: np.ndarray | None = None

    def __post_init__(self):
        X = np.ascontiguousarray(self.X, dtype=float)
        tri = np.ascontiguousarray(self.tri, dtype=np.int64)
        if X.ndim != 2 or X.shape[1] != 2:
            raise MeshError(f"X must have shape (N, 2), got {X.shape}")
        if tri.ndim != 2 or tri.shape[1] != 3 or len(tri) == 0:
            raise MeshError(f"tri must have shape (E, 3) with E > 0, got {tri.shape}")
        if tri.min() < 0 or tri.max() >= len(X):
            raise MeshError(f"tri refers to nodes outside 0..{len(X) - 1} (min {tri.min()}, max {tri.max()})")
        if not np.isfinite(X).all():
            raise MeshError("X contains non-finite coordinates")
        if self.element_X is not None or self.placed is not None:
            self._check_sewn(X, tri)
        corners = X[tri] if self.element_X is None else self.element_X
        area2 = _corner_area2(corners)
        flip = area2 < 0
        if flip.any() and self.element_X is not None:
            e = int(np.flatnonzero(flip)[0])
            raise MeshError(f"{flip.sum()} element(s) of a sewn mesh are clockwise in element_X (first: element {e}); "
                            "give every element's corners counter-clockwise, as in its panel")
        if flip.any():
            tri = tri.copy()
            tri[flip] = tri[flip][:, [0, 2, 1]]
            area2 = np.abs(area2)
        scale = float(np.max(np.ptp(corners.reshape(-1, 2), axis=0))) ** 2
        tiny = area2 <= 1e-14 * scale
        if tiny.any():
            e = int(np.flatnonzero(tiny)[0])
            c = corners[e].mean(axis=0)
            raise MeshError(
                f"{tiny.sum()} degenerate (zero-area) triangle(s), first: element {e} at "
                f"({c[0]:.6g}, {c[1]:.6g}); remove or re-mesh them"
            )
        unused = np.setdiff1d(np.arange(len(X)), tri.ravel())
        if len(unused):
            raise MeshError(f"{len(unused)} node(s) belong to no triangle (first: node {unused[0]}); remove them")
        object.__setattr__(self, "X", X)
        object.__setattr__(self, "tri", tri)
        self.topology  # noqa: B018 -- validates the edge structure now (non-manifold edges)
        if self.folds is not None:
            self.fold_mask  # noqa: B018 -- every fold edge an interior edge of the mesh
        if self.seams is not None:
            seams = np.asarray(self.seams, dtype=np.int64).reshape(-1, 2)
            if len(seams) and (seams.min() < 0 or seams.max() >= len(X)):
                raise MeshError(f"seams refer to nodes outside 0..{len(X) - 1}")
            object.__setattr__(self, "seams", seams)

    def _check_sewn(self, X, tri):
        """Shapes and values of ``element_X`` and ``placed`` (given together)."""
        if self.element_X is None or self.placed is None:
            raise MeshError("a sewn mesh needs both element_X (E, 3, 2) and placed (N, 3); got one of them")
        ex = np.ascontiguousarray(self.element_X, dtype=float)
        pl = np.ascontiguousarray(self.placed, dtype=float)
        if ex.shape != (len(tri), 3, 2) or pl.shape != (len(X), 3):
            raise MeshError(f"element_X must have shape ({len(tri)}, 3, 2) and placed ({len(X)}, 3); "
                            f"got {ex.shape} and {pl.shape}")
        if not (np.isfinite(ex).all() and np.isfinite(pl).all()):
            raise MeshError("element_X or placed contains non-finite coordinates")
        object.__setattr__(self, "element_X", ex)
        object.__setattr__(self, "placed", pl)

    @cached_property
    def fold_mask(self) -> np.ndarray:
        """(E, 3) bool: local edge k of element e is a fold edge (:attr:`folds`)."""
        return fold_edge_mask(self.topology, self.folds, self.n_nodes)

    @cached_property
    def chart_is_flat(self) -> bool:
        """Whether ``X`` is a flat layout of the mesh (every triangle as large there as its reference, to 1e-9), so
        that points can be located in it (:meth:`locate`): always for a flat mesh; for a sewn one only when its
        chart happens to be one (a single panel placed flat, the circle skirt's ring seen from above)."""
        if self.element_X is None:
            return True
        return bool(np.allclose(np.abs(_signed_area2(self.X, self.tri)), 2.0 * self.area, rtol=1e-9,
                                atol=1e-9 * float(self.area.max())))

    @property
    def corners(self) -> np.ndarray:
        """(E, 3, 2) flat reference coordinates of every element's corners [m]: ``element_X``, or ``X[tri]``."""
        return self.X[self.tri] if self.element_X is None else self.element_X

    # --- sizes ------------------------------------------------------------------------------
    @property
    def n_nodes(self) -> int:
        return len(self.X)

    @property
    def n_elements(self) -> int:
        return len(self.tri)

    @cached_property
    def area(self) -> np.ndarray:
        """(E,) reference triangle areas [m^2]."""
        return 0.5 * _corner_area2(self.corners)

    @cached_property
    def node_area(self) -> np.ndarray:
        """(N,) lumped nodal areas, a third of each adjacent triangle [m^2]."""
        return np.bincount(self.tri.ravel(), np.repeat(self.area / 3.0, 3), minlength=self.n_nodes)

    @cached_property
    def element_size(self) -> np.ndarray:
        """(E,) average side length h of each triangle [m] (the h of Eq. 28)."""
        P = self.corners
        d = P[:, [1, 2, 0]] - P[:, [2, 0, 1]]
        return np.linalg.norm(d, axis=2).mean(axis=1)

    @property
    def X3(self) -> np.ndarray:
        """(N, 3) reference positions in space [m]: ``placed``, or the flat plane ``(X, z0)``."""
        if self.placed is not None:
            return self.placed
        return np.column_stack([self.X, np.full(self.n_nodes, self.z0)])

    @cached_property
    def topology(self) -> EdgeTopology:
        return edge_topology(self.tri, self.n_nodes)

    @cached_property
    def boundary_nodes(self) -> np.ndarray:
        """Sorted indices of nodes on the boundary."""
        t = self.topology
        e, k = np.nonzero(t.is_boundary)
        return np.unique(np.r_[self.tri[e, (k + 1) % 3], self.tri[e, (k + 2) % 3]])

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """(B, 2) boundary edges, oriented counter-clockwise around the domain."""
        e, k = np.nonzero(self.topology.is_boundary)
        return np.stack([self.tri[e, (k + 1) % 3], self.tri[e, (k + 2) % 3]], axis=1)

    def nodes_in_box(self, xmin, xmax, ymin, ymax, tol=None) -> np.ndarray:
        """Indices of nodes with reference coordinates in the box (inclusive, with tolerance) [m]."""
        if tol is None:
            tol = 1e-6 * float(np.ptp(self.X, axis=0).max())
        x, y = self.X[:, 0], self.X[:, 1]
        m = (x >= xmin - tol) & (x <= xmax + tol) & (y >= ymin - tol) & (y <= ymax + tol)
        return np.flatnonzero(m)

    def nearest_node(self, points) -> np.ndarray:
        """Index of the node nearest to each reference point ``points (P, 2)`` [m]."""
        from scipy.spatial import cKDTree

        return cKDTree(self.X).query(np.atleast_2d(points))[1]

    def locate(self, points):
        """Element containing each reference point and its barycentric coordinates.

        Returns ``(elem (P,), bary (P, 3))``; elem is -1 for points outside the mesh.
        """
        if not self.chart_is_flat:
            raise MeshError(f"{self.name}: a mesh sewn from panels has no flat chart to locate reference points in "
                            "(its X is the plan view of the placed panels, which overlap); pick nodes by position")
        pts = np.atleast_2d(np.asarray(points, float))
        brute = len(pts) <= BRUTE_LOCATE_POINTS and len(pts) * self.n_elements <= BRUTE_LOCATE_PAIRS
        if brute:
            elem = self._locate_brute(pts)
        else:  # many points (a remesh transfer): matplotlib's trapezoid-map search
            from matplotlib.tri import Triangulation

            finder = Triangulation(self.X[:, 0], self.X[:, 1], self.tri).get_trifinder()
            elem = np.asarray(finder(pts[:, 0], pts[:, 1]), dtype=np.int64)
        P = self.X[self.tri[np.maximum(elem, 0)]]
        T = np.stack([P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]], axis=2)
        l12 = np.linalg.solve(T, (pts - P[:, 0])[..., None])[..., 0]
        bary = np.column_stack([1 - l12.sum(axis=1), l12])
        if brute:  # a point on an edge (to the 1e-10 tolerance of the search) gets coordinates >= 0
            found = elem >= 0
            bary[found] = np.clip(bary[found], 0.0, None)
            bary[found] /= bary[found].sum(axis=1, keepdims=True)
        return elem, bary

    def _locate_brute(self, pts) -> np.ndarray:
        """Element containing each point ``(P, 2)`` [m] by the barycentric coordinates against every
        triangle (the one it lies deepest in, edges included to 1e-10 of the element; -1 outside)."""
        P = self.X[self.tri]  # (E, 3, 2)
        e1, e2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]  # (E,) twice the signed area
        d = pts[:, None, :] - P[None, :, 0]  # (P, E, 2)
        l1 = (d[..., 0] * e2[:, 1] - d[..., 1] * e2[:, 0]) / det
        l2 = (e1[:, 0] * d[..., 1] - e1[:, 1] * d[..., 0]) / det
        depth = np.minimum(np.minimum(l1, l2), 1.0 - l1 - l2)  # > 0 inside, 0 on an edge
        best = depth.argmax(axis=1)  # the triangle the point is deepest in (one side of a shared edge)
        return np.where(depth[np.arange(len(pts)), best] >= -1e-10, best, -1).astype(np.int64)

    def summary(self) -> dict:
        return {
            "name": self.name,
            "nodes": self.n_nodes,
            "elements": self.n_elements,
            "h_mean_m": float(self.element_size.mean()),
            **self.info,
        }


def _signed_area2(X, tri):
    return _corner_area2(X[tri])


def _corner_area2(P):
    """Twice the signed areas ``(E,)`` of triangles with corners ``P (E, 3, 2)``."""
    d1, d2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    return d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]


# --- generators ------------------------------------------------------------------------------


def rectangle(lx, ly, nx, ny, *, origin=(0.0, 0.0), pattern="right", z0=0.0) -> TriMesh:
    """Structured triangulation of a ``lx`` x ``ly`` rectangle with ``nx`` x ``ny`` nodes.

    Parameters
    ----------
    lx, ly : side lengths [m]
    nx, ny : nodes along x and y (>= 2)
    origin : lower-left corner [m]
    pattern : diagonal pattern of each grid cell: ``"right"`` (all /), ``"left"`` (all \\),
        ``"alternate"`` (/ and \\ in a checkerboard) or ``"union-jack"`` (mirrored about the centre
        lines, so the mesh has the rectangle's symmetries).
    """
    nx, ny = int(nx), int(ny)
    if nx < 2 or ny < 2:
        raise MeshError(f"a rectangle needs at least 2 x 2 nodes, got {nx} x {ny}")
    if lx <= 0 or ly <= 0:
        raise MeshError(f"rectangle sides must be positive, got {lx} x {ly}")
    if pattern not in PATTERNS:
        raise MeshError(f'unknown diagonal pattern "{pattern}"; use one of {", ".join(PATTERNS)}')
    xs = origin[0] + np.linspace(0.0, lx, nx)
    ys = origin[1] + np.linspace(0.0, ly, ny)
    X = np.stack(np.meshgrid(xs, ys, indexing="xy"), axis=-1).reshape(-1, 2)
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="xy")
    i, j = i.ravel(), j.ravel()
    n00 = j * nx + i
    n10, n01, n11 = n00 + 1, n00 + nx, n00 + nx + 1
    if pattern == "right":
        slash = np.ones_like(i, dtype=bool)
    elif pattern == "left":
        slash = np.zeros_like(i, dtype=bool)
    elif pattern == "alternate":
        slash = (i + j) % 2 == 0
    else:  # union-jack: diagonals point away from the centre
        ci, cj = (nx - 1) / 2.0, (ny - 1) / 2.0
        slash = ((i + 0.5 - ci) * (j + 0.5 - cj)) > 0
    t_slash = np.stack([np.stack([n00, n10, n11], 1), np.stack([n00, n11, n01], 1)], 1)
    t_back = np.stack([np.stack([n00, n10, n01], 1), np.stack([n10, n11, n01], 1)], 1)
    tri = np.where(slash[:, None, None], t_slash, t_back).reshape(-1, 3)
    info = {"generator": "rectangle", "size": [lx, ly], "nodes_xy": [nx, ny], "pattern": pattern}
    return TriMesh(X, tri, z0=z0, name=f"rectangle {nx}x{ny}", info=info)


def polar(r_outer, n_radial, n_circ, *, r_inner=0.0, centre=(0.0, 0.0), pattern="alternate",
          z0=0.0, grading=1.0) -> TriMesh:
    """Polar mesh of a disc or annulus (a square sheet meshed in rings is :func:`square_polar`).

    Parameters
    ----------
    r_outer : outer radius [m]
    n_radial : nodes along a radius, including the inner ring (and the centre for a disc)
    n_circ : nodes around each ring
    r_inner : inner radius [m]; 0 gives a disc with a centre node (fan of triangles around it)
    pattern : diagonal of each quadrilateral: ``"right"``, ``"left"`` or ``"alternate"``.
    grading : outermost ring spacing over the innermost (geometric progression; 1: uniform rings). Below 1
        the rings crowd towards the outer edge, above 1 towards the centre (a clamped inner ring: the bend
        at a drape tester's disc edge).
    """
    n_radial, n_circ = int(n_radial), int(n_circ)
    if not (np.isfinite(grading) and 0.05 <= grading <= 20.0):
        raise MeshError(f"polar mesh grading = {grading!r}: give the outer/inner ring spacing ratio in [0.05, 20]")
    if n_radial < 2 or n_circ < 3:
        raise MeshError(f"a polar mesh needs n_radial >= 2 and n_circ >= 3, got {n_radial}, {n_circ}")
    if not (0 <= r_inner < r_outer):
        raise MeshError(f"need 0 <= r_inner < r_outer, got r_inner={r_inner}, r_outer={r_outer}")
    if pattern not in ("right", "left", "alternate"):
        raise MeshError(f'unknown diagonal pattern "{pattern}" for a polar mesh; use right, left or alternate')
    theta = 2 * np.pi * np.arange(n_circ) / n_circ
    direction = np.column_stack([np.cos(theta), np.sin(theta)])
    disc = r_inner == 0.0
    steps = float(grading) ** (np.arange(n_radial - 1) / max(n_radial - 2, 1))
    rings = r_inner + (r_outer - r_inner) * np.concatenate([[0.0], np.cumsum(steps) / steps.sum()])
    first = 1 if disc else 0
    X_rings = (rings[first:, None, None] * direction[None]).reshape(-1, 2)
    X = np.vstack([np.zeros((1, 2)), X_rings]) if disc else X_rings
    X = X + np.asarray(centre, float)
    offset = 1 if disc else 0
    nr = n_radial - first  # number of rings with n_circ nodes
    r, c = np.meshgrid(np.arange(nr - 1), np.arange(n_circ), indexing="ij")
    r, c = r.ravel(), c.ravel()
    a = offset + r * n_circ + c
    b = offset + r * n_circ + (c + 1) % n_circ
    a2, b2 = a + n_circ, b + n_circ
    if pattern == "right":
        diag = np.ones_like(r, dtype=bool)
    elif pattern == "left":
        diag = np.zeros_like(r, dtype=bool)
    else:
        diag = (r + c) % 2 == 0
    t1 = np.where(diag[:, None], np.stack([a, b, b2], 1), np.stack([a, b, a2], 1))
    t2 = np.where(diag[:, None], np.stack([a, b2, a2], 1), np.stack([b, b2, a2], 1))
    tri = np.vstack([t1, t2])
    if disc:
        c = np.arange(n_circ)
        fan = np.stack([np.zeros(n_circ, int), 1 + c, 1 + (c + 1) % n_circ], 1)
        tri = np.vstack([fan, tri])
    kind = "disc" if disc else "annulus"
    info = {"generator": kind, "r_outer": r_outer, "r_inner": r_inner, "nodes_radial_circ": [n_radial, n_circ],
            "grading": float(grading)}
    return TriMesh(X, tri, z0=z0, name=f"{kind} {n_radial}x{n_circ}", info=info)


def equilateral_nodes(area, h) -> float:
    """Nodes of a mesh of equilateral triangles of side ``h`` on ``area`` (any one length unit): ``2 area /
    (sqrt(3) h^2)``, two triangles of area ``sqrt(3) h^2 / 4`` per node; what the advancing-front mesher
    gives at target size ``h``, boundary effects aside (Python floats: inf, no warning, on overflow)."""
    return 2.0 / math.sqrt(3.0) * float(area) / h / h


def square_polar_core_radius(half_side, n_radial, n_circ) -> float:
    """The default core radius of :func:`square_polar` [m]: the quadrilaterals next to the core are square
    (circumferential spacing ``2 pi r0 / n_circ`` = radial spacing ``(R - r0) / (n_radial - 1)``)."""
    return float(half_side) / (1.0 + 2 * np.pi / n_circ * (n_radial - 1))


def square_polar_nodes(half_side, n_radial, n_circ, core_radius=None) -> int:
    """Nodes of :func:`square_polar` without meshing its core: the rings exactly, the core's interior as
    :func:`equilateral_nodes` on its disc at its spacing less its boundary ring (within a few percent)."""
    r0 = square_polar_core_radius(half_side, n_radial, n_circ) if core_radius is None else float(core_radius)
    core = equilateral_nodes(np.pi * r0 * r0, 2 * np.pi * r0 / n_circ)
    return int(n_radial * n_circ + max(0.0, core - n_circ))


def polar_nodes(n_radial, n_circ, r_inner=0.0) -> int:
    """Nodes of :func:`polar`: ``n_radial`` rings of ``n_circ``, the innermost of a disc being its centre."""
    return int((n_radial - 1) * n_circ + 1 if r_inner == 0.0 else n_radial * n_circ)


def square_polar(half_side, n_radial, n_circ, *, centre=(0.0, 0.0), core_radius=None, pattern="right",
                 z0=0.0) -> TriMesh:
    """A square sheet meshed by rings that blend from a circle to the square's edge, around a core.

    This is how we read the paper's "21 x 160" and "31 x 240" node meshes of the 50 x 50 cm sheet
    on the round pedestal (§4.4, Fig. 10): ``n_radial`` rings of ``n_circ`` nodes; ring 0 is a circle
    of radius ``core_radius``, the last ring is the square's edge, ring t in between is
    ``rho(t) [(1 - t) c(theta) + t c(theta) / |c(theta)|_inf]`` with ``rho`` linear in t. A polar fan
    down to the centre would put slivers, and patches whose six points lie on a line pair (singular,
    Eq. 2), at the centre; the disc inside ring 0 is instead meshed by our advancing-front mesher
    with ring 0's nodes as its boundary. The default ``core_radius`` makes the quadrilaterals next to
    the core square (circumferential spacing = radial spacing).

    Parameters
    ----------
    half_side : half the side of the square sheet [m]
    n_radial, n_circ : rings and nodes per ring
    core_radius : radius of the unstructured core [m]
    """
    from rftstatic.mesh.mesher import Domain, generate

    n_radial, n_circ = int(n_radial), int(n_circ)
    if n_radial < 2 or n_circ < 8:
        raise MeshError(f"square_polar needs n_radial >= 2 and n_circ >= 8, got {n_radial}, {n_circ}")
    if pattern not in ("right", "left", "alternate"):
        raise MeshError(f'unknown diagonal pattern "{pattern}" for a square-polar mesh; use right, left or alternate')
    R = float(half_side)
    if core_radius is None:
        core_radius = square_polar_core_radius(R, n_radial, n_circ)
    if not (0 < core_radius < R):
        raise MeshError(f"core_radius must lie in (0, half_side = {R}), got {core_radius}")
    theta = 2 * np.pi * np.arange(n_circ) / n_circ
    c = np.column_stack([np.cos(theta), np.sin(theta)])
    q = c / np.abs(c).max(axis=1, keepdims=True)
    t = np.linspace(0.0, 1.0, n_radial)[:, None, None]
    rho = core_radius + t * (R - core_radius)
    rings = (rho * ((1 - t) * c + t * q)).reshape(-1, 2)
    r, k = np.meshgrid(np.arange(n_radial - 1), np.arange(n_circ), indexing="ij")
    r, k = r.ravel(), k.ravel()
    a_, b_ = r * n_circ + k, r * n_circ + (k + 1) % n_circ
    a2, b2 = a_ + n_circ, b_ + n_circ
    diag = np.ones_like(r, bool) if pattern == "right" else ((r + k) % 2 == 0 if pattern == "alternate" else np.zeros_like(r, bool))
    t1 = np.where(diag[:, None], np.stack([a_, b_, b2], 1), np.stack([a_, b_, a2], 1))
    t2 = np.where(diag[:, None], np.stack([a_, b2, a2], 1), np.stack([b_, b2, a2], 1))
    core = generate(Domain.polygon(rings[:n_circ]), 2 * np.pi * core_radius / n_circ)
    # core nodes on ring 0 are ring 0's own nodes: match them, append the interior ones
    from scipy.spatial import cKDTree

    dist, idx = cKDTree(rings[:n_circ]).query(core.points)
    on_ring = dist < 1e-6 * core_radius
    remap = np.empty(len(core.points), dtype=np.int64)
    remap[on_ring] = idx[on_ring]
    interior = np.flatnonzero(~on_ring)
    remap[interior] = len(rings) + np.arange(len(interior))
    X = np.vstack([rings, core.points[interior]]) + np.asarray(centre, float)
    tri = np.vstack([t1, t2, remap[core.triangles]])
    info = {"generator": "square-polar", "half_side": R, "nodes_radial_circ": [n_radial, n_circ],
            "core_radius": core_radius, "core_nodes": int(len(interior))}
    return TriMesh(X, tri, z0=z0, name=f"square-polar {n_radial}x{n_circ}", info=info)


def read(path, *, length_scale=1.0, z0=None) -> TriMesh:
    """Read a flat triangle mesh with meshio (any format it reads), checked as every surface file is
    (:func:`rftstatic.mesh.surface.check_triangles`: degenerate, duplicate triangles, non-manifold edges).

    Parameters
    ----------
    path : file name
    length_scale : SI value of the file's length unit [m]
    z0 : height of the reference plane [m]; default: the file's (constant) z
    """
    from rftstatic.mesh.surface import check_triangles, read_triangles

    P, tri, _ = read_triangles(path, quads="refuse")
    P = P * length_scale
    z = P[:, 2]
    span = max(np.ptp(P[:, :2], axis=0).max(), 1e-300)
    if np.ptp(z) > 1e-9 * span:
        raise MeshError(
            f"{path}: the mesh is not flat in a plane z = const (z spans {np.ptp(z):.3g}); the reference "
            "configuration of a fabric is flat: export it in the x-y plane"
        )
    used = np.unique(tri)
    _, first, count = np.unique(np.round(P[used, :2] / span, 12), axis=0, return_index=True, return_counts=True)
    if (count > 1).any():
        i = int(used[first[np.argmax(count > 1)]])
        raise MeshError(f"{path}: node {i} at {P[i, :2].tolist()} is repeated (coincident nodes); merge "
                        "duplicate nodes before exporting (the sheet would come apart there)")
    check_triangles(P, tri, where=str(path))
    remap = np.full(len(P), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    mesh_z0 = float(z[used].mean()) if z0 is None else z0
    return TriMesh(P[used, :2], remap[tri], z0=mesh_z0, name=str(path), info={"generator": "file", "path": str(path)})
