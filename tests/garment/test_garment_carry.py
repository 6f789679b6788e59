"""Carrying a garment's drape between meshes of its pattern (rftstatic.app.garment_carry)."""

import json

import numpy as np
import pytest

from rftstatic.app.garment import dressed_mesh, write_obj
from rftstatic.app.garment_carry import _panel_positions, carry_drape
from rftstatic.cli import main
from rftstatic.garment.sewing import seam_pairs, sew
from rftstatic.scenes.schema import load_scene


def test_sewn_positions_spread_back_to_both_sides_of_every_seam():
    scene = load_scene("skirt-a-line")
    pmesh, mesh, _ = dressed_mesh(scene, 8.0)
    pairs = seam_pairs(pmesh)
    sewn, node_of = sew(mesh, pairs, mesh.X3)
    x_sewn = np.random.default_rng(0).normal(size=(sewn.n_nodes, 3))
    x = _panel_positions(pmesh, x_sewn, "test")
    assert x.shape == (pmesh.n_nodes, 3)
    np.testing.assert_array_equal(x, x_sewn[node_of])
    np.testing.assert_array_equal(x[pairs[:, 0]], x[pairs[:, 1]])  # both sides of a seam at one position
    with pytest.raises(ValueError, match="garment.h"):
        _panel_positions(pmesh, x_sewn[:-1], "test")


def test_a_flat_placed_garment_carries_onto_its_own_plane(tmp_path):
    # the ring placed flat at the waist, written as a run's garment.obj, carried to a finer mesh: every node of the
    # finer ring lies in the waist plane at its own flat position (the carry is exact for a flat patch)
    scene = load_scene("skirt-circle")
    pc, mc, uv = dressed_mesh(scene, 10.0)
    write_obj(tmp_path / "garment.obj", mc.X3 / 0.01, mc.tri, uv / 0.01)
    from rftstatic.garment.sewing import carry_closed
    from rftstatic.app.garment import read_obj_uv

    pf, mf, _ = dressed_mesh(scene, 7.0)
    x = carry_closed(pc, _panel_positions(pc, read_obj_uv(tmp_path / "garment.obj")[0] * 0.01, "t"), pf)
    np.testing.assert_allclose(x[:, 2], mf.X3[:, 2], atol=1e-9)
    inside = np.linalg.norm(mf.X3[:, :2], axis=1) < 0.6  # the hem's arc nodes lie outside the coarse polygon
    np.testing.assert_allclose(x[inside], mf.X3[inside], atol=1e-9)


def test_a_coarse_circle_skirt_drape_is_held_on_a_finer_mesh(tmp_path):
    out = tmp_path / "coarse"
    assert main(["case", "skirt-circle", "--out", str(out), "--no-figures", "--set", "garment.h=6"]) == 0
    own = json.loads((out / "summary.json").read_text())
    table = carry_drape(load_scene("skirt-circle"), out, 6.0, out=tmp_path / "carry", h=5.0)
    assert table["converged"] and table["stable_minimum"]
    assert table["folds_carried"] == own["garment"]["hem_folds"] == table["hem_folds"]
    # --resume continues a garment run from its checkpoint (here the converged state: the same drape at once)
    assert main(["case", "skirt-circle", "--out", str(out), "--no-figures", "--set", "garment.h=6", "--resume"]) == 0
    again = json.loads((out / "summary.json").read_text())
    assert again["garment"]["hem_folds"] == own["garment"]["hem_folds"] and again["converged"]
    assert again["energies"]["total"] == pytest.approx(own["energies"]["total"], rel=1e-9)
