"""The study's pieces without Dask: parameter space, Latin hypercube, MEASURE paths, the results table,
and the command line's input errors (status 2, one line naming the argument)."""

import json
from pathlib import Path
import math

import numpy as np
import pytest

from rftstatic import api, cli
from rftstatic.scenes.schema import parse_override
from rftstatic.study import measures, space, store


def test_latin_hypercube_has_one_sample_in_each_stratum_and_is_reproducible():
    u = space.latin_hypercube(3, 16, seed=4)
    assert u.shape == (16, 3)
    for j in range(3):
        assert sorted(np.floor(u[:, j] * 16).astype(int)) == list(range(16))
    assert np.array_equal(u, space.latin_hypercube(3, 16, seed=4))
    assert not np.array_equal(u, space.latin_hypercube(3, 16, seed=5))


def test_grid_times_hypercube_and_log_range():
    s = space.parse_vary(["element=RFT3,RFT6", "mesh.nodes=[9,3],[13,3]", "material.B_warp=0.01:1:log"], 5)
    pts = s.points(5, seed=0)
    assert len(pts) == 2 * 2 * 5
    assert {tuple(p["mesh.nodes"]) for p in pts} == {(9, 3), (13, 3)}
    b = sorted({p["material.B_warp"] for p in pts})
    assert len(b) == 5 and all(0.01 <= v <= 1 for v in b)
    # log-uniform strata: one sample per decade-fifth
    assert sorted(np.floor((np.log10(b) + 2) / 2 * 5).astype(int)) == list(range(5))


def test_override_text_round_trips_through_set_parser():
    for key, value in [("a.b", 0.1 + 0.2), ("a", 1e-300), ("a", "RFT3"), ("a", [9, 3]), ("a", True), ("a", 7)]:
        assert parse_override(space.format_override(key, value)) == (key, value)


@pytest.mark.parametrize("text, word", [("material.B_warp", "KEY=VALUES"), ("material.B_warp=2:1", "LO < HI"),
                                        ("material.B_warp=a:b", "not numbers"), ("x=-1:1:log", "LO > 0"),
                                        ("x=1:2:lin", "LO:HI or LO:HI:log")])
def test_malformed_vary_is_refused_naming_it(text, word):
    with pytest.raises(space.StudyError, match=word) as err:
        space.parse_vary([text], 4)
    assert "--vary" in str(err.value)


def test_measures_from_a_summary_and_peirce_bending_length():
    theta = math.radians(41.5)  # Peirce's angle: the bending length is half the overhang
    l = 5.0
    summary = {"probes": {"tip": {"reference": [l, 0, 0], "deformed": [l * math.cos(theta) * 0.9, 0.1,
                                                                        -l * math.sin(theta) * 0.9]}},
               "drape": {"drape_coefficient": 0.61, "fold_count": 7}, "newton_iterations": 30,
               "resolved_scene": {"supports": [{"kind": "clamped", "box": [0, 0, -0.5, 0.5]}]}}
    assert measures.measure(summary, "probes.tip.y") == 0.1
    assert measures.measure(summary, "drape.fold_count") == 7
    assert measures.measure(summary, "probes.other.x") is None
    assert measures.measure(summary, "cantilever.bending_length") == pytest.approx(0.5093 * l, rel=1e-3)
    # a cantilever tester's own reading wins over the one derived from the tip (colleague's analysis)
    tester = {**summary, "cantilever": {"bending_length": 1.7, "overhang": 3.4}}
    assert measures.measure(tester, "cantilever.bending_length") == 1.7
    assert measures.measure(tester, "cantilever.overhang") == 3.4
    measures.check_measure("cantilever.overhang", {"analysis": "cantilever", "probes": []})
    measures.check_measure("cantilever.bending_length", {"analysis": "cantilever"})
    for bad in ("cantilever.overhang", "cantilever"):
        with pytest.raises(space.StudyError, match="cantilever"):
            measures.check_measure(bad, {"analysis": "static", "probes": [{"name": "tip"}]})
    with pytest.raises(space.StudyError, match='probe named "tip"'):
        measures.check_measure("cantilever.bending_length", {"analysis": "static", "probes": []})
    scene = api.load_scene("strip")
    measures.check_measure("probes.tip.z", scene)
    for bad in ("probes.tip.w", "probes.end.x", "drape.folds", "tip"):
        with pytest.raises(space.StudyError, match="unknown MEASURE path"):
            measures.check_measure(bad, scene)


