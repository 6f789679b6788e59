"""Adaptive remeshing carries the frictions' committed slips (bending hysteresis 2HB, shear hysteresis 2HG) to every
new mesh (rftstatic.remesh.adapt.carry_slip: each new element takes the slip of the old element holding its
centroid), the steps on the new mesh go on from them, and a checkpoint keeps them for a resume."""

from pathlib import Path

import numpy as np
import pytest

from rftstatic.app import remeshed
from rftstatic.app.remeshed import solve_remesh_scene, summarize
from rftstatic.remesh import relax_driver, static_driver
from rftstatic.scenes.build import build_model
from rftstatic.scenes.options import remesh_options
from rftstatic.scenes.schema import load_scene
from tests.app.test_remesh_resume import _interrupt_call

# the lab fabric of tests/app/test_levels.py with bending hysteresis, or with shear hysteresis
LAB = "kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5"
BENDING = [f"material={{{LAB}, kes_2HB_warp=0.05, kes_2HB_weft=0.04}}"]
SHEAR = [f"material={{{LAB}, kes_2HG=1.0}}"]
# the 20 x 20 cm sheet on the pedestal, remeshed relaxation (tests/app/test_remesh_resume.py): chunks of 200 steps,
# a remesh after each, to t_end = 3 s
RELAX = ["mesh.h=4.0", "remesh.const=2.0", "remesh.h_lower=2.5", "remesh.h_upper=5.0", "remesh.every=200",
         "remesh.kappa_h2_max=6.0", "dynamics.t_end=3.0"]
# the clamped strip, static route: 105 nodes, then 64 and 73 (0.7 s)
STRIP = ["mesh.kind=unstructured", "mesh.h=0.25", "remesh.const=0.04", "remesh.h_lower=0.1", "remesh.h_upper=0.4",
         "remesh.max_cycles=4"]


def _check_owners(old_mesh, slip, new_mesh, carried):
    """Each new element's slip is that of an old element holding its centroid (barycentric coordinates computed
    here, all old elements against all new centroids: the meshes are small)."""
    c = new_mesh.X[new_mesh.tri].mean(axis=1)  # (E_new, 2)
    P = old_mesh.X[old_mesh.tri]  # (E_old, 3, 2)
    d1, d2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    r = c[:, None, :] - P[None, :, 0]
    l1 = (r[..., 0] * d2[:, 1] - r[..., 1] * d2[:, 0]) / det
    l2 = (d1[:, 0] * r[..., 1] - d1[:, 1] * r[..., 0]) / det
    holds = np.minimum(np.minimum(1.0 - l1 - l2, l1), l2) >= -1e-9  # (E_new, E_old)
    assert holds.any(axis=1).all()  # the sheet's outline is straight: every new centroid lies in the old mesh
    same = (carried[:, None, :] == slip[None, :, :]).all(axis=2)
    assert (holds & same).any(axis=1).all()


def _spy_carry(monkeypatch, module):
    """Record every ``carry_slip(old, slip, new)`` of ``module`` as ``(old, slip, new, out)``."""
    carried, real = [], module.carry_slip

    def spy(old, slip, new):
        out = real(old, slip, new)
        carried.append((old, None if slip is None else slip.copy(), new, out))
        return out

    monkeypatch.setattr(module, "carry_slip", spy)
    return carried


