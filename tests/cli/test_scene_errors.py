"""Scenes the property test (tests/app/test_scene_property.py) found mishandled: each is now an input error
(exit 2) of one line that names the scene file and the key."""

import pytest

from rftstatic.cli import main


def _run(capsys, tmp_path, scene, sets=(), text=None):
    """Exit status and stderr of ``case SCENE --set ...`` (``text``: a scene file of that content)."""
    if text is not None:
        scene = tmp_path / "scene.toml"
        scene.write_text(text)
    argv = ["case", str(scene), *(a for kv in sets for a in ("--set", kv)), "--out", str(tmp_path / "o"),
            "--no-figures"]
    code = main(argv)
    return code, capsys.readouterr().err.strip()


def _assert_input_error(code, err, key, fragment):
    assert code == 2, err
    assert "\n" not in err and "Traceback" not in err, err
    assert f": {key}: " in err and fragment in err, err


@pytest.mark.parametrize("sets, key, fragment", [
    # was: internal error: KeyError: 'nu' (an isotropic shell's key next to a fabric preset)
    (["material.nu=-1e-05"], "material.nu", 'does not apply next to preset = "wool-kang-yu"'),
    (["material.E=1e6"], "material.E", "does not apply next to preset"),
    # a mesh too big to build: was a MemoryError (an internal error) or a run that never ends
    (["mesh.nodes=[100000000,1000000]"], "mesh.nodes", "more than 2,000,000"),
])
def test_strip_mutations_are_input_errors(capsys, tmp_path, sets, key, fragment):
    _assert_input_error(*_run(capsys, tmp_path, "strip", sets), key, fragment)


@pytest.mark.parametrize("mesh, key, fragment", [
    # was: "error: the smallest target size 0.167 m exceeds the domain's width 0.01 m" (no file, no key)
    ("h = 16.7", "mesh.h", "is larger than the sheet (1 across"),
    ("h = 1e-300", "mesh.h", "would give countless nodes"),
    ("h = 1e-4\nsize = [50.0, 50.0]", "mesh.h", "would give about 2.89e+11 nodes"),
    ("h = -1.0", "mesh.h", "must be > 0"),
    ("h = 1.0\nsize = [-5.0, 5.0]", "mesh.size", "both sides must be > 0"),
    ("h = 1.0\nradius = 0.0", "mesh.radius", "must be > 0"),
])
def test_bad_unstructured_sizes_are_input_errors(capsys, tmp_path, mesh, key, fragment):
    text = f'[mesh]\nkind = "unstructured"\n{mesh}\n[[supports]]\nkind = "pinned"\nat = [0.0, 0.0]\n'
    _assert_input_error(*_run(capsys, tmp_path, None, text=text), key, fragment)


def test_a_negative_seed_is_an_input_error(capsys, tmp_path):
    # was: internal error: ValueError: expected non-negative integer (numpy's generator, deep in the solver)
    code, err = _run(capsys, tmp_path, "strip", ["mesh.nodes=[5,3]", "solver.seed=-100000000000",
                                                  "solver.perturbation=0.01"])
    _assert_input_error(code, err, "solver.seed", "must be an integer >= 0")


@pytest.mark.parametrize("scene, obstacle", [("pedestal-square-20", "half_width=1e300"),
                                             ("pedestal-round-50", "radius=1e300")])
def test_a_huge_pedestal_is_no_internal_error(capsys, tmp_path, scene, obstacle):
    # was: RuntimeWarning: overflow in the footprint's area (an error under the test suite's warning filter)
    nodes = "[5,5]" if scene == "pedestal-square-20" else "[3,8]"
    code, err = _run(capsys, tmp_path, scene, [f"mesh.nodes={nodes}", f"obstacles.0.{obstacle}"])
    assert code in (0, 3) and "internal error" not in err, err


@pytest.mark.parametrize("pattern", ["RIGHT", "union-jack"])
def test_an_unknown_square_polar_pattern_is_an_input_error(capsys, tmp_path, pattern):
    # was: accepted silently, and meshed as "left"
    code, err = _run(capsys, tmp_path, "pedestal-round-50", ["mesh.nodes=[2,17]", f"mesh.pattern={pattern}"])
    _assert_input_error(code, err, "mesh", f'unknown diagonal pattern "{pattern}" for a square-polar mesh')