def test_store_rewrites_the_table_and_recovers_rows_from_point_folders(tmp_path):
    s = store.Store(tmp_path, ["mesh.nodes", "probes.tip.z"])
    s.add({"key": "a" * 16, "status": "ok", "mesh.nodes": [9, 3], "probes.tip.z": -4.3818048362912, "converged": True})
    s.add({"key": "b" * 16, "status": "failed", "mesh.nodes": [13, 3], "error": "ValueError: x, y"})
    folder = s.folder("c" * 16)
    folder.mkdir(parents=True)
    (folder / "point.json").write_text(json.dumps({"key": "c" * 16, "status": "ok", "probes.tip.z": -1.0}))
    again = store.Store(tmp_path, ["mesh.nodes", "probes.tip.z", "probes.tip.x"])
    assert again.rows["a" * 16]["mesh.nodes"] == [9, 3]
    assert again.rows["a" * 16]["probes.tip.z"] == -4.3818048362912
    assert again.rows["b" * 16]["error"] == "ValueError: x, y"
    assert again.done("b" * 16) and not again.done("b" * 16, retry_failed=True)
    assert not again.done("a" * 16, needs=["cantilever.bending_length"])
    assert again.recover(["c" * 16, "d" * 16]) == 1
    assert "c" * 16 in store.Store(tmp_path, []).rows


def test_store_reads_a_key_that_looks_like_a_number_as_text(tmp_path):
    """A hex key of digits around an 'e' parses as a float (55159628e9139277 -> inf): read back as text."""
    key = "55159628e9139277"
    store.Store(tmp_path, ["probes.tip.z"]).add({"key": key, "status": "ok", "probes.tip.z": -1.5,
                                                 "folder": "points/" + key, "worker": "1e3"})
    again = store.Store(tmp_path, ["probes.tip.z"])
    assert list(again.rows) == [key] and again.rows[key]["key"] == key
    assert again.rows[key]["worker"] == "1e3" and again.rows[key]["probes.tip.z"] == -1.5
    again.write()
    assert next(iter(store.Store(tmp_path, []).rows.values()))["key"] == key


def test_point_key_follows_the_resolved_scene():
    a = store.point_key(api.load_scene("strip", ["material.B_warp=0.083"]))
    assert a == store.point_key(api.load_scene("strip", ["material.B_warp=0.083"]))
    assert a != store.point_key(api.load_scene("strip", ["material.B_warp=0.084"]))


