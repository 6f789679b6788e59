"""bench profile (rftstatic.bench.phases, rftstatic.bench.profile): phases that add up, nesting, restoring."""

import importlib
import time

import pytest

from rftstatic.bench import phases
from rftstatic.bench.phases import OTHER, PHASES, STABILITY, TARGETS, PhaseClock

TINY = ["mesh.nodes=[21,5]"]  # the strip: 105 nodes, 32 Newton iterations


class FakeTime:
    """A clock that moves only when the code under test "works" (``_busy``): exact phase times on a loaded machine."""

    now = 0.0

    @classmethod
    def perf_counter(cls):
        return cls.now


def _busy(seconds):
    FakeTime.now += seconds


@pytest.fixture(autouse=True)
def _fake_clock(request, monkeypatch):
    if "fake" in request.node.name:
        monkeypatch.setattr(phases, "time", FakeTime)


def test_time_goes_to_the_innermost_phase_and_the_phases_add_up_to_the_total_fake_clock():
    clock = PhaseClock()
    inner = clock.wrap(lambda: _busy(0.02), "inner")
    outer = clock.wrap(lambda: (_busy(0.01), inner(), inner()), "outer")
    clock.start()
    outer()
    _busy(0.01)
    total = clock.stop()
    assert total == pytest.approx(sum(clock.seconds.values()), rel=1e-12)
    assert clock.seconds["inner"] == pytest.approx(0.04, abs=1e-12)
    assert clock.seconds["outer"] == pytest.approx(0.01, abs=1e-12)
    assert clock.seconds[OTHER] == pytest.approx(0.01, abs=1e-12)
    assert clock.calls["inner"] == 2 and clock.calls["outer"] == 1


def test_an_opaque_phase_keeps_what_it_calls_but_not_the_numba_compile_fake_clock():
    clock = PhaseClock()
    assembly = clock.wrap(lambda: _busy(0.01), phases.TANGENT)
    compile_ = clock.wrap(lambda: _busy(0.01), phases.NUMBA, "compilations")
    check = clock.wrap(lambda: (assembly(), compile_()), STABILITY)
    clock.start()
    check()
    clock.stop()
    assert clock.seconds[STABILITY] == pytest.approx(0.01, abs=1e-12)
    assert clock.seconds[phases.NUMBA] == pytest.approx(0.01, abs=1e-12)
    assert clock.seconds.get(phases.TANGENT, 0.0) == 0.0 and clock.events["compilations"] == 1


def test_a_generator_is_timed_per_resumption_and_passes_values_exceptions_and_its_return_fake_clock():
    clock = PhaseClock()

    def route():
        got = []
        try:
            while True:
                _busy(0.005)
                got.append((yield len(got)))
        except KeyError:
            return got

    timed = clock.wrap(route, "route")
    clock.start()
    gen = timed()
    assert next(gen) == 0
    _busy(0.02)  # the driver's work between two pauses (a checkpoint) is not the route's
    assert gen.send("a") == 1
    with pytest.raises(StopIteration) as stop:
        gen.throw(KeyError("end"))
    clock.stop()
    assert stop.value.value == ["a"]
    assert clock.seconds["route"] == pytest.approx(0.010, abs=1e-12)
    assert clock.seconds[OTHER] == pytest.approx(0.02, abs=1e-12)


def test_every_target_exists():
    """A renamed function or method must fail here, not silently drop out of the profile."""
    for module, qualname, phase, _ in TARGETS:
        assert phase in PHASES
        try:
            owner = importlib.import_module(module)
        except ImportError:
            continue  # numba or scikit-sparse not installed: nothing of theirs to time
        for part in qualname.split("."):
            owner = getattr(owner, part)


