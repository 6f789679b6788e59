"""The one at-rest test (rftstatic.solvers.rest): each criterion on states that are and are not at rest."""

import numpy as np
import pytest

from rftstatic.errors import ParameterError
from rftstatic.solvers.rest import AtRest, RestCriterion


def test_kinetic_criterion_compares_the_kinetic_energy_with_its_peak():
    c = RestCriterion(1e-6)
    assert c.holds(0.9e-6, 1.0) and not c.holds(1.1e-6, 1.0)
    assert c.holds(5.0, 1e7) and not c.holds(5.0, 1e6)  # a ratio, not an absolute energy
    # the force is not asked: a large residual does not matter
    assert c.holds(1e-9, 1.0, residual=1e9, load_norm=1.0)
    assert c.holds(0.0, 0.0) and not c.holds(1e-30, 0.0)  # nothing moved yet: at rest only without motion
    assert c.record() == {"criterion": "kinetic", "tol_kinetic": 1e-6, "tol_force": None}


def test_force_criterion_needs_both_still_motion_and_balanced_force():
    c = RestCriterion(1e-8, tol_force=1e-4)
    still, moving = (1e-9, 1.0), (1e-7, 1.0)
    assert c.holds(*still, residual=0.9e-4 * 2.0, load_norm=2.0)
    assert not c.holds(*still, residual=1.1e-4 * 2.0, load_norm=2.0)  # still but out of balance
    assert not c.holds(*moving, residual=0.0, load_norm=2.0)  # balanced but moving
    # a loaded sheet that never moved and is in balance is at rest; one out of balance is not
    assert c.holds(0.0, 0.0, residual=1e-5, load_norm=1.0)
    assert not c.holds(0.0, 0.0, residual=1.0, load_norm=1.0)
    assert c.record() == {"criterion": "kinetic+force", "tol_kinetic": 1e-8, "tol_force": 1e-4}


def test_an_unloaded_sheet_measures_its_force_by_its_own_peak():
    c = RestCriterion(1e-8, tol_force=1e-4)
    assert c.holds(0.0, 0.0, residual=0.0, load_norm=0.0, peak_residual=0.0)  # flat and unloaded
    assert not c.holds(0.0, 0.0, residual=1.0, load_norm=0.0, peak_residual=1.0)  # a perturbed start
    assert c.holds(1e-9, 1.0, residual=0.9e-4, load_norm=0.0, peak_residual=1.0)
    assert not c.holds(1e-9, 1.0, residual=1.1e-4, load_norm=0.0, peak_residual=1.0)


def test_samples_are_tested_element_wise():
    c = RestCriterion(1e-3, tol_force=1e-2)
    got = c.holds(np.array([1.0, 1e-4, 1e-4]), np.array([1.0, 1.0, 1.0]), np.array([0.0, 0.0, 1.0]), 10.0)
    assert got.tolist() == [False, True, False]


def test_time_at_rest_is_the_first_sample_after_the_last_one_in_motion():
    h = {"time": np.arange(6.0), "kinetic": np.array([0.0, 1.0, 0.5, 1e-7, 2e-3, 1e-8]),
         "residual": np.array([5.0, 4.0, 3.0, 2.0, 1e-3, 1e-5])}
    assert RestCriterion(1e-6).time_at_rest(h) == 5.0  # sample 4 moves again (2e-3 of the peak)
    assert RestCriterion(1e-2).time_at_rest(h) == 3.0
    # with the force: sample 3 is still but 2.0 N out of balance against a 10 N load
    assert RestCriterion(1e-2, tol_force=1e-2).time_at_rest(h, load_norm=10.0) == 4.0
    assert RestCriterion(1e-2, tol_force=1e-7).time_at_rest(h, load_norm=10.0) is None  # never balanced
    flat = {"time": np.arange(3.0), "kinetic": np.zeros(3), "residual": np.zeros(3)}
    assert RestCriterion(1e-6).time_at_rest(flat) is None  # no motion to come to rest from


def test_at_rest_tracks_the_peaks_and_resumes_from_a_history():
    rest = AtRest(RestCriterion(1e-3, tol_force=1e-2), load_norm=1.0)
    assert not rest(None, {"kinetic": 2.0, "residual": 1.0})
    assert rest.peak_kinetic == 2.0
    assert rest(None, {"kinetic": 1e-3, "residual": 1e-3})  # 5e-4 of the peak, 1e-3 of the load
    resumed = AtRest(RestCriterion(1e-3, tol_force=1e-2), load_norm=1.0)
    resumed.resume_from({"kinetic": [0.5, 2.0], "residual": [1.0, 3.0]})
    assert (resumed.peak_kinetic, resumed.peak_residual) == (2.0, 3.0)


@pytest.mark.parametrize("kw, key", [({"tol_kinetic": 0.0}, "tol_kinetic"), ({"tol_kinetic": 1.0}, "tol_kinetic"),
                                     ({"tol_kinetic": 1e-6, "tol_force": -1.0}, "tol_force"),
                                     ({"tol_kinetic": "small"}, "tol_kinetic")])
def test_a_bad_tolerance_names_its_key(kw, key):
    with pytest.raises(ParameterError, match=key) as err:
        RestCriterion(**kw)
    assert err.value.key == key
