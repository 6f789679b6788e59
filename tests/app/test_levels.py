"""Mesh sequencing (``solver.levels``): the coarser meshes of a scene, the transfer of an equilibrium to
the next mesh, and a drape solved level by level, saved as it goes and taken up again by a resume."""

import json

import numpy as np
import pytest

import rftstatic.app.levels as levels_mod
from rftstatic.app import static as app
from rftstatic.app.levels import solve_levels, transfer_start
from rftstatic.errors import ConvergenceError, SceneError
from rftstatic.scenes.build import build_model
from rftstatic.scenes.levels import AUTO_COARSEST, AUTO_FROM, auto_levels, level_mesh, level_nodes, level_scenes
from rftstatic.scenes.options import run_options, static_options
from rftstatic.scenes.schema import load_scene

DRAPE = ["mesh.nodes=[17,17]", "solver.levels=2"]  # 9 x 9 by the scene's relaxation, 17 x 17 by Newton: ~6 s


@pytest.mark.parametrize("scene, nodes, expected", [
    ("pedestal-square-80", [201, 201], [[51, 51], [101, 101], [201, 201]]),
    ("pedestal-square-80", [81, 81], [[21, 21], [41, 41], [81, 81]]),
    ("pedestal-square-20", [34, 33], [[10, 9], [18, 17], [34, 33]]),
    ("pedestal-round-50", [21, 160], [[6, 40], [11, 80], [21, 160]]),
    ("pedestal-round-50", [31, 240], [[9, 64], [16, 120], [31, 240]]),
])
def test_each_level_has_about_twice_the_element_size_of_the_next(scene, nodes, expected):
    sc = load_scene(scene, [f"mesh.nodes={nodes}", "solver.levels=3"])
    levels = level_scenes(sc, 3)
    assert [s.get("mesh.nodes") for s in levels] == expected
    assert levels[-1] is sc
    assert all(s.get("solver.levels") == 1 and s.get("probes") is None for s in levels[:-1])
    assert level_scenes(sc, 1) == [sc]


def test_an_unstructured_level_doubles_h_and_a_file_mesh_has_none(tmp_path):
    sc = load_scene("pedestal-round-50-unstructured")
    h = sc.get("mesh.h")
    assert level_mesh(sc, 2)["h"] == pytest.approx(4 * h)
    path = tmp_path / "file.toml"
    path.write_text('[mesh]\nkind = "file"\npath = "sheet.msh"\n[solver]\nlevels = 2\n')
    with pytest.raises(SceneError, match="solver.levels.*file"):
        level_scenes(load_scene(str(path)), 2)


@pytest.mark.parametrize("scene, overrides, levels", [
    ("pedestal-square-80", [], 1),  # the paper's 81 x 81: the scene's own route
    ("pedestal-square-80", ["mesh.nodes=[101,101]"], 1),  # 10,201 nodes
    ("pedestal-square-80", ["mesh.nodes=[121,121]"], 1),  # 14,641 nodes
    ("pedestal-square-80", ["mesh.nodes=[141,141]"], 3),  # 19,881 nodes: from 36 x 36
    ("pedestal-square-80", ["mesh.nodes=[201,201]"], 3),  # 40,401 nodes: from 51 x 51
    ("pedestal-round-50", ["mesh.nodes=[31,240]"], 1),  # 12,464 nodes, the finer mesh of the reports
    ("pedestal-round-50", ["mesh.nodes=[61,480]"], 4),  # 49,000 nodes: from 9 x 64 (16 x 120 has 3,100)
    ("pedestal-round-50-unstructured", [], 1),
    ("pedestal-round-50-unstructured", ["mesh.h=0.2"], 4),
    ("strip", ["mesh.nodes=[6001,3]"], 1),  # 18,003 nodes, but a coarser strip would have 2 nodes across
    ("pedestal-square-80", ["mesh.nodes=[201,201]", "solver.levels=2"], 2),  # a count given is kept
])
def test_auto_levels_sequence_large_meshes_from_a_coarsest_of_at_most_AUTO_COARSEST(scene, overrides, levels):
    sc = load_scene(scene, overrides)
    given = "solver.levels=2" in overrides
    assert sc.get("solver.levels") is None or given  # "auto" is the default
    assert run_options(sc).levels == levels
    if not given:
        assert auto_levels(sc) == levels
        assert (level_nodes(sc) >= AUTO_FROM) == (levels > 1 or scene == "strip")
        if levels > 1:
            assert level_nodes(sc, levels - 1) <= AUTO_COARSEST < level_nodes(sc, levels - 2)