@pytest.mark.parametrize("argv, words", [
    (["sweep", "strip", "--vary", "material.B_wrap=0.05,0.1"], ["--vary material.B_wrap=0.05", "unknown key"]),
    (["sweep", "strip", "--vary", "material.B_warp=0.1:0.05", "--samples", "3"], ["--vary", "LO < HI"]),
    (["sweep", "strip", "--vary", "material.B_warp=0.05:0.1"], ["--samples"]),
    (["fit", "strip", "--free", "material.B_warp=0.03:0.3", "--target", "probes.tap.z=-4"],
     ["--target", "probes.tap.z", "unknown MEASURE path"]),
    (["fit", "strip", "--free", "material.B_wrp=0.03:0.3", "--target", "probes.tip.z=-4"], ["--free", "B_wrp"]),
    (["fit", "strip", "--free", "material.B_warp=0.3:0.03", "--target", "probes.tip.z=-4"], ["--free", "LO < HI"]),
    (["fit", "strip", "--run", "warp:", "--run", "weft:material.warp_angle=90", "--free", "material.B_warp=0.03:0.3",
      "--target", "probes.tip.z=-4"], ["--target", "name one of the runs (warp, weft)"]),
    (["fit", "strip", "--run", "warp:", "--run", "weft:material.warp_angle=90", "--free", "material.B_warp=0.03:0.3",
      "--target", "warp:probes.tip.z=-4"], ["--run weft: no --target names it"]),
    (["fit", "strip", "--run", "warp:material.B_warp=0.1", "--free", "material.B_warp=0.03:0.3",
      "--target", "warp:probes.tip.z=-4"], ["--run", "is a --free key"]),
    (["fit", "strip", "--run", "weft:material.warp_angel=90", "--free", "material.B_warp=0.03:0.3",
      "--target", "weft:probes.tip.z=-4"], ["--run weft:material.warp_angel=90", "warp_angel"]),
    (["fit", "strip", "--run", "warp", "--free", "material.B_warp=0.03:0.3", "--target", "warp:probes.tip.z=-4"],
     ["--run", "expected LABEL[@SCENE]:"]),
    (["fit", "strip", "--free", "material.B_warp=0.03:0.3", "--target", "weft:probes.tip.z=-4"],
     ["there is no --run weft"]),
    (["fit", "strip", "--run", "warp:", "--run", "x@no-such-scene:", "--free", "material.B_warp=0.03:0.3",
      "--target", "warp:probes.tip.z=-4", "--target", "x:probes.tip.z=-4"], ["--run x@no-such-scene:", "no-such-scene"]),
    (["fit", "strip", "--run", "warp:", "--run", "disc@pedestal-square-20:", "--free", "material.B_warp=0.03:0.3",
      "--target", "warp:probes.tip.z=-4", "--target", "disc:probes.tip.z=0.6"], ["--target", "no probe \"tip\""]),
])
def test_bad_study_arguments_exit_2_with_one_line(argv, words, tmp_path, capsys):
    assert cli.main([*argv, "--out", str(tmp_path / "s")]) == cli.EXIT["input"]
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("error: ")
    for w in words:
        assert w in err


def test_run_overrides_split_at_commas_outside_brackets():
    from rftstatic.study.fit import Run, parse_runs

    free = space.parse_free(["material.B_warp=0.03:0.3"])
    assert parse_runs([], free) == [Run(None)]
    assert parse_runs(["warp:", "fine:mesh.nodes=[17,5], material.warp_angle=90"], free) == [
        Run("warp", ()), Run("fine", ("mesh.nodes=[17,5]", "material.warp_angle=90"))]
    assert parse_runs(["disc@pedestal-square-20:element=RFT3"], free) == [
        Run("disc", ("element=RFT3",), "pedestal-square-20")]


def test_identifiability_of_a_sensitivity_matrix():
    from rftstatic.study import identify

    keys = ["B_warp", "B_weft"]
    good = identify.analyse({"warp:c": {"B_warp": 0.28, "B_weft": 0.0}, "weft:c": {"B_warp": 0.0, "B_weft": 0.28}},
                            keys)
    assert good["condition_number"] == pytest.approx(1.0)
    assert good["amplification"] == pytest.approx({"B_warp": 1 / 0.28, "B_weft": 1 / 0.28})
    assert identify.warnings(good) == []
    # the tip drop: 0.1 % per 1 % of B, a 1 % error becomes 10 % in B
    weak = identify.analyse({"z": {"B_warp": -0.1}}, ["B_warp"])
    (line,) = identify.warnings(weak)
    assert line.startswith("B_warp is barely identifiable from the targets") and "~10 %" in line
    # two measures of the warp strip hardly see B_weft: near-singular, B_weft amplified
    same = identify.analyse({"warp:x": {"B_warp": 0.65, "B_weft": 0.002}, "warp:z": {"B_warp": -0.1, "B_weft": 0.0}},
                            keys)
    lines = identify.warnings(same)
    assert len(lines) == 3 and "near-singular" in lines[0] and "log B_weft" in lines[0]
    # an exact solve of the 2 x 2 system passes z's error to B_warp through the tiny B_weft column
    assert lines[1].startswith("B_warp is barely identifiable") and lines[2].startswith("B_weft is barely identifiable")
    assert same["amplification"]["B_weft"] > 100
    assert same["weakest_combination"]["B_weft"] == pytest.approx(1.0, abs=0.01)
    # fewer targets than keys
    under = identify.analyse({"c": {"B_warp": 0.28, "B_weft": 0.1}}, keys)
    assert under["condition_number"] is None
    assert "1 target(s) cannot identify 2 free keys" in identify.warnings(under)[0]


