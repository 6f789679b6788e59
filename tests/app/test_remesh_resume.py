"""Remeshed runs checkpoint their cycles (static route) and chunks and remeshes (remeshed relaxation);
``--resume`` continues them to the mesh and state of the uninterrupted run; a checkpoint of another scene or
other overrides, or a corrupt one, is refused naming the file and the fix (exit status 2)."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rftstatic import api
from rftstatic.app import remeshed
from rftstatic.cli import main
from rftstatic.errors import CheckpointError
from rftstatic.remesh import relax_driver
from rftstatic.remesh import checkpoint as remesh_checkpoint
from rftstatic.scenes.schema import load_scene
from rftstatic.solvers import static as static_solver

# the clamped strip, static route: 105 nodes, then 68 (settled); 0.7 s
STRIP = ["mesh.kind=unstructured", "mesh.h=0.25", "remesh.const=0.04", "remesh.h_lower=0.1", "remesh.h_upper=0.4",
         "remesh.max_cycles=4"]
# the 20 x 20 cm sheet on the pedestal, remeshed relaxation: 5 chunks of 200 steps, 4 remeshes and one chunk
# on a settled mesh between them (before chunk 3), to t_end; 0.9 s
RELAX = ["mesh.h=4.0", "remesh.const=2.0", "remesh.h_lower=2.5", "remesh.h_upper=5.0", "remesh.every=200",
         "remesh.kappa_h2_max=6.0", "dynamics.t_end=3.0"]
SQUARE = "remesh-pedestal-square-20"
ROOT = Path(__file__).resolve().parents[2]


def _run(scene, out, **kw):
    return remeshed.run(scene, Path(out), progress=False, figures=False, **kw)


def _header(scene):
    return remeshed.checkpoint_header(scene)


def load_remesh_checkpoint(path, header):
    """The saved State of a remeshed run: its phase and its driver's position."""
    state = remesh_checkpoint.load_remesh_state(path, header)
    position = state.route.get(remesh_checkpoint.REMESH_STATIC) or state.route.get(remesh_checkpoint.REMESH_RELAX)
    return SimpleNamespace(phase=remesh_checkpoint.where(state)["phase"], state=position)


@pytest.fixture(scope="module")
def strip_full(tmp_path_factory):
    scene = load_scene("strip", STRIP)
    return scene, _run(scene, tmp_path_factory.mktemp("strip") / "full")


@pytest.fixture(scope="module")
def relax_full(tmp_path_factory):
    scene = load_scene(SQUARE, RELAX)
    return scene, _run(scene, tmp_path_factory.mktemp("relax") / "full")


def _same_run(resumed, full):
    """The resumed run ended on the uninterrupted run's mesh, state and summary values."""
    a, b = resumed.summary, full.summary
    assert resumed.model.mesh.n_nodes == full.model.mesh.n_nodes
    assert np.array_equal(resumed.model.mesh.tri, full.model.mesh.tri)
    assert np.abs(resumed.U - full.U).max() <= 1e-12 * np.abs(full.U).max()
    assert [(r["nodes"], r["triangles"], r["reason"], r["step"]) for r in a["records"]] == \
        [(r["nodes"], r["triangles"], r["reason"], r["step"]) for r in b["records"]]
    for key in ("nodes", "elements", "remeshes", "converged", "t", "steps", "alpha_final", "newton_iterations",
                "max_relative_curvature", "residual_relative"):
        assert a.get(key) == pytest.approx(b.get(key), rel=1e-12), key
    assert a["probes"] == b["probes"] or all(
        np.allclose(a["probes"][k]["deformed"], b["probes"][k]["deformed"], rtol=1e-12) for k in b["probes"])
    if "drape" in b:
        assert a["drape"]["drape_coefficient"] == pytest.approx(b["drape"]["drape_coefficient"], rel=1e-12)


def _interrupt_call(monkeypatch, owner, name, k):
    """``owner.name`` raises KeyboardInterrupt at its k-th call (a Ctrl-C there)."""
    original, calls = getattr(owner, name), []

    def cut(*a, **kw):
        calls.append(1)
        if len(calls) == k:
            raise KeyboardInterrupt
        return original(*a, **kw)

    monkeypatch.setattr(owner, name, cut)


