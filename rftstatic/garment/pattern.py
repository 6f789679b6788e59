"""The sewing pattern: panels (flat outlines with a grain line and a placement) and the seams joining them.

Everything is in SI: lengths [m], angles [deg] as a pattern states them. A :class:`Pattern` checks
itself when built (:func:`check_pattern`); each error is a :class:`PatternError` that names the
pattern's file, the panel and the edge, and says what to change:

- an edge of (nearly) zero length (below 1e-6 of its panel's size);
- an arc whose radius is below half its chord; an outline that is not a closed chain of edges;
- a self-intersecting outline (its curved edges sampled at 32 segments each, every pair of
  non-adjacent segments tested), holes crossing it or each other, a hole outside the outline;
- a seam naming a missing panel or edge; an edge in two seams (or sewn to itself);
- a seam whose two edges differ in length by more than the pattern's ``seam_tolerance``, by default
  :data:`SEAM_LENGTH_TOLERANCE` (5 % of the longer: sewers ease a little fullness into a seam, more
  is a drafting error -- or a gathered seam, which a pattern states by a larger ``seam_tolerance``;
  GarmentCode's sample dress sews a 28.7 cm bodice waist to 22.0 cm of skirt, 23 %).

A panel not placed (overlapping another at the start) needs the meshes:
:func:`rftstatic.garment.meshing.check_placement`.

Placement (GarmentCode's convention, that of its simulator ``pygarment.meshgen``): a panel point
(x, y) is at R (x, y, 0) + t in space, t the translation [m] and R = Rz(gamma) Ry(beta) Rx(alpha)
for ``rotation = (alpha, beta, gamma)`` [deg] (Maya's "xyz" order: about x first, then y, then z,
fixed axes). GarmentCode's pattern writer (``Panel.assembly``) stores scipy's intrinsic "XYZ" angles
(R = Rx Ry Rz); the two agree when at most one angle is nonzero, as in GarmentCode's sample patterns,
and differ otherwise: such a file places its panels as GarmentCode's simulator does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rftstatic.errors import SceneError
from rftstatic.garment.curves import EDGE_KINDS, edge_length, edge_points, edge_turning, points_in_polygon
from rftstatic.mesh.mesher.domain import segments_cross

__all__ = ["PatternError", "Edge", "Panel", "Seam", "Pattern", "check_pattern", "rotation_matrix",
           "SEAM_KINDS", "ORIENTATIONS", "SEAM_LENGTH_TOLERANCE", "GRAIN_DEFAULT"]

SEAM_KINDS = ("sew", "fold", "open")
"""``sew``: the two edges are sewn together; ``fold``: a hem turned back on itself (the edges
join along a fold line); ``open``: paired but left open (a slit, a placket)."""

ORIENTATIONS = ("reversed", "aligned")
"""How a seam's edges pair: ``reversed`` -- A's start meets B's end (two panels drawn
counter-clockwise and sewn right side to right side, GarmentCode's default); ``aligned`` -- start
meets start (GarmentCode's ``"right_wrong"`` stitch)."""

SEAM_LENGTH_TOLERANCE = 0.05
"""Largest relative length difference of a seam's two edges, |L_a - L_b| / max(L_a, L_b) [-]."""

GRAIN_DEFAULT = 90.0
"""Grain line (warp direction) of a panel that states none: along the panel's y axis [deg], the
vertical of a pattern piece drawn upright, as GarmentCode draws them."""

_ZERO_EDGE = 1e-6       # relative to the panel's size
_CHECK_SEGMENTS = 32    # segments per curved edge in the self-intersection check


class PatternError(SceneError):
    """Invalid sewing pattern; the message names the file, panel and edge, and what to change."""


@dataclass(frozen=True)
class Edge:
    """One edge of a panel outline, from vertex ``start`` to vertex ``end``.

    Attributes
    ----------
    start, end : vertex indices into the panel's ``vertices``
    kind : ``"line"``, ``"arc"`` or ``"bezier"`` (:mod:`rftstatic.garment.curves`)
    radius : arc radius [m] (arcs only)
    large : the arc spans more than half its circle (arcs only)
    right : the arc's midpoint lies right of the chord start -> end (arcs only)
    controls : Bézier control points ((x, y), ...) [m], one (quadratic) or two (cubic)
    """

    start: int
    end: int
    kind: str = "line"
    radius: float = 0.0
    large: bool = False
    right: bool = False
    controls: tuple = ()

    def shape(self):
        """Keyword arguments of the :mod:`rftstatic.garment.curves` functions for this edge."""
        return dict(radius=self.radius, large=self.large, right=self.right, controls=self.controls)


@dataclass(frozen=True, eq=False)
class Panel:
    """A flat pattern piece.

    Attributes
    ----------
    name : unique within the pattern
    vertices : (M, 2) outline vertices in panel coordinates [m]
    edges : the closed loops' edges, loop after loop, edge k ending where the next edge of its loop
        starts; any orientation
    loops : number of edges of each closed loop, the outline first, then the holes (a ring panel's
        waist); default one loop of all edges
    grain : grain line = warp direction, counter-clockwise from the panel's x axis [deg]
    translation : (3,) placement t [m]
    rotation : (3,) placement Euler angles (alpha, beta, gamma) [deg] (module docstring)
    """

    name: str
    vertices: np.ndarray
    edges: tuple
    grain: float = GRAIN_DEFAULT
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    loops: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "vertices", np.asarray(self.vertices, dtype=float).reshape(-1, 2))
        object.__setattr__(self, "edges", tuple(self.edges))
        object.__setattr__(self, "loops", tuple(int(n) for n in self.loops) or (len(self.edges),))
        object.__setattr__(self, "translation", np.asarray(self.translation, dtype=float).reshape(3))
        object.__setattr__(self, "rotation", np.asarray(self.rotation, dtype=float).reshape(3))

    def ends(self, k):
        """Start and end points (2,), (2,) [m] of edge k."""
        e = self.edges[k]
        return self.vertices[e.start], self.vertices[e.end]

    def edge_length(self, k):
        """Arc length of edge k [m]."""
        return edge_length(*self.ends(k), self.edges[k].kind, **self.edges[k].shape())

    def edge_turning(self, k):
        """Tangent turning along edge k [rad] (0 for a straight edge)."""
        return edge_turning(*self.ends(k), self.edges[k].kind, **self.edges[k].shape())

    def edge_points(self, k, n):
        """(n+1, 2) points along edge k, equally spaced by arc length, start to end [m]."""
        return edge_points(*self.ends(k), n, self.edges[k].kind, **self.edges[k].shape())

    def loop_edges(self):
        """Edge indices of each loop: a tuple of ranges, the outline first."""
        ends = np.cumsum((0,) + self.loops)
        return tuple(range(int(a), int(b)) for a, b in zip(ends[:-1], ends[1:]))

    def next_edge(self, k):
        """The edge that follows edge k in its loop."""
        loop = next(r for r in self.loop_edges() if k in r)
        return loop.start + (k + 1 - loop.start) % len(loop)

    def outline(self, per_curve=_CHECK_SEGMENTS):
        """The loops as polylines: points (S, 2) [m], the segment from point s to the next point of its
        loop, the edge (S,) and the loop (S,) each segment belongs to, and the next point's index (S,)."""
        pts, owner, loop, nxt = [], [], [], []
        start = 0
        for j, edges in enumerate(self.loop_edges()):
            first = start
            for k in edges:
                n = 1 if self.edges[k].kind == "line" else per_curve
                pts.append(self.edge_points(k, n)[:-1])
                owner.append(np.full(n, k))
                loop.append(np.full(n, j))
                start += n
            nxt.append(np.r_[np.arange(first + 1, start), first])
        return np.concatenate(pts), np.concatenate(owner), np.concatenate(loop), np.concatenate(nxt)

    @property
    def size(self):
        """Largest extent of the vertices [m]."""
        return float(np.ptp(self.vertices, axis=0).max())