def test_the_auto_node_counts_are_the_built_meshes_and_a_file_mesh_has_one_level(tmp_path):
    for scene, ov in [("pedestal-square-80", ["mesh.nodes=[41,41]"]), ("pedestal-round-50", ["mesh.nodes=[11,80]"]), ("pedestal-round-50", ["mesh.nodes=[31,240]"]),
                      ("cusick-30", []),
                      ("pedestal-round-50-unstructured", [])]:
        sc = load_scene(scene, ov)
        built = build_model(sc, quiet=True)[0].mesh.n_nodes
        assert level_nodes(sc) == pytest.approx(built, rel=0.0 if scene == "pedestal-square-80" else 0.05)
    path = tmp_path / "file.toml"
    path.write_text('[mesh]\nkind = "file"\npath = "sheet.msh"\n')
    assert auto_levels(load_scene(str(path))) == 1


def test_a_levels_word_other_than_auto_names_the_key():
    sc = load_scene("pedestal-square-20", ['solver.levels="many"'])
    with pytest.raises(SceneError, match=r'solver\.levels: must be an integer or "auto", got \'many\''):
        run_options(sc)


def test_too_many_levels_name_the_key_and_the_coarsest_mesh():
    sc = load_scene("pedestal-square-20", ["mesh.nodes=[9,9]"])
    with pytest.raises(SceneError, match=r"solver.levels.*\[2, 2\]"):
        level_scenes(sc, 4)
    with pytest.raises(SceneError, match=r"solver.levels.*\[1, 6\]"):
        level_scenes(sc, 7)


def test_the_transfer_carries_a_linear_field_exactly_and_keeps_the_supports():
    coarse, _ = build_model(load_scene("strip", ["mesh.nodes=[11,3]"]))
    fine, _ = build_model(load_scene("strip", ["mesh.nodes=[21,5]"]))
    A = np.array([[0.01, -0.02], [0.03, 0.005], [0.2, -0.1]])  # (3, 2): U = A X + b on the free nodes
    U = coarse.mesh.X @ A.T + [0.001, 0.002, -0.003]
    U0 = transfer_start(coarse, U, fine)
    expected = fine.mesh.X @ A.T + [0.001, 0.002, -0.003]
    free = fine.free
    assert np.allclose(U0[free], expected[free], atol=1e-14)
    assert not np.any(U0[fine.fixed]) and fine.fixed.any()


@pytest.fixture(scope="module")
def drape(tmp_path_factory):
    out = tmp_path_factory.mktemp("levels") / "run"
    result = app.run(load_scene("pedestal-square-20", DRAPE), out, progress=False, figures=False)
    return result, out


def test_a_drape_solved_level_by_level_is_a_stable_equilibrium_of_the_fine_mesh(drape):
    result, out = drape
    s = json.loads((out / "summary.json").read_text())
    assert s["converged"] and s["stable_minimum"] and s["route"] == "relax+newton+levels"
    assert [lv["mesh"] for lv in s["levels"]] == ["[9, 9]", "[17, 17]"]
    assert s["levels"][1]["route"] == "newton" and s["levels"][0]["route"] == "relax+newton"
    assert s["newton_iterations"] == sum(lv["iterations"] for lv in s["levels"])
    # the equilibrium checked by its own residual on the scene's (fine) model
    r = result.model.residual(result.U, 1.0)[result.model.free]
    assert np.linalg.norm(r) <= 1e-5 * np.linalg.norm(result.model.load)
    assert s["drape"]["fold_count"] == 4 and s["max_penetration"] < 1e-3
    assert not list(out.glob("level-*.npz"))  # a finished run keeps no levels


def test_a_resumed_sequence_takes_up_the_saved_levels(tmp_path, drape):
    scene = load_scene("pedestal-square-20", DRAPE)
    model, _ = build_model(scene)
    opts = static_options(scene, progress=False)
    first = solve_levels(scene, model, opts, folder=tmp_path)
    assert (tmp_path / "level-1.npz").exists()
    again = solve_levels(scene, build_model(scene)[0], opts, folder=tmp_path, resume=True)
    assert again.levels[0]["resumed"] and "resumed" not in again.levels[1]
    assert np.allclose(again.U, first.U, rtol=0, atol=1e-9)
    # a level saved for another model (another fabric) is solved again
    other = load_scene("pedestal-square-20", DRAPE + ["material.weight=0.03"])
    res = solve_levels(other, build_model(other)[0], static_options(other, progress=False), folder=tmp_path,
                       resume=True)
    assert "resumed" not in res.levels[0]


