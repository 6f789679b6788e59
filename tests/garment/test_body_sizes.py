"""The dress form's size chart (rftstatic.references.body_sizes) and [body] size."""

import numpy as np
import pytest

from rftstatic.app.garment import dress_form
from rftstatic.garment.body import ellipse_perimeter
from rftstatic.references.body_sizes import size_chart
from rftstatic.errors import SceneError
from rftstatic.scenes.schema import load_scene

BODY = ("bust_girth", "waist_girth", "hip_girth", "bust_height", "waist_height", "hip_height", "shoulder_breadth",
        "shoulder_height", "neck_girth", "neck_height")


def test_the_chart_grows_with_the_size_and_each_size_is_a_valid_form():
    chart = size_chart()
    sizes = sorted(chart)
    assert sizes == list(range(sizes[0], sizes[-1] + 1, 4)) and len(sizes) >= 6
    for k in ("bust_girth", "waist_girth", "hip_girth", "neck_girth"):
        assert np.all(np.diff([chart[s][k] for s in sizes]) > 0), k  # girths grow with the size
    for s in sizes:
        assert abs(chart[s]["bust_girth"] - s) < 2.0 and chart[s]["women"] >= 30
        assert chart[s]["hip_height"] < chart[s]["waist_height"] < chart[s]["bust_height"] < chart[s]["shoulder_height"]


def _scene(body):
    data = load_scene("skirt-circle").data
    data = {**data, "body": {"kind": "dress-form", **body}}
    from rftstatic.scenes.schema import scene_from_dict

    return scene_from_dict(data, name="sized")


@pytest.mark.parametrize("size", [80, 92, 108])
def test_a_size_gives_a_form_with_the_charts_girths(size):
    form = dress_form(_scene({"size": size}))
    row = size_chart()[size]
    z, a, b = form.levels()
    # the hip, waist and bust sections (levels 1-3) have the chart's girths (cm -> m) at the chart's heights
    np.testing.assert_allclose(ellipse_perimeter(a[1:4], b[1:4]),
                               np.array([row["hip_girth"], row["waist_girth"], row["bust_girth"]]) / 100, rtol=1e-9)
    np.testing.assert_allclose(z[1:4], np.array([row["hip_height"], row["waist_height"], row["bust_height"]]) / 100)


def test_a_measurement_given_overrides_the_size():
    form = dress_form(_scene({"size": 92, "waist_girth": 70.0}))
    _, a, b = form.levels()
    assert ellipse_perimeter(a[2], b[2]) == pytest.approx(0.70, rel=1e-9)


@pytest.mark.parametrize("size", [83, 200])
def test_a_size_not_in_the_chart_names_the_key_and_the_sizes(size):
    with pytest.raises(SceneError, match=r"body\.size.*80, 84"):
        dress_form(_scene({"size": size}))


@pytest.mark.parametrize("size", ["M", True])
def test_a_size_that_is_not_a_number_names_the_key(size):
    with pytest.raises(SceneError, match=r"body\.size: expected int/float"):
        _scene({"size": size})
