"""The release route (a support lowered under the sheet at full weight) and the obstacle pose it moves."""

import json

import numpy as np
import pytest

from rftstatic import api
from rftstatic.contact.obstacles import Floor, Sphere
from rftstatic.contact.penalty import PenaltyContact
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import static_options
from rftstatic.solvers.checkpoint import restore_state, state_arrays, read_checkpoint
from rftstatic.solvers.drive import drive, finish
from rftstatic.solvers.newton import start_state
from rftstatic.solvers.release import RELEASE, release, support_lift
from rftstatic.solvers.static import static_route

COARSE = ["solver.start=release", "mesh.nodes=[5,48]", "solver.release_step=0.5"]
"""cusick-30 on a coarse polar mesh (5 rings x 48): 8 folds, DC 62.7 % in 6 s of route."""


def test_a_translated_obstacle_is_the_obstacle_built_there():
    """Energy, force and tangent with an offset on the candidate list equal those of the obstacle built at the
    translated pose (a floor and a sphere, moved in z and sideways); a changed pose remakes the list."""
    rng = np.random.default_rng(3)
    x = rng.uniform(-0.05, 0.05, (40, 3))
    area = rng.uniform(0.5, 1.5, 40) * 1e-5
    moved = PenaltyContact([Floor(-0.01), Sphere([0.0, 0.0, -0.06], 0.05)], area, 1e6, smoothing=1e-3)
    shift = np.array([[0.0, 0.0, 0.02], [0.01, -0.02, 0.03]])
    built = PenaltyContact([Floor(0.01), Sphere([0.01, -0.02, -0.03], 0.05)], area, 1e6, smoothing=1e-3)
    cands = moved.new_candidates()
    cands.offsets = shift
    a, b = moved.evaluate(x, candidates=cands), built.evaluate(x)
    assert a.energy > 0 and a.energy == pytest.approx(b.energy, rel=1e-12)
    np.testing.assert_allclose(a.force, b.force, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(a.tangent_blocks, b.tangent_blocks, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(moved.force(x, candidates=cands), b.force, rtol=1e-12, atol=1e-18)
    assert len(cands) > 0
    cands.offsets = np.zeros((2, 3))  # back at rest: the list made at the moved pose is dropped
    assert cands.offsets is None and len(cands) == 0
    assert moved.evaluate(x, candidates=cands).energy == pytest.approx(moved.evaluate(x).energy, rel=1e-12)
    with pytest.raises(ValueError, match="one .x, y, z. translation per obstacle"):
        cands.offsets = np.ones((3, 3))
        moved.evaluate(x, candidates=cands)


def test_only_a_release_scene_has_the_support_and_it_rests_clear_of_the_sheet():
    model, extras = build_model(api.load_scene("cusick-30", COARSE))
    assert extras["obstacles"] == [] and len(model.contact.obstacles) == 1
    diagonal = float(np.linalg.norm(np.ptp(model.X3, axis=0)))
    assert support_lift(model) == pytest.approx(1.1 * diagonal)
    plain, _ = build_model(api.load_scene("cusick-30", ["mesh.nodes=[5,48]"]))
    assert plain.contact is None


@pytest.fixture(scope="module")
def coarse():
    scene = api.load_scene("cusick-30", COARSE)
    model, extras = build_model(scene)
    opts = static_options(scene, progress=False)
    state = start_state(model, opts.newton.linear_solver)
    saved = []  # a checkpoint of the State at every pause
    result = drive(static_route(model, state, opts), lambda p: saved.append(state_arrays(state, {})))
    return scene, model, extras, opts, result, saved


def test_the_release_converges_to_a_stable_drape_clear_of_its_support(coarse):
    scene, model, extras, opts, result, _ = coarse
    assert result.converged and result.stable and result.route == "release"
    heights = [s["support_height"] for s in result.load_steps]
    assert heights[-1] == 0.0 and all(np.diff(heights) < 0)  # lowered step by step to its rest
    assert result.energies["contact"] == 0.0  # it carries nothing at the end
    assert model.contact.max_penetration(model.positions(result.U)) == 0.0
    x = model.positions(result.U)
    assert x[:, 2].min() < -0.04  # the 6 cm overhang hangs: the hem more than 4 cm below the disc
    r = model.residual(result.U, 1.0)[model.free]
    assert np.linalg.norm(r) <= opts.newton.rtol * np.linalg.norm(model.load[model.free]) * 1.01


def test_a_release_resumed_from_a_mid_route_checkpoint_is_bit_identical(coarse, tmp_path):
    scene, model, extras, opts, result, saved = coarse
    assert len(saved) >= 4
    path = tmp_path / "checkpoint.npz"
    np.savez(path, **saved[2])  # after the third step: the support part-way down
    _, fields = read_checkpoint(path)
    fresh, _ = build_model(scene)
    state = restore_state(fresh, fields, start_state(fresh, opts.newton.linear_solver))
    assert 0 < state.route[RELEASE].height < support_lift(fresh) and state.obstacle_offsets is not None
    again = finish(static_route(fresh, state, opts))
    assert again.converged and np.array_equal(again.U, result.U)
    assert [s["support_height"] for s in again.load_steps] == [s["support_height"] for s in result.load_steps]


def test_the_release_without_a_support_says_what_is_missing():
    scene = api.load_scene("cusick-30", ["mesh.nodes=[5,48]"])
    model, _ = build_model(scene)
    opts = static_options(scene, progress=False).replace(start="release")
    with pytest.raises(ValueError, match="needs a support to lower"):
        finish(release(model, start_state(model), opts))


@pytest.mark.slow
def test_seeded_releases_give_a_distribution_in_the_summary(tmp_path):
    res = api.run("cusick-30", tmp_path / "run", overrides=COARSE + ["solver.seeds=3", "solver.perturbation=0.1"],
                  figures=False)
    seeds = json.loads((tmp_path / "run" / "summary.json").read_text())["seeds"]
    assert seeds["count"] == 3 and seeds["solved"] == 3 and len(seeds["fold_counts"]) == 3
    assert 0 < seeds["drape_coefficient_percent_mean"] < 100 and seeds["fold_count_mean"] >= 2
    assert seeds["lowest_energy"]["energy"] == min(r["energy"] for r in seeds["specimens"]) < 0
    assert res.summary["seeds"] == seeds


@pytest.mark.slow
def test_an_interrupted_release_run_resumes_to_the_same_drape(coarse, tmp_path):
    """The app's run: interrupted after the fourth step (its checkpoint saved there), ``--resume`` ends on the
    uninterrupted route's drape, bit for bit."""
    from rftstatic.app import static as app

    scene, model, extras, opts, result, _ = coarse
    steps = []

    def stop(lam, U):
        steps.append(U)
        if len(steps) == 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        app.run(scene, tmp_path, progress=False, figures=False, callback=stop, checkpoint_seconds=0.0)
    res = app.run(scene, tmp_path, progress=False, figures=False, resume=True)
    assert res.summary["checkpoint"]["resumed_from"]["phase"] == "release"
    assert np.array_equal(res.U, result.U) and res.summary["route"] == "release"
