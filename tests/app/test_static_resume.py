"""Static runs checkpoint their converged increments and relaxation segments; ``--resume`` continues them
to the equilibrium of the uninterrupted run; a checkpoint of another mesh or options, or a corrupt one,
is refused with a CheckpointError."""

import json
import signal
from types import SimpleNamespace

import numpy as np
import pytest

from rftstatic.app import static as app
from rftstatic.app.registry import resume_scene
from rftstatic.cli import main
from rftstatic.errors import CheckpointError
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import static_options
from rftstatic.scenes.schema import load_scene
from rftstatic.solvers import load_steps, rest
from rftstatic.model.state import State
from rftstatic.solvers.checkpoint import explicit_header, save_atomic, state_arrays
from rftstatic.solvers.static_checkpoint import load_static_state, where

STRIP = ["mesh.nodes=[21,5]"]  # 7 load increments in about 0.2 s
DRAPE = ["mesh.nodes=[7,7]"]  # start = "relax": two handovers (the first Newton fails, below), about 3 s


@pytest.fixture(scope="module", autouse=True)
def _first_handover_fails():
    """Newton from the first relaxed state gets 4 iterations and no continuation, so that the coarse drape's
    first handover fails (with the route's own budget it converges in 43) and its relaxation goes on: the
    route's second segment, PD check and second handover are what these tests interrupt and resume."""
    from rftstatic.solvers import static

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(static, "RELAX_NEWTON_ITERATIONS", 2)
        mp.setattr(static, "FIRST_HANDOVER_CONTINUATIONS", 0)
        yield


def _solve(scene, out, **kw):
    return app.run(scene, out, progress=False, figures=False, **kw)


def _load(scene, path):
    """The saved State of the static solve in ``path``, and its routes' positions by name."""
    model, _ = build_model(scene)
    state = load_static_state(path, model, static_options(scene, progress=False), scene=scene.name)
    r = state.route
    return SimpleNamespace(state=state, phase=where(state)["phase"], load_path=r.get("load-steps"),
                           route=r.get("relax-route"), segment=r.get("relax-segment"),
                           result=r.get("static", {}).get("result"))


def _same(a, b, rtol=1e-9):
    return float(np.abs(a - b).max()) <= rtol * float(np.abs(b).max())


@pytest.fixture(scope="module")
def strip_full(tmp_path_factory):
    scene = load_scene("strip", STRIP)
    return scene, _solve(scene, tmp_path_factory.mktemp("strip") / "full")


@pytest.fixture(scope="module")
def drape_full(tmp_path_factory):
    scene = load_scene("pedestal-square-20", DRAPE)
    return scene, _solve(scene, tmp_path_factory.mktemp("drape") / "full")


def _interrupt_at(k):
    """A callback(lam, U) that raises KeyboardInterrupt at the k-th converged increment."""
    seen = []

    def callback(lam, U):
        seen.append(lam)
        if len(seen) == k:
            raise KeyboardInterrupt

    return callback


# ------------------------------------------------------------------------------------ load-steps route
def test_an_interrupted_load_step_solve_resumes_to_the_same_equilibrium(tmp_path, strip_full):
    scene, full = strip_full
    steps = full.summary["solver_path"]
    assert len(steps) >= 5 and full.summary["checkpoint"]["writes"] == 2  # throttled: the last increment, the result
    out = tmp_path / "cut"
    with pytest.raises(KeyboardInterrupt):  # at the 4th increment; the 3rd is the last one kept
        _solve(scene, out, callback=_interrupt_at(4), checkpoint_seconds=1e9)
    assert sorted(p.name for p in out.iterdir()) == ["checkpoint.npz"]  # written on the interrupt, no tmp left
    saved = _load(scene, out / "checkpoint.npz")
    assert saved.phase == "load-steps" and saved.load_path.lam == steps[2]["lam"]
    assert len(saved.load_path.result.load_steps) == 3 and saved.load_path.U_prev is not None
    resumed = _solve(scene, out, resume=True)
    assert _same(resumed.U, full.U)
    assert resumed.summary["solver_path"] == steps  # the load-step record continues
    assert resumed.summary["newton_iterations"] == full.summary["newton_iterations"]
    assert resumed.summary["checkpoint"]["resumed_from"] == {"phase": "load-steps", "load_factor": steps[2]["lam"],
                                                             "load_steps": 3}


