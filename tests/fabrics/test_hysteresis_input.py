"""Bending hysteresis as scene input: KES 2HB keys, conversion, refusals, and the State's checkpoint."""

import numpy as np
import pytest

from rftstatic.errors import SceneError
from rftstatic.scenes.material import build_material, material_summary
from rftstatic.scenes.schema import scene_from_dict
from rftstatic.units import STANDARD_GRAVITY

LAB = {"kes_B_warp": 0.083, "kes_B_weft": 0.063, "kes_W": 19.0, "kes_T": 0.5}


def _scene(table):
    return scene_from_dict({"units": "cm-gf-s", "material": table})


def test_kes_2hb_gives_the_friction_moment_half_the_loop_width():
    scene = _scene({**LAB, "kes_2HB_warp": 0.05, "kes_2HB_weft": 0.04, "hysteresis_ratio": 20.0})
    mat = build_material(scene)
    gf = STANDARD_GRAVITY * 1e-3
    assert mat.hysteresis.M0_warp == pytest.approx(0.025 * gf, rel=1e-12)
    assert mat.hysteresis.M0_weft == pytest.approx(0.020 * gf, rel=1e-12)
    assert mat.hysteresis.ratio == 20.0
    summary = material_summary(scene, mat)
    assert summary["bending_hysteresis"]["M0_warp"] == pytest.approx(0.025, rel=1e-12)
    assert summary["lab"]["M0_warp"]["from"] == "kes_2HB_warp"
    assert build_material(_scene(dict(LAB))).hysteresis is None


@pytest.mark.parametrize("table, key", [
    ({**LAB, "kes_2HB_warp": 0.05}, "material.kes_2HB_weft"),
    ({**LAB, "hysteresis_ratio": 5.0}, "material.hysteresis_ratio"),
    ({**LAB, "kes_2HB_warp": 0.05, "kes_2HB_weft": 0.04, "hysteresis_ratio": 0.1}, "material.hysteresis_ratio"),
    ({**LAB, "kes_2HB_warp": 50.0, "kes_2HB_weft": 0.04}, "material.kes_2HB_warp"),
])
def test_bad_hysteresis_input_names_the_key(table, key):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        build_material(_scene(table))


def test_checkpoint_keeps_the_slip_and_the_dissipation(tmp_path):
    from rftstatic.mesh import trimesh as mesh
    from rftstatic.model import model
    from rftstatic.model.state import State
    from rftstatic.solvers.checkpoint import read_checkpoint, restore_state, state_arrays

    mat = build_material(_scene({**LAB, "kes_2HB_warp": 0.05, "kes_2HB_weft": 0.04}))
    mod = model.Model(mesh.rectangle(0.02, 0.01, 5, 3), mat)
    state = State.initial(mod)
    state.slip = np.random.default_rng(1).normal(size=state.slip.shape)
    state.dissipated = 1.25e-6
    path = tmp_path / "c.npz"
    np.savez(path, **state_arrays(state, {"what": "test"}))
    _, saved = read_checkpoint(path)
    back = restore_state(mod, saved)
    np.testing.assert_array_equal(back.slip, state.slip)
    assert back.dissipated == 1.25e-6


def test_arc_length_route_is_refused_with_hysteresis():
    from rftstatic.scenes.build import build_model
    from rftstatic.scenes.schema import load_scene

    table = "material={" + ", ".join(f"{k}={v}" for k, v in {**LAB, "kes_2HB_warp": 0.05,
                                                             "kes_2HB_weft": 0.04}.items()) + "}"
    with pytest.raises(SceneError, match=r"solver\.continuation: \"arc-length\" does not commit"):
        build_model(load_scene("strip", [table, "solver.continuation=arc-length"]))