@dataclass(frozen=True)
class Seam:
    """Two panel edges joined: edge ``a_edge`` of panel ``a_panel`` and edge ``b_edge`` of ``b_panel``.

    ``orientation`` is one of :data:`ORIENTATIONS`, ``kind`` one of :data:`SEAM_KINDS`. A ``fold`` seam is a crease
    (a hem: side b is the part turned back, e.g. the hem's facing) with the rest dihedral ``angle`` [deg] across it
    (180: turned back flat onto side a) and the crease's ``width`` [m] (None: the elements' height at the seam;
    :mod:`rftstatic.element.hinge`).
    """

    a_panel: str
    a_edge: int
    b_panel: str
    b_edge: int
    orientation: str = "reversed"
    kind: str = "sew"
    angle: float = 180.0
    width: float | None = None

    def label(self):
        return f"{self.a_panel}:{self.a_edge} -- {self.b_panel}:{self.b_edge}"


@dataclass(frozen=True, eq=False)
class Pattern:
    """Panels and the seams joining them, in SI; checked on construction (:func:`check_pattern`).

    Attributes
    ----------
    panels : tuple of :class:`Panel`
    seams : tuple of :class:`Seam`
    units : the unit the file gave its lengths in (``"m"``, ``"cm"``, ``"mm"``); values here are in m
    source : the file read (for messages), or a label
    seam_tolerance : largest relative length difference of a seam's two edges [-]
    """

    panels: tuple
    seams: tuple = ()
    units: str = "m"
    source: str = "<pattern>"
    seam_tolerance: float = SEAM_LENGTH_TOLERANCE

    def __post_init__(self):
        object.__setattr__(self, "panels", tuple(self.panels))
        object.__setattr__(self, "seams", tuple(self.seams))
        check_pattern(self)

    def panel(self, name):
        """The panel called ``name``."""
        for p in self.panels:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def index(self):
        """{panel name: position in ``panels``}."""
        return {p.name: i for i, p in enumerate(self.panels)}