def test_every_increment_is_saved_without_the_throttle(tmp_path, strip_full):
    scene, full = strip_full
    out = tmp_path / "each"
    s = _solve(scene, out, checkpoint_seconds=0.0).summary
    assert s["checkpoint"]["writes"] == len(full.summary["solver_path"]) + 1  # and the result
    done = _load(scene, out / "checkpoint.npz")  # the last: the result, which a resume only writes out
    assert done.phase == "done" and done.result.lam == 1.0
    again = _solve(scene, out, resume=True)
    assert np.array_equal(again.U, full.U) and again.summary["newton_iterations"] == full.summary["newton_iterations"]


def test_ctrl_c_exits_130_and_resume_continues_from_the_partial_folder(tmp_path, monkeypatch, capsys, strip_full):
    scene, full = strip_full
    args = ["case", "strip", *[a for kv in STRIP for a in ("--set", kv)], "--no-figures", "--out"]
    out = tmp_path / "s"
    newton, calls = load_steps.newton, []

    def interrupted(*a, **kw):  # Ctrl-C in the middle of the 5th increment's Newton iteration
        calls.append(1)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return newton(*a, **kw)

    monkeypatch.setattr(load_steps, "newton", interrupted)
    assert main([*args, str(out)]) == 130
    assert "--resume" in capsys.readouterr().err
    monkeypatch.setattr(load_steps, "newton", newton)
    partial = tmp_path / "s.partial"
    assert _load(scene, partial / "checkpoint.npz").load_path.lam == full.summary["solver_path"][3]["lam"]
    assert main([*args, str(out), "--resume"]) == 0
    assert not partial.exists()
    s = json.loads((out / "summary.json").read_text())
    assert s["converged"] and s["checkpoint"]["resumed_from"]["load_steps"] == 4
    assert s["solver_path"] == full.summary["solver_path"]
    tip = full.summary["probes"]["tip"]["deformed"]
    assert s["probes"]["tip"]["deformed"] == pytest.approx(tip, rel=1e-9, abs=1e-12)


def test_resume_without_a_checkpoint_runs_from_the_start(tmp_path, caplog, strip_full):
    scene, full = strip_full
    s = resume_scene(scene, tmp_path / "new", progress=False, figures=False)
    assert s["converged"] and s["checkpoint"]["resumed_from"] is None
    assert s["solver_path"] == full.summary["solver_path"] and "from the start" in caplog.text
    assert not (tmp_path / "new.partial").exists()


# -------------------------------------------------------------------------------- refused checkpoints
@pytest.fixture
def saved_strip(tmp_path, strip_full):
    scene, _ = strip_full
    out = tmp_path / "cut"
    with pytest.raises(KeyboardInterrupt):
        _solve(scene, out, callback=_interrupt_at(3), checkpoint_seconds=1e9)
    return out


@pytest.mark.parametrize("overrides,fragment", [
    (["mesh.nodes=[25,5]"], "125 nodes"),  # another mesh
    (["mesh.nodes=[21,5]", "solver.rtol=1e-7"], "rtol"),  # other solver options
    (["mesh.nodes=[21,5]", "element=RFT3"], "another model"),
])
def test_a_checkpoint_of_another_mesh_or_options_is_refused(saved_strip, overrides, fragment):
    with pytest.raises(CheckpointError, match=fragment) as err:
        _solve(load_scene("strip", overrides), saved_strip, resume=True)
    assert str(saved_strip / "checkpoint.npz") in str(err.value)


def test_a_checkpoint_of_another_scene_is_refused(saved_strip):
    with pytest.raises(CheckpointError, match="scene 'strip'"):
        _solve(load_scene("pedestal-square-20", ["mesh.nodes=[5,5]"]), saved_strip, resume=True)


