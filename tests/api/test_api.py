"""The Python API (rftstatic.api) that the command line uses: load, build, run, result."""

import json

import numpy as np
import pytest

from rftstatic import api


def test_run_a_scene_returns_its_state_and_summary(tmp_path):
    scene = api.load_scene("pedestal-square-20", ["mesh.nodes=[9,9]"])
    assert api.analysis_of(scene) == "static"
    model, extras = api.build_model(scene)
    assert model.contact is not None and len(extras["obstacles"]) == 1  # static: penalty contact
    result = api.run(scene, tmp_path / "ps", figures=False)
    assert result.converged and result.U.shape == (model.mesh.n_nodes, 3)
    written = json.loads((tmp_path / "ps" / "summary.json").read_text())
    assert written == result.summary
    s = result.summary
    # what ran, recorded with the result: the resolved scene, the code, the memory it took
    assert s["resolved_scene"]["mesh"]["nodes"] == [9, 9] and s["overrides"] == {"mesh.nodes": [9, 9]}
    assert set(s["software"]) >= {"rftstatic", "git_commit", "code", "python"} and len(s["software"]["code"]) == 12
    assert s["peak_memory_mb"] > 10
    # the state is an equilibrium of the model (independent of the solver's own convergence test)
    r = np.where(result.model.free, result.model.residual(result.U), 0.0)
    assert np.linalg.norm(r) < 1e-5 * np.linalg.norm(result.model.load)


def test_dynamic_scenes_use_kinematic_contact_and_the_registry(tmp_path):
    scene = api.load_scene("remesh-sphere-30", ["mesh.h=3.0"])
    assert api.analysis_of(scene) == "remeshed"
    model, extras = api.build_model(scene)
    assert model.contact is None and extras["obstacles"]  # relax: the obstacles act kinematically
    assert api.analysis_of(api.load_scene("hang-20")) == "dynamic"
    assert set(api.ANALYSES) == {"static", "dynamic", "relax", "remeshed", "cantilever", "garment", "garment-motion"}


def test_run_by_name_with_overrides_and_bad_input(tmp_path):
    result = api.run("strip", tmp_path / "s", overrides=["mesh.nodes=[11,3]"], figures=False)
    assert result.converged and result.summary["nodes"] == 33
    with pytest.raises(api.SceneError, match="mesh.kind"):
        api.run("strip", tmp_path / "t", overrides=["mesh.kind=hexagon"])
    with pytest.raises(ValueError, match="overrides"):
        api.run(api.load_scene("strip"), tmp_path / "u", overrides=["element=RFT3"])


def test_the_penalty_contact_is_a_contact_law():
    from rftstatic.contact.law import ContactLaw

    model, _ = api.build_model(api.load_scene("pedestal-square-20", ["mesh.nodes=[9,9]"]))
    assert isinstance(model.contact, ContactLaw)