def test_resume_from_the_command_line_takes_up_a_saved_level(tmp_path):
    """``case NAME --resume`` on a folder that holds only saved levels (a run killed on its finest mesh)
    continues from them (:func:`rftstatic.app.registry.resume_scene`), then leaves no level behind."""
    from rftstatic.app.registry import resume_scene

    scene = load_scene("pedestal-square-20", DRAPE)
    out = tmp_path / "run"
    solve_levels(scene, build_model(scene)[0], static_options(scene, progress=False), folder=out)
    (out / "level-2.npz").unlink(missing_ok=True)  # the finest level is never saved; as if killed there
    s = resume_scene(scene, out, progress=False, figures=False)
    assert s["converged"] and s["levels"][0]["resumed"] and "resumed" not in s["levels"][1]
    assert not list(out.glob("level-*.npz"))


def test_the_load_scaled_route_on_the_coarsest_mesh_and_newton_above_it(tmp_path):
    """``continuation = "arc-length"`` follows the path on the coarsest mesh only; the finer levels are
    Newton at full load from the level below (no path from their transferred start), no relaxation."""
    scene = load_scene("pedestal-square-20", DRAPE + ["solver.start=load-steps", "solver.continuation=arc-length",
                                                      "solver.relax_fallback=false"])
    s = app.run(scene, tmp_path / "run", progress=False, figures=False).summary
    assert s["converged"] and s["stable_minimum"] and s["route"] == "arc-length+levels"
    assert [lv["route"] for lv in s["levels"]] == ["arc-length", "newton"]
    assert s["relax"] == {} and len(s["path"]["steps"]) > 0 and s["path"]["final_negative"] == 0


def test_a_failed_finest_level_is_reported_with_the_levels_solved_below_it(tmp_path, monkeypatch):
    """When the finest Newton fails, summary.json still lists every level (the coarse ones converged, the
    finest not), the route and the counters over all of them; the state written is the finest level's
    last iterate at full load (a cut back would have unloaded the carried drape)."""
    route = levels_mod.static_route

    def starved_finest(model, state, options, *, U0=None, **kw):  # the fine level gets a single iteration
        if U0 is not None:
            options = options.replace(max_iterations=1, max_continuations=0)
        return route(model, state, options, U0=U0, **kw)

    monkeypatch.setattr(levels_mod, "static_route", starved_finest)
    out = tmp_path / "run"
    with pytest.raises(ConvergenceError, match=r"level 2 of 2 .* from the given state") as info:
        app.run(load_scene("pedestal-square-20", DRAPE), out, progress=False, figures=False)
    assert info.value.result.lam == 1.0 and info.value.result.cutbacks == 0
    s = json.loads((out / "summary.json").read_text())
    assert not s["converged"] and s["route"] == "relax+newton+levels" and s["load_factor"] == 1.0
    assert [(lv["mesh"], lv["converged"]) for lv in s["levels"]] == [("[9, 9]", True), ("[17, 17]", False)]
    assert s["newton_iterations"] == sum(lv["iterations"] for lv in s["levels"])
    assert (out / "level-1.npz").exists()  # kept for a --resume


MATCHED = DRAPE[:1] + ["solver.levels=3", "solver.level_membrane=matched"]  # 5 x 5, 9 x 9, 17 x 17


def test_membrane_match_gives_a_coarse_level_the_finest_meshs_locking_number():
    from rftstatic.app.levels import membrane_match
    from rftstatic.model.model import locking_number

    scenes = level_scenes(load_scene("pedestal-square-80", ["mesh.nodes=[201,201]"]), 3)
    meshes = [build_model(sc, quiet=True)[0].mesh for sc in scenes]
    assert [membrane_match(m, meshes[-1]) for m in meshes] == pytest.approx([1 / 16, 1 / 4, 1.0], rel=1e-12)
    assert membrane_match(meshes[-1], meshes[0]) == 1.0  # a finer mesh is never stiffened
    coarse = build_model(scenes[0], quiet=True, membrane_scale=1 / 16)[0]
    fine = build_model(scenes[-1], quiet=True)[0]
    assert locking_number(coarse.mesh, coarse.material) == pytest.approx(locking_number(fine.mesh, fine.material),
                                                                         rel=1e-9)
    assert np.allclose(coarse.material.Db, fine.material.Db) and coarse.material.weight == fine.material.weight