def test_a_corrupt_checkpoint_is_a_checkpoint_error_and_exit_status_2(tmp_path, capsys, strip_full):
    scene, _ = strip_full
    partial = tmp_path / "s.partial"
    partial.mkdir()
    (partial / "checkpoint.npz").write_bytes(b"PK\x03\x04 cut short")
    with pytest.raises(CheckpointError, match="corrupt or incomplete"):
        _solve(scene, partial, resume=True)
    args = ["case", "strip", *[a for kv in STRIP for a in ("--set", kv)], "--no-figures", "--resume"]
    assert main([*args, "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "corrupt or incomplete" in err and "checkpoint.npz" in err and "Traceback" not in err


def test_a_dynamic_runs_checkpoint_is_not_taken_for_a_static_one(tmp_path, strip_full):
    scene, _ = strip_full
    model, _ = build_model(scene)
    save_atomic(tmp_path / "checkpoint.npz", state_arrays(State.initial(model), explicit_header(model, ())))
    with pytest.raises(CheckpointError, match="not written by a static solve"):
        _solve(scene, tmp_path, resume=True)


# ------------------------------------------------------------------------------------ relaxation route
def _press_ctrl_c_at_sample(monkeypatch, k):
    """SIGINT at the k-th sample of the relaxation's rest test (the explicit loop then stops at a whole step)."""
    test, seen = rest.AtRest.__call__, []

    def call(self, state, rec):
        seen.append(1)
        if len(seen) == k:
            signal.raise_signal(signal.SIGINT)
        return test(self, state, rec)

    monkeypatch.setattr(rest.AtRest, "__call__", call)


def test_a_relaxation_interrupted_mid_segment_resumes_step_for_step(tmp_path, monkeypatch, drape_full):
    scene, full = drape_full
    assert full.summary["route"] == "relax+newton" and len(full.summary["relax"]["handovers"]) == 2
    out = tmp_path / "cut"
    _press_ctrl_c_at_sample(monkeypatch, 25)
    with pytest.raises(KeyboardInterrupt, match="checkpoint saved"):
        _solve(scene, out, checkpoint_seconds=1e9)
    monkeypatch.undo()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    saved = _load(scene, out / "checkpoint.npz")
    assert saved.phase == "relax" and saved.segment is not None and 480 < saved.segment["step"] < 500
    resumed = _solve(scene, out, resume=True)
    assert np.array_equal(resumed.U, full.U)  # the explicit steps are those of the uninterrupted run
    assert resumed.summary["relax"]["handovers"] == full.summary["relax"]["handovers"]
    assert resumed.summary["relax"]["steps"] == full.summary["relax"]["steps"]
    assert resumed.summary["stable_minimum"] == full.summary["stable_minimum"]


def test_a_relaxation_interrupted_at_a_handover_resumes_there(tmp_path, drape_full):
    scene, full = drape_full
    out = tmp_path / "cut"
    with pytest.raises(KeyboardInterrupt):  # the final Newton converged; its increment is not saved
        _solve(scene, out, callback=_interrupt_at(1), checkpoint_seconds=1e9)
    saved = _load(scene, out / "checkpoint.npz")
    assert saved.phase == "handover" and saved.segment is None
    first = full.summary["relax"]["handovers"][0]
    assert saved.route.info["handovers"] == [first] and saved.route.t_used == pytest.approx(
        full.summary["relax"]["time_s"])
    resumed = _solve(scene, out, resume=True)
    assert _same(resumed.U, full.U) and resumed.summary["relax"]["handovers"] == full.summary["relax"]["handovers"]
    done = _load(scene, out / "checkpoint.npz")  # a finished solve is saved as such
    assert done.phase == "done" and np.array_equal(done.result.U, resumed.U)


def test_the_relaxation_fallback_saves_the_failure_of_the_load_steps(tmp_path, monkeypatch):
    """Load steps that fail hand over to the relaxation from the flat sheet; its checkpoint carries that
    failure (message, last equilibrium, counts) for the summary of the resumed solve."""
    scene = load_scene("strip", ["mesh.nodes=[11,3]", "solver.max_load_steps=1"])
    out = tmp_path / "cut"
    _press_ctrl_c_at_sample(monkeypatch, 2)
    with pytest.raises(KeyboardInterrupt, match="checkpoint saved"):
        _solve(scene, out, checkpoint_seconds=1e9)
    saved = _load(scene, out / "checkpoint.npz")
    assert saved.phase == "relax" and saved.segment["step"] == 21
    first = saved.route.first
    assert "1 load increments used" in str(first) and saved.route.info["after_failure"] == str(first)
    assert first.result.lam > 0 and len(first.result.load_steps) == 1 and first.result.U.shape == (33, 3)
