"""Moving obstacles (rftstatic.contact.motion): keyframes, the penalty contact evaluated in the body frame of a
rotated and translated obstacle (force = grad energy, tangent = grad force, the same as the obstacle built at
that pose), friction on a moving surface (a sticking sheet follows the body exactly, a frictionless one stays put)
and an explicit run resumed from its checkpoint mid-motion."""

import numpy as np
import pytest

from rftstatic.contact.candidates import CandidateList
from rftstatic.contact.friction import FrictionLaw, seated
from rftstatic.contact.motion import Keyframes, ObstacleMotion, Poses, rotation
from rftstatic.contact.obstacles import Floor, RoundPedestal, Sphere
from rftstatic.contact.obstacles.surface_mesh import SurfaceObstacle
from rftstatic.contact.penalty import PenaltyContact, auto_penalty
from rftstatic.material import preset
from rftstatic.mesh.trimesh import rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.model.state import State
from rftstatic.solvers.drive import finish
from rftstatic.solvers.explicit import explicit_steps, run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions

AXIS = np.array([0.3, -0.5, 1.0])
CENTRE = np.array([0.01, 0.02, -0.03])
SHIFT = np.array([0.004, -0.006, 0.002])
ANGLE = 0.7  # [rad]


def _pose(m, angle=ANGLE, shift=SHIFT):
    """``m`` obstacles turned by ``angle`` about AXIS through CENTRE and translated by ``shift``."""
    R = np.broadcast_to(rotation(AXIS, angle), (m, 3, 3))
    return Poses(R, np.tile(CENTRE, (m, 1)), np.tile(shift, (m, 1)), np.zeros((m, 3, 3)), np.zeros((m, 3)))


def _near_surface(obstacle, poses, rng, n=40):
    """Points within 0.3 mm of ``obstacle`` at ``poses`` (both sides) [m]."""
    lo, hi = obstacle.bounding_box()
    lo, hi = np.maximum(lo, -0.06), np.minimum(hi, 0.06)
    y = obstacle.closest_point(rng.uniform(lo, hi, size=(n, 3)))
    _, nb = obstacle.signed_distance(y)
    y = y + rng.uniform(-3e-4, 3e-4, n)[:, None] * nb
    R = poses.rotation[0]
    return (y - CENTRE) @ R.T + CENTRE + poses.translation[0]


def test_rotation_and_keyframes():
    """Rodrigues' matrix is orthogonal, turns about its axis by the angle (right-handed); the smooth step goes
    3 u^2 - 2 u^3 between the keys and holds outside them; the linear one goes with u."""
    R = rotation([0, 0, 2.0], np.pi / 2)
    np.testing.assert_allclose(R @ [1.0, 0, 0], [0, 1.0, 0], atol=1e-15)
    R = rotation(AXIS, ANGLE)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(R @ AXIS, AXIS, atol=1e-15)
    assert np.trace(R) == pytest.approx(1 + 2 * np.cos(ANGLE), rel=1e-14)
    k = Keyframes([0.5, 1.5], [0.0, 1.0], [0, 0, 1], [0, 0, 0], [[0, 0, 0], [2.0, 0, 0]])
    for t, u in ((0.0, 0.0), (0.5, 0.0), (0.75, 0.25), (1.0, 0.5), (1.25, 0.75), (2.0, 1.0)):
        w = 3 * u * u - 2 * u**3
        ang, s = k.angle_translation(t)
        assert ang == pytest.approx(w, abs=1e-15) and s[0] == pytest.approx(2 * w, abs=1e-15)
    lin = Keyframes([0.5, 1.5], [0.0, 1.0], [0, 0, 1], [0, 0, 0], [[0, 0, 0], [2.0, 0, 0]], interpolation="linear")
    assert lin.angle_translation(0.75)[0] == pytest.approx(0.25, abs=1e-15)


