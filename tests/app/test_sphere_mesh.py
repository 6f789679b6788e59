"""sphere-mesh (sphere-30 with the sphere as a triangulated icosphere file) against the analytic sphere."""

import numpy as np
import pytest

from rftstatic import api

SAGITTA_CM = 5.0 * (1.0 - np.cos(np.arctan(2.0) / 8.0 / np.sqrt(3.0)))
"""Upper bound of the facets' distance to the sphere through their vertices on the 1,280-triangle icosphere
(a level-3 facet's circumradius angle is about its edge angle / sqrt 3, the edge angle 63.4 deg / 8) [cm]."""


def _deepest_chord(res, obstacle):
    """Least signed distance [m] of the sheet's triangle centroids and edge midpoints to ``obstacle``."""
    x = res.model.positions(res.U)
    mesh = res.model.mesh
    mids = np.concatenate([x[mesh.tri].mean(axis=1), 0.5 * x[mesh.topology.edges].sum(axis=1)])
    return float(min(0.0, obstacle.signed_distance(mids)[0].min()))


def test_coarse_sphere_mesh_drapes_as_the_analytic_sphere(tmp_path):
    """9 x 9 nodes (3.75 cm elements) on the 1,280-triangle icosphere of cases/ (facets within 0.13 mm of the
    sphere): drape coefficient and total energy within 1.5 % (relative) of the analytic sphere's; no node inside
    the obstacle; the flat triangles dip into the icosphere between their nodes no deeper than into the
    analytic sphere plus the facet sagitta (sheet chords cross a curved obstacle as a discretisation effect;
    the independent crossing check counts them, validation/mesh_obstacles.md)."""
    common = ["mesh.nodes=[9, 9]", "contact.smoothing=0.07"]  # the scene's onset on both
    mesh = api.run("sphere-mesh", tmp_path / "mesh", overrides=common, figures=False)
    ball = api.run("sphere-30", tmp_path / "ball", overrides=common, figures=False)
    sm, sb = mesh.summary, ball.summary
    assert sm["converged"] and sb["converged"]
    assert sm["drape"]["drape_coefficient"] == pytest.approx(sb["drape"]["drape_coefficient"], rel=0.015)
    assert sm["energies"]["total"] == pytest.approx(sb["energies"]["total"], rel=0.015)
    crossing = sm["obstacle_crossings"][0]
    assert crossing["smallest_node_distance"] > 0.0 and "obstacle_crossings" not in sb
    chord_ball = _deepest_chord(ball, ball.extras["obstacles"][0]) / 0.01  # [cm]
    assert crossing["deepest_chord"] == pytest.approx(_deepest_chord(mesh, mesh.extras["obstacles"][0]) / 0.01)
    assert abs(crossing["deepest_chord"]) <= abs(chord_ball) + SAGITTA_CM + 1e-3
