"""The path-following report on synthetic runs (record + summary.json as the drape child writes them): no solve."""

import json
from pathlib import Path

from rftstatic.validate import BENCHMARKS, path_following as pf
from rftstatic.validate.report import write_report

GF_CM = 9.80665e-5  # J


def _summary(*, levels=(), converged=True, stable=True, folds=9, dc=0.1223, energy=-418.92, route="arc-length"):
    return {
        "converged": converged, "message": "converged" if converged else "stopped at load factor 0.36",
        "load_factor": 1.0 if converged else 0.3605, "route": route + ("+levels" if levels else ""),
        "newton_iterations": 475, "stable_minimum": stable, "mesh": {"nodes_xy": [33, 33]},
        "software": {"code": "abcdef123456", "git_commit": "d56ab6f3e0867b06ce076dd672f7d4b016a94ef2"},
        "path": {"steps": [{"lam": 0.0}] * 67,
                 "critical_points": [{"kind": "bifurcation", "lam": 0.00917}, {"kind": "limit", "lam": 0.033},
                                     {"kind": "limit", "lam": 0.2}, {"kind": "limit", "lam": 0.5},
                                     {"kind": "limit", "lam": 0.84}],
                 "switches": [{}, {}], "descents": 3, "final_negative": 0},
        "levels": list(levels), "energies": {"total": energy},
        "drape": {"drape_coefficient": dc, "fold_count": folds, "fold_angles_deg": [20.0, 60.0]}}


LEVELS = [{"level": 0, "mesh": "[9, 64]", "route": "arc-length", "iterations": 8793, "wall_time_s": 303.2,
           "energy_J": -420.5 * GF_CM},
          {"level": 1, "mesh": "[16, 120]", "route": "newton", "iterations": 479, "wall_time_s": 84.0,
           "energy_J": -420.7 * GF_CM},
          {"level": 2, "mesh": "[31, 240]", "route": "newton", "iterations": 371, "wall_time_s": 233.0,
           "energy_J": -420.83 * GF_CM}]


def _record(tmp_path, name, summary, *, nodes=7440, loadavg=(3.5, 3.0, 2.5)):
    d = tmp_path / name
    d.mkdir()
    (d / "summary.json").write_text(json.dumps(summary))
    if loadavg:
        (d / pf.LOADAVG).write_text(json.dumps({"loadavg": list(loadavg), "measured": "at the end of this run"}))
    rec = {"dir": str(d), "element": "RFT6", "nodes": nodes, "converged": summary["converged"], "error": "",
           "load_factor": summary["load_factor"], "newton_iterations": 9643, "build_s": 2.0, "solve_s": 620.0,
           "peak_rss_mb": 1864.0, "process_s": 630.0, "overrides": []}
    return pf.attach(rec)


def test_path_following_is_registered():
    assert "path_following" in BENCHMARKS
    assert callable(pf.run)


def test_overrides_carry_the_route_levels_and_mesh():
    assert pf.overrides((31, 240), True, 3) == pf.ROUTE + ["solver.levels=3", "mesh.nodes=[31,240]"]
    assert pf.overrides((33, 33), False, 1) == pf.ROUTE
    assert "solver.relax_fallback=false" in pf.ROUTE and "solver.continuation=arc-length" in pf.ROUTE
    assert [c[0] for c in pf.QUICK] == ["pedestal-square-20", "sphere-30"]
    assert len(pf.FULL) == 8


