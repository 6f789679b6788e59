"""A body given as surfaces of one topology at increasing times (rftstatic.contact.obstacles.surface_sequence): the shape between
frames is the surface built from the interpolated vertices, a sequence of translated copies is the rigid
translation, a sheet sticking on a sequence that moves follows it and a frictionless one stays put; bad frames
are refused."""

import numpy as np
import pytest

from rftstatic.contact.friction import FrictionLaw, seated
from rftstatic.contact.motion import ObstacleMotion, Poses, ShapeClock
from rftstatic.contact.obstacles.surface_mesh import SurfaceObstacle
from rftstatic.contact.penalty import PenaltyContact, auto_penalty
from rftstatic.contact.obstacles.surface_sequence import SurfaceSequence
from rftstatic.material import preset
from rftstatic.mesh.surface import read_triangles
from rftstatic.mesh.trimesh import rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.solvers.explicit import run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions


def _obj(path, P, T):
    path.write_text("".join(f"v {a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in P) +
                    "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in T))
    return path


def _surface(path):
    return SurfaceObstacle(path, units="m", feature_angle=100.0)


def _ball(tmp_path, radii, shift=(0.0, 0.0, 0.0)):
    """Icospheres of the given radii [m] (frame k moved by k x shift)."""
    P, T, _ = read_triangles("cases/icosphere-3.obj")
    P = P / np.linalg.norm(P, axis=1).max()
    return [_surface(_obj(tmp_path / f"f{k}.obj", r * P + k * np.asarray(shift), T)) for k, r in enumerate(radii)]


def _near(ob, rng, n=60):
    """Points within 0.3 mm of the faces' centroids of ``ob``, off its edges (where the closest face inside is a
    tie that round-off decides) [m]."""
    P, T = ob.surface()
    pick = rng.choice(len(T), n, replace=False)
    c = P[T[pick]].mean(axis=1)
    nf = np.cross(P[T[pick, 1]] - P[T[pick, 0]], P[T[pick, 2]] - P[T[pick, 0]])
    nf /= np.linalg.norm(nf, axis=1)[:, None]
    return c + rng.uniform(-3e-4, 3e-4, n)[:, None] * nf


def _poses(m, t):
    return Poses(np.broadcast_to(np.eye(3), (m, 3, 3)), np.zeros((m, 3)), np.zeros((m, 3)), np.zeros((m, 3, 3)),
                 np.zeros((m, 3)), np.full(m, t), 1e-3)


def test_the_shape_between_frames_is_the_surface_of_the_interpolated_vertices(tmp_path):
    """A ball growing from 3 to 4 cm in 1 s: at t = 0.25 s its contact (energy, force, tangent) is that of the 3.25 cm
    ball built from a file; at and outside the frames' times, that of the frames."""
    seq = SurfaceSequence.from_frames(_ball(tmp_path, [0.03, 0.04]), [0.0, 1.0])
    built = _ball(tmp_path / "..", [0.0325])[0]
    rng = np.random.default_rng(3)
    x = _near(built, rng)
    area = rng.uniform(0.5, 1.5, len(x)) * 1e-5
    moving = PenaltyContact([seq], area, 1e6, smoothing=4e-4)
    cands = moving.new_candidates()
    cands.poses = _poses(1, 0.25)
    a, b = moving.evaluate(x, candidates=cands), PenaltyContact([built], area, 1e6, smoothing=4e-4).evaluate(x)
    assert a.n_active > 10 and a.energy == pytest.approx(b.energy, rel=1e-9)
    np.testing.assert_allclose(a.force, b.force, rtol=1e-8, atol=1e-9 * np.abs(b.force).max())
    np.testing.assert_allclose(a.tangent_blocks, b.tangent_blocks, rtol=1e-8, atol=1e-9 * np.abs(b.tangent_blocks).max())
    np.testing.assert_array_equal(seq.vertices_at(-1.0), seq.frames[0].V)
    np.testing.assert_array_equal(seq.vertices_at(2.0), seq.frames[1].V)
    assert seq.drift(0.0, 0.25) == pytest.approx(0.0025, rel=1e-12)


def test_a_sequence_of_translated_copies_is_the_rigid_translation(tmp_path):
    """Frames of one ball moved 2 cm along x: at t = 0.5 s the contact equals that of the first frame translated
    by 1 cm through the rigid poses."""
    frames = _ball(tmp_path, [0.03, 0.03], shift=(0.02, 0.0, 0.0))
    seq = SurfaceSequence.from_frames(frames, [0.0, 1.0])
    rng = np.random.default_rng(5)
    x = _near(frames[0], rng) + [0.01, 0.0, 0.0]
    area = np.full(len(x), 1e-5)
    a_c = PenaltyContact([seq], area, 1e6, smoothing=4e-4)
    ca = a_c.new_candidates()
    ca.poses = _poses(1, 0.5)
    b_c = PenaltyContact([frames[0]], area, 1e6, smoothing=4e-4)
    cb = b_c.new_candidates()
    cb.offsets = [[0.01, 0.0, 0.0]]
    a, b = a_c.evaluate(x, candidates=ca), b_c.evaluate(x, candidates=cb)
    assert a.n_active > 10
    np.testing.assert_allclose(a.force, b.force, rtol=1e-8, atol=1e-9 * np.abs(b.force).max())
    v = seq.surface_velocity(x, 0.5, 1e-3)
    np.testing.assert_allclose(v, np.tile([0.02, 0.0, 0.0], (len(x), 1)), rtol=1e-9)


def test_bad_frames_are_refused(tmp_path):
    balls = _ball(tmp_path, [0.03, 0.04])
    with pytest.raises(ValueError, match="strictly increasing"):
        SurfaceSequence.from_frames(balls, [1.0, 1.0])
    P, T, _ = read_triangles("cases/icosphere-3.obj")
    other = _surface(_obj(tmp_path / "other.obj", 0.03 * P, T[:, [0, 2, 1]][::-1]))
    with pytest.raises(ValueError, match="another topology"):
        SurfaceSequence.from_frames([balls[0], other], [0.0, 1.0])


@pytest.mark.slow
def test_a_sheet_on_a_moving_table_sequence_follows_it_with_friction(tmp_path):
    """A 10 cm wool sheet on a table top given as two frames (cases/table-top.obj and the same moved 3 mm along x and
    1.5 mm up, 0.3 s apart): sticking (mu = 0.5) it ends moved by that within 2e-5 m (the frames' linear interpolation
    starts and stops the table with a velocity jump of 1 cm/s, which friction takes mu g dt per step to pass on:
    the sheet slips v^2 / (2 mu g) = 1e-5 m at each); frictionless it only rises."""
    P, T, _ = read_triangles("cases/table-top.obj")
    P = 0.01 * P
    move = np.array([0.003, 0.0, 0.0015])
    frames = [_surface(_obj(tmp_path / "a.obj", P, T)), _surface(_obj(tmp_path / "b.obj", P + move, T))]
    seq = SurfaceSequence.from_frames(frames, [0.02, 0.32])
    mesh = rectangle(0.1, 0.1, 7, 7, origin=(-0.05, -0.05))
    mat = preset("wool-kang-yu")
    h = float(mesh.element_size.mean())
    k = auto_penalty(membrane_rigidity=mat.membrane_scale, bending_rigidity=mat.bending_scale, weight=mat.weight, h=h)
    for mu in (0.5, 0.0):
        law = FrictionLaw(np.array([mu]), np.array([mu]), eps=1e-6) if mu else None
        contact = PenaltyContact([seq], mesh.node_area, k, smoothing=0.05 * h, friction=law,
                                 motion=ObstacleMotion([ShapeClock(seq.end)]))
        model = Model(mesh, mat, supports=Supports.none(mesh.n_nodes), load=gravity_load(mesh, mat.weight),
                      contact=contact)
        U0 = seated(contact, mesh.X3, model.load) - mesh.X3
        res = run_explicit(model, ExplicitOptions(t_end=0.4, alpha=2.0, progress=False), U0=U0)
        d = res.U - U0
        if mu:
            np.testing.assert_allclose(d, np.tile(move, (mesh.n_nodes, 1)), rtol=0, atol=2e-5)
        else:
            assert np.abs(d[:, :2]).max() < 1e-9 and np.allclose(d[:, 2], move[2], atol=2e-5)