@pytest.mark.parametrize("kwargs, match", [
    ({"times": [0.0, 0.0]}, "increase strictly"),
    ({"axis": [0, 0, 0]}, "nonzero"),
    ({"angles": [0.0]}, "one per time"),
    ({"translations": [[0, 0, 0]]}, "one per time"),
    ({"interpolation": "cubic"}, "unknown"),
])
def test_bad_keyframes_are_refused_with_the_key(kwargs, match):
    args = {"times": [0.0, 1.0], "angles": [0.0, 1.0], "axis": [0, 0, 1], "centre": [0, 0, 0],
            "translations": [[0, 0, 0], [0, 0, 0]], **kwargs}
    with pytest.raises(ValueError, match=match):
        Keyframes(**args)


def test_chord_velocity_carries_a_point_of_the_body_to_where_the_body_takes_it():
    """(P1) with the step's chord velocity: x + dt v(x) is the image at t + dt of the body point at x at t."""
    k = Keyframes([0.0, 1.0], [0.0, 1.2], AXIS, CENTRE, [[0, 0, 0], SHIFT])
    motion = ObstacleMotion([k])
    t, dt = 0.37, 1e-3
    p0, p1 = motion.poses(t, dt), motion.poses(t + dt)
    x = np.random.default_rng(1).uniform(-0.1, 0.1, (5, 3))
    y = p0.to_body(x, 0)
    landed = (y - CENTRE) @ p1.rotation[0].T + CENTRE + p1.translation[0]
    np.testing.assert_allclose(x + dt * p0.velocity(x, 0), landed, rtol=0, atol=1e-15)


OBSTACLES = {
    "sphere": Sphere([0.0, 0.0, -0.05], 0.05),
    "round": RoundPedestal([0.0, 0.0], 0.04, top_z=0.0, edge_radius=0.006),
}


@pytest.mark.parametrize("name", list(OBSTACLES))
def test_force_and_tangent_are_derivatives_with_a_rotated_pose(name):
    """Central differences of the energy give the force, of the force the tangent blocks (P2), on a turned
    and translated sphere and rounded pedestal (nodes on and near the rounded edge)."""
    rng = np.random.default_rng(4)
    ob = OBSTACLES[name]
    poses = _pose(1)
    x = _near_surface(ob, poses, rng)
    contact = PenaltyContact([ob], rng.uniform(0.5, 1.5, len(x)) * 1e-5, 1e6, smoothing=2e-4)
    cands = contact.new_candidates()
    cands.poses = poses
    st = contact.evaluate(x, candidates=cands)
    assert st.n_active > 5
    h = 1e-7
    fd_f = np.zeros_like(x)
    fd_k = np.zeros((len(x), 3, 3))
    for i in range(3):  # perturb every node at once in one direction: the blocks are node-diagonal
        d = np.zeros_like(x)
        d[:, i] = h
        ep = np.array([contact.evaluate(x + d * (np.arange(len(x)) == a)[:, None], tangent=False,
                                        candidates=cands).energy for a in range(len(x))])
        em = np.array([contact.evaluate(x - d * (np.arange(len(x)) == a)[:, None], tangent=False,
                                        candidates=cands).energy for a in range(len(x))])
        fd_f[:, i] = (ep - em) / (2 * h)
        fd_k[:, :, i] = (contact.force(x + d, candidates=cands) - contact.force(x - d, candidates=cands)) / (2 * h)
    scale = np.abs(st.force).max()
    np.testing.assert_allclose(st.force, fd_f, rtol=1e-5, atol=1e-6 * scale)
    kscale = np.abs(st.tangent_blocks).max()
    np.testing.assert_allclose(st.tangent_blocks, fd_k, rtol=1e-4, atol=1e-4 * kscale)


