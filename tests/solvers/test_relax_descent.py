"""A failed Newton handover's lower-energy last iterate is where the relaxation goes on (rftstatic.solvers.relaxation.
newton_descent); a higher one, one short of full load or a non-finite one is not."""

from types import SimpleNamespace

import numpy as np

from rftstatic import api
from rftstatic.scenes.build import build_model
from rftstatic.solvers.newton import StaticResult, start_state
from rftstatic.solvers.relaxation import newton_descent


def test_the_relaxation_goes_on_from_a_lower_energy_newton_iterate_only():
    model, _ = build_model(api.load_scene("strip", ["mesh.nodes=[5,21]"]))
    state = start_state(model)
    n = model.mesh.n_nodes
    sag = np.zeros((n, 3))
    sag[:, 2] = -1e-5 * (model.mesh.X3[:, 0] - model.mesh.X3[:, 0].min()) / np.ptp(model.mesh.X3[:, 0])  # 10 um tip
    sag *= model.free  # the clamped end stays
    flat = np.zeros((n, 3))
    assert model.potential(sag, 1.0) < model.potential(flat, 1.0)  # the strip's weight pulls the tip down
    route = SimpleNamespace(U=flat.copy(), V=np.ones((n, 3)))
    assert newton_descent(model, state, route, StaticResult(U=sag, lam=1.0, converged=False))
    assert np.array_equal(route.U, sag) and not np.any(route.V)  # from the lower iterate, at rest
    for U, lam in ((flat, 1.0), (sag, 0.5), (np.full((n, 3), np.nan), 1.0)):
        kept = route.U.copy()
        assert not newton_descent(model, state, route, StaticResult(U=U, lam=lam, converged=False))
        assert np.array_equal(route.U, kept)
    assert not newton_descent(model, state, route, None)
