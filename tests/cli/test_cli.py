"""Scenes and the command line: runs, outputs, and errors that name the file, key and value."""

import json

import pytest

from rftstatic.cli import main
from rftstatic.errors import SceneError
from rftstatic.scenes.schema import load_scene


def test_list_shows_the_strip(capsys):
    assert main(["list"]) == 0
    assert "strip" in capsys.readouterr().out


def test_case_with_overrides_writes_summary_vtu_and_views(tmp_path, capsys):
    out = tmp_path / "strip"
    code = main(["case", "strip", "--set", "element=RFT3", "--set", "mesh.nodes=[11, 3]", "--out", str(out)])
    assert code == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["element"] == "RFT3" and s["nodes"] == 33 and s["elements"] == 40
    assert s["converged"] is True and s["load_steps"] >= 1 and s["newton_iterations"] >= s["load_steps"]
    assert s["units"] == "cm-gf-s" and s["linear_solver"] in ("cholmod", "scipy")
    tip = s["probes"]["tip"]
    assert tip["reference"] == pytest.approx([5.0, 0.0, 0.0])
    # the tip hangs: about 1.8 cm from the clamp and 4.3 cm below it (heavy elastica: 1.77, -4.34)
    assert 1.5 < tip["deformed"][0] < 2.1 and -4.6 < tip["deformed"][2] < -4.0
    for name in ("deformed.vtu", "view_side.png", "view_top.png", "view_iso.png"):
        assert (out / name).stat().st_size > 0


def test_case_accepts_a_path(tmp_path):
    scene = tmp_path / "mine.toml"
    scene.write_text('units = "cm-gf-s"\n[mesh]\nsize = [2.0, 1.0]\nnodes = [5, 3]\n'
                     '[[supports]]\nkind = "clamped"\nbox = [-1.0, -1.0, -1.0, 1.0]\n')
    assert main(["case", str(scene), "--out", str(tmp_path / "o"), "--no-figures"]) == 0


@pytest.mark.parametrize("override,fragment", [
    ("mesh.sise=[1, 2]", "mesh.sise: unknown key"),
    ("element=RFT9", 'element: "RFT9" is not an element'),
    ("mesh.nodes=3", "mesh.nodes: expected an array"),
    ("units=furlongs", "unknown unit system"),
    ("solver.rtol=[1]", "solver.rtol: expected"),
])
def test_bad_scene_values_name_file_and_key(override, fragment):
    with pytest.raises(SceneError) as info:
        load_scene("strip", [override])
    assert "strip.toml" in str(info.value) and fragment in str(info.value)