def test_a_profiled_solve_in_process_adds_up_and_restores_the_originals(tmp_path):
    from rftstatic.bench.profile import run_scene
    from rftstatic.model.model import Model
    from rftstatic.solvers import linear

    tangent, solve = Model.tangent, linear.CholmodSolver.solve
    r = run_scene("strip", TINY)
    assert Model.tangent is tangent and linear.CholmodSolver.solve is solve
    assert [p["phase"] for p in r["phases"]] == list(PHASES)
    assert sum(p["seconds"] for p in r["phases"]) == pytest.approx(r["total_s"], rel=1e-9)
    seconds = {p["phase"]: p["seconds"] for p in r["phases"]}
    assert seconds[phases.TANGENT] > 0 and seconds[phases.RESIDUAL] > 0 and seconds[phases.OUTPUT] > 0
    assert r["converged"] and r["newton_iterations"] >= 10
    assert r["events"]["tangent assemblies"] >= r["newton_iterations"]
    if linear.cholmod_available():
        assert r["events"]["numeric factorisations"] >= r["factorisations"] > 0
        assert seconds[phases.FACTOR] > 0 and r["events"]["symbolic analyses"] >= 1


def test_bench_profile_of_a_tiny_scene_in_a_fresh_process_prints_every_phase(capsys):
    from rftstatic.bench.profile import main

    t0 = time.perf_counter()
    assert main(["strip", *(a for o in TINY for a in ("--set", o)), "--format", "markdown"]) == 0
    assert time.perf_counter() - t0 < 60  # two fresh interpreters (with and without the timers), a few seconds idle
    out = capsys.readouterr().out
    for phase in PHASES:
        assert f"| {phase} |" in out
    assert "| **total** (the run in the child) |" in out and "| Newton iterations | 32 |" in out
    assert "without the timers" in out and "peak memory" in out
    assert "same iterations, factorisations and steps: yes" in out  # the timers change no result


def test_the_record_adds_up_and_formats(capsys):
    from rftstatic.bench.profile import format_record, profile

    r = profile("strip", TINY, compare=False)
    assert sum(p["seconds"] for p in r["phases"]) == pytest.approx(r["total_s"], rel=1e-9)
    assert r["process_s"] > r["total_s"] > 0 and r["peak_rss_mb"] > 10
    assert 0 <= r["timer_cost_s"] < 0.1 * r["total_s"]
    text = format_record(r)
    assert all(p in text for p in PHASES) and "--no-compare" in text


def test_an_unknown_scene_is_an_input_error_naming_it(capsys):
    from rftstatic.cli import main

    assert main(["bench", "profile", "no-such-scene"]) == 2
    assert "no-such-scene" in capsys.readouterr().err
    assert main(["bench", "scenes", "strip", "no-such-scene", "--quick"]) == 2
    assert "no-such-scene" in capsys.readouterr().err
    assert main(["bench", "strip", "--set", "x=1"]) == 2  # options belong to profile and scenes


def test_bench_scenes_quick_runs_each_scene_in_its_own_process(capsys):
    from rftstatic.bench.paper_scenes import QUICK, SCENES, main

    assert set(QUICK) == set(SCENES)
    assert main(["strip", "hang-20", "--quick"]) == 0
    out = capsys.readouterr().out
    strip = next(line for line in out.splitlines() if line.startswith("strip"))
    hang = next(line for line in out.splitlines() if line.startswith("hang-20"))
    assert " 105 " in strip and " 32 " in strip and "static / load-steps" in strip
    assert " 121 " in hang and "dynamic" in hang and "FAILED" not in out


def test_the_newton_bench_runs_every_child_on_one_thread(monkeypatch):
    from rftstatic.bench import harness, newton

    seen = {}

    def fake(target, kwargs, *, name, timeout, env=None):
        seen[name] = env
        raise harness.ChildError("not run", name=name)

    monkeypatch.setattr(harness, "run_child", fake)
    assert newton._child("strip_solve", {"nx": 5, "ny": 3}, "strip") is None
    assert seen["strip"]["OMP_NUM_THREADS"] == "1" and seen["strip"]["NUMBA_NUM_THREADS"] == "1"
