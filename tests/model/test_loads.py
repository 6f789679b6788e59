"""The conservative end moment: potential, force and load stiffness, and the roll-up."""

import numpy as np
import pytest

from rftstatic import material
from rftstatic.mesh import trimesh as mesh
from rftstatic.model import model
from rftstatic.model.loads import LeverMoment
from rftstatic.solvers import static


def _rolled_strip(nx=25, ny=3, element="RFT6"):
    L, b = 12.0, 1.0
    shell = material.isotropic_shell(E=1.2e6, nu=0.0, thickness=0.1)
    d = L / (nx - 1)
    m = mesh.rectangle(L + d, b, nx + 1, ny, origin=(0.0, -b / 2))
    grid = np.arange(m.n_nodes).reshape(ny, nx + 1)
    share = np.full(ny, 1.0)
    share[[0, -1]] = 0.5
    M = 2 * np.pi * shell.Db[0, 0] * b / L
    term = LeverMoment(grid[:, nx - 1], grid[:, nx], M * share / share.sum())
    fixed = np.zeros((m.n_nodes, 3), bool)
    fixed[:, 1] = True
    sup = model.Supports(grid[:, 0], np.zeros(0, int), fixed)
    return model.Model(m, shell, element=element, supports=sup, load_terms=[term]), term, grid[:, nx - 1], L


def test_moment_force_and_load_stiffness_are_derivatives_of_its_potential():
    mod, term, _, _ = _rolled_strip()
    rng = np.random.default_rng(0)
    x = mod.X3 + 0.5 * rng.normal(size=mod.X3.shape)
    f = term.force(x)
    rows, cols, blocks = term.tangent_blocks(x)
    K = np.zeros((mod.mesh.n_nodes, 3, mod.mesh.n_nodes, 3))
    np.add.at(K, (rows, slice(None), cols), blocks)
    h = 1e-6
    for n in np.unique(np.r_[term.tip, term.lever]):
        for i in (0, 2):
            xp, xm = x.copy(), x.copy()
            xp[n, i] += h
            xm[n, i] -= h
            assert (term.potential(xp) - term.potential(xm)) / (2 * h) == pytest.approx(f[n, i], rel=1e-6, abs=1e-9)
            fd = (term.force(xp) - term.force(xm)) / (2 * h)
            assert np.abs(fd - K[:, :, n, i]).max() < 1e-5 * np.abs(K).max()


def test_end_moment_rolls_the_strip_into_a_full_circle():
    mod, _, tip, L = _rolled_strip()
    opts = static.StaticOptions.from_keys(progress=False, initial_increment=0.0125, max_increment=0.0125)
    res = static.solve_static(mod, options=opts)
    assert res.converged
    end = mod.X3[tip] + res.U[tip]
    # theta = 2 pi: the tip comes back to the clamp (exact: -U = L, W = 0), within the 25 x 3 mesh error
    assert np.abs(end[:, [0, 2]]).max() < 0.01 * L