def test_cli_reports_scene_errors_without_traceback(capsys, tmp_path):
    assert main(["case", "strip", "--set", "mesh.kind=hexagon", "--no-figures", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "mesh.kind" in err and "hexagon" in err and "Traceback" not in err


def test_unknown_scene_lists_known_ones():
    with pytest.raises(SceneError, match="known scenes: .*strip"):
        load_scene("no-such-scene")


def test_support_box_without_nodes_is_an_error(tmp_path):
    with pytest.raises(SceneError, match=r"supports.0.box.*contains no node"):
        from rftstatic.scenes.build import build_model

        build_model(load_scene("strip", ["supports.0.box=[9.0, 9.0, 9.0, 9.0]"]))


def test_preset_with_an_override_changes_only_that_rigidity():
    from rftstatic.scenes.build import build_material

    base = build_material(load_scene("strip"))
    mod = build_material(load_scene("strip", ["material.C_warp=111.82"]))  # gf/cm, a tenth of the wool's
    assert mod.Dm[0, 0] == pytest.approx(0.1 * base.Dm[0, 0])
    assert mod.Dm[1, 1] == pytest.approx(base.Dm[1, 1]) and mod.Db[0, 0] == pytest.approx(base.Db[0, 0])


def test_bad_guide_options_name_the_scene_file_and_the_solver_key():
    from rftstatic.scenes.options import static_options

    scene = load_scene("pedestal-round-50", ["solver.guide_folds=12", "solver.guide_weight=1.5"])
    with pytest.raises(SceneError, match=r"pedestal-round-50\.toml: solver\.guide_weight: 1\.5 is out of range: must be in \[0, 1\)"):
        static_options(scene)
    scene = load_scene("pedestal-square-20", ["solver.start=load-steps", "solver.guide_folds=4",
                                              "solver.guide_weight=0.2"])
    with pytest.raises(SceneError, match=r'solver\.guide_folds: .*needs solver.start = "relax"'):
        static_options(scene)


# ------------------------------------------------------------------------ exit statuses and bounded work
def test_non_finite_scene_numbers_are_input_errors(capsys, tmp_path):
    # TOML accepts nan and inf; a scene may not (a NaN weight once looped for ever in the load steps)
    for override in ("material.weight=nan", "mesh.size=[nan,5]", "mesh.z=inf"):
        assert main(["case", "strip", "--set", override, "--no-figures", "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err
        assert "strip.toml" in err and "not a finite number" in err and "Traceback" not in err


def test_an_explicit_run_beyond_the_step_limit_is_refused_before_it_starts(capsys, tmp_path):
    import time

    t0 = time.perf_counter()
    code = main(["case", "hang-20", "--set", "mesh.nodes=[7,7]", "--set", "dynamics.dt=1e-300", "--no-figures",
                 "--out", str(tmp_path / "o")])
    assert code == 2 and time.perf_counter() - t0 < 60
    err = capsys.readouterr().err
    assert "dynamics.dt" in err and "max_steps" in err


def test_a_relaxation_not_at_rest_by_t_end_exits_3(capsys, tmp_path):
    code = main(["case", "strip", "--set", "mesh.nodes=[11,3]", "--set", "analysis=relax", "--set",
                 "dynamics.t_end=0.05", "--no-figures", "--out", str(tmp_path / "o")])
    assert code == 3 and "did not come to rest" in capsys.readouterr().err
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["converged"] is False


def test_internal_errors_are_one_line_and_verbose_shows_the_traceback(monkeypatch, capsys, tmp_path):
    from rftstatic import api

    def broken(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(api, "run", broken)
    assert main(["case", "strip", "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("internal error: ZeroDivisionError: a bug") and "\n" not in err
    with pytest.raises(ZeroDivisionError):
        main(["case", "strip", "-v", "--out", str(tmp_path / "o")])  # -v after the subcommand too


def test_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0 and capsys.readouterr().out.startswith("rftstatic ")


@pytest.mark.parametrize("override, fragment", [
    ('supports.0.box=["a",0,0,0]', "supports.0.box: item 0 = 'a' is not a number"),
    ("probes.0.at=[5.0]", "probes.0.at: expected 2 items"),
    ('output.views=["front"]', 'output.views: item 0 = "front" is not one of side, top, iso'),
    ("mesh.nodes=[11.7,5]", "mesh.nodes: item 0 = 11.7 is not an int"),
    ("mesh.patern=left", 'did you mean "mesh.pattern"?'),
    ("title.x=1", '"title" is a value'),
    ("solver.linear_solver=mumps", 'solver.linear_solver: "mumps" is not one of auto, cholmod, scipy, amg'),
    ("solver.max_step=-1.0", "solver.max_step: -1.0 is out of range: must be > 0"),
    ("solver.max_step=abc", 'solver.max_step: must be a number or "auto", got \'abc\''),
])
def test_list_contents_enums_and_typos_are_scene_errors(override, fragment):
    with pytest.raises(SceneError) as info:
        from rftstatic.scenes.options import static_options

        static_options(load_scene("strip", [override]))
    assert fragment in str(info.value)


def test_a_misspelt_scene_name_gets_the_closest_suggested():
    with pytest.raises(SceneError, match='did you mean "strip"'):
        load_scene("strp")


@pytest.mark.parametrize("scene, override, fragment", [
    ("pedestal-round-50", "mesh.size=[1.0,1.0]", "mesh.size: does not apply to a square-polar mesh"),
    ("strip", "mesh.radius=3.0", "mesh.radius: does not apply to a rectangle mesh"),
    ("strip", "material.kind=isotropic", 'material.kind: does not apply next to preset = "wool-kang-yu"'),
])
def test_keys_that_do_not_apply_are_scene_errors(scene, override, fragment):
    from rftstatic.scenes.build import build_model

    with pytest.raises(SceneError) as info:
        build_model(load_scene(scene, [override]))
    assert fragment in str(info.value)


@pytest.mark.parametrize("override, key", [
    ("probes.0.at=[50.0,0.0]", "probes.0.at"),
    ("loads.point=[{at=[9.0,9.0],force=[0,0,-1]}]", "loads.point.0.at"),
])
def test_points_off_the_sheet_are_scene_errors_not_snapped(override, key):
    from rftstatic.scenes.build import build_model

    with pytest.raises(SceneError, match=f"{key}: .* is not on the sheet"):
        build_model(load_scene("strip", [override]))


def test_a_support_with_both_box_and_at_is_a_scene_error():
    from rftstatic.scenes.build import build_model

    with pytest.raises(SceneError, match="supports.0.at: give box"):
        build_model(load_scene("strip", ["supports.0.at=[[0.0,0.0]]"]))


def test_broken_scene_files_are_scene_errors(tmp_path):
    garbage = tmp_path / "garbage.toml"
    garbage.write_bytes(bytes(range(128, 256)))
    latin = tmp_path / "latin.toml"
    latin.write_bytes('title = "laine mérinos"\n'.encode("latin-1"))
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    for path, fragment in ((garbage, "not a text file in UTF-8"), (latin, "not a text file in UTF-8"),
                           (folder, "not a scene file")):
        with pytest.raises(SceneError, match=fragment):
            load_scene(str(path))
