"""The garment analysis end to end (rftstatic.app.garment): panels placed, seams closed and merged, draped on the
dress form, checked by tests independent of the solve (crossings against the form itself, seam pairs merged)."""

import json

import numpy as np
import pytest

from rftstatic.app.garment import read_obj_uv
from rftstatic.cli import main
from rftstatic.garment.meshing import mesh_pattern
from rftstatic.garment.readers import read_pattern
from rftstatic.garment.sewing import SEAM_CLOSED, seam_pairs
from rftstatic.scenes.schema import load_scene

def _check_dressed(out, pattern_path, h):
    summary = json.loads((out / "summary.json").read_text())
    g = summary["garment"]
    assert summary["converged"] and summary["stable_minimum"]
    assert g["body_crossing_pairs"] == 0 and summary["self_intersections"]["pairs"] == 0
    assert g["largest_seam_gap"] <= SEAM_CLOSED * g["mean_element_size"]
    pmesh = mesh_pattern(read_pattern(pattern_path), h)
    pairs = seam_pairs(pmesh)
    assert g["nodes_sewn"] == len(pairs)
    # garment.obj: one texture coordinate per panel corner; each face's flat edge lengths are its panel's
    x, vt, tri, vt_tri = read_obj_uv(out / "garment.obj")
    assert len(vt) == pmesh.n_nodes and len(x) == pmesh.n_nodes - len(pairs)
    flat = np.linalg.norm(vt[vt_tri[:, 1]] - vt[vt_tri[:, 0]], axis=1)
    uv = np.concatenate([m.X for m in pmesh.meshes]) * 100
    np.testing.assert_allclose(flat, np.linalg.norm(uv[vt_tri[:, 1]] - uv[vt_tri[:, 0]], axis=1), rtol=1e-7)
    return summary


@pytest.mark.slow
def test_the_a_line_skirt_sews_and_drapes(tmp_path):
    out = tmp_path / "out"
    assert main(["case", "skirt-a-line", "--out", str(out), "--no-figures", "--set", "garment.h=3"]) == 0
    summary = _check_dressed(out, load_scene("skirt-a-line").path.parent / "patterns" / "skirt-a-line.toml", 0.03)
    assert summary["garment"]["hem_folds"] >= 2


@pytest.mark.slow
def test_the_dress_sews_on_a_coarse_mesh_and_drapes_on_its_own(tmp_path):
    # four panels, six seams; the seams closed on a 6 cm mesh, carried to the 4 cm garment mesh and closed there
    out = tmp_path / "out"
    assert main(["case", "dress", "--out", str(out), "--no-figures", "--set", "garment.h=4",
                 "--set", "garment.closing_h=6"]) == 0
    summary = _check_dressed(out, load_scene("dress").path.parent / "patterns" / "dress-shift.toml", 0.04)
    levels = summary["garment"]["closing_levels"]
    assert [r["h"] for r in levels] == [6, 4]
    assert levels[1]["largest_seam_gap_start"] < levels[0]["largest_seam_gap_start"] / 30  # carried nearly closed
    assert summary["garment"]["panels"] == 4


def test_the_garmentcode_json_skirt_is_the_toml_skirt(tmp_path):
    # the same A-line skirt written to GarmentCode's published schema: the same panels, placement and seam pairs, so
    # the sewing and the drape (test_the_a_line_skirt_sews_and_drapes) are the same run
    from rftstatic.app.garment import dressed_mesh

    toml = load_scene("skirt-a-line")
    text = toml.path.read_text().replace("patterns/skirt-a-line.toml", "patterns/skirt-a-line.json")
    (tmp_path / "patterns").symlink_to(toml.path.parent / "patterns")
    (tmp_path / "s.toml").write_text(text)
    js = load_scene(str(tmp_path / "s.toml"))
    (pa, ma, _), (pb, mb, _) = dressed_mesh(toml), dressed_mesh(js)
    np.testing.assert_allclose(ma.X3, mb.X3, atol=1e-12)
    np.testing.assert_allclose(ma.element_X, mb.element_X, atol=1e-12)
    np.testing.assert_array_equal(ma.tri, mb.tri)
    np.testing.assert_array_equal(seam_pairs(pa), seam_pairs(pb))


@pytest.mark.slow
def test_the_dress_drapes_on_a_chart_size(tmp_path):
    # the ANSUR II size 84 (rftstatic.references.body_sizes) in place of the scene's measurements
    out = tmp_path / "out"
    assert main(["case", "dress", "--out", str(out), "--no-figures", "--set", "garment.h=2.5",
                 "--set", "garment.closing_h=5", "--set",
                 'body={kind="dress-form", size=84, neck_length=6.0, bottom_height=62.0}']) == 0
    summary = _check_dressed(out, load_scene("dress").path.parent / "patterns" / "dress-shift.toml", 0.025)
    assert summary["garment"]["panels"] == 4


@pytest.mark.slow
def test_the_hemmed_skirt_sews_its_folds_and_drapes_with_the_hem_turned_up(tmp_path):
    # the A-line skirt with 4 cm facings turned up at fold seams: sewn, creased at 180 deg, draped on the form
    out = tmp_path / "out"
    assert main(["case", "skirt-a-line-hem", "--out", str(out), "--no-figures", "--set", "garment.h=3",
                 "--set", "garment.closing_h=3"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    g = summary["garment"]
    assert summary["converged"] and summary["stable_minimum"]
    assert g["body_crossing_pairs"] == 0 and summary["self_intersections"]["pairs"] == 0
    assert g["largest_seam_gap"] <= SEAM_CLOSED * g["mean_element_size"]
    pmesh = mesh_pattern(read_pattern(load_scene("skirt-a-line-hem").path.parent / "patterns" /
                                      "skirt-a-line-hem.toml"), 0.03)
    hem_edges = sum(len(p) - 1 for s, p in zip(pmesh.pattern.seams, pmesh.seam_pairs) if s.kind == "fold")
    assert g["crease_edges"] == hem_edges
    assert g["crease_off_rest_max_deg"] < 45  # the facings lie turned up on the skirt
    # the hem is the crease: the lowest line of the skirt, below the facings' free edge
    x, _, tri, _ = read_obj_uv(out / "garment.obj")
    assert g["hem_lowest"] == pytest.approx(x[:, 2].min(), abs=1e-6)