def _obj(path, P, T):
    path.write_text("".join(f"v {a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in P) +
                    "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in T))


def test_a_moved_obstacle_is_the_obstacle_built_at_that_pose(tmp_path):
    """Energy, force and tangent of a sphere and a triangle-surface box (an icosphere file) turned and moved by
    the candidate list's poses equal those of the same obstacles built at the new pose."""
    from rftstatic.mesh.surface import read_triangles

    P, T, _ = read_triangles("cases/icosphere-3.obj")
    P = 0.03 * P / np.linalg.norm(P, axis=1).max()
    _obj(tmp_path / "at-rest.obj", P, T)
    R = rotation(AXIS, ANGLE)
    _obj(tmp_path / "moved.obj", (P - CENTRE) @ R.T + CENTRE + SHIFT, T)
    sphere = Sphere([0.01, -0.01, 0.0], 0.04)
    c_moved = (sphere.centre - CENTRE) @ R.T + CENTRE + SHIFT
    rest = [sphere, SurfaceObstacle(tmp_path / "at-rest.obj", units="m", feature_angle=100.0)]
    built = [Sphere(c_moved, 0.04), SurfaceObstacle(tmp_path / "moved.obj", units="m", feature_angle=100.0)]
    rng = np.random.default_rng(7)
    # on the polyhedron: points near its faces' centroids, off the edges (where the closest face inside is a tie)
    pick = rng.choice(len(T), 30, replace=False)
    c = P[T[pick]].mean(axis=1)
    nf = np.cross(P[T[pick, 1]] - P[T[pick, 0]], P[T[pick, 2]] - P[T[pick, 0]])
    nf /= np.linalg.norm(nf, axis=1)[:, None] * np.sign(np.einsum("ni,ni->n", nf, c))[:, None]
    y = c + rng.uniform(-3e-4, 3e-4, 30)[:, None] * nf
    x = np.concatenate([_near_surface(sphere, _pose(1), rng, 30), (y - CENTRE) @ R.T + CENTRE + SHIFT])
    area = rng.uniform(0.5, 1.5, len(x)) * 1e-5
    moved = PenaltyContact(rest, area, 1e6, smoothing=4e-4)
    cands = moved.new_candidates()
    cands.poses = _pose(2)
    a, b = moved.evaluate(x, candidates=cands), PenaltyContact(built, area, 1e6, smoothing=4e-4).evaluate(x)
    assert a.n_active > 10 and a.energy == pytest.approx(b.energy, rel=1e-9)
    np.testing.assert_allclose(a.force, b.force, rtol=1e-8, atol=1e-9 * np.abs(b.force).max())
    np.testing.assert_allclose(a.tangent_blocks, b.tangent_blocks, rtol=1e-6,
                               atol=1e-8 * np.abs(b.tangent_blocks).max())


def test_the_candidate_list_stays_exact_while_the_body_turns():
    """A list kept over a body's turn (measured in its body frame) gives the forces of a fresh evaluation at
    every pose, and refreshes once the relative motion reaches half its margin."""
    rng = np.random.default_rng(2)
    ob = OBSTACLES["sphere"]
    x = _near_surface(ob, _pose(1, 0.0, np.zeros(3)), rng, 60)
    contact = PenaltyContact([ob], np.full(len(x), 1e-5), 1e6, smoothing=2e-4)
    cands = contact.new_candidates()
    motion = ObstacleMotion([Keyframes([0.0, 1.0], [0.0, 0.5], AXIS, CENTRE, [[0, 0, 0], SHIFT])])
    for t in np.linspace(0.0, 1.0, 41):
        cands.poses = motion.poses(t, 0.025)
        fresh = CandidateList(contact.margin)
        fresh.poses = cands.poses
        np.testing.assert_array_equal(contact.force(x, candidates=cands), contact.force(x, candidates=fresh))
    assert 1 < cands.refreshes < 41


def _sheet_on_floor(mu, n=7, size=0.1):
    """A 10 cm wool square lying on a floor at z = 0 (penalty contact, friction ``mu``, no supports) whose motion
    is set by the test."""
    mesh = rectangle(size, size, n, n)
    mat = preset("wool-kang-yu")
    h = float(mesh.element_size.mean())
    k = auto_penalty(membrane_rigidity=mat.membrane_scale, bending_rigidity=mat.bending_scale, weight=mat.weight, h=h)
    law = FrictionLaw(np.array([mu]), np.array([mu]), eps=1e-6) if mu else None
    return mesh, mat, k, h, law


def _turning_run(mu, motion, t_end=0.6, state=None, pause_at=None):
    mesh, mat, k, h, law = _sheet_on_floor(mu)
    centre = 0.5 * (mesh.X3.min(axis=0) + mesh.X3.max(axis=0))
    contact = PenaltyContact([Floor(0.0)], mesh.node_area, k, smoothing=0.05 * h, friction=law,
                             motion=motion(centre))
    model = Model(mesh, mat, supports=Supports.none(mesh.n_nodes), load=gravity_load(mesh, mat.weight),
                  contact=contact)
    U0 = seated(contact, mesh.X3, model.load) - mesh.X3  # each node's weight balanced by the penalty
    opts = ExplicitOptions(t_end=t_end, alpha=2.0, progress=False, energy_tol=0.05)
    return model, centre, U0, opts


def test_a_sheet_sticking_on_a_turning_table_turns_with_it_and_a_frictionless_one_stays_put():
    """A sheet lying on a floor that turns 30 deg about the vertical through the sheet's centre (and moves 1 cm
    sideways) in 0.5 s, smooth-stepped: with mu = 0.5 (the table's peak acceleration needs mu >= 0.04) every node
    ends where the table took its point (1.8e-15 m measured: the impulses carry a sticking node at the chord
    velocity of the body's step); frictionless, it stays where it lay (7.6e-19 m). The energy balance with the table's work (body_work) holds the explicit check."""
    turn, shift = np.radians(30.0), np.array([0.01, 0.0, 0.0])

    def motion(c):
        return ObstacleMotion([Keyframes([0.0, 0.5], [0.0, turn], [0, 0, 1], c, [[0, 0, 0], shift])])

    for mu in (0.5, 0.0):
        model, c, U0, opts = _turning_run(mu, motion)
        res = run_explicit(model, opts, U0=U0)
        x0, x = model.X3 + U0, model.X3 + res.U
        R = rotation([0, 0, 1], turn)
        target = (x0 - c) @ R.T + c + shift
        if mu:
            assert np.abs(x - target).max() < 1e-12
        else:
            assert np.abs(x - x0).max() < 1e-12 and np.abs(target - x0).max() > 0.04


def test_a_run_on_a_moving_body_resumes_to_the_bit():
    """An explicit run on a turning floor with friction, paused mid-motion and resumed from its saved State (the
    checkpoint's arrays, poses included), ends bit-identical to the run without the pause."""
    from rftstatic.solvers.checkpoint import read_checkpoint, restore_state, state_arrays

    def motion(c):
        return ObstacleMotion([Keyframes([0.0, 0.3], [0.0, 0.4], [0, 0, 1], c, [[0, 0, 0], [0.005, 0, 0]])])

    model, _, U0, opts = _turning_run(0.5, motion, t_end=0.4)
    whole = run_explicit(model, opts, U0=U0)
    state = State.initial(model, U0)
    route = explicit_steps(model, state, opts)
    paused = None
    for pause in route:
        if pause.step >= whole.steps // 3:
            paused = pause
            break
    assert paused is not None and state.obstacle_poses is not None and state.obstacle_poses.rotated
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "c.npz"
        np.savez(path, **state_arrays(state, {"test": 1}))
        _, saved = read_checkpoint(path)
    again = restore_state(model, saved)
    np.testing.assert_array_equal(again.obstacle_poses.rotation, state.obstacle_poses.rotation)
    res = finish(explicit_steps(model, again, opts))
    np.testing.assert_array_equal(res.U, whole.U)
    np.testing.assert_array_equal(res.V, whole.V)
