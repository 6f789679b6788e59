"""Pattern readers: GarmentCode JSON and the TOML form describe the same garment alike; units, curvature."""

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from rftstatic.garment import PatternError, read_pattern
from rftstatic.garment.readers import parse_garmentcode, parse_toml

PATTERNS = Path(__file__).resolve().parents[2] / "cases" / "patterns"


def _same(p, q):
    assert [x.name for x in p.panels] == [x.name for x in q.panels]
    for a, b in zip(p.panels, q.panels):
        np.testing.assert_allclose(a.vertices, b.vertices, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.translation, b.translation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.rotation, b.rotation, rtol=0, atol=1e-12)
        assert a.grain == b.grain
        assert a.edges == b.edges
    assert p.seams == q.seams


def test_toml_and_json_give_the_same_skirt():
    toml, js = read_pattern(PATTERNS / "skirt-a-line.toml"), read_pattern(PATTERNS / "skirt-a-line.json")
    _same(toml, js)
    assert toml.units == js.units == "cm"
    front = toml.panel("front")
    # cm -> m, and the waist arc: radius 46.29 cm over a 35.10 cm chord
    np.testing.assert_allclose(front.vertices[2], [0.1755, 0.5552])
    half = np.arcsin(0.1755 / 0.4629)
    assert front.edge_length(2) == pytest.approx(0.4629 * 2 * half, rel=1e-12)
    assert front.edge_length(1) == pytest.approx(np.hypot(0.4030 - 0.1755, 0.5552), rel=1e-12)


def test_units_convert_to_si():
    base = {"units": "m", "panels": [{"name": "p", "vertices": [[0, 0], [1, 0], [1, 2]], "translate": [0, 0, 1]}]}
    for unit, f in (("cm", 100), ("mm", 1000)):
        d = copy.deepcopy(base)
        d["units"] = unit
        d["panels"][0]["vertices"] = [[f * x for x in v] for v in d["panels"][0]["vertices"]]
        d["panels"][0]["translate"] = [0, 0, f]
        _same(parse_toml(base), parse_toml(d))
    spec = json.loads((PATTERNS / "skirt-circle.json").read_text())
    mm = parse_garmentcode(spec)
    assert mm.units == "mm"
    assert mm.panel("front").edge_length(1) == pytest.approx(np.pi * 0.6114, rel=1e-12)   # half hem circle
    np.testing.assert_allclose(mm.panel("back").translation, [0, 1.0, -0.2])


@pytest.mark.parametrize("units", ["inch", "km", None])
def test_unknown_units_are_refused(units):
    with pytest.raises(PatternError, match="units"):
        parse_toml({"units": units, "panels": [{"name": "p", "vertices": [[0, 0], [1, 0], [1, 1]]}]}, source="f.toml")


@pytest.mark.parametrize("uim", [0, -100, "cm"])
def test_bad_units_in_meter_are_refused(uim):
    spec = json.loads((PATTERNS / "skirt-a-line.json").read_text())
    spec["properties"]["units_in_meter"] = uim
    with pytest.raises(PatternError, match="units_in_meter"):
        parse_garmentcode(spec, source="s.json")


def _one_edge_spec(curvature):
    edge = {"endpoints": [0, 1]}
    if curvature is not None:
        edge["curvature"] = curvature
    return {"pattern": {"panels": {"p": {"vertices": [[0, 0], [10, 0], [10, 10], [0, 10]],
                                         "edges": [edge, {"endpoints": [1, 2]}, {"endpoints": [2, 3]},
                                                   {"endpoints": [3, 0]}],
                                         "translation": [0, 0, 0], "rotation": [0, 0, 0]}},
                        "stitches": []},
            "properties": {"units_in_meter": 100, "curvature_coords": "relative"}}


