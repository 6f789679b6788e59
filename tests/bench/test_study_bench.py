"""The study benchmark runs at a tiny size: 4 points of the 9 x 3 strip, one by one and on one worker."""

import pytest

pytest.importorskip("distributed")


def test_study_bench_runs_small(capsys):
    from rftstatic.bench import study

    out = study.run(points=4, sets=["mesh.nodes=[9,3]"], workers=(1,))
    assert [r["workers"] for r in out] == [0, 1]
    assert out[1]["failed"] == 0 and out[1]["points_s"] > 0 and out[0]["wall_s"] > 0
    text = capsys.readouterr().out
    assert "points/min" in text and "overhead" in text
