"""Static drape with penalty contact: a sheet on a floor, and small versions of every scene type."""

import json

import numpy as np
import pytest

from rftstatic import material
from rftstatic.cli import main
from rftstatic.contact.obstacles import Floor
from rftstatic.contact.penalty import PenaltyContact, auto_penalty
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from rftstatic.scenes.build import build_model, hold_inplane_rigid_modes
from rftstatic.scenes.options import static_options
from rftstatic.scenes.schema import load_scene
from rftstatic.solvers import static

QUIET = dict(progress=False)


def test_sheet_laid_on_a_floor_rests_on_it_with_its_weight_as_reaction():
    m = mesh.rectangle(0.1, 0.1, 7, 7, origin=(-0.05, -0.05))
    wool = material.preset("wool-kang-yu")
    h = float(m.element_size.mean())
    k = auto_penalty(membrane_rigidity=wool.membrane_scale, bending_rigidity=wool.bending_scale,
                     weight=wool.weight, h=h)
    contact = PenaltyContact([Floor(0.0)], m.node_area, k)
    sup = model.Supports.none(m.n_nodes)
    hold_inplane_rigid_modes(m, sup)
    mod = model.Model(m, wool, supports=sup, load=model.gravity_load(m, wool.weight), contact=contact)
    res = static.solve_static(mod, options=static.StaticOptions.from_keys(**QUIET))
    assert res.converged
    x = mod.positions(res.U)
    reaction = -contact.force(x)  # what the floor pushes on the sheet
    weight = wool.weight * m.area.sum()
    assert reaction[:, 2].sum() == pytest.approx(weight, rel=1e-6)
    # uniform pressure w sinks every node by w / k, a tiny fraction of the element size
    assert np.allclose(x[:, 2], -wool.weight / k, rtol=1e-3, atol=1e-3 * wool.weight / k)
    assert contact.max_penetration(x) < 1e-3 * h
    assert np.abs(res.U[:, :2]).max() < 1e-9 * h


def _run(name, *overrides):
    scene = load_scene(name, list(overrides))
    mod, extras = build_model(scene)
    res = static.solve_static(mod, options=static_options(scene, progress=False))
    return scene, mod, res


def _check_equilibrium(mod, res, rtol=1e-5):
    assert res.converged
    r = mod.residual(res.U).ravel()[mod.free.ravel()]
    assert np.linalg.norm(r) <= rtol * np.linalg.norm(mod.load)  # the drape scenes' solver.rtol
    x = mod.positions(res.U)
    assert mod.contact.max_penetration(x) < 0.01 * mod.mesh.element_size.mean()


def test_small_square_pedestal_is_in_equilibrium_and_its_mirror_images_too():
    scene, mod, res = _run("pedestal-square-20", "mesh.nodes=[9, 9]", "solver.perturbation=0.0")
    _check_equilibrium(mod, res)
    # the folds may pick an asymmetric branch, but the scene is symmetric about y = 0 (union-jack mesh,
    # orthotropic wool in those axes, centred pedestal, in-plane holds on the x axis): the mirror image
    # of the drape must be an equilibrium too
    X = mod.mesh.X
    free = mod.free.ravel()
    for axis in (1,):
        mirror = X.copy()
        mirror[:, axis] *= -1
        j = mod.mesh.nearest_node(mirror)
        assert np.abs(X[j] - mirror).max() < 1e-12
        Um = res.U[j].copy()
        Um[:, axis] *= -1
        r = mod.residual(Um).ravel()[free]
        assert np.linalg.norm(r) < 1e-5 * np.linalg.norm(mod.load)


def test_small_round_pedestal_and_sphere_converge():
    for name, overrides in (("pedestal-round-50", ["mesh.nodes=[5, 24]"]),
                            ("sphere-30", ["mesh.nodes=[9, 9]"])):
        _, mod, res = _run(name, *overrides)
        _check_equilibrium(mod, res)


def test_drape_summary_reports_measures(tmp_path):
    out = tmp_path / "p"
    assert main(["case", "pedestal-square-20", "--set", "mesh.nodes=[9,9]", "--no-figures", "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    d = s["drape"]
    assert 0.0 < d["drape_coefficient"] < 1.0
    # a square sheet on a square pedestal folds at its four corners: one fold per quadrant, about the
    # diagonals (measured 47.5, 136, 224, 317.5 deg on 9 x 9)
    assert d["fold_count"] == 4
    angles = np.sort(np.asarray(d["fold_angles_deg"]) % 360.0)
    assert np.all(np.abs(angles - np.array([45.0, 135.0, 225.0, 315.0])) < 10.0)
    assert s["max_penetration"] < 0.01 * 20 / 8 and s["converged"]
    assert s["perturbation_seed"] == 1
    # the self-intersection check, in cm: the same as on the written state (deformed.vtu, cm)
    import meshio

    from rftstatic.post.measures.intersections import smallest_distance

    si = s["self_intersections"]
    assert si["pairs"] == si["triangles"] == 0 and si["area_fraction"] == 0.0 and si["seconds"] >= 0.0
    m = meshio.read(out / "deformed.vtu")
    d, pair = smallest_distance(m.points, m.cells_dict["triangle"])
    assert si["smallest_distance"] == pytest.approx(d, rel=1e-9) and si["smallest_distance_pair"] == list(pair)
    assert 0.5 < si["smallest_distance"] < 2.5 <= si["within"] < 3.0   # cm: the grid is 2.5 cm


def test_a_sheet_smaller_than_the_pedestal_has_no_drape_coefficient(tmp_path):
    out = tmp_path / "small"
    assert main(["case", "pedestal-square-20", "--set", "mesh.nodes=[9,9]", "--set", "mesh.size=[5.0,5.0]",
                 "--set", "mesh.origin=[-2.5,-2.5]", "--set", "probes=[]", "--no-figures", "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["converged"] and s["drape"]["applicable"] is False and "footprint" in s["drape"]["reason"]