@pytest.mark.parametrize("material,columns", [(BENDING, 2), (SHEAR, 1)], ids=["2HB", "2HG"])
def test_a_remeshed_relaxation_carries_the_slips_to_every_new_mesh(monkeypatch, material, columns):
    """Every chunk of explicit steps goes on from the slips the last one committed; at a remesh they go to the new
    elements by the owner element (non-zero, as they were), and the first chunk there starts from them."""
    chunks = []

    class Spy(relax_driver.ExplicitStepper):
        def __call__(self, model, U, V, n, **kw):
            out = super().__call__(model, U, V, n, **kw)
            chunks.append((model, kw.get("slip"), out[3].copy(), out[4]))
            return out

    monkeypatch.setattr(remeshed, "explicit_advance", lambda **kw: Spy(**kw))
    carried = _spy_carry(monkeypatch, relax_driver)
    scene = load_scene("remesh-pedestal-square-20", RELAX + material)
    solved = solve_remesh_scene(scene)
    assert len(carried) == len(solved["records"]) - 1 >= 2
    for k, (model, start, end, _) in enumerate(chunks):
        assert start.shape == (model.mesh.n_elements, columns)
        if k and chunks[k - 1][0] is model:  # the same mesh: the slips the last chunk committed
            np.testing.assert_array_equal(start, chunks[k - 1][2])
    stepped = 0  # remeshes followed by steps (the last may end the run at t_end)
    for old, slip, new, out in carried:
        before, after = [c for c in chunks if c[0] is old][-1], [c for c in chunks if c[0] is new][:1]
        np.testing.assert_array_equal(slip, before[2])  # the slips committed on the old mesh
        assert np.abs(out).max() > 0 and out.shape == (new.mesh.n_elements, columns)
        _check_owners(old.mesh, slip, new.mesh, out)
        for c in after:
            np.testing.assert_array_equal(c[1], out)  # the steps on the new mesh start from them
            stepped += 1
    assert stepped >= 2
    assert np.abs(solved["slip"]).max() > 0
    assert solved["dissipated"] == pytest.approx(sum(c[3] for c in chunks), rel=1e-12) and solved["dissipated"] > 0
    summary = summarize(scene, remesh_options(scene), solved)
    key = "bending_hysteresis" if columns == 2 else "shear_hysteresis"
    spent = summary[key]["dissipated" if columns == 2 else "dissipated_both_frictions"]
    assert spent == pytest.approx(scene.units.from_si(solved["dissipated"], "energy"), rel=1e-12)


@pytest.mark.parametrize("material,slip", [(BENDING, [5.0, -5.0]), (SHEAR, [0.01])], ids=["2HB", "2HG"])
def test_the_stepper_steps_from_the_slips_it_is_given(material, slip):
    """The remeshed relaxation's stepper goes on from the committed slips it is given (a friction that slipped pulls
    the flat sheet at rest away from where a virgin fabric's steps take it); virgin slips give the steps without."""
    model = build_model(load_scene("remesh-pedestal-square-20", RELAX + material))[0]
    stepper = relax_driver.ExplicitStepper(alpha=1.0, mass_scale=100.0)
    Z = np.zeros((model.mesh.n_nodes, 3))
    U0, _, t0 = stepper(model, Z, Z, 5)
    virgin = stepper(model, Z, Z, 5, slip=model.initial_slip())
    np.testing.assert_array_equal(virgin[0], U0)
    assert virgin[2] == t0 and virgin[4] >= 0.0
    given = np.tile(slip, (model.mesh.n_elements, 1))
    U1, _, _, slip1, _ = stepper(model, Z, Z, 5, slip=given)
    assert slip1.shape == given.shape and np.abs(U1 - U0).max() > 1e-3 * np.abs(U0).max()


