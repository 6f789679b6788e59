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


def test_an_interrupted_drag_resumes_bit_identical(tmp_path):
    """The moving support's records (its work and impulse, State.route) are checkpointed: the drag cut at 0.13 s
    and resumed ends where the uninterrupted run did, its mean reaction to the bit."""
    from rftstatic.app.dynamic import run_dynamic_scene
    from rftstatic.app.registry import resume_scene
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene

    scene = load_scene("drag-floor", ["dynamics.checkpoint_every=0.05"])

    def run(out, **kw):
        model, extras = build_model(scene)
        return run_dynamic_scene(scene, model, extras, out, progress=False, figures=False, **kw)

    full = run(tmp_path / "full")

    def interrupt(state, sample):
        if state.t > 0.13:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(tmp_path / "cut", callback=interrupt)
    resumed = resume_scene(scene, tmp_path / "cut", progress=False, figures=False)
    assert 0 < resumed["resumed_from_t"] <= 0.13
    assert resumed["drive"] == full["drive"] and resumed["energies"] == full["energies"]
