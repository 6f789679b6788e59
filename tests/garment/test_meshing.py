"""Panel meshing: seam node counts match, sewn nodes meet when the seams are closed, quality, placement."""

from pathlib import Path

import numpy as np
import pytest

from rftstatic.garment import PatternError, check_placement, mesh_pattern, place, read_pattern
from rftstatic.garment.meshing import edge_segments

PATTERNS = Path(__file__).resolve().parents[2] / "cases" / "patterns"
H = 0.03


@pytest.fixture(scope="module")
def a_line():
    return mesh_pattern(read_pattern(PATTERNS / "skirt-a-line.toml"), H)


@pytest.fixture(scope="module")
def circle():
    return mesh_pattern(read_pattern(PATTERNS / "skirt-circle.json"), H)


def _closed(pmesh):
    """Synthetic closing placement: both panels at the pattern's rotations, translated to one plane."""
    t = np.array([p.translation for p in pmesh.pattern.panels])
    t[:, 2] = 0.0
    return place(pmesh, translations=t)


@pytest.mark.parametrize("which", ["a_line", "circle"])
def test_seam_nodes_pair_and_meet_when_closed(which, request):
    pm = request.getfixturevalue(which)
    counts = edge_segments(pm.pattern, H)
    x = _closed(pm)
    for seam, pairs in zip(pm.pattern.seams, pm.seam_pairs):
        n = counts[seam.a_panel, seam.a_edge]
        assert n == counts[seam.b_panel, seam.b_edge]
        assert pairs.shape == (n + 1, 2)
        assert len(np.unique(pairs)) == 2 * (n + 1)                # one to one, two distinct sides
        np.testing.assert_allclose(x[pairs[:, 0]], x[pairs[:, 1]], rtol=0, atol=1e-12)
        # at the pattern's own placement the sides are apart, by the panels' z offset
        start = place(pm)
        gap = np.linalg.norm(start[pairs[:, 0]] - start[pairs[:, 1]], axis=1)
        dz = abs(np.diff([p.translation[2] for p in pm.pattern.panels])[0])
        np.testing.assert_allclose(gap, dz, rtol=1e-12)


@pytest.mark.parametrize("which", ["a_line", "circle"])
def test_mesh_quality_and_area(which, request):
    pm = request.getfixturevalue(which)
    for panel, mesh, q, nodes in zip(pm.pattern.panels, pm.meshes, pm.quality, pm.edge_nodes):
        assert q.min_angle > 28.0 and q.mean_min_angle > 50.0
        assert 0.5 * H < mesh.element_size.mean() < 1.2 * H
        # the outline's edge nodes lie on their edges, in order, and are the mesh's boundary
        for k, idx in enumerate(nodes):
            np.testing.assert_allclose(mesh.X[idx], panel.edge_points(k, len(idx) - 1), atol=1e-15)
        outline = np.concatenate([e[:-1] for e in nodes])
        assert set(outline) == set(mesh.boundary_nodes.tolist())
        # area: the mesh is the outline's inscribed polygon (chords of the arcs), area within 1 %
        poly = mesh.X[outline]
        area = 0.5 * abs(np.dot(poly[:, 0], np.roll(poly[:, 1], -1)) - np.dot(np.roll(poly[:, 0], -1), poly[:, 1]))
        assert mesh.area.sum() == pytest.approx(area, rel=1e-12)


def test_circle_skirt_area():
    pm = mesh_pattern(read_pattern(PATTERNS / "skirt-circle.json"), 0.02)
    exact = 0.5 * np.pi * (0.6114 ** 2 - 0.1114 ** 2)              # half annulus [m²]
    for mesh in pm.meshes:
        assert mesh.area.sum() == pytest.approx(exact, rel=2e-3)   # chords of h = 2 cm on r = 11 cm


