"""Static checkpoints at the solver level: a model with a potential load (an end moment rolling a strip
past half a turn) resumes on the branch of its lever angles."""

import numpy as np
import pytest

from rftstatic import material
from rftstatic.mesh import trimesh
from rftstatic.model import model as model_mod
from rftstatic.model.loads import LeverMoment
from rftstatic.references import END_MOMENT
from rftstatic.solvers.options import StaticOptions
from rftstatic.solvers.drive import drive
from rftstatic.solvers.newton import start_state
from rftstatic.solvers.static import solve_static, static_route
from rftstatic.solvers.static_checkpoint import load_static_state, static_saver


def _rolled_strip(nx=9):
    c = END_MOMENT
    d = c.L / (nx - 1)
    m = trimesh.rectangle(c.L + d, c.b, nx + 1, 2, origin=(0.0, -c.b / 2))
    grid = np.arange(m.n_nodes).reshape(2, nx + 1)
    sup = model_mod.Supports(grid[:, 0].astype(np.int64), np.zeros(0, np.int64), np.zeros((m.n_nodes, 3), bool))
    sup.fixed[:, 1] = True
    shell = material.isotropic_shell(E=c.E, nu=c.nu, thickness=c.h)
    term = LeverMoment(grid[:, nx - 1], grid[:, nx], c.load_max * np.array([0.5, 0.5]))
    return model_mod.Model(m, shell, element="RFT3", supports=sup, load_terms=[term], quiet=True)


def test_a_resumed_roll_up_keeps_the_branch_of_its_lever_angles(tmp_path):
    opts = StaticOptions.from_keys(progress=False, initial_increment=0.1, max_increment=0.1, intermediate_rtol=1e-6)
    full = solve_static(_rolled_strip(), options=opts)
    assert full.converged and len(full.load_steps) >= 5
    path = tmp_path / "checkpoint.npz"
    model = _rolled_strip()

    def stop(lam, U):
        if lam > 0.75:  # the end has turned past pi: angles only a committed branch tells apart
            raise KeyboardInterrupt

    saver = static_saver(path, model, opts, every_seconds=0.0)
    state = start_state(model)
    with pytest.raises(KeyboardInterrupt), saver.on_interrupt():
        drive(static_route(model, state, opts, callback=stop), saver.on(state))
    again = _rolled_strip()
    saved = load_static_state(path, again, opts)
    assert 0.5 < saved.route["load-steps"].lam <= 0.75 and saved.load_branches[0][0] > np.pi
    res = drive(static_route(again, saved, opts))
    assert res.converged and [s["lam"] for s in res.load_steps] == [s["lam"] for s in full.load_steps]
    assert np.abs(res.U - full.U).max() <= 1e-9 * np.abs(full.U).max()
    # the moment's potential -M phi counts the turns: on another branch it would be off by 2 pi M
    assert res.energies == pytest.approx(full.energies, rel=1e-9, abs=1e-9)