def test_a_static_remesh_run_carries_the_slips_to_every_new_mesh(monkeypatch):
    """Each cycle's Newton starts from the slips of the last cycle's equilibrium, carried by the owner element; the
    dissipation adds up over the cycles."""
    solves, real = [], static_driver._solve

    def spy(model, options, *, U0=None, history=(None, 0.0)):
        result, out = real(model, options, U0=U0, history=history)
        solves.append((model, history, out))
        return result, out

    monkeypatch.setattr(static_driver, "_solve", spy)
    carried = _spy_carry(monkeypatch, static_driver)
    solved = solve_remesh_scene(load_scene("strip", STRIP + BENDING))
    assert solved["converged"] and len(solves) == len(solved["records"]) >= 2 and len(carried) == len(solves) - 1
    assert not any(r.solve["restarted"] for r in solved["records"])
    for k, (old, slip, new, out) in enumerate(carried):
        (m0, _, (end, spent)), (m1, (start, spent_before), _) = solves[k], solves[k + 1]
        assert m0 is old and m1 is new
        np.testing.assert_array_equal(slip, end)
        assert np.abs(out).max() > 0 and out.shape == (new.mesh.n_elements, 2)
        _check_owners(old.mesh, slip, new.mesh, out)
        np.testing.assert_array_equal(start, out)  # the next Newton goes on from them ...
        assert spent_before == spent  # ... and from the dissipation so far
    assert solved["dissipated"] == solves[-1][2][1] > solves[0][2][1] > 0
    np.testing.assert_array_equal(solved["slip"], solves[-1][2][0])


@pytest.mark.parametrize("name,overrides,owner,call", [
    ("remesh-pedestal-square-20", RELAX, relax_driver.ExplicitStepper, 4),  # after the 2nd remesh
    ("strip", STRIP, static_driver, 2),  # in the solve of cycle 1
], ids=["relax", "static"])
def test_a_resumed_run_takes_the_slips_up_from_its_checkpoint(tmp_path, monkeypatch, name, overrides, owner, call):
    """A run with bending hysteresis interrupted after a remesh ends, resumed from its checkpoint, with the
    uninterrupted run's dissipation and yielded shares (a checkpoint without the slips would start the friction
    virgin again: less dissipated)."""
    scene = load_scene(name, overrides + BENDING)

    def run(out, **kw):
        return remeshed.run(scene, Path(out), progress=False, figures=False, checkpoint_seconds=1e9, **kw).summary

    full = run(tmp_path / "full")
    _interrupt_call(monkeypatch, owner, "__call__" if owner is relax_driver.ExplicitStepper else "_solve", call)
    with pytest.raises(KeyboardInterrupt):
        run(tmp_path / "cut")
    monkeypatch.undo()
    resumed = run(tmp_path / "cut", resume=True)
    assert resumed["checkpoint"]["resumed_from"] is not None
    assert resumed["nodes"] == full["nodes"] and resumed["bending_hysteresis"]["dissipated"] > 0
    for key, value in full["bending_hysteresis"].items():
        assert resumed["bending_hysteresis"][key] == pytest.approx(value, rel=1e-12), key


def test_a_remeshed_relaxation_with_hysteresis_comes_to_rest():
    """The rest test weighs the out-of-balance force at the committed slips: the coarse sheet with bending hysteresis
    comes to rest on a settled mesh (measured at t = 21 s of 30; at the virgin fabric's residual it never did)."""
    s = solve_remesh_scene(load_scene("remesh-pedestal-square-20", RELAX[:-1] + ["dynamics.t_end=30.0"] + BENDING))
    assert s["converged"] and s["stopped_by"] == "rest" and s["t"] < 25.0


def test_a_restart_without_saved_slips_starts_the_friction_virgin():
    """A remeshed relaxation's checkpoint without slips (written before they were kept) goes on with the virgin
    fabric's, carried from then on, not without friction history at all; a saved one is taken as it is."""
    from rftstatic.model.state import State

    model = build_model(load_scene("remesh-pedestal-square-20", RELAX + BENDING))[0]
    old = State(U=np.zeros((model.mesh.n_nodes, 3)), V=np.zeros((model.mesh.n_nodes, 3)), dissipated=2e-6)
    slip, spent = relax_driver._friction_history(model, old, restart=object())
    np.testing.assert_array_equal(slip, model.initial_slip())
    assert spent == 2e-6
    old.slip = np.ones_like(slip)
    assert relax_driver._friction_history(model, old, restart=object())[0] is old.slip
    fresh = relax_driver._friction_history(model, old, restart=None)
    assert not fresh[0].any() and fresh[1] == 0.0