def rotation_matrix(angles):
    """(3, 3) rotation R = Rz(gamma) Ry(beta) Rx(alpha) of Euler angles (alpha, beta, gamma) [deg]."""
    a, b, c = np.radians(np.asarray(angles, dtype=float).reshape(3))
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
    return rz @ ry @ rx


# ---------------------------------------------------------------------------------------- checks
def check_pattern(pattern):
    """Raise :class:`PatternError` for the first problem of ``pattern`` (module docstring)."""
    src = pattern.source
    if not (isinstance(pattern.seam_tolerance, (int, float)) and 0 <= pattern.seam_tolerance < 1):
        raise PatternError(f"{src}: seam_tolerance = {pattern.seam_tolerance!r}; give a fraction in [0, 1)")
    names = [p.name for p in pattern.panels]
    if not names:
        raise PatternError(f"{src}: the pattern has no panels; add at least one")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise PatternError(f"{src}: panel name {dup[0]!r} is used twice; give every panel its own name")
    for p in pattern.panels:
        _check_panel(p, src)
    _check_seams(pattern, src)


def _check_panel(p, src):
    where = f"{src}: panel {p.name!r}"
    if not np.isfinite(p.vertices).all() or not np.isfinite(p.translation).all() \
            or not np.isfinite(p.rotation).all() or not np.isfinite(p.grain):
        raise PatternError(f"{where}: non-finite vertex, grain or placement value; give finite numbers")
    m = len(p.vertices)
    if sum(p.loops) != len(p.edges) or min(p.loops) < 2:
        raise PatternError(f"{where}: loops {p.loops} of {len(p.edges)} edges; every closed loop needs at least "
                           "2 edges and the loops must list all edges")
    for k, e in enumerate(p.edges):
        if not (0 <= e.start < m and 0 <= e.end < m):
            raise PatternError(f"{where}, edge {k}: endpoints ({e.start}, {e.end}) outside the "
                               f"{m} vertices (0..{m - 1}); fix the edge's endpoints")
        nxt = p.next_edge(k)
        if e.end != p.edges[nxt].start:
            raise PatternError(f"{where}, edge {k}: ends at vertex {e.end} but edge {nxt} starts at "
                               f"vertex {p.edges[nxt].start}; list each loop's edges as one closed chain")
        if e.kind not in EDGE_KINDS:
            raise PatternError(f"{where}, edge {k}: kind {e.kind!r}; use one of {EDGE_KINDS}")
        if e.kind == "bezier" and np.asarray(e.controls, float).size not in (2, 4):
            raise PatternError(f"{where}, edge {k}: a Bézier edge needs 1 or 2 control points, "
                               f"got {np.asarray(e.controls).size // 2}")
        a, b = p.ends(k)
        if np.hypot(*(b - a)) <= _ZERO_EDGE * max(p.size, 1e-300):
            raise PatternError(f"{where}, edge {k}: zero length (vertices {e.start} and {e.end} coincide at "
                               f"{tuple(np.round(a, 9))} m); remove the edge or move a vertex "
                               "(a full circle is two half arcs)")
        try:
            p.edge_length(k)
        except ValueError as err:
            raise PatternError(f"{where}, edge {k}: {err}; give a radius of at least half the chord") from None
    _check_outline(p, where)


