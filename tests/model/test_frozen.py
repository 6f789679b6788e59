"""A built Model, its self-contact law and its potential loads are read-only; a solve's changes live in
its State."""

import numpy as np
import pytest

from rftstatic import material
from rftstatic.contact.self_contact.law import SelfContact
from rftstatic.mesh import trimesh
from rftstatic.model.frozen import FrozenError
from rftstatic.model.loads import LeverMoment
from rftstatic.model.model import Model
from rftstatic.model.state import State


def _model(**kw):
    mesh = trimesh.rectangle(1.0, 1.0, 5, 5, pattern="right")
    shell = material.isotropic_shell(E=1e6, nu=0.3, thickness=0.01, weight=1.0)
    return Model(mesh, shell, element="RFT3", **kw)


def test_assigning_to_a_built_model_raises():
    model = _model(self_contact=SelfContact(trimesh.rectangle(1.0, 1.0, 5, 5, pattern="right"), 0.05, 2.0))
    for name, value in (("material", None), ("element", "RFT6"), ("new_attribute", 1.0)):
        with pytest.raises(FrozenError, match=f"Model is read-only once built: cannot set '{name}'"):
            setattr(model, name, value)
    with pytest.raises(FrozenError):
        del model.load
    with pytest.raises(FrozenError, match="SelfContact is read-only once built: cannot set 'stiffness'"):
        model.self_contact.stiffness *= 8.0
    assert model.self_contact.stiffness == 2.0
    with pytest.raises(ValueError, match="read-only"):  # the constant arrays too
        model.load[0, 2] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        model.free[0] = False
    assert model.plan is model.plan  # built on first use, then constant


def test_the_penalty_contact_law_is_read_only():
    from rftstatic.contact.obstacles import Floor
    from rftstatic.contact.penalty import PenaltyContact

    law = PenaltyContact([Floor(0.0)], np.ones(4), 1e3)
    with pytest.raises(FrozenError, match="PenaltyContact is read-only once built: cannot set 'stiffness'"):
        law.stiffness = 2e3


def test_a_lever_moment_is_read_only_and_its_branch_is_handed_in():
    term = LeverMoment([0], [1], [2.0])
    with pytest.raises(FrozenError):
        term.moments = np.array([3.0])
    x = np.zeros((2, 3))
    x[1] = [-1.0, 0.0, -1e-3]  # the lever just past -pi
    principal = term.angles(x)
    assert principal[0] == pytest.approx(-np.pi + 1e-3)
    branch = np.array([np.pi - 0.1])  # committed on the upper side: the angle continues past pi
    assert term.branch(x, branch)[0] == pytest.approx(np.pi + 1e-3)
    assert term.potential(x, branch) == pytest.approx(-2.0 * (np.pi + 1e-3))
    assert term.potential(x) == pytest.approx(-2.0 * principal[0])


def test_the_self_contact_scale_is_the_states_and_scales_energy_force_and_tangent():
    mesh = trimesh.rectangle(1.0, 1.0, 5, 5, pattern="right")
    sc = SelfContact(mesh, 0.05, 2.0)
    model, bare = _model(self_contact=sc), _model()
    X = mesh.X3
    U = np.zeros_like(X)
    right = X[:, 0] > 0.6  # the right columns folded over the left ones, 0.02 m above them
    U[right, 0] = 1.0 - 2.0 * X[right, 0]
    U[right, 2] = 0.02
    one, scaled = State.initial(model), State.initial(model)
    assert one.self_contact_scale == 1.0
    scaled.self_contact_scale = 8.0
    e1 = model.energies(U, pairs=one.self_pairs)["self_contact"]
    e8 = model.energies(U, pairs=scaled.self_pairs)["self_contact"]
    assert e1 > 0 and e8 == pytest.approx(8.0 * e1, rel=1e-12)
    assert model.energies(U)["self_contact"] == pytest.approx(e1, rel=1e-12)  # no cache: the law as built
    f0 = bare.internal_force(U)
    f1 = model.internal_force(U, pairs=one.self_pairs) - f0
    f8 = model.internal_force(U, pairs=scaled.self_pairs) - f0
    assert np.abs(f1).max() > 0
    np.testing.assert_allclose(f8, 8.0 * f1, rtol=1e-10, atol=1e-12 * np.abs(f1).max())
    K0 = bare.tangent(U)[1]
    K1 = model.tangent(U, pairs=one.self_pairs)[1] - K0
    K8 = model.tangent(U, pairs=scaled.self_pairs)[1] - K0
    assert abs(K1).max() > 0 and abs(K8 - 8.0 * K1).max() <= 1e-10 * abs(K8).max()
    assert sc.stiffness == 2.0  # the law itself is unchanged
    with pytest.raises(ValueError, match="no self-contact"):
        State.initial(bare).self_contact_scale = 2.0