def test_row_values_of_a_levels_run(tmp_path):
    rec = _record(tmp_path, "r31", _summary(levels=LEVELS, dc=0.1114, energy=-420.83))
    v = pf.row_values(rec, GF_CM)
    assert v["levels"] == 3 and v["meshes"] == "9 x 64 -> 16 x 120 -> 31 x 240"
    assert v["iterations"] == "8793 (path) / 479 / 371"
    assert v["level_walls"] == "303 + 84 + 233"
    assert abs(v["level_energies"][-1] + 420.83) < 1e-9
    assert v["steps"] == 67 and v["switches"] == 2 and v["descents"] == 3
    assert v["critical"] == "1 bifurcation (0.0092); 4 limit (0.033-0.84)"
    assert v["converged"] and v["stable"] is True and v["folds"] == 9 and v["dc"] == 0.1114
    assert v["energy"] == -420.83 and v["wall"] == 622.0 and v["peak_mb"] == 1864.0 and v["loadavg"] == 3.5
    assert v["commit"] == "d56ab6f3e086" and pf._commit("d56ab6f3e0867b06+dirty") == "d56ab6f3e086+dirty"
    line = pf.table_line("pedestal-round-50, 31 x 240", v)
    assert line.count("|") == pf.TABLE_HEAD[0].count("|")
    assert "| 3: 9 x 64 -> 16 x 120 -> 31 x 240 | yes | yes | 67 |" in line
    assert "| 0.1114 | 9 | -420.83 | 622 (303 + 84 + 233) | 1864 | 3.50 |" in line
    assert pf.row_passed(rec)


def test_row_values_of_a_single_mesh_run_that_stopped(tmp_path):
    rec = _record(tmp_path, "r33", _summary(converged=False, stable=None), nodes=1089, loadavg=None)
    v = pf.row_values(rec, GF_CM)
    assert v["levels"] == 1 and v["meshes"] == "33 x 33" and v["iterations"] == "475 (path)"
    assert v["loadavg"] is None and v["loadavg_note"] == "not recorded"
    line = pf.table_line("pedestal-square-20, 33 x 33", v)
    assert "**NO** (load factor 0.3605)" in line and line.count("|") == pf.TABLE_HEAD[0].count("|")
    assert not pf.row_passed(rec)
    assert not pf.row_passed({"crashed": "boom"})
    assert pf.critical_summary([]) == "0"


def test_comparison_states_the_papers_folds_and_energy_differences(tmp_path):
    path = {(21, 160): _record(tmp_path, "p21", _summary(levels=LEVELS[:2], energy=-418.92))}
    relax = {(21, 160): _record(tmp_path, "x21", _summary(route="relax", energy=-419.09, dc=0.12))}
    text, differ = pf.comparison_section(path, relax)
    assert "| 21 x 160 | load-scaled (arc-length, levels) | yes | yes | 9 |" in text
    assert "| -418.92 | +0.17 |" in text and "| 12 |" in text
    assert "31 x 240 | load-scaled (arc-length, levels) | not run" in text
    assert [n for _, _, n in differ] == [9, 9]


def test_run_builds_the_report_from_the_runs(tmp_path, monkeypatch):
    made = {}

    def fake_solve(scene, ov):
        made[scene] = ov
        s = _summary(levels=LEVELS if any(o.startswith("solver.levels") for o in ov) else ())
        rec = _record(tmp_path, f"{scene}-{len(made)}", s)
        rec["overrides"] = ov
        return rec

    monkeypatch.setattr(pf, "solve_case", fake_solve)
    monkeypatch.setattr(pf, "run_cached_only", lambda *a: None)
    res = pf.run(quick=True)
    assert res.passed and res.discrepancy == "" and len(res.rows) == 2
    assert made["sphere-30"] == pf.ROUTE + ["mesh.nodes=[17,17]"]
    path = write_report(res, tmp_path, quick=True)
    text = path.read_text()
    assert "pedestal-square-20, 33 x 33" in text and "sphere-30, 17 x 17" in text and "Exact paths" in text
    assert json.loads((tmp_path / "path_following.json").read_text())["passed"] is True

    monkeypatch.setattr(pf, "QUICK", [("pedestal-round-50", (21, 160), False, 2)])
    res = pf.run(quick=True)
    assert res.passed and "12 folds" in res.discrepancy and "21 x 160: 9 folds" in res.discrepancy


