"""Sewing (rftstatic.garment.sewing): seam springs, the closing stage and the merge of the seams' two sides."""

from pathlib import Path

import numpy as np
import pytest

from rftstatic.garment.meshing import mesh_pattern, place
from rftstatic.garment.pattern import PatternError
from rftstatic.garment.readers import read_pattern
from rftstatic.garment.sewing import (FOLD_START_TOLERANCE, SEAM_CLOSED, carry_closed, close_seams, fold_chains,
                                     panel_mesh, seam_pairs, sew, turned_back)
from rftstatic.material import preset
from rftstatic.model.loads import SeamSprings
from rftstatic.model.model import Model

PATTERNS = Path(__file__).resolve().parents[2] / "cases" / "patterns"

# a tube of two 20 x 30 cm panels facing each other 16 cm apart, sewn along both long sides
TUBE = """
units = "cm"
[[panels]]
name = "front"
vertices = [[-10, 0], [10, 0], [10, 30], [-10, 30]]
grain = 90
translate = [0, 0, 8]
[[panels]]
name = "back"
vertices = [[-10, 0], [10, 0], [10, 30], [-10, 30]]
grain = 90
translate = [0, 0, -8]
rotate = [0, 180, 0]
[[seams]]
a = "front:1"
b = "back:3"
[[seams]]
a = "front:3"
b = "back:1"
"""


@pytest.fixture(scope="module")
def tube(tmp_path_factory):
    path = tmp_path_factory.mktemp("tube") / "tube.toml"
    path.write_text(TUBE)
    pmesh = mesh_pattern(read_pattern(path), 0.04)
    return pmesh, panel_mesh(pmesh, place(pmesh))


def test_seam_springs_force_is_the_gradient_and_tangent_the_hessian():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(7, 3))
    springs = SeamSprings([[0, 3], [2, 5], [6, 1]], [1.5, 0.3, 2.0])
    f = springs.force(x)
    rows, cols, blocks = springs.tangent_blocks(x)
    K = np.zeros((21, 21))
    for r, c, b in zip(rows, cols, blocks):
        K[3 * r:3 * r + 3, 3 * c:3 * c + 3] += b
    h = 1e-6
    for d in range(21):
        e = np.zeros(21)
        e[d] = h
        e = e.reshape(7, 3)
        assert (springs.potential(x + e) - springs.potential(x - e)) / (2 * h) == pytest.approx(f.ravel()[d], abs=1e-8)
        np.testing.assert_allclose((springs.force(x + e) - springs.force(x - e)).ravel() / (2 * h), K[:, d], atol=1e-8)
    np.testing.assert_allclose(springs.force(x + [1.0, -2.0, 0.5]), f)  # a rigid shift changes nothing
    assert np.allclose(springs.gaps(x), np.linalg.norm(x[[0, 2, 6]] - x[[3, 5, 1]], axis=1))


def test_the_placed_panels_are_stress_free_and_the_springs_pull_the_seams(tube):
    pmesh, mesh = tube
    pairs = seam_pairs(pmesh)
    assert len(pairs) == sum(len(p) for p in pmesh.seam_pairs)
    np.testing.assert_allclose(np.linalg.norm(mesh.X3[pairs[:, 0]] - mesh.X3[pairs[:, 1]], axis=1), 0.16, atol=1e-12)
    model = Model(mesh, preset("wool-kang-yu"), element="RFT6", load_terms=(SeamSprings(pairs, 1.0),), quiet=True)
    zero = np.zeros((mesh.n_nodes, 3))
    assert model.energies(zero)["bending"] == pytest.approx(0, abs=1e-14)
    assert model.energies(zero)["membrane"] == pytest.approx(0, abs=1e-14)
    r = model.residual(zero)
    assert np.abs(r[pairs[:, 0], 2]).min() > 0.1 and (r[pairs[:, 0], 2] > 0).all()  # front pulled back (-z)


