"""The drag scene (cases/drag-floor.toml): a support moving at a prescribed velocity ([[supports]] velocity,
rftstatic.scenes.drive) in a dynamic run; its summary's mean reaction over mu times the weight pulled is 1."""

import json

import pytest

from rftstatic.cli import main


def _case(tmp_path, *sets):
    out = tmp_path / "run"
    args = ["case", "drag-floor", "--no-figures", "--out", str(out)]
    for s in sets:
        args += ["--set", s]
    return main(args), out


def test_the_drag_scene_reports_mu_times_the_weight_it_pulls(tmp_path):
    rc, out = _case(tmp_path)
    assert rc == 0
    d = json.loads((out / "summary.json").read_text())["drive"]
    assert d["mu"] == 0.3 and d["weight_pulled"] > 0
    assert abs(d["reaction_over_mu_weight"] - 1.0) < 0.02, d  # measured 1.0055


@pytest.mark.parametrize("sets, fragment", [
    (["supports.0.velocity=[1, 2]"], "expected 3 items"),
    (["supports.0.velocity=[-1, 0, 0.5]"], "holds xy only, but its velocity moves z"),
    (["analysis=static"], 'a support moves only in a dynamic run; analysis = "static"'),
])
def test_a_bad_support_velocity_exits_2_naming_the_key_and_the_fix(tmp_path, capsys, sets, fragment):
    rc, _ = _case(tmp_path, *sets)
    err = capsys.readouterr().err
    assert rc == 2 and "supports.0.velocity" in err and fragment in err, err