def test_combined_mesh(a_line):
    c = a_line.combined()
    mesh = c.mesh
    assert mesh.n_nodes == a_line.n_nodes == sum(m.n_nodes for m in a_line.meshes)
    assert np.bincount(c.panel_of_element).tolist() == [m.n_elements for m in a_line.meshes]
    assert np.bincount(c.panel_of_node).tolist() == [m.n_nodes for m in a_line.meshes]
    np.testing.assert_allclose(c.warp_angle, np.pi / 2)           # grain = 90 deg in the skirt's file
    np.testing.assert_array_equal(c.seam_pairs, np.concatenate(a_line.seam_pairs))
    assert np.bincount(c.seam_of_pair).tolist() == [len(q) for q in a_line.seam_pairs]
    np.testing.assert_allclose(mesh.area.sum(), sum(m.area.sum() for m in a_line.meshes), rtol=1e-12)
    # each panel keeps its flat geometry (shifted), and the panels laid side by side do not overlap
    for p, m in enumerate(a_line.meshes):
        shifted = mesh.X[c.panel_of_node == p] - m.X
        np.testing.assert_allclose(shifted - shifted[0], 0, atol=1e-15)
    xmax = [mesh.X[c.panel_of_node == p, 0].max() for p in range(2)]
    xmin = [mesh.X[c.panel_of_node == p, 0].min() for p in range(2)]
    assert xmax[0] < xmin[1]


def test_placement_checks(a_line):
    check_placement(a_line)                                         # the file's placement: apart
    with pytest.raises(PatternError, match=r"skirt-a-line.toml: panels 'front' and 'back' lie in one plane"):
        check_placement(a_line, _closed(a_line))
    # back turned to cross the front (shifted up 1.3 cm: the two meshes are the same, so a symmetric
    # crossing would meet node on node and edge on edge, which the crossing test counts as touching)
    x = place(a_line, translations=[[0, 0.4, 0.15], [0.05, 0.413, 0.2]], rotations=[[0, 0, 0], [0, 70, 0]])
    with pytest.raises(PatternError, match=r"panels 'front' and 'back' intersect in their placement"):
        check_placement(a_line, x)
    # touching along a seam line is allowed: the back, in the front's plane, turned about z so that its
    # edge 3 lies on the front's edge 1 (the side seam sewn flat, the panels side by side)
    (x0, _), (x1, _), (x2, y2), _ = a_line.pattern.panels[0].vertices  # hem ends, then the waist ends
    gamma = 2 * np.degrees(np.arctan2(x1 - x2, y2))
    c, s = np.cos(np.radians(gamma)), np.sin(np.radians(gamma))
    t = np.array([x1, 0.0]) - np.array([[c, -s], [s, c]]) @ [x0, 0.0]
    x = place(a_line, translations=[[0, 0, 0], [*t, 0]], rotations=[[0, 0, 0], [0, 0, gamma]])
    pairs = a_line.seam_pairs[0]
    np.testing.assert_allclose(x[pairs[:, 0]], x[pairs[:, 1]], atol=1e-12)
    check_placement(a_line, x)


def test_bad_element_size(a_line):
    with pytest.raises(PatternError, match="element size h = 0.5 m"):
        mesh_pattern(a_line.pattern, 0.5)
    with pytest.raises(PatternError, match="element size h = -1"):
        mesh_pattern(a_line.pattern, -1)


def test_dart_in_one_panel():
    """A dart: two edges of one panel sewn to each other; the tip node pairs with itself and the two
    sides mirror each other about the dart's axis x = 20 cm."""
    from rftstatic.garment.readers import parse_toml

    pattern = parse_toml({"units": "cm",
                          "panels": [{"name": "skirt",
                                      "vertices": [[0, 0], [40, 0], [40, 50], [24, 50], [20, 35], [16, 50], [0, 50]]}],
                          "seams": [{"a": "skirt:3", "b": "skirt:4"}]})
    pm = mesh_pattern(pattern, 0.02)
    pairs = pm.seam_pairs[0]
    assert pairs[-1, 0] == pairs[-1, 1]                       # the tip
    assert len(np.unique(pairs)) == 2 * len(pairs) - 1
    x = pm.meshes[0].X
    np.testing.assert_allclose(x[pairs[:, 0], 0] - 0.2, 0.2 - x[pairs[:, 1], 0], atol=1e-15)
    np.testing.assert_allclose(x[pairs[:, 0], 1], x[pairs[:, 1], 1], atol=1e-15)
    assert pm.quality[0].min_angle > 28.0


