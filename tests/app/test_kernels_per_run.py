"""A run's result does not depend on what ran before it in the process: its kernel back end is chosen
from its scene (rftstatic.compiled.choose_kernels) and named in its summary."""

import json

import numpy as np

from rftstatic import compiled
from rftstatic.api import run


def test_a_scene_solved_again_after_other_solves_gives_the_same_bits(tmp_path):
    over = ["mesh.nodes=[21,5]"]
    first = run("strip", tmp_path / "a", overrides=over, figures=False)
    assert first.summary["kernels"] == "numpy"  # 160 elements: numba's load would cost more than it saves
    assert json.loads((tmp_path / "a" / "summary.json").read_text())["kernels"] == "numpy"
    if compiled.numba_available():
        # the compiled kernels used in between: with them loaded in the process, the old process-wide rule
        # ran every later solve compiled (results equal to round-off only)
        from rftstatic.contact.self_contact.law_kernels import load_compiled
        from rftstatic.model.model import Model

        m = first.model
        other = Model(m.mesh, m.material, element=m.element, supports=m.supports, load=m.load, kernels="compiled")
        other.tangent(first.U)
        assert load_compiled()
    again = run("strip", tmp_path / "c", overrides=over, figures=False)
    assert again.summary["kernels"] == "numpy"
    assert again.summary["energies"] == first.summary["energies"]
    assert again.summary["probes"] == first.summary["probes"]
    np.testing.assert_array_equal(again.U, first.U)