def test_relative_bezier_curvature():
    # quadratic control at u = 0.5, v = -0.4 chord lengths: (0.05, -0.04) m, below the bottom edge
    quad = parse_garmentcode(_one_edge_spec({"type": "quadratic", "params": [[0.5, -0.4]]})).panels[0].edges[0]
    assert quad.kind == "bezier"
    np.testing.assert_allclose(quad.controls, [[0.05, -0.04]])
    old = parse_garmentcode(_one_edge_spec([0.5, -0.4])).panels[0].edges[0]     # Garment-Pattern-Generator
    assert old == quad
    cubic = parse_garmentcode(_one_edge_spec({"type": "cubic", "params": [[0.25, 0.0], [0.75, 0.0]]})).panels[0]
    assert cubic.edge_length(0) == pytest.approx(0.1, rel=1e-9)          # control points on the chord
    # a quadratic Bezier with its control on the chord's perpendicular bisector: parabola of
    # half-width w = 0.05 m and sagitta s = 0.02 m (half the control's offset)
    p = parse_garmentcode(_one_edge_spec({"type": "quadratic", "params": [[0.5, -0.4]]})).panels[0]
    w, s = 0.05, 0.02
    k = 4 * s / (2 * w) ** 2 * 2 * w          # parabola y = 4 s x (1 - x) / L, arc length analytic
    exact = (np.sqrt(1 + k * k) * k + np.arcsinh(k)) / (2 * k) * 2 * w
    assert p.edge_length(0) == pytest.approx(exact, rel=1e-6)


@pytest.mark.parametrize("curv", [{"type": "spline", "params": []}, {"type": "circle", "params": [1.0]},
                                  {"type": "cubic", "params": [[0.5, 0.1]]}])
def test_unsupported_curvature_is_refused(curv):
    with pytest.raises(PatternError, match=r"panel 'p', edge 0: .*curvature"):
        parse_garmentcode(_one_edge_spec(curv), source="s.json")


def test_absolute_curvature_coords_refused():
    spec = _one_edge_spec(None)
    spec["properties"]["curvature_coords"] = "absolute"
    with pytest.raises(PatternError, match="curvature_coords"):
        parse_garmentcode(spec, source="s.json")


def test_right_wrong_stitch_is_aligned():
    spec = json.loads((PATTERNS / "skirt-a-line.json").read_text())
    spec["pattern"]["stitches"][0].append("right_wrong")
    p = parse_garmentcode(spec)
    assert [s.orientation for s in p.seams] == ["aligned", "reversed"]


def test_toml_unknown_key_and_bad_seam_reference(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text('units = "cm"\n[[panels]]\nname = "a"\nvertices = [[0, 0], [1, 0], [1, 1]]\ncolour = "red"\n')
    with pytest.raises(PatternError, match=r"p.toml: panel 'a': unknown key 'colour'"):
        read_pattern(f)
    f.write_text('units = "cm"\n[[panels]]\nname = "a"\nvertices = [[0, 0], [1, 0], [1, 1]]\n'
                 '[[seams]]\na = "a-0"\nb = "a:1"\n')
    with pytest.raises(PatternError, match=r'give "panel:edge"'):
        read_pattern(f)
    with pytest.raises(PatternError, match="unknown pattern format"):
        read_pattern(tmp_path / "p.dxf")
    with pytest.raises(PatternError, match="no such pattern file"):
        read_pattern(tmp_path / "missing.toml")


@pytest.mark.parametrize("key, value, match", [("translate", [0, 1], "translate = \\[0, 1\\]; give three numbers"),
                                               ("rotate", "x", "rotate = 'x' is not numeric"),
                                               ("grain", "warp", "grain = 'warp'"),
                                               ("arcs", [5], "expected a table")])
def test_toml_bad_values_are_named(key, value, match):
    data = {"units": "cm", "panels": [{"name": "a", "vertices": [[0, 0], [1, 0], [1, 1]], key: value}]}
    with pytest.raises(PatternError, match="p.toml: panel 'a'.*" + match):
        parse_toml(data, source="p.toml")