def test_the_package_and_the_case_command_do_not_import_dask(tmp_path):
    import subprocess
    import sys

    code = ("import sys; from rftstatic import cli; import rftstatic.api; "
            "assert cli.main(['case', 'strip', '--set', 'mesh.nodes=[5,3]', '--no-figures', '--out', sys.argv[1]]) == 0; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')]; assert not bad, bad")
    root = str(Path(api.__file__).resolve().parents[1])
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "s")], check=True, cwd=tmp_path, capture_output=True,
                   env={**__import__("os").environ, "PYTHONPATH": root})


def test_plots_draw_numeric_and_category_keys_and_skip_failed_points(tmp_path):
    from rftstatic.study.plots import plot_study

    rows = [{"status": "ok", "material.B_warp": b, "element": e, "mesh.nodes": [9, 3], "probes.tip.z": -4 - b}
            for b in (0.05, 0.1) for e in ("RFT3", "RFT6")]
    rows.append({"status": "failed", "material.B_warp": 0.2, "element": "RFT3", "mesh.nodes": [9, 3]})
    one = plot_study(rows, ["element"], ["probes.tip.z", "drape.drape_coefficient"], tmp_path / "one")
    two = plot_study(rows, ["material.B_warp", "element"], ["probes.tip.z"], tmp_path / "two")
    three = plot_study(rows, ["material.B_warp", "element", "mesh.nodes"], ["probes.tip.z"], tmp_path / "three")
    assert [p.name for p in one + two + three] == ["probes.tip.z.png"] * 3  # no drape on a strip: no plot
    assert all(p.stat().st_size > 1000 for p in one + two + three)


def test_progress_lines_off_a_terminal_every_tenth_or_once_when_brief():
    import io

    from rftstatic.study.runner import StudyProgress

    for brief, expected in ((False, 6), (True, 1)):
        stream = io.StringIO()
        progress = StudyProgress(6, "fit evaluation 1", 2, stream=stream, brief=brief)
        for i in range(6):
            progress.update({"status": "failed" if i == 2 else "ok"})
        progress.close()
        lines = stream.getvalue().splitlines()
        assert len(lines) == expected
        assert lines[-1].startswith("fit evaluation 1: 6/6 done, 0 running, 1 failed")


def test_an_execution_passes_its_options_to_the_engine():
    """``sweep`` and ``fit`` take where their points run as one :class:`~rftstatic.study.runner.Execution`."""
    import dataclasses

    from rftstatic.study.runner import Execution
    from rftstatic.study.space import StudyError

    engine = Execution(scheduler="tcp://127.0.0.1:1", workers=3, timeout=2.5, figures=True).engine()
    assert (engine.scheduler, engine.workers, engine.timeout, engine.started) == ("tcp://127.0.0.1:1", 3, 2.5, False)
    with pytest.raises(StudyError, match="--workers 0: must be >= 1"):
        Execution(workers=0).engine()
    with pytest.raises(StudyError, match="--timeout -1: must be > 0 seconds"):
        Execution(timeout=-1.0).engine()
    with pytest.raises(dataclasses.FrozenInstanceError):
        Execution().workers = 2
