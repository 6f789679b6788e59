"""Panel meshes with matching seam nodes, the panels placed in space, and the placement check.

Seam nodes. Every edge is cut into n segments of equal arc length,
n = max(round(L / h), ceil(turning / 15 deg), 1), so a curved edge keeps at least one segment per
15 deg of turning; the two edges of a seam both get the larger of their two counts. A seam of n
segments thus has n + 1 nodes on each side, equally spaced along each edge (the lengths may differ
by the ease, up to 5 %), and node k of side A pairs with node k of side B (``aligned``) or node
n - k (``reversed``). These boundary nodes go to the advancing-front mesher
(:func:`rftstatic.mesh.mesher.front.advance_front`) unchanged: the mesher fills the outline and its
smoothing (:func:`rftstatic.mesh.mesher.improve.improve`) never moves a boundary node. The size
field is h inside and, near the boundary, the shorter boundary segment at each node, graded
(:meth:`rftstatic.mesh.mesher.BackgroundGrid.from_samples`), so that a short edge beside long ones
(a notch, a waistband step) gets small triangles around it rather than slivers. An edge far below h
next to a corner can still stop the front (GarmentCode's jumpsuit: a 0.9 mm edge at h = 15 mm);
the error names the panel's shortest edge.

Grain. Each panel's mesh stays in panel coordinates; its grain angle [deg] is kept with it, and
:meth:`PatternMesh.combined` gives every element's warp angle [rad] from the combined mesh's x axis,
so the material frame can follow the grain line per panel.

Placement. :func:`place` maps every node to R (x, y, 0) + t (:mod:`rftstatic.garment.pattern`);
:func:`check_placement` refuses panels whose placed triangles intersect those of another panel
(:func:`rftstatic.post.measures.intersections.intersecting_pairs`, after a bounding-box test per
pair of panels), or that lie in one plane and overlap there (which the crossing test, made for a
zero-thickness sheet, does not count): a panel left at the origin, or two panels on top of each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rftstatic.garment.curves import points_in_polygon
from rftstatic.garment.pattern import PatternError, rotation_matrix
from rftstatic.mesh.mesher.domain import segments_cross
from rftstatic.mesh.trimesh import TriMesh

__all__ = ["PatternMesh", "CombinedMesh", "mesh_pattern", "edge_segments", "place", "check_placement"]

_TURN_PER_SEGMENT = math.radians(15.0)
_LAYOUT_GAP = 0.1       # gap between panels laid side by side in the combined flat mesh, in panel sizes
_PLANE_TOL = 1e-6       # coplanarity, relative to the panels' size
_GRID_CELLS_MIN, _GRID_CELLS_MAX = 200, 1000    # size-field grid: cells across a panel, at least / at most


@dataclass(frozen=True, eq=False)
class PatternMesh:
    """The meshed pattern.

    Attributes
    ----------
    pattern : the :class:`~rftstatic.garment.pattern.Pattern`
    h : target element size [m]
    meshes : per panel a :class:`~rftstatic.mesh.trimesh.TriMesh`, flat, in panel coordinates [m]
    edge_nodes : per panel, per edge, the node indices (n_k + 1,) of the panel's mesh along the edge,
        start to end
    offsets : (P + 1,) first global node id of each panel (panel p owns ``offsets[p]:offsets[p+1]``)
    seam_pairs : per seam, (n + 1, 2) global node ids, side A then side B (the tip of a dart, where a
        seam's two edges meet, pairs with itself)
    quality : per panel the mesher's :class:`~rftstatic.mesh.mesher.MeshQuality`
    """

    pattern: object
    h: float
    meshes: tuple
    edge_nodes: tuple
    offsets: np.ndarray
    seam_pairs: tuple
    quality: tuple

    @property
    def n_nodes(self):
        return int(self.offsets[-1])

    def combined(self):
        """One flat mesh of all panels, for the sewing and draping steps: :class:`CombinedMesh`."""
        shift, xs, tris = 0.0, [], []
        for p, m in enumerate(self.meshes):
            lo, hi = m.X.min(axis=0), m.X.max(axis=0)
            xs.append(m.X + np.array([shift - lo[0], 0.0]))
            shift += (hi[0] - lo[0]) * (1 + _LAYOUT_GAP)
            tris.append(m.tri + self.offsets[p])
        n_el = [len(m.tri) for m in self.meshes]
        grain = np.radians([pn.grain for pn in self.pattern.panels])
        pairs = np.concatenate(self.seam_pairs) if self.seam_pairs else np.zeros((0, 2), np.int64)
        return CombinedMesh(
            mesh=TriMesh(X=np.concatenate(xs), tri=np.concatenate(tris), name="garment"),
            panel_of_node=np.repeat(np.arange(len(self.meshes)), np.diff(self.offsets)),
            panel_of_element=np.repeat(np.arange(len(self.meshes)), n_el),
            warp_angle=np.repeat(grain, n_el), seam_pairs=pairs,
            seam_of_pair=np.repeat(np.arange(len(self.seam_pairs)), [len(q) for q in self.seam_pairs]))


@dataclass(frozen=True, eq=False)
class CombinedMesh:
    """All panels in one flat mesh (global node ids, as :meth:`PatternMesh.combined` gives it).

    Attributes
    ----------
    mesh : :class:`TriMesh` of all panels laid side by side along x (each shifted so they do not
        overlap; each element keeps its panel's flat reference geometry) [m]
    panel_of_node : (N,) int panel index of each node
    panel_of_element : (E,) int panel index of each element
    warp_angle : (E,) grain line of each element's panel from the mesh's x axis [rad]
    seam_pairs : (S, 2) int global node ids of all seams' pairs, seam after seam
    seam_of_pair : (S,) int the seam of each pair (index into ``pattern.seams``)
    """

    mesh: TriMesh
    panel_of_node: np.ndarray
    panel_of_element: np.ndarray
    warp_angle: np.ndarray
    seam_pairs: np.ndarray
    seam_of_pair: np.ndarray


def edge_segments(pattern, h):
    """Segments per edge: ``{(panel, edge): n}`` for target size h [m] (module docstring)."""
    def count(panel, k):
        return max(1, round(panel.edge_length(k) / h), math.ceil(panel.edge_turning(k) / _TURN_PER_SEGMENT - 1e-9))

    n = {(p.name, k): count(p, k) for p in pattern.panels for k in range(len(p.edges))}
    for s in pattern.seams:
        a, b = (s.a_panel, s.a_edge), (s.b_panel, s.b_edge)
        n[a] = n[b] = max(n[a], n[b])
    return n


def _mesh_panel(panel, counts, h, where):
    from rftstatic.errors import MeshingError
    from rftstatic.mesh.mesher.front import advance_front
    from rftstatic.mesh.mesher.improve import improve
    from rftstatic.mesh.mesher.quality import measure_quality
    from rftstatic.mesh.mesher.sizefield import BackgroundGrid

    pts, bedges, edge_nodes = [], [], []
    b = 0
    for j, loop in enumerate(panel.loop_edges()):
        first = b
        for k in loop:
            n = counts[panel.name, k]
            pts.append(panel.edge_points(k, n)[:-1])
            edge_nodes.append(b + np.arange(n + 1))
            b += n
        idx = np.arange(first, b)
        edge_nodes[-1][-1] = first                              # the loop closes
        x, y = np.concatenate(pts)[first:].T
        ccw = np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0
        keep = ccw == (j == 0)                                  # domain on the left: outline CCW, holes CW
        bedges.append(np.column_stack([idx, np.roll(idx, -1)] if keep else [np.roll(idx, -1), idx]))
    bpoints, bedges = np.concatenate(pts), np.concatenate(bedges)
    lo, hi = bpoints.min(axis=0), bpoints.max(axis=0)
    a_, b_ = bedges.T
    seg_len = np.hypot(*(bpoints[b_] - bpoints[a_]).T)
    local = np.full(b, np.inf)
    np.minimum.at(local, a_, seg_len)                            # the shorter boundary segment at each node
    np.minimum.at(local, b_, seg_len)
    extent = float((hi - lo).max()) + 2 * h
    spacing = min(max(float(local.min()), extent / _GRID_CELLS_MAX), extent / _GRID_CELLS_MIN)
    size = BackgroundGrid.from_samples(bpoints, np.minimum(local, h), np.r_[lo - h, hi + h], h_upper=h,
                                       spacing=spacing)
    try:
        points, tri = advance_front(bpoints, bedges.astype(np.int64), size)
    except MeshingError as err:
        lengths = [panel.edge_length(k) for k in range(len(panel.edges))]
        k = int(np.argmin(lengths))
        raise PatternError(f"{where}: the mesher failed ({err}); its shortest edge, edge {k}, is {lengths[k]:.3g} m "
                           f"long against h = {h:g} m: try a smaller h, or merge that edge into a neighbour") from None
    movable = np.ones(len(points), bool)
    movable[:b] = False
    improve(points, tri, movable)
    return TriMesh(X=points, tri=tri, name=panel.name), tuple(edge_nodes), measure_quality(points, tri, size)


def mesh_pattern(pattern, h):
    """Mesh every panel with target size ``h`` [m], seam nodes matched (module docstring).

    Returns
    -------
    :class:`PatternMesh`
    """
    if not (isinstance(h, (int, float)) and math.isfinite(h) and h > 0):
        raise PatternError(f"{pattern.source}: element size h = {h!r}; give a positive length [m]")
    smallest = min(p.size for p in pattern.panels)
    if h > 0.5 * smallest:
        raise PatternError(f"{pattern.source}: element size h = {h:g} m is more than half the smallest panel "
                           f"({smallest:g} m); use a smaller h")
    counts = edge_segments(pattern, h)
    meshes, edge_nodes, quality = [], [], []
    for p in pattern.panels:
        m, en, q = _mesh_panel(p, counts, h, f"{pattern.source}: panel {p.name!r}")
        meshes.append(m)
        edge_nodes.append(en)
        quality.append(q)
    offsets = np.concatenate([[0], np.cumsum([m.n_nodes for m in meshes])]).astype(np.int64)
    index = pattern.index
    pairs = []
    for s in pattern.seams:
        pa, pb = index[s.a_panel], index[s.b_panel]
        na = edge_nodes[pa][s.a_edge] + offsets[pa]
        nb = edge_nodes[pb][s.b_edge] + offsets[pb]
        pairs.append(np.column_stack([na, nb[::-1] if s.orientation == "reversed" else nb]))
    return PatternMesh(pattern=pattern, h=float(h), meshes=tuple(meshes), edge_nodes=tuple(edge_nodes),
                       offsets=offsets, seam_pairs=tuple(pairs), quality=tuple(quality))


def place(pmesh, *, translations=None, rotations=None):
    """Starting positions X3 (N, 3) [m] of all nodes (global ids): each panel's R (x, y, 0) + t.

    ``translations`` (P, 3) [m] and ``rotations`` (P, 3) [deg] replace the pattern's placements
    (e.g. a synthetic closing placement in a test).
    """
    panels = pmesh.pattern.panels
    t = np.array([p.translation for p in panels]) if translations is None else np.asarray(translations, float)
    r = np.array([p.rotation for p in panels]) if rotations is None else np.asarray(rotations, float)
    out = np.empty((pmesh.n_nodes, 3))
    for p, m in enumerate(pmesh.meshes):
        R = rotation_matrix(r[p])
        out[pmesh.offsets[p]:pmesh.offsets[p + 1]] = m.X @ R[:, :2].T + t[p]
    return out


def check_placement(pmesh, X3=None):
    """Raise :class:`PatternError` when two placed panels intersect or overlap in one plane.

    Parameters
    ----------
    pmesh : :class:`PatternMesh`
    X3 : (N, 3) node positions [m]; default :func:`place` of the pattern's placement
    """
    from rftstatic.post.measures.intersections import intersecting_pairs

    x = place(pmesh) if X3 is None else np.asarray(X3, float)
    pat, off = pmesh.pattern, pmesh.offsets
    scale = max(float(np.ptp(x, axis=0).max()), 1e-300)
    for i in range(len(pat.panels)):
        for j in range(i + 1, len(pat.panels)):
            xi, xj = x[off[i]:off[i + 1]], x[off[j]:off[j + 1]]
            if (xi.min(axis=0) > xj.max(axis=0) + _PLANE_TOL * scale).any() or \
                    (xj.min(axis=0) > xi.max(axis=0) + _PLANE_TOL * scale).any():
                continue
            where = f"{pat.source}: panels {pat.panels[i].name!r} and {pat.panels[j].name!r}"
            ti, tj = pmesh.meshes[i].tri, pmesh.meshes[j].tri + len(xi)
            if len(intersecting_pairs(np.vstack([xi, xj]), np.vstack([ti, tj]))):
                raise PatternError(f"{where} intersect in their placement; change their translation or rotation "
                                   "so that they start apart")
            if _coplanar_overlap(pmesh, i, j, xi, xj, scale):
                raise PatternError(f"{where} lie in one plane and overlap at the start (a panel not placed?); "
                                   "give each panel its own translation/rotation around the body")


def _coplanar_overlap(pmesh, i, j, xi, xj, scale):
    """Panels i and j in one plane with overlapping areas: a centroid of one inside the other's
    outline, or outline edges properly crossing (touching along a seam is not overlap)."""
    def frame(x):
        c = x.mean(axis=0)
        _, _, vt = np.linalg.svd(x - c, full_matrices=False)
        return c, vt
    ci, vi = frame(xi)
    _, vj = frame(xj)
    tol = _PLANE_TOL * scale
    if abs(abs(vi[2] @ vj[2]) - 1.0) > _PLANE_TOL or np.abs((xj - ci) @ vi[2]).max() > tol:
        return False
    to2 = lambda x: (x - ci) @ vi[:2].T                      # noqa: E731 -- the common plane's coordinates
    sides = []                                               # every loop's sides, as segment ends
    for p, x in ((i, xi), (j, xj)):
        a = np.concatenate([e[:-1] for e in pmesh.edge_nodes[p]])
        b = np.concatenate([e[1:] for e in pmesh.edge_nodes[p]])
        sides.append((to2(x[a]), to2(x[b])))
    cent = [to2(x[m.tri].mean(axis=1)) for x, m in ((xi, pmesh.meshes[i]), (xj, pmesh.meshes[j]))]
    if points_in_polygon(cent[0], *sides[1]).any() or points_in_polygon(cent[1], *sides[0]).any():
        return True
    (a0, a1), (b0, b1) = sides
    return bool(segments_cross(a0, a1, b0, b1, tol=tol).any())