def test_a_membrane_scale_must_be_positive_and_one_leaves_the_fabric_alone():
    material = build_model(load_scene("pedestal-square-20", ["mesh.nodes=[5,5]"]), quiet=True)[0].material
    assert material.membrane_scaled(1.0) is material
    half = material.membrane_scaled(0.5)
    assert np.allclose(half.Dm, 0.5 * material.Dm) and half.info["membrane_scale"] == 0.5
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="membrane scale"):
            material.membrane_scaled(bad)
    with pytest.raises(SceneError, match="level_membrane"):
        run_options(load_scene("pedestal-square-20", ["solver.level_membrane=soft"]))


def test_matched_levels_reach_an_equilibrium_of_the_scenes_own_fabric(tmp_path):
    """``level_membrane = "matched"``: the coarsest route with the scene's fabric, then again with the matched
    membrane, the middle level matched, the finest the scene's model; the result is checked on that model."""
    scene = load_scene("pedestal-square-20", MATCHED)
    model = build_model(scene)[0]
    res = solve_levels(scene, model, static_options(scene, progress=False), folder=tmp_path)
    first, middle, finest = res.levels
    assert first["membrane_scale"] == 1.0 and first["route"] == "relax+newton"
    assert first["matched"]["converged"] and first["matched"]["membrane_scale"] == pytest.approx(1 / 16)
    assert middle["membrane_scale"] == pytest.approx(1 / 4) and finest["membrane_scale"] == 1.0
    assert res.converged and res.stable
    assert res.iterations == sum(lv["iterations"] + lv.get("matched", {}).get("iterations", 0) for lv in res.levels)
    assert np.array_equal(model.material.Dm, build_model(scene)[0].material.Dm)
    r = model.residual(res.U, 1.0)[model.free]
    assert np.linalg.norm(r) <= 1e-5 * np.linalg.norm(model.load)
    # the saved levels are those of the matched models: a resume takes them up
    again = solve_levels(scene, build_model(scene)[0], static_options(scene, progress=False), folder=tmp_path,
                         resume=True)
    assert again.levels[0]["resumed"] and again.levels[1]["resumed"]
    assert np.allclose(again.U, res.U, rtol=0, atol=1e-9)


def test_a_coarsest_level_that_fails_with_its_membrane_matched_carries_the_scenes_fabric(tmp_path, monkeypatch, caplog):
    solve = levels_mod.solve_static

    def matched_fails(model, **kw):
        if model.material.info.get("membrane_scale", 1.0) < 1.0 and model.mesh.n_nodes == 25:
            raise ConvergenceError("no convergence (as if)", result=None)
        return solve(model, **kw)

    monkeypatch.setattr(levels_mod, "solve_static", matched_fails)
    scene = load_scene("pedestal-square-20", MATCHED)
    res = solve_levels(scene, build_model(scene)[0], static_options(scene, progress=False))
    assert not res.levels[0]["matched"]["converged"] and res.converged
    assert "did not converge with its membrane matched" in caplog.text


def test_a_generated_mesh_without_nodes_has_the_builders_default_nodes():
    """A rectangle without ``mesh.nodes`` is built with the default nodes, and the mesh sequence counts the same
    (found by the scene property test: ``levels = "auto"`` raised KeyError 'nodes')."""
    import copy

    from rftstatic.scenes.schema import MESH_NODES, Scene

    base = load_scene("pedestal-square-20")
    data = copy.deepcopy(base.data)
    del data["mesh"]["nodes"]
    sc = Scene(data, base.path, base.name, {})
    built = build_model(sc, quiet=True)[0].mesh.n_nodes
    assert built == level_nodes(sc) == MESH_NODES["rectangle"][0] * MESH_NODES["rectangle"][1]
    assert auto_levels(sc) == 1 and run_options(sc).levels == 1
    assert level_mesh(sc, 1)["nodes"] == [6, 6]


