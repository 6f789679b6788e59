"""The kernel back end is a constant of the run: chosen from the scene before it starts, held by the Model."""

import numpy as np
import pytest

from rftstatic import compiled, material
from rftstatic.contact.self_contact.law import SelfContact
from rftstatic.mesh import trimesh
from rftstatic.model.model import Model


def test_the_choice_depends_on_the_mesh_size_self_contact_and_numba_only(monkeypatch):
    n = compiled.STATIC_COMPILED_MIN_ELEMENTS
    monkeypatch.setattr(compiled, "numba_available", lambda: True)
    assert compiled.choose_kernels(n - 1) == "numpy" and compiled.choose_kernels(n) == "compiled"
    assert compiled.choose_kernels(8, self_contact=True) == "compiled"
    assert compiled.choose_kernels(10 * n, requested="numpy") == "numpy"
    monkeypatch.setattr(compiled, "numba_available", lambda: False)
    assert compiled.choose_kernels(10 * n, self_contact=True) == "numpy"
    with pytest.raises(ValueError, match="need numba"):
        compiled.choose_kernels(8, requested="compiled")
    with pytest.raises(ValueError, match="kernels must be one of numpy, compiled"):
        compiled.choose_kernels(8, requested="numba")


def test_a_scene_chooses_its_kernels_by_size_self_contact_and_route_or_says_which(monkeypatch):
    from rftstatic.errors import SceneError
    from rftstatic.scenes.build import build_model, run_kernels
    from rftstatic.scenes.schema import load_scene

    monkeypatch.setattr(compiled, "numba_available", lambda: True)
    mesh = trimesh.rectangle(1.0, 1.0, 5, 5, pattern="right")  # 32 elements
    assert run_kernels(load_scene("strip"), mesh) == "numpy"
    assert run_kernels(load_scene("strip", ["solver.continuation=arc-length"]), mesh) == "compiled"  # a long route
    assert run_kernels(load_scene("hang-20"), mesh) == "compiled"  # an explicit run
    assert run_kernels(load_scene("strip", ["kernels=compiled"]), mesh) == "compiled"
    assert run_kernels(load_scene("strip", ["solver.continuation=arc-length", "kernels=numpy"]), mesh) == "numpy"
    assert build_model(load_scene("strip", ["kernels=numpy", "mesh.nodes=[5,3]"]))[0].kernels == "numpy"
    with pytest.raises(SceneError, match=r'strip\.toml: kernels: "numba" is not a kernel back end; use auto, numpy, '
                       r'compiled'):
        load_scene("strip", ["kernels=numba"])
    monkeypatch.setattr(compiled, "numba_available", lambda: False)
    with pytest.raises(SceneError, match=r'kernels: "compiled": kernels "compiled" need numba'):
        run_kernels(load_scene("strip", ["kernels=compiled"]), mesh)


def test_a_model_holds_its_kernels_and_takes_the_self_contact_laws():
    mesh = trimesh.rectangle(1.0, 1.0, 5, 5, pattern="right")
    shell = material.isotropic_shell(E=1e6, nu=0.3, thickness=0.01, weight=1.0)
    assert Model(mesh, shell).kernels == "numpy"  # 32 elements: numpy is cheaper than loading numba
    assert Model(mesh, shell, kernels="numpy").kernels == "numpy"
    law = SelfContact(mesh, 0.05, 1.0, kernels="numpy")
    assert law.kernels == "numpy" and not law.compiled and law.new_pairs().compiled is False
    assert Model(mesh, shell, self_contact=law).kernels == "numpy"
    if compiled.numba_available():
        with pytest.raises(ValueError, match="differ from the self-contact law's"):
            Model(mesh, shell, self_contact=law, kernels="compiled")


def test_the_two_back_ends_of_a_model_agree_to_round_off():
    pytest.importorskip("numba")
    mesh = trimesh.rectangle(1.0, 0.5, 9, 5)
    shell = material.isotropic_shell(E=1e6, nu=0.3, thickness=0.01, weight=1.0)
    a, b = Model(mesh, shell, kernels="numpy"), Model(mesh, shell, kernels="compiled")
    U = 1e-2 * np.random.default_rng(3).standard_normal((mesh.n_nodes, 3))
    assert b.energies(U)["membrane"] == pytest.approx(a.energies(U)["membrane"], rel=1e-12)
    fa, Ka = a.tangent(U)
    fb, Kb = b.tangent(U)
    np.testing.assert_allclose(fb, fa, rtol=1e-10, atol=1e-12 * np.abs(fa).max())
    assert abs(Kb - Ka).max() <= 1e-10 * abs(Ka).max()
