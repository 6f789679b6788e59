"""The pattern model: edge geometry (arcs, arc-length sampling, Euler order) and every bad input named."""

import copy

import numpy as np
import pytest

from rftstatic.garment import PatternError
from rftstatic.garment.curves import arc_geometry, edge_points
from rftstatic.garment.pattern import SEAM_LENGTH_TOLERANCE, rotation_matrix
from rftstatic.garment.readers import parse_toml

SQUARE = [[0, 0], [10, 0], [10, 10], [0, 10]]


def _two_squares(**seam):
    return {"units": "cm",
            "panels": [{"name": "front", "vertices": copy.deepcopy(SQUARE)},
                       {"name": "back", "vertices": copy.deepcopy(SQUARE), "translate": [0, 0, -5]}],
            "seams": [{"a": "front:1", "b": "back:3", **seam}]}


def _raises(data, *pieces):
    with pytest.raises(PatternError) as err:
        parse_toml(data, source="garment.toml")
    msg = str(err.value)
    assert msg.startswith("garment.toml: ")
    for piece in pieces:
        assert piece in msg, msg
    return msg


# ------------------------------------------------------------------------------------- geometry
@pytest.mark.parametrize("right, large", [(True, False), (False, False), (True, True), (False, True)])
def test_arc_flags(right, large):
    a, b, r = np.array([0.0, 0.0]), np.array([1.0, 0.0]), 0.8
    pts = edge_points(a, b, 64, "arc", radius=r, large=large, right=right)
    centre, _, sweep = arc_geometry(a, b, r, large=large, right=right)
    np.testing.assert_allclose(np.hypot(*(pts - centre).T), r, rtol=1e-12)        # on the circle
    np.testing.assert_allclose(pts[[0, -1]], [a, b], atol=1e-15)
    mid = pts[32]
    assert (mid[1] < 0) == right                        # the chord runs along +x: right is -y
    assert (abs(sweep) > np.pi) == large
    seg = np.hypot(*np.diff(pts, axis=0).T)
    np.testing.assert_allclose(seg, seg[0], rtol=1e-12)                        # uniform by arc length


def test_bezier_points_are_uniform_in_arc_length():
    cp = np.array([[0, 0], [0.1, 0.8], [0.6, -0.5], [1, 0]])
    pts = edge_points(cp[0], cp[-1], 50, "bezier", controls=tuple(map(tuple, cp[1:3])))
    t = np.linspace(0, 1, 200_001)[:, None]          # the cubic sampled finely, independently
    dense = (1 - t) ** 3 * cp[0] + 3 * t * (1 - t) ** 2 * cp[1] + 3 * t ** 2 * (1 - t) * cp[2] + t ** 3 * cp[3]
    s = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(dense, axis=0).T))])
    at = np.array([s[np.argmin(np.hypot(*(dense - q).T))] for q in pts])
    np.testing.assert_allclose(np.diff(at), s[-1] / 50, rtol=1e-3)


def test_rotation_is_maya_xyz():
    # rotation (90, 0, 90): first about x (y -> z), then about z (x -> y)
    R = rotation_matrix([90, 0, 90])
    np.testing.assert_allclose(R @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(R @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(rotation_matrix([0, 180, 0]) @ [1, 2, 0], [-1, 2, 0], atol=1e-14)


# ------------------------------------------------------------------------------------ bad input
def test_seam_length_tolerance():
    ok = _two_squares()
    ok["panels"][1]["vertices"][2][1] = ok["panels"][1]["vertices"][3][1] = 10 / (1 + 0.9 * SEAM_LENGTH_TOLERANCE)
    parse_toml(ok)                                # within the ease allowed: accepted
    bad = _two_squares()
    bad["panels"][1]["vertices"][2][1] = bad["panels"][1]["vertices"][3][1] = 9.0
    _raises(bad, "seam 0 (front:1 -- back:3)", "panel 'front' edge 1 is 0.1 m", "panel 'back' edge 3 0.09 m",
            "differ by 10.0 % > 5 %")
    gathered = parse_toml(bad, seam_tolerance=0.15)              # a gathered seam, stated
    assert gathered.seam_tolerance == 0.15
    with pytest.raises(PatternError, match="seam_tolerance = 1.5"):
        parse_toml(bad, seam_tolerance=1.5)


def test_missing_panel_or_edge():
    d = _two_squares()
    d["seams"][0]["b"] = "sleeve:3"
    _raises(d, "seam 0", "no panel 'sleeve'", "fix the panel name")
    d = _two_squares()
    d["seams"][0]["b"] = "back:7"
    _raises(d, "seam 0", "panel 'back' has no edge 7", "0..3")


def test_edge_in_two_seams():
    d = _two_squares()
    d["seams"].append({"a": "front:2", "b": "back:3"})
    _raises(d, "seam 1 (front:2 -- back:3)", "panel 'back', edge 3 is already in seam 0")
    d = _two_squares()
    d["seams"] = [{"a": "front:1", "b": "front:1"}]
    _raises(d, "panel 'front', edge 1 is already in seam 0")


def test_self_intersecting_outline():
    d = _two_squares()
    d["panels"][0]["vertices"] = [[0, 0], [10, 10], [10, 0], [0, 10]]       # a bow tie
    _raises(d, "panel 'front'", "intersects itself", "edge 0 crosses edge 2")
    d = _two_squares()                                    # an arc bulging across the opposite edge
    d["panels"][0]["vertices"] = [[0, 0], [10, 0], [10, 2], [0, 2]]
    d["panels"][0]["arcs"] = [{"edge": 0, "radius": 5, "side": "left"}]
    _raises(d, "panel 'front'", "edge 0 crosses edge 2")


def test_zero_length_edge_and_small_arc_radius():
    d = _two_squares()
    d["panels"][0]["vertices"] = [[0, 0], [10, 0], [10, 10], [10, 10], [0, 10]]
    d["seams"] = []
    _raises(d, "panel 'front', edge 2: zero length", "vertices 2 and 3 coincide")
    d = _two_squares()
    d["panels"][0]["arcs"] = [{"edge": 0, "radius": 4, "side": "left"}]
    _raises(d, "panel 'front', edge 0", "smaller than half its chord")


def test_bad_seam_kind_and_duplicate_panel():
    _raises(_two_squares(kind="glue"), "seam 0", "kind 'glue'", "sew")
    _raises(_two_squares(orientation="twisted"), "seam 0", "orientation 'twisted'")
    d = _two_squares()
    d["panels"][1]["name"] = "front"
    _raises(d, "panel name 'front' is used twice")


def test_bad_holes():
    d = _two_squares()
    d["panels"][0]["holes"] = [[[20, 20], [30, 20], [30, 30]]]
    _raises(d, "panel 'front'", "hole of edges [4, 5, 6] is not inside the outline")
    d["panels"][0]["holes"] = [[[5, 5], [15, 5], [15, 8]]]
    _raises(d, "panel 'front'", "intersects itself", "edge 1 crosses edge 4")
    d["panels"][0]["holes"] = [[[2, 2], [4, 2], [4, 4]], [[3, 2.5], [3.5, 2.5], [3.5, 3]]]
    _raises(d, "panel 'front'", "hole of edges [7, 8, 9] is not inside the outline (or lies inside another hole)")
    d["panels"][0]["holes"] = [[[2, 2], [4, 2]]]                     # two straight edges: no area
    _raises(d, "panel 'front'", "loop of edges [4, 5] encloses no area")