def test_element_values_go_to_the_old_element_holding_each_new_centroid():
    """rftstatic.remesh.transfer.element_values, checked by barycentric coordinates computed here."""
    from rftstatic.remesh.transfer import element_values

    coarse = build_model(load_scene("strip", ["mesh.nodes=[11,3]"]))[0].mesh
    fine = build_model(load_scene("strip", ["mesh.nodes=[21,5]"]))[0].mesh
    values = np.stack([np.arange(coarse.n_elements, dtype=float), -np.arange(coarse.n_elements) ** 2.0], axis=1)
    out = element_values(coarse, values, fine)
    assert out.shape == (fine.n_elements, 2)
    owner = out[:, 0].astype(int)
    np.testing.assert_array_equal(out[:, 1], -owner ** 2.0)
    c = fine.X[fine.tri].mean(axis=1)
    P = coarse.X[coarse.tri[owner]]  # (E_fine, 3, 2)
    T = np.stack([P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]], axis=2)
    b12 = np.linalg.solve(T, (c - P[:, 0])[..., None])[..., 0]
    bary = np.column_stack([1.0 - b12.sum(axis=1), b12])
    assert bary.min() >= -1e-12  # each fine centroid lies in the coarse element whose value it took
    with pytest.raises(ValueError, match="one row per element"):
        element_values(coarse, values[:-1], fine)


HYSTERESIS = ["material={kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5, kes_2HB_warp=0.05, "
              "kes_2HB_weft=0.04}"]


def test_the_frictions_slips_go_to_the_next_level_and_a_resume_takes_them_up(tmp_path, monkeypatch):
    """A drape with bending hysteresis solved level by level: the fine level's Newton starts from the coarse
    equilibrium's committed slips (carried by levels.carry_slip, not a virgin fabric), the saved level keeps them, and
    a resumed sequence, which reads them from the level file, ends where the uninterrupted one did."""
    scene = load_scene("pedestal-square-20", DRAPE + HYSTERESIS)
    opts = static_options(scene, progress=False)
    carried = []
    real = levels_mod.carry_slip

    def spy(coarse, slip, fine):
        out = real(coarse, slip, fine)
        carried.append((slip.copy(), out))
        return out

    monkeypatch.setattr(levels_mod, "carry_slip", spy)
    first = solve_levels(scene, build_model(scene)[0], opts, folder=tmp_path)
    assert first.converged and len(carried) == 1
    coarse_slip, fine_slip = carried[0]
    assert np.abs(coarse_slip).max() > 0  # the coarse drape slipped somewhere
    assert fine_slip.shape == (build_model(scene)[0].mesh.n_elements, 2)
    assert np.abs(fine_slip).max() == np.abs(coarse_slip).max()  # piecewise constant: the values carried as they are
    again = solve_levels(scene, build_model(scene)[0], opts, folder=tmp_path, resume=True)
    assert again.levels[0]["resumed"] and len(carried) == 2
    np.testing.assert_array_equal(carried[1][0], coarse_slip)
    assert np.allclose(again.U, first.U, rtol=0, atol=1e-9)


def test_a_sequenced_run_returns_the_finest_levels_slips_and_the_whole_routes_dissipation(tmp_path, monkeypatch):
    """``app.run`` with mesh sequencing returns what a run going on from its drape starts from (the finest level's
    committed slips, ``RunResult.slip``), and its hysteresis summary counts the energy the frictions dissipated along
    the whole route: the coarse level's relaxation and the fine level's Newton."""
    scene = load_scene("pedestal-square-20", DRAPE + HYSTERESIS)
    saved = []
    real = levels_mod._save_level

    def spy(folder, k, model, U, record, slip=None, dissipated=0.0):
        saved.append(dissipated)
        return real(folder, k, model, U, record, slip, dissipated)

    monkeypatch.setattr(levels_mod, "_save_level", spy)
    res = app.run(scene, tmp_path, progress=False, figures=False)
    fine = res.model.mesh.n_elements
    assert res.slip is not None and res.slip.shape == (fine, 2) and np.abs(res.slip).max() > 0
    assert len(saved) == 1 and saved[0] > 0  # the coarse level dissipated on its way down
    dissipated = res.summary["bending_hysteresis"]["dissipated"]
    assert dissipated >= scene.units.from_si(saved[0], "energy") * (1 - 1e-12)