# ------------------------------------------------------------------------------------------ static route
def test_an_interrupted_static_remesh_run_resumes_after_its_last_cycle(tmp_path, monkeypatch, strip_full):
    scene, full = strip_full
    assert full.summary["remeshes"] == 1 and full.summary["checkpoint"]["writes"] == 2  # one per solved cycle
    out = tmp_path / "cut"
    _interrupt_call(monkeypatch, static_solver, "static_route", 2)  # Ctrl-C in the solve of cycle 1
    with pytest.raises(KeyboardInterrupt):
        _run(scene, out)
    monkeypatch.undo()
    assert sorted(p.name for p in out.iterdir()) == ["checkpoint.npz"]
    saved = load_remesh_checkpoint(out / "checkpoint.npz", _header(scene))
    assert saved.phase == "cycle" and saved.state.cycle == 0 and len(saved.state.meshes) == 1
    assert saved.state.meshes[0].n_nodes == full.summary["initial_nodes"] and saved.state.result.converged
    resumed = _run(scene, out, resume=True)
    _same_run(resumed, full)
    assert resumed.summary["checkpoint"]["resumed_from"] == {"phase": "cycle", "mesh": 0, "nodes": 105}
    again = _run(scene, out, resume=True)  # from the last cycle's checkpoint: the model rebuilt on its saved mesh
    _same_run(again, full)
    assert again.summary["checkpoint"]["resumed_from"]["mesh"] == 1 and again.summary["checkpoint"]["writes"] == 0


# ------------------------------------------------------------------------------------ remeshed relaxation
@pytest.mark.parametrize("call,phase", [(3, "chunk"), (4, "remesh")])
def test_an_interrupted_remeshed_relaxation_resumes_to_the_same_state(tmp_path, monkeypatch, relax_full, call, phase):
    """Ctrl-C in chunk ``call``: the state before it is saved (a chunk kept back by the throttle is written on
    the interrupt, a remesh at once), and the resumed run takes the uninterrupted run's steps and meshes."""
    scene, full = relax_full
    assert full.summary["remeshes"] == 4 and full.summary["stopped_by"] == "t_end"
    out = tmp_path / "cut"
    _interrupt_call(monkeypatch, relax_driver.ExplicitStepper, "__call__", call)
    with pytest.raises(KeyboardInterrupt):
        _run(scene, out, checkpoint_seconds=1e9)
    monkeypatch.undo()
    saved = load_remesh_checkpoint(out / "checkpoint.npz", _header(scene))
    assert saved.phase == phase and saved.state.steps == 200 * (call - 1)
    assert len(saved.state.meshes) == len(saved.state.records) == (2 if call == 3 else 3)
    resumed = _run(scene, out, resume=True)
    _same_run(resumed, full)
    assert resumed.summary["checkpoint"]["resumed_from"]["steps"] == 200 * (call - 1)


def test_a_finished_relaxation_resumes_from_its_end(tmp_path):
    """A run that ended (here at dynamics.max_steps: its finer meshes need more steps than the first) saves its
    end: resuming it only writes the outputs again."""
    scene = load_scene(SQUARE, [*RELAX, "remesh.h_lower=2.0", "remesh.const=1.0", "dynamics.max_steps=1100"])
    out = tmp_path / "done"
    full = _run(scene, out)
    assert full.summary["stopped_by"] == "max_steps" and full.summary["steps"] == 1100
    saved = load_remesh_checkpoint(out / "checkpoint.npz", _header(scene))
    assert saved.phase == "done" and saved.state.done
    t = time.perf_counter()
    again = _run(scene, out, resume=True)
    assert time.perf_counter() - t < 0.5 * full.summary["wall_time_s"] + 0.5
    _same_run(again, full)


# ----------------------------------------------------------------------------------- command line, api
def _args(name, overrides, out):
    return ["case", name, *[a for kv in overrides for a in ("--set", kv)], "--no-figures", "--out", str(out)]


def test_ctrl_c_exits_130_and_resume_continues_from_the_partial_folder(tmp_path, monkeypatch, capsys, relax_full):
    scene, full = relax_full
    out = tmp_path / "r"
    _interrupt_call(monkeypatch, relax_driver.ExplicitStepper, "__call__", 4)
    assert main(_args(SQUARE, RELAX, out)) == 130
    assert "--resume" in capsys.readouterr().err
    monkeypatch.undo()
    partial = tmp_path / "r.partial"
    assert (partial / "checkpoint.npz").exists() and not out.exists()
    summary = api.resume(SQUARE, out, overrides=RELAX, figures=False)  # the API continues it as --resume does
    assert not partial.exists() and (out / "summary.json").exists()
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["checkpoint"]["resumed_from"]["steps"] == 600 == summary["checkpoint"]["resumed_from"]["steps"]
    assert on_disk["nodes"] == full.summary["nodes"] and on_disk["steps"] == full.summary["steps"]
    for k, p in full.summary["probes"].items():
        assert on_disk["probes"][k]["deformed"] == pytest.approx(p["deformed"], rel=1e-12)