def _check_outline(p, where):
    """Self-intersection of the loops (touching non-adjacent segments), and every hole inside the
    outline and outside the other holes."""
    v, owner, loop, nxt = p.outline()
    w = v[nxt]
    i = np.arange(len(v))
    skip = (i[:, None] == i[None, :]) | (nxt[:, None] == i[None, :]) | (i[:, None] == nxt[None, :])
    hit = segments_cross(v, w, v, w) & ~skip
    if hit.any():
        a, b = np.argwhere(hit)[0]
        ea, eb = sorted((int(owner[a]), int(owner[b])))
        what = f"edge {ea} crosses edge {eb}" if ea != eb else f"edge {ea} crosses itself"
        raise PatternError(f"{where}: the outline intersects itself ({what} near "
                           f"({v[a][0]:.6g}, {v[a][1]:.6g}) m); fix the vertices or the edges' curvature "
                           "so that the outline is a simple closed curve")
    for j in range(len(p.loops)):
        x, y = v[loop == j].T
        if abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) <= 1e-12 * p.size ** 2:
            raise PatternError(f"{where}: the loop of edges {list(p.loop_edges()[j])} encloses no area; "
                               "give it at least 3 vertices not on one line, or curve an edge")
    for j in range(1, len(p.loops)):
        first = v[loop == j][:1]
        inside = [q for q in range(len(p.loops)) if q != j and points_in_polygon(first, v[loop == q])[0]]
        if inside != [0]:
            raise PatternError(f"{where}: the hole of edges {list(p.loop_edges()[j])} is not inside the outline "
                               "(or lies inside another hole); fix its vertices")
def _check_seams(pattern, src):
    index = pattern.index
    used = {}
    for s, seam in enumerate(pattern.seams):
        where = f"{src}: seam {s} ({seam.label()})"
        if seam.kind not in SEAM_KINDS:
            raise PatternError(f"{where}: kind {seam.kind!r}; use one of {SEAM_KINDS}")
        if seam.orientation not in ORIENTATIONS:
            raise PatternError(f"{where}: orientation {seam.orientation!r}; use one of {ORIENTATIONS}")
        if not (isinstance(seam.angle, (int, float)) and 0 < seam.angle <= 180):
            raise PatternError(f"{where}: fold angle = {seam.angle!r}; give the crease's rest angle in (0, 180] deg "
                               "(180: turned back flat)")
        if seam.width is not None and not (isinstance(seam.width, (int, float)) and 0 < seam.width < np.inf):
            raise PatternError(f"{where}: fold width = {seam.width!r}; give a length > 0 or leave it out")
        lengths = []
        for name, k in ((seam.a_panel, seam.a_edge), (seam.b_panel, seam.b_edge)):
            if name not in index:
                raise PatternError(f"{where}: no panel {name!r} (panels: {', '.join(index)}); "
                                   "fix the panel name")
            n = len(pattern.panels[index[name]].edges)
            if not (isinstance(k, (int, np.integer)) and 0 <= k < n):
                raise PatternError(f"{where}: panel {name!r} has no edge {k!r} (its edges are 0..{n - 1}); "
                                   "fix the edge index")
            if (name, k) in used:
                raise PatternError(f"{where}: panel {name!r}, edge {k} is already in seam {used[name, k]}; "
                                   "an edge joins at most one seam (split the edge, or remove a seam)")
            used[name, k] = s
            lengths.append(pattern.panels[index[name]].edge_length(k))
        la, lb = lengths
        diff = abs(la - lb) / max(la, lb)
        if diff > pattern.seam_tolerance:
            raise PatternError(
                f"{where}: panel {seam.a_panel!r} edge {seam.a_edge} is {la:.6g} m long, panel {seam.b_panel!r} "
                f"edge {seam.b_edge} {lb:.6g} m: they differ by {100 * diff:.1f} % > "
                f"{100 * pattern.seam_tolerance:g} % (the ease a seam may take); correct the edges or the seam, "
                "or allow a gathered seam a larger seam_tolerance")
