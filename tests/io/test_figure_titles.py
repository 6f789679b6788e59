"""Figure titles say which fabric was run (issue: a scene's title names the fabric it was written for)."""

from rftstatic.io.results import run_label
from rftstatic.scenes.build import build_model
from rftstatic.scenes.schema import load_scene


def test_the_run_label_names_the_fabric_that_was_run():
    small = ["mesh.nodes=[3,16]"]
    assert run_label(build_model(load_scene("cusick-30", small))[0]).startswith("fabric wool-kang-yu, RFT6, ")
    other = build_model(load_scene("cusick-30", [*small, "material.preset=ctd-12-light-stiff"]))[0]
    assert run_label(other).startswith("fabric ctd-12-light-stiff, ")
    changed = build_model(load_scene("cusick-30", [*small, "material.B_warp=0.2"]))[0]
    assert run_label(changed).startswith("fabric wool-kang-yu (modified), ")
    assert run_label(changed).endswith(f"{changed.mesh.n_nodes} nodes")