def test_seams_close_and_merge_into_a_tube(tube):
    pmesh, mesh = tube
    pairs = seam_pairs(pmesh)
    mat = preset("wool-kang-yu")
    Dm = mat.Dm

    def build(springs):
        return Model(mesh, mat, element="RFT6", load_terms=(springs,), quiet=True)

    c = close_seams(build, pairs, (), weight=mat.weight * float(mesh.area.sum()),
                    stiffest=0.5 * min(Dm[0, 0], Dm[1, 1]), t_stage=1.0, alpha=8.0)
    assert c.closed and c.largest_gap <= SEAM_CLOSED * mesh.element_size.mean()
    assert c.largest_gap_start == pytest.approx(0.16)
    sewn, node_of = sew(mesh, pairs, c.x)
    assert sewn.n_nodes == mesh.n_nodes - len(pairs)
    assert np.array_equal(node_of[pairs[:, 0]], node_of[pairs[:, 1]])
    # one closed tube: no boundary along the seams, two boundary loops (the ends)
    assert len(sewn.boundary_edges) == len(mesh.boundary_edges) - 2 * (len(pairs) - len(pmesh.seam_pairs))
    # every patch along a seam now reaches across it: the sewn model has real opposite nodes there
    model = Model(sewn, mat, element="RFT6", quiet=True)
    assert model.patches.has_opposite.sum() > Model(mesh, mat, element="RFT6", quiet=True).patches.has_opposite.sum()
    # merging moves the nodes by half the last gap: the CST strains (RFT3: each element on its own) barely change
    # (RFT6's mid-side strains see the patch, folded sharply at a closed seam, and are no measure of the merge)
    before = Model(mesh, mat, element="RFT3", quiet=True).membrane_strain(c.x - mesh.X3)
    after = Model(sewn, mat, element="RFT3", quiet=True).membrane_strain(np.zeros((sewn.n_nodes, 3)))
    assert np.abs(after - before).max() < 2 * SEAM_CLOSED
    # the chart keeps each sewn node's first panel node's coordinates
    first = np.full(sewn.n_nodes, mesh.n_nodes)
    np.minimum.at(first, node_of, np.arange(mesh.n_nodes))
    np.testing.assert_array_equal(sewn.X, mesh.X[first])


def test_sewing_a_triangle_onto_itself_is_an_error(tube):
    pmesh, mesh = tube
    t = mesh.tri[0]
    with pytest.raises(PatternError, match="collapses 1 triangle"):
        sew(mesh, np.array([[t[0], t[1]]]), mesh.X3, where="tube.toml")


# a 20 x 30 cm panel with a 4 cm hem facing turned back behind it (1 cm apart), its hem a fold seam
HEMMED = """
units = "cm"
[[panels]]
name = "skirt"
vertices = [[-10, 0], [10, 0], [10, 30], [-10, 30]]
translate = [0, 0, 8]
[[panels]]
name = "facing"
vertices = [[-10, -4], [10, -4], [10, 0], [-10, 0]]   # drawn below the hem, as cut; turned up behind the skirt
translate = [0, 0, 7]
rotate = [180, 0, 0]
[[seams]]
a = "skirt:0"
b = "facing:2"
kind = "fold"
"""


def _close(pmesh):
    mesh = panel_mesh(pmesh, place(pmesh))
    pairs = seam_pairs(pmesh)
    mat = preset("wool-kang-yu")

    def build(springs):
        return Model(mesh, mat, element="RFT6", load_terms=(springs,), quiet=True)

    c = close_seams(build, pairs, (), weight=mat.weight * float(mesh.area.sum()),
                    stiffest=0.5 * min(mat.Dm[0, 0], mat.Dm[1, 1]), t_stage=1.0, alpha=8.0)
    return mesh, pairs, c, mat


def test_a_fold_seam_is_closed_merged_and_becomes_a_crease_turned_back(tmp_path):
    path = tmp_path / "hem.toml"
    path.write_text(HEMMED)
    pmesh = mesh_pattern(read_pattern(path), 0.02)
    mesh, pairs, c, mat = _close(pmesh)
    assert c.closed
    (chain,) = fold_chains(pmesh)
    sewn, node_of = sew(mesh, pairs, c.x, where="hem.toml", folds=[chain])
    assert len(sewn.folds) == len(chain.nodes) - 1
    np.testing.assert_allclose(np.abs(sewn.folds.angle), np.pi)
    model = Model(sewn, mat, element="RFT6", quiet=True)
    assert len(model.hinges) == len(sewn.folds)
    # the closed hem is turned back: its creases within FOLD_START_TOLERANCE of 180 deg
    assert (np.degrees(np.abs(model.hinges.angles(sewn.X3))) > 180 - FOLD_START_TOLERANCE).all()
    # the patches end at the crease: no patch of the skirt reaches into the facing
    facing = turned_back(pmesh)
    reach = model.patches.nodes[~facing]  # (a missing opposite's slot holds the element's own vertex)
    facing_only = np.setdiff1d(np.unique(sewn.tri[facing]), np.unique(sewn.tri[~facing]))
    assert not np.isin(reach, facing_only).any()


def test_a_fold_seam_placed_unfolded_is_refused_naming_the_seam(tmp_path):
    path = tmp_path / "flat.toml"
    path.write_text(HEMMED.replace("rotate = [180, 0, 0]", "").replace("translate = [0, 0, 7]",
                                                                      "translate = [0, -1, 8]"))
    pmesh = mesh_pattern(read_pattern(path), 0.04)
    mesh, pairs, c, _ = _close(pmesh)
    with pytest.raises(PatternError, match="fold seam skirt:0 -- facing:2 closed at"):
        sew(mesh, pairs, c.x, where="flat.toml", folds=fold_chains(pmesh))


