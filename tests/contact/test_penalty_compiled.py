"""The compiled explicit force of the penalty contact (rftstatic.contact.penalty_compiled) against the numpy path it
replaces: bit for bit (np.array_equal, and the bits themselves) along walks of a sheet of points through the
rigid analytic obstacles (inside, in the smoothing onset, outside; the candidate list valid and refreshed), alone
and several at once, with and without the onset, with and without a candidate list; and where it does not apply."""

import numpy as np
import pytest

from rftstatic.compiled import numba_available
from rftstatic.contact import penalty as penalty_module
from rftstatic.contact.obstacles import Floor, RoundPedestal, Sphere, SquarePedestal
from rftstatic.contact.obstacles import pedestal_kernels
from rftstatic.contact.penalty import PenaltyContact
from rftstatic.contact.penalty_compiled import compiled_force, point_form

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")

OBSTACLES = {
    "round": [RoundPedestal([0.001, -0.002], 0.05, top_z=0.0, edge_radius=0.004)],
    "round-finite": [RoundPedestal([0.0, 0.0], 0.04, top_z=0.0, edge_radius=0.006, height=0.05)],
    "square": [SquarePedestal([0.002, 0.0], (0.05, 0.035), top_z=0.0, edge_radius=0.005)],
    "sphere": [Sphere([0.0, 0.001, -0.05], 0.05)],
    "floor": [Floor(-0.004)],
    "all": [Floor(-0.03), Sphere([0.03, 0.0, -0.02], 0.02), SquarePedestal([-0.03, 0.0], 0.02, top_z=-0.001,
                                                                          edge_radius=0.003),
            RoundPedestal([0.0, 0.04], 0.02, top_z=0.0005, edge_radius=0.002)],
}


def _sheet(n):
    """An ``n x n`` sheet of points 12 cm wide at z = 0, its node areas [m^2]."""
    s = np.linspace(-0.06, 0.06, n)
    X, Y = np.meshgrid(s, s)
    x = np.column_stack([X.ravel(), Y.ravel(), np.zeros(n * n)])
    return x, np.full(n * n, (s[1] - s[0]) ** 2)


def _walk(x0, rng, steps=60):
    """Positions of a jittered sheet sinking through z = 0: small steps (the list stays valid), a jump now and then
    (it is refreshed), points inside, in the onset and outside."""
    x = x0 + rng.normal(scale=1e-3, size=x0.shape)
    for k in range(steps):
        x = x + rng.normal(scale=2e-5, size=x.shape) - [0.0, 0.0, 2e-5]
        if k % 17 == 16:
            x = x + rng.normal(scale=2e-3, size=x.shape)
        yield x


def _forces(contact, xs, listed, monkeypatch, compiled):
    if not compiled:
        monkeypatch.setattr(penalty_module, "compiled_force", lambda *args: None)
    cand = contact.new_candidates() if listed else None
    out = [contact.force(x, candidates=cand) for x in xs]
    monkeypatch.undo()
    return out, (cand.refreshes if listed else 0)


def _same_bits(a, b):
    return np.array_equal(a, b) and np.array_equal(a.view(np.int64), b.view(np.int64))


@pytest.mark.parametrize("name", list(OBSTACLES))
@pytest.mark.parametrize("smoothing", [1.5e-3, 0.0])
@pytest.mark.parametrize("n", [17, 41])  # 289 nodes: the numpy path's pedestal twins in numpy, 1,681: compiled
def test_compiled_force_is_bit_identical(name, smoothing, n, monkeypatch):
    x0, area = _sheet(n)
    contact = PenaltyContact(OBSTACLES[name], area, 4.4e7, smoothing=smoothing)
    assert contact.point_form is not None
    for listed in (True, False):
        xs = list(_walk(x0, np.random.default_rng(n)))
        ref, refreshes = _forces(contact, xs, listed, monkeypatch, compiled=False)
        new, refreshes_new = _forces(contact, xs, listed, monkeypatch, compiled=True)
        assert refreshes_new == refreshes and (not listed or 1 < refreshes < len(xs))
        assert all(_same_bits(a, b) for a, b in zip(ref, new))
        pushed = sum(int(np.count_nonzero(np.any(f != 0.0, axis=1))) for f in ref)
        assert pushed > 0
    phi = np.min([ob.signed_distance(xs[-1])[0] for ob in OBSTACLES[name]], axis=0)
    # the walk has points inside, in the onset and outside
    assert np.any(phi < 0.0) and np.any(phi > max(smoothing, 1e-4))
    assert smoothing == 0.0 or np.any((phi >= 0.0) & (phi < smoothing))


def test_compiled_distances_equal_the_obstacles(monkeypatch):
    """pedestal_kernels.distances_at gives each obstacle's numpy signed distance and normal (values; a zero may
    differ in sign) at points everywhere around it, the pedestals' numpy twins included."""
    from rftstatic.contact.obstacles._pedestal_numba import distances_at

    rng = np.random.default_rng(5)
    obstacles = [ob for group in OBSTACLES.values() for ob in group]
    x = rng.uniform(-0.08, 0.08, size=(3000, 3))
    x[:1000, 2] *= 0.1
    x[1000:1010, :2] = 0.0  # the round pedestal's axis, the sphere's vertical
    x[1010] = [0.0, 0.001, -0.05]  # the sphere's centre
    kinds, params = point_form(obstacles)
    index = np.arange(x.shape[0])
    phi, normal = np.empty((len(obstacles), x.shape[0])), np.empty((len(obstacles), x.shape[0], 3))
    distances_at(x, index, kinds, params, phi, normal)
    for threshold in (10 ** 12, 1):
        monkeypatch.setattr(pedestal_kernels, "COMPILED_MIN_POINTS", threshold)
        for m, ob in enumerate(obstacles):
            p, nrm = ob.signed_distance(x)
            assert np.array_equal(phi[m], p) and np.array_equal(normal[m], nrm), (threshold, ob)


class _OwnSphere(Sphere):
    """A subclass: it inherits the distance, not the point kernel (it could change the distance)."""


def test_what_takes_the_numpy_path():
    x, area = _sheet(17)
    assert point_form([_OwnSphere([0.0, 0.0, -0.05], 0.05)]) is None
    assert point_form([Floor(0.0), _OwnSphere([0.0, 0.0, -0.05], 0.05)]) is None
    assert point_form([]) is None
    contact = PenaltyContact([Floor(-0.001)], area, 1e6, smoothing=1e-3)
    assert compiled_force(contact, x, None) is not None
    small, small_area = _sheet(15)  # 225 nodes: below COMPILED_MIN_POINTS, numba is not loaded for them
    assert compiled_force(PenaltyContact([Floor(-0.001)], small_area, 1e6), small, None) is None
    cand = contact.new_candidates()
    cand.offsets = [[0.0, 0.0, 0.001]]  # a moved obstacle: the numpy path
    assert compiled_force(contact, x, cand) is None
