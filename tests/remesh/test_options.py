"""The remeshing drivers' options (rftstatic.remesh.options): defaults once, bad values named."""

import dataclasses

import pytest

from rftstatic.errors import ParameterError
from rftstatic.mesh import GRADATION
from rftstatic.remesh.options import RemeshOptions, RemeshRelaxOptions
from rftstatic.solvers.relaxation import RELAX_REST

SIZING = {"const": 1e-3, "h_lower": 1e-3, "h_upper": 4e-3}


def test_defaults():
    o = RemeshOptions(**SIZING)
    assert (o.gradation, o.transfer, o.damping, o.every, o.kappa_h2_max) == (GRADATION, "mesh", "fixed", None, None)
    m = RemeshRelaxOptions()
    assert m.rest == RELAX_REST and m.alpha is None and m.chunk == 200
    assert len(dataclasses.fields(RemeshOptions)) <= 15 and len(dataclasses.fields(RemeshRelaxOptions)) <= 15


@pytest.mark.parametrize("kw, key", [
    ({"const": 0.0}, "const"), ({"h_lower": 5e-3}, "h_lower"), ({"gradation": 0.9}, "gradation"),
    ({"tol": -0.1}, "tol"), ({"transfer": "spline"}, "transfer"), ({"damping": "adaptive"}, "damping"),
    ({"every": 0}, "every"), ({"max_cycles": -1}, "max_cycles"), ({"kappa_h2_max": -1.0}, "kappa_h2_max"),
    ({"kappa_h_max": float("inf")}, "kappa_h_max"),
])
def test_remesh_options_name_a_bad_value(kw, key):
    with pytest.raises(ParameterError) as err:
        RemeshOptions(**{**SIZING, **kw})
    assert err.value.key == f"remesh.{key}"


@pytest.mark.parametrize("kw, key", [({"alpha": -1.0}, "alpha"), ({"mass_scale": 0.0}, "mass_scale"),
                                     ({"chunk": 0}, "chunk"), ({"max_steps": 1.5}, "max_steps"),
                                     ({"max_remesh": -1}, "max_remesh"), ({"rest": 1e-8}, "rest")])
def test_remesh_relax_options_name_a_bad_value(kw, key):
    with pytest.raises(ParameterError) as err:
        RemeshRelaxOptions(**kw)
    assert err.value.key == key


def test_a_scene_remesh_value_is_named_with_its_scene_key():
    from rftstatic.errors import SceneError
    from rftstatic.scenes.options import remesh_options
    from rftstatic.scenes.schema import scene_from_dict

    scene = scene_from_dict({"units": "SI", "mesh": {"size": [0.05, 0.01], "nodes": [11, 3]},
                             "remesh": {"const": 1e-3, "h_lower": 2.0, "h_upper": 1.0}}, name="bad-remesh")
    with pytest.raises(SceneError, match=r"remesh.h_lower: h_lower = 2.0 exceeds h_upper = 1.0"):
        remesh_options(scene)
