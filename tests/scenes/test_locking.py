"""``[mesh] locking = "refine"`` (rftstatic.scenes.locking): the mesh chosen from the fabric's C/B."""

import pytest

from rftstatic.errors import SceneError
from rftstatic.model.model import LOCKING_WARN, locking_number
from rftstatic.scenes.build import build_material, build_mesh
from rftstatic.scenes.mesh_build import structured_nodes
from rftstatic.scenes.schema import load_scene

LIMP = "material.preset=ctd-291-light-soft"  # the library's limp fabric: (C/B) h^2 = 2.95e4 on cusick-30's mesh


def _lock(scene):
    return locking_number(build_mesh(scene), build_material(scene))


def test_a_limp_fabric_gets_a_mesh_below_the_locking_limit():
    given = load_scene("cusick-30", ["mesh.locking=warn", LIMP])
    refined = load_scene("cusick-30", [LIMP])  # the scene says "refine"
    assert _lock(given) > LOCKING_WARN >= _lock(refined) > 0.5 * LOCKING_WARN  # to the limit, not far past it
    a, b = structured_nodes(refined)
    assert a > 13 and b > 160 and build_mesh(refined).n_nodes == a * b


def test_a_fabric_below_the_limit_keeps_the_scene_mesh():
    assert structured_nodes(load_scene("cusick-30")) == [13, 160]  # the wool: 3.9e3
    assert structured_nodes(load_scene("cusick-30", [LIMP, "element=RFT3"])) == [13, 160]  # RFT3 does not lock


def test_node_counts_given_as_an_override_are_kept():
    assert structured_nodes(load_scene("cusick-30", ["mesh.nodes=[7,80]", LIMP])) == [7, 80]


def test_a_rectangle_scales_both_counts(tmp_path):
    text = (load_scene("pedestal-square-20").path.read_text()
            .replace('[mesh]', '[mesh]\nlocking = "refine"').replace("nodes = [33, 33]", "nodes = [9, 9]"))
    path = tmp_path / "square.toml"
    path.write_text(text)
    sq = load_scene(str(path), [LIMP])
    a, b = structured_nodes(sq)
    assert a == b > 9
    assert _lock(sq) <= LOCKING_WARN


@pytest.mark.parametrize("sets, text", [
    (["mesh.locking=always"], "'always' is not a mode"),
    (["mesh.kind=unstructured", "mesh.h=1.0", "mesh.radius=15.0", "mesh.locking=refine", LIMP],
     "unstructured mesh has none"),
])
def test_bad_locking_input_names_the_key(sets, text):
    with pytest.raises(SceneError, match="mesh.locking") as err:
        build_mesh(load_scene("cusick-30", sets))
    assert text in str(err.value)


def test_a_refinement_past_the_mesh_size_limit_is_a_scene_error():
    with pytest.raises(SceneError, match="mesh.locking") as err:
        build_mesh(load_scene("cusick-30", ["material.C_warp=1e15"]))
    assert "more than 2,000,000" in str(err.value)
