"""sphere-mesh (sphere-30 with the sphere as a triangulated icosphere file) against the analytic sphere."""

import pytest

from rftstatic import api


@pytest.mark.parametrize("nodes", ["[13, 13]"])
def test_coarse_sphere_mesh_drapes_as_the_analytic_sphere(tmp_path, nodes):
    """13 x 13 nodes (2.5 cm elements) on the 1,280-triangle icosphere of cases/ (facets within 0.24 mm of the
    sphere, 0.05 of an element): the drape coefficient within 1.5 % (relative) of the analytic sphere's and the
    total energy within 1.5 %, 0 sheet/obstacle crossing pairs and no node inside the obstacle."""
    common = [f"mesh.nodes={nodes}"]
    mesh = api.run("sphere-mesh", tmp_path / "mesh", overrides=common, figures=False).summary
    ball = api.run("sphere-30", tmp_path / "ball", overrides=common, figures=False).summary
    assert mesh["converged"] and ball["converged"]
    dc_m, dc_b = mesh["drape"]["drape_coefficient"], ball["drape"]["drape_coefficient"]
    assert dc_m == pytest.approx(dc_b, rel=0.015)
    assert mesh["energies"]["total"] == pytest.approx(ball["energies"]["total"], rel=0.015)
    crossing = mesh["obstacle_crossings"][0]
    assert crossing["pairs"] == 0 and crossing["smallest_node_distance"] > 0.0
    assert "obstacle_crossings" not in ball
