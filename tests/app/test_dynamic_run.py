"""Dynamic scenes end to end (§4.6): outputs, physics of the first instants, checkpoint and resume."""

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from rftstatic.app.dynamic import run_dynamic_scene
from rftstatic.app.registry import resume_scene
from rftstatic.cli import main
from rftstatic.errors import SceneError
from rftstatic.scenes.schema import load_scene

TINY = ["mesh.nodes=[9,9]", "dynamics.t_end=0.05", "dynamics.checkpoint_every=0.01", "dynamics.samples=5",
        "dynamics.frames=[0,0.02,0.05]"]
G = 980.665  # [cm/s^2]


def _args(extra=()):
    return [a for kv in (*TINY, *extra) for a in ("--set", kv)]


def _tiny_scene(extra=()):
    return load_scene("hang-20", [*TINY, *extra])


def _run(scene, out, **kw):
    from rftstatic.scenes.build import build_model

    model, extras = build_model(scene)
    return run_dynamic_scene(scene, model, extras, out, progress=False, figures=False, **kw)


def test_tiny_hang_writes_well_formed_outputs(tmp_path):
    out = tmp_path / "h"
    assert main(["case", "hang-20", *_args(), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    for key in ("scene", "element", "nodes", "elements", "dt", "dt_estimate", "steps", "wall_time_s",
                "element_steps_per_second", "probes", "time_at_rest", "energies", "converged", "at_rest"):
        assert key in s, key
    assert s["nodes"] == 81 and s["elements"] == 128 and s["analysis"] == "dynamic"
    assert s["dt"] <= s["dt_estimate"]["dt"] * (1 + 1e-12) and s["steps"] * s["dt"] == pytest.approx(0.05)
    # probe trajectories: time, x, y, z of equal length, one value per history sample
    assert set(s["probes"]) == {"free-corner-1", "free-corner-2", "free-edge-mid"}
    for p in s["probes"].values():
        n = len(p["time"])
        assert n >= 10 and len(p["x"]) == len(p["y"]) == len(p["z"]) == n
        assert p["time"][0] == 0.0 and p["time"][-1] == pytest.approx(0.05)
        assert [p["x"][0], p["y"][0], p["z"][0]] == pytest.approx(p["reference"])
    # the PVD lists VTUs that exist, at increasing times, with the mesh's node count
    import meshio

    root = ET.parse(out / "series.pvd").getroot()
    sets = root.findall("./Collection/DataSet")
    times = [float(d.get("timestep")) for d in sets]
    assert len(sets) == s["vtu_series"]["states"] >= 4 and times == sorted(times)
    for d in (sets[0], sets[-1]):
        assert meshio.read(out / d.get("file")).points.shape == (81, 3)
    for f in s["frames"]:
        assert f["state_time"] - f["time"] < s["dt"] + 1e-12
        for name in f["files"].values():
            assert (out / name).stat().st_size > 0
    assert (out / "animation.gif").read_bytes()[:3] == b"GIF" and (out / "energy.png").stat().st_size > 0
    assert (out / "checkpoint.npz").exists()
    assert s["view"] == "view.html" and (out / "view.html").stat().st_size > 1_000_000   # a slider over the states
    assert (out / "view.html").read_text().count('"label":"') >= s["vtu_series"]["states"]
    # every saved state checked for self-intersection: a sheet falling for 0.05 s crosses nothing
    si = s["self_intersections"]
    assert si["saved_states"] == s["vtu_series"]["states"] == len(si["pairs_saved"]) and si["saved_skipped"] == 0
    assert si["pairs"] == si["max_pairs_saved"] == 0 and 0.0 <= si["max_pairs_at"] <= 0.05
    assert 0.0 < si["smallest_distance"] < si["within"] < 3.0   # cm


def test_first_instants_are_a_damped_free_fall_and_energy_balances(tmp_path):
    """Far from the pins the sheet falls as z = -(g/alpha) (t - (1 - exp(-alpha t)) / alpha)."""
    s = _run(_tiny_scene(), tmp_path / "h")
    alpha, t = 5.0, 0.05
    z_fall = -(G / alpha) * (t - (1 - np.exp(-alpha * t)) / alpha)
    assert s["probes"]["free-edge-mid"]["z"][-1] == pytest.approx(z_fall, rel=0.03)
    e = s["energies"]["final"]
    # kinetic + stored + dissipated = work of gravity, to the scheme's accuracy
    assert abs(e["total"]) < 2e-3 * e["external_work"]
    assert e["dissipated"] > 0 and e["kinetic"] > 0


def test_resume_after_interruption_reproduces_the_uninterrupted_run(tmp_path):
    scene = _tiny_scene()
    full = _run(scene, tmp_path / "full")

    def interrupt(state, sample):
        if state.t > 0.03:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _run(scene, tmp_path / "cut", callback=interrupt)
    assert (tmp_path / "cut" / "checkpoint.npz").exists() and not (tmp_path / "cut" / "summary.json").exists()
    resumed = resume_scene(scene, tmp_path / "cut", progress=False, figures=False)
    assert 0 < resumed["resumed_from_t"] <= 0.03
    assert resumed["steps"] == full["steps"]
    for name, p in full["probes"].items():
        for k in ("time", "x", "y", "z"):
            assert resumed["probes"][name][k] == p[k]  # bitwise
    assert resumed["energies"] == full["energies"] and resumed["time_at_rest"] == full["time_at_rest"]
    import meshio

    last = sorted((tmp_path / "full" / "series").glob("*.vtu"))[-1].name
    a = meshio.read(tmp_path / "full" / "series" / last).points
    b = meshio.read(tmp_path / "cut" / "series" / last).points
    assert np.array_equal(a, b)


def test_cli_resume_continues_from_the_checkpoint(tmp_path, capsys):
    out = tmp_path / "h"
    assert main(["case", "hang-20", *_args(), "--out", str(out), "--no-figures"]) == 0
    first = json.loads((out / "summary.json").read_text())
    assert main(["case", "hang-20", *_args(), "--out", str(out), "--no-figures", "--resume"]) == 0
    again = json.loads((out / "summary.json").read_text())
    assert again["resumed_from_t"] is not None and first["resumed_from_t"] is None
    assert again["probes"] == first["probes"]


def test_resume_with_another_end_time_names_the_key(tmp_path):
    _run(_tiny_scene(), tmp_path / "h")
    with pytest.raises(SceneError, match="dynamics.t_end"):
        resume_scene(_tiny_scene(["dynamics.t_end=0.06"]), tmp_path / "h", progress=False, figures=False)


@pytest.mark.parametrize("override,fragment", [
    ("dynamics.t_ned=1", "dynamics.t_ned: unknown key"),
    ("dynamics.alpha=-1", "dynamics.alpha"),
    ("dynamics.frames=[0,5]", "dynamics.frames"),
    ("dynamics.samples=ten", "dynamics.samples"),
])
def test_bad_dynamics_key_names_it(tmp_path, capsys, override, fragment):
    code = main(["case", "hang-20", *_args([override]), "--out", str(tmp_path / "x"), "--no-figures"])
    assert code == 2
    err = capsys.readouterr().err
    assert fragment in err and "hang-20.toml" in err


def test_relax_reaches_the_static_solution(tmp_path):
    """Dynamic relaxation (mass scaled, damped) of the clamped strip rests at the Newton solution."""
    scene = load_scene("strip", ["analysis=relax", "mesh.nodes=[11,3]", "element=RFT3", "dynamics.t_end=3",
                                 "dynamics.alpha=20", "dynamics.mass_scale=1", "dynamics.compare_static=true",
                                 "dynamics.samples=4"])
    s = _run(scene, tmp_path / "r")
    assert s["converged"] and s["at_rest"] and s["t"] < 3
    cmp = s["static_comparison"]
    # at rest the kinetic energy is 1e-8 of its peak and |P - F| 1e-4 |P|: the Newton solution to 1e-3
    assert cmp["static_converged"] and cmp["relative"] < 1e-3


@pytest.mark.slow
@pytest.mark.parametrize("name,side,t_end,wall", [("hang-20", 20.0, 2.0, 120.0), ("hang-100", 100.0, 2.4, 60.0)])
def test_full_hanging_sheets_come_to_rest_hanging(tmp_path, name, side, t_end, wall):
    """Figs. 12-13: the sheet falls, swings past the vertical and is at rest by the paper's last frame."""
    out = tmp_path / name
    assert main(["case", name, "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["converged"] and s["at_rest"] and s["time_at_rest"] < t_end
    assert s["wall_time_s"] < wall
    mid = s["probes"]["free-edge-mid"]
    # at rest the free edge hangs about one side length below the pinned edge, in the pins' plane
    assert mid["final"][2] == pytest.approx(-side, rel=0.05) and abs(mid["final"][0]) < 0.05 * side
    assert min(mid["x"]) < -0.05 * side  # swung past the vertical on the way
    assert len(s["frames"]) == 4 and all(len(f["files"]) == 2 for f in s["frames"])


# --------------------------------------------------------------- the output folder is replaced as a whole
def test_a_run_replaces_an_earlier_run_as_a_whole_and_refuses_a_foreign_folder(tmp_path, capsys):
    out = tmp_path / "h"
    assert main(["case", "hang-20", *_args(), "--out", str(out), "--no-figures"]) == 0
    (out / "frame_t9.png").write_bytes(b"stale")  # a file only an earlier run wrote
    assert main(["case", "hang-20", *_args(), "--out", str(out), "--no-figures"]) == 0
    assert not (out / "frame_t9.png").exists() and (out / "summary.json").exists()
    assert not (tmp_path / "h.partial").exists() and sorted(p.name for p in tmp_path.iterdir()) == ["h"]
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    assert main(["case", "hang-20", *_args(), "--out", str(foreign), "--no-figures"]) == 4
    assert "not an rftstatic output" in capsys.readouterr().err
    assert (foreign / "notes.txt").read_text() == "keep me"


def test_an_interrupted_run_resumes_from_its_partial_folder(tmp_path):
    scene = _tiny_scene()
    full = _run(scene, tmp_path / "full")
    out = tmp_path / "cut"

    def interrupt(state, sample):
        if state.t > 0.03:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):  # as registry.run leaves it: the checkpoint in cut.partial
        _run(scene, tmp_path / "cut.partial", callback=interrupt)
    resumed = resume_scene(scene, out, progress=False, figures=False)
    assert not (tmp_path / "cut.partial").exists() and (out / "summary.json").exists()
    assert resumed["steps"] == full["steps"] and resumed["energies"] == full["energies"]


@pytest.mark.parametrize("figures", [False, True])
def test_the_summary_is_written_once_and_names_its_rest_test(tmp_path, monkeypatch, figures):
    from rftstatic.app import dynamic
    from rftstatic.scenes.build import build_model

    written = []
    real = dynamic.write_json
    monkeypatch.setattr(dynamic, "write_json", lambda path, data: (written.append(path.name), real(path, data)))
    scene = _tiny_scene(["analysis=relax", "dynamics.rest_tolerance=1e-3", "dynamics.force_tolerance=0.5"])
    model, extras = build_model(scene)
    summary = run_dynamic_scene(scene, model, extras, tmp_path, progress=False, figures=figures)
    assert written == ["summary.json"]
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk["rest_test"] == summary["rest_test"] == {
        "at_rest": {"criterion": "kinetic+force", "tol_kinetic": 1e-3, "tol_force": 0.5},
        "time_at_rest": {"criterion": "kinetic", "tol_kinetic": 1e-3, "tol_force": None}}
    assert "critical step" in on_disk["dt_reason"] and ("energy_plot" in on_disk) == figures
    assert (tmp_path / "view.html").exists() == ("view" in on_disk) == figures
