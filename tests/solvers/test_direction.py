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

