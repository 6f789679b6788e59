"""A dynamic or relax run from an equilibrium with bending or shear hysteresis goes on from that equilibrium's
committed slips (rftstatic.app.dynamic._run ``slip=``, the static run's RunResult.slip), so its out-of-balance force
(the at-rest test's) is weighed at them, not at the virgin fabric's; the garment-motion analysis passes its drape's."""

from types import SimpleNamespace

import numpy as np
import pytest

from rftstatic.app import dynamic, garment, garment_motion, static
from rftstatic.app.result import RunResult
from rftstatic.scenes import build
from rftstatic.scenes.build import build_model
from rftstatic.scenes.schema import load_scene

# the lab fabric of tests/app/test_remesh_slip.py with bending hysteresis, or with both frictions (the strip bends
# without shear: its shear friction alone never slips)
LAB = "kes_B_warp=0.083, kes_B_weft=0.063, kes_W=19.0, kes_T=0.5"
BENDING = f"material={{{LAB}, kes_2HB_warp=0.05, kes_2HB_weft=0.04}}"
BOTH = f"material={{{LAB}, kes_2HB_warp=0.05, kes_2HB_weft=0.04, kes_2HG=1.0}}"
STRIP = ["mesh.nodes=[11,3]"]  # the clamped 5 x 1 cm strip, 33 nodes
RELAX = ["analysis=relax", "dynamics.t_end=0.5", "dynamics.mass_scale=100", "dynamics.alpha=5.0"]


@pytest.mark.parametrize("material", [BENDING, BOTH], ids=["2HB", "2HB+2HG"])
def test_a_relaxation_from_a_drape_with_its_slips_starts_at_rest_and_stays(tmp_path, material):
    """The strip's static drape (tip 4.2 cm down; 35 % of the warp patches yielded) relaxed for 0.5 s from its
    committed slips: out of balance by 1.8e-11 of the weight at t = 0 (8.0e-10 with both frictions: the static
    solve's tolerance), it does not move (1.4e-16 m; 1.3e-13 m) and the frictions spend nothing (8e-20 J; 8e-18 J).
    From the virgin fabric (before: ``_run`` had no ``slip``, the garment-motion stage started so) the same start is
    out of balance by 3.0e-3 of the weight (9.3e-2 with both) and moves (9.6e-8 m; 2.9e-6 m)."""
    drape = static.run(load_scene("strip", STRIP + [material]), tmp_path / "static", progress=False, figures=False)
    assert drape.converged and drape.slip is not None and np.abs(drape.slip).max() > 0
    scene = load_scene("strip", STRIP + [material] + RELAX)
    runs = {}
    for name, slip in (("committed", drape.slip), ("virgin", None)):
        model, extras = build_model(scene)
        runs[name] = dynamic._run(scene, model, extras, tmp_path / name, progress=False, figures=False, U0=drape.U,
                                  slip=slip)[1]
    weight = np.linalg.norm(np.where(model.free, model.load, 0.0))
    kept, virgin = runs["committed"], runs["virgin"]
    assert kept.history["residual"][0] < 1e-8 * weight
    assert np.abs(kept.U - drape.U).max() < 1e-12 and kept.state.dissipated < 1e-15  # m, J
    assert virgin.history["residual"][0] > 1e-4 * weight and np.abs(virgin.U - drape.U).max() > 1e-9


def test_a_slip_of_another_shape_is_refused(tmp_path):
    scene = load_scene("strip", STRIP + [BENDING] + RELAX)
    model, extras = build_model(scene)
    with pytest.raises(ValueError, match="slip must have the shape"):
        dynamic._run(scene, model, extras, tmp_path, progress=False, figures=False, slip=np.zeros((3, 2)))


def test_the_garment_motion_stage_goes_on_from_the_drapes_slips(tmp_path, monkeypatch):
    """The moving stage of skirt-turn starts from the drape's U and committed slips (the drape and the stage's
    model stand-ins: only what is handed on is checked)."""
    drape = RunResult({"garment": {"contact_smoothing": 0.5}}, SimpleNamespace(mesh=None), np.zeros((4, 3)),
                      slip=np.full((2, 2), 0.25))
    handed = {}

    class Handed(Exception):
        pass

    def stage_run(scene, model, extras, out, **kw):
        handed.update(kw)
        raise Handed

    monkeypatch.setattr(garment, "run", lambda *a, **kw: drape)
    monkeypatch.setattr(build, "build_model", lambda *a, **kw: (None, {}))
    monkeypatch.setattr(dynamic, "_run", stage_run)
    with pytest.raises(Handed):
        garment_motion.run(load_scene("skirt-turn"), tmp_path, progress=False, figures=False)
    assert handed["U0"] is drape.U and handed["slip"] is drape.slip
