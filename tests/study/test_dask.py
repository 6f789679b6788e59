"""Studies on Dask, on the strip with 9 x 3 nodes (0.1-0.5 s a point): a sweep on a 2-worker
LocalCluster, the same sweep on a scheduler and two workers started as separate processes (and a point
over --timeout there), a driver killed mid-sweep and resumed, a fit that recovers the strip's bending
rigidity from its tip drop, a fit over a warp and a weft strip that recovers B_warp and B_weft, and a
point over --timeout on a LocalCluster (201 x 41 nodes)."""

import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rftstatic import api, cli
from rftstatic.study.worker import worker_environment

pytest.importorskip("distributed")

ROOT = Path(api.__file__).resolve().parents[1]
COARSE = "mesh.nodes=[9,3]"
B_TRUE = 0.083  # wool-kang-yu B_warp [gf cm]


def _env():
    env = {**os.environ, **worker_environment()}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    return env


def _rows(out: Path) -> list[dict]:
    with open(out / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc) -> None:
    if proc.poll() is None:
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(proc.pid, sig)
            except ProcessLookupError:
                return
            try:
                proc.wait(5)
                return
            except subprocess.TimeoutExpired:
                continue


@pytest.fixture
def processes():
    """Started subprocesses (each in its own session), stopped with their process groups at the end."""
    started = []
    yield started
    for proc in reversed(started):
        _stop(proc)


def _sweep(out, *extra):
    return ["sweep", "strip", "--set", COARSE, "--vary", "material.B_warp=0.05,0.12",
            "--vary", "material.B_weft=0.04,0.09", "--out", str(out), *extra]


def test_sweep_on_a_local_cluster_then_nothing_to_run(tmp_path, capsys):
    out = tmp_path / "sweep"
    assert cli.main(_sweep(out, "--workers", "2")) == 0
    stdout = capsys.readouterr().out
    assert "Dask local scheduler tcp://" in stdout
    rows = _rows(out)
    assert len(rows) == 4 and {r["status"] for r in rows} == {"ok"}
    by_b = {}
    for r in rows:
        assert (out / r["folder"] / "summary.json").exists() and (out / r["folder"] / "deformed.vtu").exists()
        by_b.setdefault(float(r["material.B_warp"]), []).append(float(r["probes.tip.z"]))
    assert max(by_b[0.12]) > min(by_b[0.05])  # a stiffer warp: the tip drops less
    # B_weft acts across the strip: its tip drop changes by less than 1e-3 of the warp's effect
    assert abs(by_b[0.05][0] - by_b[0.05][1]) < 1e-3 * abs(by_b[0.05][0] - by_b[0.12][0]) + 1e-4
    study = json.loads((out / "study.json").read_text())
    assert study["runs"][-1]["engine"] == "local" and len(study["runs"][-1]["workers"]) == 2
    assert (out / "plots" / "probes.tip.z.png").exists()
    assert cli.main(_sweep(out, "--workers", "2")) == 0  # finished: no cluster, nothing re-run
    stdout = capsys.readouterr().out
    assert "0 to run" in stdout and "Dask" not in stdout
    assert json.loads((out / "study.json").read_text())["runs"][-1] == {
        **json.loads((out / "study.json").read_text())["runs"][-1], "engine": "none", "points_run": 0}


def test_sweep_on_an_external_scheduler_and_workers(tmp_path, processes, capsys):
    from distributed import Client

    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = tmp_path / "logs"
    logs.mkdir()

    def start(name, *args):
        with open(logs / f"{name}.log", "wb") as log:
            processes.append(subprocess.Popen([sys.executable, "-m", "dask", *args], stdout=log, stderr=log,
                                              env=_env(), cwd=tmp_path, start_new_session=True))

    start("scheduler", "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")
    for i in range(2):
        start(f"worker{i}", "worker", address, "--nthreads", "1", "--nworkers", "1", "--no-dashboard",
              "--name", f"external-{i}", "--local-directory", str(tmp_path / f"w{i}"))
    deadline = time.monotonic() + 60
    while True:  # the scheduler takes a moment to listen
        try:
            with Client(address, timeout=5) as client:
                client.wait_for_workers(2, timeout=60)
                workers = set(client.scheduler_info()["workers"])
            break
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)
    out = tmp_path / "sweep"
    assert cli.main(_sweep(out, "--scheduler", address, "--workers", "2")) == 0
    assert f"Dask scheduler scheduler {address}" in capsys.readouterr().out
    rows = _rows(out)
    assert len(rows) == 4 and {r["status"] for r in rows} == {"ok"}
    assert {r["worker"] for r in rows} <= workers  # the external workers ran every point
    run = json.loads((out / "study.json").read_text())["runs"][-1]
    assert run["engine"] == "scheduler" and run["address"] == address and set(run["workers"]) == workers
    # --timeout on the external workers: the overdue point's worker is restarted by its nanny
    slow = tmp_path / "slow"
    assert cli.main(["sweep", "strip", "--vary", "mesh.nodes=[201,41],[9,3]", "--out", str(slow), "--no-plots",
                     "--scheduler", address, "--timeout", "2"]) == cli.EXIT["goal"]
    rows = {r["mesh.nodes"]: r for r in _rows(slow)}
    assert rows["[201, 41]"]["error"] == "timed out after 2 s (--timeout; its worker was restarted)"
    assert rows["[201, 41]"]["worker"] in workers and rows["[9, 3]"]["status"] == "ok"
    with Client(address, timeout=5) as client:
        client.wait_for_workers(2, timeout=60)  # the restarted worker joined again, under a new address
        assert rows["[201, 41]"]["worker"] not in client.scheduler_info()["workers"]


