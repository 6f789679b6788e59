"""The fresh-process harness (rftstatic.bench.harness): result, measures, timeout and failures named."""

import ast
import time
from pathlib import Path

import pytest

import rftstatic
from rftstatic.bench.harness import ChildError, ChildTimeout, run_child

HERE = {"PYTHONPATH": str(Path(__file__).resolve().parent)}


def test_child_returns_json_and_its_measures_and_imports_this_rftstatic(tmp_path):
    # a decoy package in the child's working directory must not be imported (python -P, PYTHONPATH first)
    (tmp_path / "rftstatic").mkdir()
    (tmp_path / "rftstatic" / "__init__.py").write_text("raise ImportError('the decoy was imported')\n")
    run = run_child("child_targets:rftstatic_file", name="where", timeout=60, cwd=tmp_path, env=HERE)
    assert run.result == {"file": rftstatic.__file__, "array": [0, 1, 2], "scalar": 0.5, "tuple": [1, 2]}
    assert "noise on stdout" in run.stdout
    assert run.wall_s > 0 and 0 < run.cpu_s < 60 and run.peak_rss_mb > 10  # numpy imported: tens of MB


def test_a_hung_child_is_killed_after_its_timeout_with_its_name():
    t0 = time.perf_counter()
    with pytest.raises(ChildTimeout, match=r"sleepy bench: no result within the timeout of 1 s; the child process "
                                           r"was killed") as info:
        run_child("child_targets:sleep", {"seconds": 600}, name="sleepy bench", timeout=1.0, env=HERE)
    assert time.perf_counter() - t0 < 10 and info.value.name == "sleepy bench"


def test_a_failing_child_names_the_run_and_the_exception():
    with pytest.raises(ChildError, match=r"bad bench: the child process raised ValueError: no such thing") as info:
        run_child("child_targets:fail", {"message": "no such thing"}, name="bad bench", timeout=60, env=HERE)
    assert info.value.exception == "ValueError" and "Traceback" in info.value.stderr
    assert isinstance(info.value, RuntimeError)  # what the benches raised before the harness


@pytest.mark.parametrize(("how", "what"), [("exit", "exited with code 3"), ("signal", "was killed by signal SIGKILL")])
def test_a_child_that_dies_without_a_result_is_an_error(how, what):
    with pytest.raises(ChildError, match=f"dying bench: the child process {what}"):
        run_child("child_targets:die", {"how": how}, name="dying bench", timeout=60, env=HERE)


def test_a_target_must_name_module_and_function():
    with pytest.raises(ValueError, match='"module:function"'):
        run_child("child_targets.sleep", name="x", timeout=1)


def test_no_child_process_of_validate_or_bench_is_forked():
    """Every child of validate and bench goes through the harness (a fresh interpreter): a fork copies
    the locks of the parent's threads (numba, CHOLMOD's OpenMP, BLAS) but not the threads."""
    package = Path(rftstatic.__file__).resolve().parent
    harness = package / "bench" / "harness.py"
    spawners = {"multiprocessing", "subprocess", "concurrent.futures", "concurrent"}
    for folder in ("validate", "bench"):
        for path in sorted((package / folder).rglob("*.py")):
            where = path.relative_to(package)
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Import):
                    names = {a.name for a in node.names}
                elif isinstance(node, ast.ImportFrom):
                    names = {node.module or ""}
                else:
                    names = set()
                if path != harness:
                    assert not names & spawners, f"{where}:{node.lineno} imports {names & spawners}: use run_child"
                if isinstance(node, ast.Attribute) and node.attr in ("fork", "forkpty"):
                    raise AssertionError(f"{where}:{node.lineno} forks")
                if isinstance(node, ast.Constant) and node.value in ("fork", "forkserver"):
                    raise AssertionError(f"{where}:{node.lineno} names the fork start method")