def test_resume_without_a_checkpoint_runs_from_the_start(tmp_path, caplog, strip_full):
    scene, full = strip_full
    s = api.resume(scene, tmp_path / "new", figures=False)
    assert s["checkpoint"]["resumed_from"] is None and s["nodes"] == full.summary["nodes"]
    assert "from the start" in caplog.text and not (tmp_path / "new.partial").exists()


# -------------------------------------------------------------------------------- refused checkpoints
@pytest.fixture(scope="module")
def saved_relax(tmp_path_factory, relax_full):
    """The folder of a relaxation interrupted before its 2nd chunk (its checkpoint: the first remesh)."""
    scene, _ = relax_full
    out = tmp_path_factory.mktemp("saved") / "cut"
    stepper, calls = relax_driver.ExplicitStepper.__call__, []

    def cut(self, *a, **kw):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return stepper(self, *a, **kw)

    relax_driver.ExplicitStepper.__call__ = cut
    try:
        with pytest.raises(KeyboardInterrupt):
            _run(scene, out)
    finally:
        relax_driver.ExplicitStepper.__call__ = stepper
    return out / "checkpoint.npz"


@pytest.mark.parametrize("name,overrides,fragment", [
    (SQUARE, [*RELAX, "remesh.h_lower=3.0"], "remesh.h_lower = 2.5 there, 3.0 here"),
    (SQUARE, [*RELAX, "dynamics.alpha=4.0"], "dynamics.alpha = 5.0 there, 4.0 here"),
    ("remesh-sphere-30", ["mesh.h=4.0"], f"scene '{SQUARE}', not 'remesh-sphere-30'"),
])
def test_a_checkpoint_of_another_scene_or_overrides_is_refused(saved_relax, name, overrides, fragment):
    with pytest.raises(CheckpointError, match=fragment) as err:
        load_remesh_checkpoint(saved_relax, _header(load_scene(name, overrides)))
    assert str(saved_relax) in str(err.value) and "delete it or run without --resume" in str(err.value)


def test_a_static_runs_checkpoint_is_not_taken_for_a_remeshed_one(tmp_path):
    strip = load_scene("strip", ["mesh.nodes=[11,3]"])
    api.run(strip, tmp_path / "s", figures=False)  # a static solve's checkpoint.npz
    with pytest.raises(CheckpointError, match="not written by a remeshed run"):
        load_remesh_checkpoint(tmp_path / "s" / "checkpoint.npz", _header(load_scene("strip", STRIP)))


@pytest.mark.parametrize("damage", ["garbage", "truncated"])
def test_a_corrupt_checkpoint_is_exit_status_2_naming_the_file_and_the_fix(tmp_path, capsys, saved_relax, damage):
    partial = tmp_path / "r.partial"
    partial.mkdir()
    data = saved_relax.read_bytes()
    (partial / "checkpoint.npz").write_bytes(b"PK\x03\x04 cut short" if damage == "garbage" else data[:len(data) // 2])
    assert main([*_args(SQUARE, RELAX, tmp_path / "r"), "--resume"]) == 2
    err = capsys.readouterr().err
    assert "corrupt or incomplete" in err and str(partial / "checkpoint.npz") in err
    assert "delete it or run without --resume" in err and "Traceback" not in err


def test_a_killed_run_resumes_and_leaves_no_temporary_file_to_misread(tmp_path, relax_full):
    """SIGKILL a command-line run once it has saved a checkpoint; a cut-short write's temporary file (made up
    here, a kill during a write leaves one) is removed and the resumed run ends as the uninterrupted one."""
    scene, full = relax_full
    out = tmp_path / "k"
    partial = tmp_path / "k.partial"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    child = subprocess.Popen([sys.executable, "-m", "rftstatic", *_args(SQUARE, RELAX, out)], cwd=ROOT, env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not (partial / "checkpoint.npz").exists() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        child.send_signal(signal.SIGKILL)
    finally:
        child.wait()
    if child.returncode == 0:
        pytest.skip("the child finished before it could be killed")
    stale = partial / "checkpoint.npz.abc123.tmp"
    stale.write_bytes(b"PK\x03\x04 a write cut short")
    summary = api.resume(scene, out, figures=False)
    assert not stale.exists() and not partial.exists()
    assert summary["checkpoint"]["resumed_from"] is not None
    assert summary["nodes"] == full.summary["nodes"] and summary["steps"] == full.summary["steps"]
    for k, p in full.summary["probes"].items():
        assert summary["probes"][k]["deformed"] == pytest.approx(p["deformed"], rel=1e-12)