def test_fold_keys_belong_to_fold_seams(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(TUBE.replace('a = "front:3"', 'angle = 90\na = "front:3"'))
    with pytest.raises(PatternError, match="angle and width belong to a fold seam"):
        read_pattern(path)
    path.write_text(HEMMED.replace('kind = "fold"', 'kind = "fold"\nangle = 270'))
    with pytest.raises(PatternError, match="fold angle = 270"):
        read_pattern(path)


def test_the_a_line_skirt_pairs_its_side_seams():
    pmesh = mesh_pattern(read_pattern(PATTERNS / "skirt-a-line.toml"), 0.05)
    pairs = seam_pairs(pmesh)
    x = place(pmesh)
    # reversed seams: front's edge 1 (hem -> waist) pairs with back's edge 3 (waist -> hem), height by height
    np.testing.assert_allclose(x[pairs[:, 0], 1], x[pairs[:, 1], 1], atol=1e-9)


def _wrap(pmesh, radius):
    """Each panel's coordinates wrapped onto a cylinder of ``radius`` [m] about the panel's y axis (a smooth, curved
    closed shape): (N, 3)."""
    uv = np.concatenate([m.X for m in pmesh.meshes])
    a = uv[:, 0] / radius
    return np.stack([radius * np.sin(a), uv[:, 1], radius * (1 - np.cos(a))], axis=1)


def test_carrying_the_closed_shape_to_a_finer_mesh():
    pattern = read_pattern(PATTERNS / "skirt-a-line.toml")
    fine = mesh_pattern(pattern, 0.03)
    # a placement is a rigid map of each panel's coordinates: carried exactly (the patch quadratic holds linear
    # fields), including the curved edges' nodes just outside the coarse polygons
    for h in (0.1, 0.06):
        coarse = mesh_pattern(pattern, h)
        np.testing.assert_allclose(carry_closed(coarse, place(coarse), fine), place(fine), atol=1e-10)
    # a curved shape (panels wrapped on a 20 cm cylinder): the rms error at the fine nodes falls as h^3 (the patch
    # quadratic; measured 2.9e-3 -> 3.4e-4 m from h = 12 to 6 cm, the chords' route "mesh" 6.0e-3 -> 1.5e-3), the
    # largest as h^2
    rms, largest = [], []
    for h in (0.12, 0.06):
        coarse = mesh_pattern(pattern, h)
        e = np.linalg.norm(carry_closed(coarse, _wrap(coarse, 0.2), fine) - _wrap(fine, 0.2), axis=1)
        rms.append(np.sqrt(np.mean(e**2)))
        largest.append(e.max())
    assert rms[1] < rms[0] / 6 and largest[1] < largest[0] / 4 and rms[1] < 5e-4


def test_the_dress_pattern_pairs_its_four_side_seams_and_two_shoulder_seams():
    pmesh = mesh_pattern(read_pattern(PATTERNS / "dress-shift.toml"), 0.05)
    assert len(pmesh.meshes) == 4 and len(pmesh.pattern.seams) == 6
    x = place(pmesh)
    for seam, pairs in zip(pmesh.pattern.seams, pmesh.seam_pairs):
        gap = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
        if seam.a_edge in (3, 5):  # shoulder seams: over the shoulder, front to back (placed 32 cm apart)
            np.testing.assert_allclose(gap, 0.32, rtol=1e-9)
        else:  # side seams: node k of one side at the height of node k of the other (reversed edges)
            np.testing.assert_allclose(x[pairs[:, 0], 1], x[pairs[:, 1], 1], atol=1e-9)
            assert gap.max() < 0.11


def test_the_self_contact_leaves_the_two_sides_of_an_open_seam_alone(tube):
    from dataclasses import replace

    from rftstatic.contact.self_contact.broad_phase import SheetPrimitives, find_pairs
    from rftstatic.contact.self_contact.law import SelfContact

    pmesh, mesh = tube
    assert np.array_equal(mesh.seams, seam_pairs(pmesh))
    # the panels with their seams all but closed (0.1 mm): each seam node lies on the other panel's edge triangles
    x = mesh.X3.copy()
    pairs = seam_pairs(pmesh)
    x[pairs[:, 1]] = x[pairs[:, 0]] + [0.0, 0.0, 1e-4]
    closed = replace(mesh, placed=x)
    bare = replace(closed, seams=None)
    law = SelfContact(closed, 5e-4, 1.0)  # its start has no pair in contact
    assert law.evaluate(x, tangent=False).n_active == 0
    kept = find_pairs(SheetPrimitives.of_mesh(closed), x, 1.0)
    joined = SheetPrimitives.of_mesh(closed).joined
    assert not (joined[kept.pt[:, :1]] == joined[closed.tri[kept.pt[:, 1]]]).any()
    with pytest.raises(ValueError, match="barrier gap"):
        SelfContact(bare, 5e-4, 1.0)
