"""The Newton direction (:func:`rftstatic.solvers.iteration.direction`): its safeguards leave no garbage
behind."""

import gc
import types

import numpy as np
import pytest
import scipy.sparse as sp

from rftstatic.model.state import State
from rftstatic.solvers import linear
from rftstatic.solvers.iteration import direction
from rftstatic.solvers.options import NewtonOptions

pytestmark = pytest.mark.skipif(not linear.cholmod_available(), reason="scikit-sparse is not installed")


def _laplacian(n, shift):
    """1-D Laplacian plus ``shift`` times the identity (CSR): positive definite for shift > 0."""
    main = np.full(n, 2.0 + shift)
    return sp.diags([main, -np.ones(n - 1), -np.ones(n - 1)], [0, -1, 1], format="csr")


class _Model:
    """The part of a Model that ``direction`` uses: an indefinite exact tangent (eigenvalues in (-1, 3))
    and a positive definite projected one."""

    def __init__(self, n, exact_shift=-1.0):
        self.n, self.exact_shift = n, exact_shift

    def tangent(self, U, psd=False, **_):
        return None, _laplacian(self.n, 0.5 if psd else self.exact_shift)


def _state(n):
    """A solve's State (no contact) with a CHOLMOD solver."""
    state = State(U=np.zeros((n // 3, 3)), V=np.zeros((n // 3, 3)))
    state.solver = linear.CholmodSolver()
    return state


def test_failed_factorisations_leave_no_reference_cycle():
    """Each failed Cholesky raises an exception whose traceback holds the frame that caught it: kept in a
    local of that frame, it made a cycle with the frame's tangents (85 MB each at 201 x 201 nodes) that
    only the cyclic collector frees, rarely in a numpy loop: 22 GB resident after 30 minutes."""
    n = 600
    model, ws, r = _Model(n), _state(n), -np.ones(n)
    gc.collect()
    gc.disable()
    try:
        d, mode, _ = direction(model, np.zeros((n // 3, 3)), 1.0, r, NewtonOptions(), ws)
        assert mode == "psd" and ws.factorisations > 2  # the exact and modified tangents failed first
        gc.set_debug(gc.DEBUG_SAVEALL)
        gc.collect()
        leaked = [o for o in gc.garbage if sp.issparse(o) or isinstance(o, types.FrameType)]
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        gc.enable()
    assert leaked == []



def test_the_ladder_starts_where_it_last_succeeded():
    """On a stretch of indefinite tangents the failed rungs are not factorised again at every iteration: after
    a direction from the projected tangent the next one starts there (one factorisation), for at most
    FALLBACK_RUN directions in a row; then the whole ladder is tried again from the exact tangent. The direction
    itself does not change: the same tangent gives it."""
    from rftstatic.solvers.iteration import FALLBACK_RUN

    n = 300
    model, ws, r, U = _Model(n), _state(n), -np.ones(n), np.zeros((n // 3, 3))
    d0, mode, _ = direction(model, U, 1.0, r, NewtonOptions(), ws)
    full = ws.factorisations
    assert mode == "psd" and full > 2 and ws.fallback == {"mode": "psd", "rung": 0, "run": 1}
    for k in range(2, FALLBACK_RUN + 1):
        before = ws.factorisations
        d, mode, _ = direction(model, U, 1.0, r, NewtonOptions(), ws)
        assert mode == "psd" and ws.factorisations - before == 1 and ws.fallback["run"] == k
        np.testing.assert_allclose(d, d0, rtol=1e-12)
    before = ws.factorisations
    direction(model, U, 1.0, r, NewtonOptions(), ws)  # the run is over: the exact tangent is tried again
    assert ws.factorisations - before > 1 and ws.fallback["run"] == 1
    # a positive definite exact tangent ends the memory
    ws.fallback["run"] = FALLBACK_RUN
    d, mode, _ = direction(_Model(n, exact_shift=0.1), U, 1.0, r, NewtonOptions(), ws)
    assert mode == "exact" and ws.fallback is None


def test_the_shift_ladder_starts_one_rung_below_its_last_success():
    """A shifted projected tangent is remembered by its rung: the next try starts one rung lower (the smallest
    shift that may still work), not at the bottom of the ladder."""
    n = 300

    class Model(_Model):  # the projected tangent is indefinite too: eigenvalues in (-0.5, 3.5)
        def tangent(self, U, psd=False, **_):
            return None, _laplacian(self.n, -0.5 if psd else -1.0)

    ws, r, U = _state(n), -np.ones(n), np.zeros((n // 3, 3))
    direction(Model(n), U, 1.0, r, NewtonOptions(), ws)
    rung = ws.fallback["rung"]
    assert ws.fallback["mode"] == "shift" and rung >= 1
    before = ws.factorisations
    _, mode, shift = direction(Model(n), U, 1.0, r, NewtonOptions(), ws)
    assert mode == "shift" and ws.factorisations - before == 2 and ws.fallback["rung"] == rung  # rung-1 fails