def test_ring_panel_with_a_hole():
    """One ring panel (the circle skirt of cases/patterns): the waist is a hole; the mesh fills the
    ring only, the hole's edges keep their own nodes, and a disc placed in the hole's plane inside the
    hole does not overlap the ring."""
    from rftstatic.garment.readers import parse_toml

    pm = mesh_pattern(read_pattern(PATTERNS / "skirt-circle-ring.toml"), 0.02)
    mesh, nodes = pm.meshes[0], pm.edge_nodes[0]
    assert mesh.area.sum() == pytest.approx(np.pi * (0.6114 ** 2 - 0.1114 ** 2), rel=2e-3)
    assert pm.quality[0].min_angle > 28.0
    waist = np.concatenate([nodes[2], nodes[3]])
    np.testing.assert_allclose(np.hypot(*mesh.X[waist].T), 0.1114, rtol=1e-12)
    assert nodes[2][0] == nodes[3][-1] and nodes[2][-1] == nodes[3][0]          # the hole closes on itself
    assert set(np.concatenate(nodes).tolist()) == set(mesh.boundary_nodes.tolist())
    # a disc (two arcs) of radius 9 cm in the waist hole, in the ring's plane: no overlap
    ring = read_pattern(PATTERNS / "skirt-circle-ring.toml").panels[0]
    disc = {"name": "disc", "vertices": [[9, 0], [-9, 0]], "translate": [0, 100, 0], "rotate": [-90, 0, 0],
            "arcs": [{"edge": 0, "radius": 9, "side": "right"}, {"edge": 1, "radius": 9, "side": "right"}]}
    toml = {"units": "cm", "panels": [
        {"name": "ring", "vertices": [[61.14, 0], [-61.14, 0]], "holes": [[[11.14, 0], [-11.14, 0]]],
         "arcs": [{"edge": k, "radius": 61.14 if k < 2 else 11.14, "side": "right"} for k in range(4)],
         "translate": [0, 100, 0], "rotate": [-90, 0, 0]}, disc]}
    both = mesh_pattern(parse_toml(toml), 0.03)
    assert both.pattern.panels[0].loops == ring.loops == (2, 2)
    check_placement(both)
    disc["vertices"] = [[15, 0], [-15, 0]]                     # larger than the hole: overlaps the ring
    disc["arcs"] = [{"edge": 0, "radius": 15, "side": "right"}, {"edge": 1, "radius": 15, "side": "right"}]
    with pytest.raises(PatternError, match="panels 'ring' and 'disc' lie in one plane and overlap"):
        check_placement(mesh_pattern(parse_toml(toml), 0.03))


@pytest.mark.parametrize("which", ["a_line", "circle"])
def test_sewn_surface_is_consistently_oriented(which, request):
    """Merging each seam's pairs gives a manifold whose triangles (counter-clockwise in their panels)
    cross every seam edge in opposite directions: the "reversed" pairing of two panels drawn
    counter-clockwise sews them right side to right side, as GarmentCode's default does."""
    pm = request.getfixturevalue(which)
    c = pm.combined()
    merge = np.arange(pm.n_nodes)
    merge[c.seam_pairs[:, 1]] = c.seam_pairs[:, 0]
    tri = merge[c.mesh.tri]
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert len(np.unique(directed, axis=0)) == len(directed)             # no edge twice the same way
    undirected, count = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    assert count.max() == 2
    seam_edges = np.sort(merge[np.c_[c.seam_pairs[:-1, 0], c.seam_pairs[1:, 0]]], axis=1)
    same_seam = c.seam_of_pair[:-1] == c.seam_of_pair[1:]
    inner = {tuple(e) for e, two in zip(undirected, count == 2) if two}
    assert all(tuple(e) in inner for e in seam_edges[same_seam])         # every seam edge now interior
