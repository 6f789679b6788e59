"""The textile laboratory's testers as scenes: the cantilever tester recovers the bending rigidity it was
given (it must reproduce the heavy elastica), and the Cusick tester's clamping disc is scene input."""

import math

import numpy as np
import pytest

from rftstatic import api
from rftstatic.errors import SceneError
from rftstatic.references.elastica import alpha_at_chord_angle, heavy_elastica


def test_elastica_at_41_5_degrees_is_the_tester_rule():
    """Peirce's 41.5 deg: the exact heavy elastica's chord meets it at alpha = W l^3 / B = 8.004, so c = l/2 reads
    G 0.052 % high; his closed form c = l (cos(theta/2) / (8 tan theta))^(1/3) is 5.7 % high in G."""
    theta = math.radians(41.5)
    alpha = alpha_at_chord_angle(theta)
    assert alpha == pytest.approx(8.0042, abs=1e-4)
    s = heavy_elastica(alpha)
    assert math.atan2(-s.tip_z, s.tip_x) == pytest.approx(theta, abs=1e-10)
    peirce = (math.cos(theta / 2) / (8 * math.tan(theta))) ** (1 / 3)
    assert (peirce / alpha ** (-1 / 3)) ** 3 - 1 == pytest.approx(0.0573, abs=5e-4)


@pytest.mark.parametrize("name", ["cantilever-warp", "cantilever-weft"])
def test_cantilever_tester_recovers_the_given_rigidity(tmp_path, name):
    c = api.run(api.load_scene(name), tmp_path / name, figures=False).summary["cantilever"]
    assert abs(c["error_elastica_vs_given"]) < 0.005
    assert abs(c["flexural_rigidity"] / c["given_bending_rigidity"] - 1) < 0.005
    assert c["bending_length"] == pytest.approx(c["overhang"] / 2)
    assert c["flexural_rigidity"] == pytest.approx(0.019 * c["bending_length"] ** 3)
    assert c["solves"][-1]["angle_deg"] == pytest.approx(41.5, abs=1e-4)


def test_bias_strip_lies_between_the_narrow_strip_and_the_plate(tmp_path):
    scene = api.load_scene("cantilever-warp", ["material.warp_angle=45.0", "mesh.nodes=[17,5]"])
    c = api.run(scene, tmp_path / "bias", figures=False).summary["cantilever"]
    assert c["narrow_strip_rigidity"] < c["rigidity_elastica"] < c["given_bending_rigidity"]


@pytest.mark.parametrize("sets, key, fragment", [
    (["supports.0.radius=16.0"], "supports.0.radius", "holds the whole specimen"),
    (["supports.0.radius=-1.0"], "supports.0.radius", "must be > 0"),
    (["supports.0.box=[0,1,0,1]"], "supports.0.radius", "give box, at or radius (one of them)"),
])
def test_clamping_disc_errors_name_key_and_value(sets, key, fragment):
    scene = api.load_scene("cusick-30", sets)
    with pytest.raises(SceneError) as err:
        api.build_model(scene)
    assert f"{key}: " in str(err.value) and fragment in str(err.value)


def test_clamping_disc_areas():
    """The annulus leaves the disc open: the specimen's area is the mesh's plus the disc's polygon."""
    scene = api.load_scene("cusick-30")
    model, extras = api.build_model(scene)
    disc = extras["disc"]
    n = 160
    polygon = 0.5 * n * 0.09**2 * math.sin(2 * math.pi / n)
    assert disc.area == pytest.approx(polygon, rel=1e-9) and disc.open_area == pytest.approx(polygon, rel=1e-9)
    assert np.isin(model.supports.clamped, np.flatnonzero(np.isclose(np.hypot(*model.mesh.X.T), 0.09))).all()