def _no_cache_env(monkeypatch, root):
    monkeypatch.setattr(pf, "cache_root", lambda: root)
    monkeypatch.delenv("RFTSTATIC_DRAPE_REFRESH", raising=False)
    monkeypatch.delenv("RFTSTATIC_DRAPE_CACHED_ONLY", raising=False)


def test_a_row_is_the_drape_benchs_cached_run_with_its_levels(tmp_path, monkeypatch):
    """A row is solved by rftstatic.bench.drape.run_cached (its child, in a fresh interpreter, does the mesh
    sequencing of solver.levels) with the row's overrides and TIMEOUT_S; the report reads its record and summary."""
    from rftstatic.bench import drape
    from rftstatic.scenes.schema import load_scene

    _no_cache_env(monkeypatch, tmp_path)
    calls, real_run_one = [], drape.run_one

    def spy(name, overrides, out, **kw):
        calls.append((name, list(overrides), Path(out), kw))
        return real_run_one(name, overrides, out, **kw)

    monkeypatch.setattr(drape, "run_one", spy)
    scene, ov = "pedestal-square-20", pf.overrides((9, 9), True, 2)
    rec = pf.solve_case(scene, ov)
    assert "crashed" not in rec, rec.get("crashed")
    d = tmp_path / drape.run_key(scene, ov)
    assert calls == [(scene, ov, d, {"figures": False, "timeout": pf.TIMEOUT_S})] and rec["dir"] == str(d)
    assert rec["loadavg"]["measured"] == "at the end of this run"
    v = pf.row_values(rec, load_scene(scene, rec["overrides"]).units.energy)
    assert v["levels"] == 2 and v["meshes"] == "5 x 5 -> 9 x 9" and v["route"] == "arc-length+levels"
    assert v["iterations"].split(" / ")[0].endswith("(path)") and v["steps"] > 0 and v["nodes"] == 81
    assert v["converged"] and v["stable"] is True and v["dc"] > 0 and v["folds"] >= 0 and v["energy"] < 0
    assert rec["process_s"] >= rec["wall_s"] > 0 and v["wall"] > 0 and v["peak_mb"] > 50 and rec["cpu_s"] > 0
    assert pf.row_passed(rec)
    row = pf.solves_row("pedestal-square-20, 9 x 9", rec, v)
    assert row["iterations"] == rec["newton_iterations"] > 0 and row["run_dir"] == str(d)
    assert v["code"] == rec["software"]["code"] == drape.code_version()

    again = pf.solve_case(scene, ov)  # cached: nothing solved, the load average of the run kept
    assert len(calls) == 1 and again["dir"] == str(d) and again["loadavg"] == rec["loadavg"]


def test_a_row_whose_child_fails_or_is_not_cached_is_listed_not_raised(tmp_path, monkeypatch):
    from rftstatic.bench import drape
    from rftstatic.bench.harness import ChildTimeout

    _no_cache_env(monkeypatch, tmp_path)
    calls = []

    def killed(name, overrides, out, **kw):
        calls.append((name, list(overrides), kw))
        raise ChildTimeout(f"{name}: no result within the timeout of {kw['timeout']:g} s\nstderr line", name=name)

    monkeypatch.setattr(drape, "run_one", killed)
    ov = pf.overrides((31, 240), True, 3)
    rec = pf.solve_case(pf.ROUND, ov)
    assert calls == [(pf.ROUND, ov, {"figures": True, "timeout": pf.TIMEOUT_S})]
    assert "solver.levels=3" in calls[0][1] and pf.TIMEOUT_S == 3 * 3600.0
    assert rec["crashed"].startswith(f"{pf.ROUND}: no result within the timeout of 10800 s") and not pf.row_passed(rec)

    monkeypatch.setenv("RFTSTATIC_DRAPE_CACHED_ONLY", "1")
    rec = pf.solve_case(pf.ROUND, ov)
    assert len(calls) == 1 and rec["crashed"].startswith("not run (not in the cache")