def test_unreachable_scheduler_is_an_input_error(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{_free_port()}"
    t0 = time.monotonic()
    from rftstatic.study import runner

    old, runner.CONNECT_TIMEOUT_S = runner.CONNECT_TIMEOUT_S, 2.0
    try:
        code = cli.main(_sweep(tmp_path / "s", "--scheduler", address))
    finally:
        runner.CONNECT_TIMEOUT_S = old
    assert code == cli.EXIT["input"] and time.monotonic() - t0 < 30
    err = capsys.readouterr().err
    assert f"--scheduler {address}: no Dask scheduler answered" in err


def test_killed_driver_loses_no_finished_point(tmp_path, processes, capsys):
    out = tmp_path / "sweep"
    values = ",".join(f"{0.05 + 0.01 * i:.2f}" for i in range(8))
    argv = ["sweep", "strip", "--set", COARSE, "--vary", f"material.B_warp={values}", "--out", str(out),
            "--workers", "1", "--no-plots"]
    proc = subprocess.Popen([sys.executable, "-m", "rftstatic", *argv], env=_env(), cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    processes.append(proc)
    deadline = time.monotonic() + 90
    while not ((out / "results.csv").exists() and len(_rows(out)) >= 2):
        assert proc.poll() is None and time.monotonic() < deadline, "the driver ended before two points"
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver, its scheduler and its worker
    proc.wait(10)
    before = {r["key"]: r for r in _rows(out)}
    assert 2 <= len(before) < 8
    stamps = {k: (out / "points" / k / "summary.json").stat().st_mtime_ns for k in before}
    assert cli.main(argv[:-2] + ["2", "--no-plots"]) == 0
    rows = {r["key"]: r for r in _rows(out)}
    assert len(rows) == 8 and {r["status"] for r in rows.values()} == {"ok"}
    for k, r in before.items():  # kept as they were, not run again
        assert rows[k]["wall_time_s"] == r["wall_time_s"] and rows[k]["worker"] == r["worker"]
        assert (out / "points" / k / "summary.json").stat().st_mtime_ns == stamps[k]
    run = json.loads((out / "study.json").read_text())["runs"][-1]
    assert run["points_run"] <= 8 - len(before)


def test_fit_recovers_the_bending_rigidity_from_the_tip_drop(tmp_path, capsys):
    synthetic = api.run("strip", tmp_path / "truth", overrides=[COARSE, f"material.B_warp={B_TRUE}"], figures=False)
    drop = synthetic.summary["probes"]["tip"]["deformed"][2]
    out = tmp_path / "fit"
    argv = ["fit", "strip", "--set", COARSE, "--free", "material.B_warp=0.03:0.3", "--target",
            f"probes.tip.z={drop!r}", "--out", str(out), "--workers", "2"]
    assert cli.main(argv) == 0
    captured = capsys.readouterr()
    fit = json.loads((out / "fit.json").read_text())
    assert fit["fitted"]["material.B_warp"] == pytest.approx(B_TRUE, rel=1e-4)
    assert fit["history"][0]["objective"] > fit["history"][-1]["objective"]
    s = fit["sensitivity"]["probes.tip.z"]["material.B_warp"]
    assert -0.2 < s < -0.05  # the drop hardly moves: 0.1 % per 1 % of B, ...
    assert "material.B_warp is barely identifiable" in captured.err  # ... and the fit says so
    assert fit["identifiability"]["amplification"]["material.B_warp"] == pytest.approx(1 / abs(s))
    n = len(_rows(out))
    assert cli.main(argv) == 0  # a repeated fit replays from results.csv: nothing runs, no cluster
    stdout = capsys.readouterr().out
    assert "Dask" not in stdout and len(_rows(out)) == n
    assert json.loads((out / "fit.json").read_text())["points_run"] == 0


def test_fit_over_two_runs_recovers_b_warp_and_b_weft_from_two_bending_lengths(tmp_path, capsys):
    # a warp strip and a weft strip (warp at 90 deg: B_weft bends it), each its cantilever bending length
    truth = {"material.B_warp": 0.083, "material.B_weft": 0.06}
    sets = [COARSE, *(f"{k}={v}" for k, v in truth.items())]
    measured = {label: api.run("strip", tmp_path / label, overrides=[*sets, *extra], figures=False).summary
                for label, extra in (("warp", []), ("weft", ["material.warp_angle=90"]))}
    from rftstatic.study.measures import bending_length

    c = {label: bending_length(s) for label, s in measured.items()}
    assert c["warp"] > 1.05 * c["weft"]  # the weft strip is the softer one
    out = tmp_path / "fit"
    argv = ["fit", "strip", "--set", COARSE, "--run", "warp:", "--run", "weft:material.warp_angle=90",
            "--free", "material.B_warp=0.03:0.3", "--free", "material.B_weft=0.03:0.3",
            "--target", f"warp:cantilever.bending_length={c['warp']!r}",
            "--target", f"weft:cantilever.bending_length={c['weft']!r}", "--out", str(out), "--workers", "2"]
    assert cli.main(argv) == 0
    captured = capsys.readouterr()
    fit = json.loads((out / "fit.json").read_text())
    for k, v in truth.items():
        assert fit["fitted"][k] == pytest.approx(v, rel=1e-2)
    assert fit["runs"] == {"warp": {"scene": "strip", "overrides": []},
                           "weft": {"scene": "strip", "overrides": ["material.warp_angle=90"]}}
    assert set(fit["targets"]) == {"warp:cantilever.bending_length", "weft:cantilever.bending_length"}
    S = fit["identifiability"]["matrix"]  # each strip's bending length depends on its own rigidity only
    assert 0.2 < S[0][0] < 0.4 and 0.2 < S[1][1] < 0.4 and abs(S[0][1]) < 0.01 and abs(S[1][0]) < 0.01
    assert fit["identifiability"]["condition_number"] < 1.1 and fit["warnings"] == []
    assert "warning" not in captured.err
    rows = _rows(out)
    assert {r["run"] for r in rows} == {"warp", "weft"} and {r["status"] for r in rows} == {"ok"}
    # every evaluation ran both strips: each run has as many points
    assert sum(r["run"] == "warp" for r in rows) == sum(r["run"] == "weft" for r in rows)
    assert cli.main(argv) == 0  # replayed from results.csv: no cluster, nothing run, the same answer
    assert "Dask" not in capsys.readouterr().out
    again = json.loads((out / "fit.json").read_text())
    assert again["points_run"] == 0 and again["fitted"] == fit["fitted"]


def test_a_failed_point_is_a_row_with_its_error_and_can_be_retried(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", "strip", "--vary", "mesh.nodes=[9,3],[1,3]", "--out", str(out), "--workers", "1", "--no-plots"]
    assert cli.main(argv) == cli.EXIT["goal"]  # the study ran; one of its points failed
    rows = {r["mesh.nodes"]: r for r in _rows(out)}
    assert rows["[9, 3]"]["status"] == "ok"
    assert rows["[1, 3]"]["status"] == "failed"
    assert "mesh.nodes: [1, 3]: a rectangle mesh needs [nx, ny] of at least [2, 2]" in rows["[1, 3]"]["error"]
    assert "failed" in capsys.readouterr().err
    assert cli.main([*argv, "--retry-failed"]) == cli.EXIT["goal"]
    assert "1 to run" in capsys.readouterr().out  # only the failed point ran again


def test_local_workers_run_on_one_thread_without_the_nanny_malloc_setting():
    import os as os_

    from rftstatic.study.runner import Engine

    engine = Engine(None, 1)
    try:
        client = engine.client()
        env = list(client.run(lambda: {k: os_.environ.get(k) for k in ("MALLOC_TRIM_THRESHOLD_", "NUMBA_NUM_THREADS",
                                                                          "OMP_NUM_THREADS")}).values())[0]
    finally:
        engine.close()
    assert env == {"MALLOC_TRIM_THRESHOLD_": None, "NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def test_a_point_over_the_timeout_is_a_failed_row_and_its_worker_is_restarted(tmp_path, capsys):
    # 201 x 41 nodes take well over 2 s (3.3 s at 101 x 21 on the idle machine); 9 x 3 about 0.1-0.7 s
    out = tmp_path / "sweep"
    argv = ["sweep", "strip", "--vary", "mesh.nodes=[201,41],[9,3]", "--out", str(out), "--workers", "1",
            "--no-plots", "--timeout", "2"]
    assert cli.main(argv) == cli.EXIT["goal"]  # the study ran to its end; one point failed
    rows = {r["mesh.nodes"]: r for r in _rows(out)}
    slow, fast = rows["[201, 41]"], rows["[9, 3]"]
    assert slow["status"] == "failed"
    assert slow["error"] == "timed out after 2 s (--timeout; its worker was restarted)"
    assert 2 <= float(slow["wall_time_s"]) < 10
    assert fast["status"] == "ok"  # the study went on, on the restarted worker
    assert fast["worker"] != slow["worker"]  # the one worker process was replaced (a new address)
    assert not list((out / "points").glob("*.started"))
    assert "timed out after 2 s" in capsys.readouterr().err


def test_timeout_must_be_positive(tmp_path, capsys):
    assert cli.main(["sweep", "strip", "--vary", "material.B_warp=0.05", "--out", str(tmp_path / "s"),
                     "--timeout", "0"]) == cli.EXIT["input"]
    assert "--timeout 0: must be > 0 seconds" in capsys.readouterr().err
