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


def test_cusick_dc_falls_as_the_specimen_grows(tmp_path):
    """Coarse meshes (1 cm rings, 80 nodes): the wool's DC falls from the 24 to the 36 cm specimen; every
    drape coefficient obeys its definition and the percentage is 100 x the fraction."""
    dc = []
    for size, rings in ((24, 4), (30, 7), (36, 10)):
        s = api.run(api.load_scene(f"cusick-{size}", [f"mesh.nodes=[{rings},80]"]), tmp_path / str(size),
                    figures=False).summary
        d = s["drape"]
        assert s["converged"] and s["stable_minimum"]
        a_d, a_s = d["disc"]["area"], d["disc"]["specimen_area"]
        assert d["drape_coefficient"] == pytest.approx((d["shadow_area"] - a_d) / (a_s - a_d), rel=1e-12)
        assert d["drape_coefficient_percent"] == pytest.approx(100 * d["drape_coefficient"])
        assert a_s == pytest.approx(math.pi * (size / 2) ** 2, rel=5e-3) and a_d == pytest.approx(math.pi * 81, rel=5e-3)
        assert len(d["hem_profile"]["r"]) == 360 and 9.0 < min(d["hem_profile"]["r"]) <= max(d["hem_profile"]["r"]) < size / 2
        assert d["fold_count"] == len(d["fold_angles_deg"]) >= 3
        dc.append(d["drape_coefficient"])
    assert dc[0] > dc[1] > dc[2] > 0


def test_seeded_specimens_report_mean_and_range(tmp_path):
    s = api.run(api.load_scene("cusick-24", ["mesh.nodes=[4,80]", "solver.seeds=2"]), tmp_path / "s",
                figures=False).summary
    g = s["seeds"]
    dcs = [r["drape_coefficient_percent"] for r in g["specimens"]]
    assert g["count"] == g["solved"] == 2 and dcs[0] == pytest.approx(s["drape"]["drape_coefficient_percent"])
    assert g["drape_coefficient_percent_min"] <= g["drape_coefficient_percent_mean"] <= g["drape_coefficient_percent_max"]
    assert g["drape_coefficient_percent_mean"] == pytest.approx(np.mean(dcs))


def test_seeds_need_a_seeded_lift():
    with pytest.raises(SceneError, match="solver.seeds: 3 seeded starts need a seeded lift"):
        from rftstatic.scenes.options import seed_count

        seed_count(api.load_scene("cusick-30", ["solver.seeds=3", "solver.perturbation=0.0"]))
