"""The force kernel's thread timing (rftstatic.bench.explicit.thread_calls) on a small scene mesh."""

import pytest


def test_thread_calls_same_force_and_timings():
    pytest.importorskip("numba")
    from rftstatic.bench.explicit import thread_calls

    m = thread_calls("cusick-30", ["mesh.nodes=[5,48]"], blocks=2, calls=3)
    assert m["elements"] == 384 and m["threads"] >= 1
    assert m["same_force"] is True  # the kernels' sums do not depend on the thread count
    for key in ("one", "all"):
        t = m[key]
        assert 0 < t["min"] <= t["p10"] <= t["median"] < 1.0


def test_thread_calls_command(capsys):
    pytest.importorskip("numba")
    from rftstatic.bench.explicit import main

    assert main(["--threads", "cusick-30", "mesh.nodes=[5,48]"]) == 0
    out = capsys.readouterr().out
    assert "384 elements, same force bits True" in out and "1 thread" in out
