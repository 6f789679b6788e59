"""Explicit dynamics (Eq. 16-22): force kernel, exactness, energy, frequency, stable step, checkpoints."""

import logging

import numpy as np
import pytest

from rftstatic.contact.obstacles import Floor, RoundPedestal, Sphere, SquarePedestal
from rftstatic.element.explicit_force import ForceKernel
from rftstatic.errors import CheckpointError, InstabilityError
from rftstatic.material import fabric, preset
from rftstatic.mesh.trimesh import rectangle
from rftstatic.model.model import Model, Supports, gravity_load
from rftstatic.model.state import State
from rftstatic.solvers.checkpoint import CheckpointSaver, explicit_header, load_explicit_state, read_checkpoint
from rftstatic.solvers.drive import drive
from rftstatic.solvers.explicit import explicit_steps
from rftstatic.solvers.explicit import run_explicit
from rftstatic.solvers.explicit_options import ExplicitOptions
from rftstatic.solvers.relaxation import RelaxOptions, relax
from rftstatic.solvers.rest import RestCriterion
from rftstatic.solvers.static import compare_with_static
from rftstatic.solvers.timestep import element_bound, lanczos_omega, lumped_mass, stable_time_step

G = 9.80665
WOOL = preset("wool-kang-yu")
# wool with 100x the bending rigidity: a bending-dominated strip whose first mode is 10x faster
STIFF = fabric(C_warp=WOOL.Dm[0, 0], C_weft=WOOL.Dm[1, 1], C_shear=WOOL.Dm[2, 2], B_warp=100 * WOOL.Db[0, 0],
               B_weft=100 * WOOL.Db[1, 1], B_twist=100 * WOOL.Db[2, 2], weight=WOOL.weight)


def strip(material=WOOL, nx=11, load_factor=1.0, element="RFT6", L=0.05, b=0.01, ny=3):
    """Cantilever strip L x b clamped at x = 0 under (a fraction of) its weight."""
    mesh = rectangle(L, b, nx, ny)
    n = mesh.n_nodes
    sup = Supports(mesh.nodes_in_box(0, 0, -1, 1), np.zeros(0, dtype=np.int64), np.zeros((n, 3), bool))
    return Model(mesh, material, element=element, supports=sup,
                 load=load_factor * gravity_load(mesh, material.weight))


def tip(model):
    return model.mesh.nearest_node([[model.mesh.X[:, 0].max(), 0.5 * model.mesh.X[:, 1].max()]])[0]


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_force_kernel_equals_model_internal_force(element, backend):
    if backend == "numba":
        pytest.importorskip("numba")
    mesh = rectangle(0.04, 0.03, 7, 6, pattern="union-jack")
    model = Model(mesh, preset("wool-kang-yu", warp_angle_deg=30.0), element=element)
    U = 2e-3 * np.random.default_rng(1).standard_normal((mesh.n_nodes, 3))
    f, W = ForceKernel(model, backend=backend)(U, energy=True)
    f_ref = model.internal_force(U)
    e = model.energies(U)
    assert np.abs(f - f_ref).max() <= 1e-12 * np.abs(f_ref).max()
    assert W == pytest.approx(e["bending"] + e["membrane"], rel=1e-12)


@pytest.mark.parametrize("element", ["RFT3", "RFT6"])
def test_threaded_force_kernel_is_the_serial_one(element):
    """The threaded numba force (element blocks, then a per-node gather) equals the serial pass, on
    a small mesh forced onto it."""
    pytest.importorskip("numba")
    mesh = rectangle(0.04, 0.03, 9, 7, pattern="union-jack")
    model = Model(mesh, preset("wool-kang-yu", warp_angle_deg=30.0), element=element)
    U = 2e-3 * np.random.default_rng(2).standard_normal((mesh.n_nodes, 3))
    f1, W1 = ForceKernel(model, backend="numba", threads=1)(U, energy=True)
    for threads in (2, 3):  # more element blocks than numba has threads run in turn
        f, W = ForceKernel(model, backend="numba", threads=threads)(U, energy=True)
        assert np.abs(f - f1).max() <= 1e-13 * np.abs(f1).max()
        assert W == pytest.approx(W1, rel=1e-13)


def test_lumped_mass_is_total_mass_and_scaled():
    model = strip()
    m = lumped_mass(model, 100.0)
    assert m.sum() == pytest.approx(100 * WOOL.mass_per_area * 0.05 * 0.01, rel=1e-12)


def test_free_fall_is_exact():
    """Consistent start v_(-1/2) = -a dt/2: central differences are exact for constant acceleration."""
    mesh = rectangle(0.05, 0.03, 6, 4, z0=0.2)
    model = Model(mesh, WOOL, load=gravity_load(mesh, WOOL.weight))
    r = run_explicit(model, ExplicitOptions(t_end=0.01, progress=False))
    assert r.steps > 50
    assert np.abs(r.U[:, 2] + 0.5 * G * r.t**2).max() <= 1e-14
    assert np.abs(r.U[:, :2]).max() <= 1e-30  # rigid translation: membrane force is round-off only
    # the energy balance holds too: kinetic = weight * drop
    h = r.history
    assert np.abs(h["total"]).max() <= 1e-12 * np.abs(h["external_work"]).max()


def test_undamped_energy_stays_bounded():
    """Strip released under gravity, no damping, ~6 periods of its first mode: total energy within 1e-4."""
    model = strip(STIFF)
    r = run_explicit(model, ExplicitOptions(t_end=0.4, progress=False))
    h = r.history
    scale = np.abs(h["external_work"]).max()
    assert h["kinetic"].max() > 0.2 * scale  # it really vibrates
    assert np.abs(h["total"] - h["total"][0]).max() <= 1e-4 * scale


def test_cantilever_frequency_matches_beam_theory():
    """Small amplitude (1 % of the weight): f1 = 1.875^2 / (2 pi L^2) sqrt(B / rho_A)."""
    L = 0.05
    model = strip(STIFF, nx=21, load_factor=0.01, L=L)
    n = tip(model)
    r = run_explicit(model, ExplicitOptions(t_end=0.25, sample_every=1, progress=False), probes=[n])
    z = r.probes[:, 0, 2]
    zc = z - 0.5 * (z.max() + z.min())
    t = r.history["time"]
    i = np.flatnonzero(np.sign(zc[1:]) != np.sign(zc[:-1]))
    tc = t[i] - zc[i] * (t[i + 1] - t[i]) / (zc[i + 1] - zc[i])  # linear interpolation of the crossings
    period = 2 * np.mean(np.diff(tc))
    f1 = 1.875**2 / (2 * np.pi * L**2) * np.sqrt(STIFF.Db[0, 0] / STIFF.mass_per_area)
    assert len(tc) >= 6
    assert 1 / period == pytest.approx(f1, rel=0.03)


def test_stable_step_estimates():
    model = strip()
    w_lanczos, _ = lanczos_omega(model)
    K = model.tangent(np.zeros((model.mesh.n_nodes, 3)), psd=True)[1].toarray()
    m = np.repeat(lumped_mass(model), 3)[model.free.ravel()]
    w_exact = np.sqrt(np.linalg.eigvalsh(K / np.sqrt(np.outer(m, m)))[-1])
    assert w_lanczos == pytest.approx(w_exact, rel=1e-6)
    assert w_exact <= element_bound(model) <= 3 * w_exact  # a safe, not too loose, bound
    est = stable_time_step(model, alpha=0.0)
    assert est.dt_crit == pytest.approx(2 / w_exact, rel=1e-6) and est.dt == pytest.approx(0.9 * est.dt_crit)
    assert stable_time_step(model, mass_scale=100.0).dt == pytest.approx(10 * est.dt, rel=1e-6)
    assert stable_time_step(model, alpha=1e4).dt < est.dt


def _blows_up(model, dt, V0, n=400):
    try:
        run_explicit(model, ExplicitOptions(t_end=n * dt, dt=dt, progress=False), V0=V0)
    except InstabilityError:
        return True
    return False


def test_automatic_step_is_close_to_the_observed_limit(caplog):
    """Bisection on dt over 400 steps from a random velocity: blow-up lies in [1.0, 1.5] x the automatic step."""
    model = strip()
    V0 = 1e-4 * np.random.default_rng(0).standard_normal((model.mesh.n_nodes, 3))
    dt_auto = stable_time_step(model).dt
    lo, hi = 1.0, 2.0
    caplog.set_level(logging.ERROR)
    assert not _blows_up(model, lo * dt_auto, V0) and _blows_up(model, hi * dt_auto, V0)
    for _ in range(6):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _blows_up(model, mid * dt_auto, V0) else (mid, hi)
    assert 1.0 <= hi <= 1.5


def test_too_large_step_warns_and_raises_with_suggestion(caplog):
    model = strip()
    est = stable_time_step(model)
    with caplog.at_level(logging.WARNING, logger="rftstatic.solvers.explicit"):
        with pytest.raises(InstabilityError, match=r"use dt <= ") as err:
            run_explicit(model, ExplicitOptions(t_end=0.05, dt=2 * est.dt, progress=False))
    assert "exceeds the stable estimate" in caplog.text
    assert err.value.suggested_dt == pytest.approx(est.dt)
    assert err.value.step > 0 and err.value.t > 0


def test_kinematic_contact_for_every_obstacle_type():
    mesh = rectangle(0.04, 0.04, 9, 9, origin=(-0.02, -0.02), z0=0.002)
    model = Model(mesh, WOOL, load=gravity_load(mesh, WOOL.weight))
    for ob in (Floor(0.0), Sphere([0, 0, -0.05], 0.05), SquarePedestal([0, 0], 0.01, top_z=0.0),
               RoundPedestal([0, 0], 0.01, top_z=0.0)):
        r = run_explicit(model, ExplicitOptions(t_end=0.05, alpha=5.0, progress=False), obstacles=[ob])
        phi, _ = ob.signed_distance(model.X3 + r.U)
        assert phi.min() >= -1e-12, type(ob).__name__
        assert r.contact_nodes > 0 and r.history["contact_loss"][-1] > 0


def test_relaxation_reaches_the_static_solution():
    """0.05 x 0.01 m wool strip, 11 x 3 nodes, clamped, own weight: relaxed = Newton within 1e-4."""
    model = strip()
    w1 = 1.875**2 / 0.05**2 * np.sqrt(WOOL.Db[0, 0] / WOOL.mass_per_area)
    s = 100.0
    r = relax(model, RelaxOptions(mass_scale=s, alpha=2 * w1 / np.sqrt(s), max_time=100.0,
                                  rest=RestCriterion(1e-8, tol_force=1e-5), progress=False))
    assert r.converged
    cmp = compare_with_static(model, r.U)
    assert cmp["max_displacement"] > 0.04  # a large (nonlinear) drape
    assert cmp["relative"] < 1e-4


def test_resume_reproduces_the_uninterrupted_run(tmp_path):
    model = strip(STIFF)
    options = ExplicitOptions(t_end=0.02, alpha=5.0, sample_every=7, progress=False)
    kw = dict(frame_times=[0.005, 0.015], probes=[tip(model)])
    full = run_explicit(model, options, **kw)
    path = tmp_path / "run.npz"

    def interrupt(state, rec):
        if state.step >= 250:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _checkpointed(model, options, path, callback=interrupt, **kw)
    assert read_checkpoint(path)[1]["step"] == 200
    assert [p.name for p in tmp_path.iterdir()] == ["run.npz"]  # no temporary file left
    res = _resume(path, model)
    assert np.array_equal(res.U, full.U) and np.array_equal(res.V, full.V)
    for k in full.history:
        assert np.array_equal(res.history[k], full.history[k]), k
    assert np.array_equal(res.probes, full.probes)
    assert [t for t, _ in res.frames] == [t for t, _ in full.frames]
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(res.frames, full.frames))
    with pytest.raises(CheckpointError, match="another model"):
        _resume(path, strip(WOOL))


def _checkpointed(model, options, path, **kw):
    """The explicit run of ``model`` driven with a checkpoint saver (every 100 steps, Ctrl-C at a whole step)."""
    state = State.initial(model)
    saver = CheckpointSaver(path, explicit_header(model, ()), every_steps=100)
    with saver.stopping():
        return drive(explicit_steps(model, state, options, **kw), saver.on(state))


def _resume(path, model):
    """The explicit run saved in ``path`` continued to its end."""
    state, options, frame_times, probes = load_explicit_state(path, model, progress=False)
    return drive(explicit_steps(model, state, options, frame_times=frame_times, probes=probes))


def test_ctrl_c_saves_a_whole_step_and_resume_reproduces_the_run(tmp_path):
    """SIGINT during a checkpointed run: the loop stops at the end of that step, saves it, raises
    KeyboardInterrupt; resuming gives the uninterrupted run bit for bit."""
    import signal

    model = strip(STIFF)
    options = ExplicitOptions(t_end=0.02, alpha=5.0, sample_every=7, progress=False)
    full = run_explicit(model, options, probes=[tip(model)])
    path = tmp_path / "run.npz"

    def press_ctrl_c(state, rec):
        if state.step >= 250:
            signal.raise_signal(signal.SIGINT)

    with pytest.raises(KeyboardInterrupt, match="checkpoint saved"):
        _checkpointed(model, options, path, probes=[tip(model)], callback=press_ctrl_c)
    saved = read_checkpoint(path)[1]["step"]
    assert 250 < saved < 260  # the step after the signal, not the last periodic checkpoint (200)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the handler is restored
    res = _resume(path, model)
    assert np.array_equal(res.U, full.U) and np.array_equal(res.V, full.V)
    for k in full.history:
        assert np.array_equal(res.history[k], full.history[k]), k


def test_a_corrupt_checkpoint_is_reported_as_such(tmp_path):
    path = tmp_path / "run.npz"
    path.write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(CheckpointError, match="corrupt or incomplete"):
        read_checkpoint(path)


def test_numpy_and_numba_runs_agree():
    pytest.importorskip("numba")
    model = strip(STIFF)
    a = run_explicit(model, ExplicitOptions(t_end=0.01, backend="numpy", progress=False))
    b = run_explicit(model, ExplicitOptions(t_end=0.01, backend="numba", progress=False))
    assert np.abs(a.U - b.U).max() <= 1e-12 * np.abs(a.U).max()


def _tuned(tuner, cost, calls):
    """The threads ``tuner`` chooses over ``calls`` kernel calls that each take ``cost[threads]`` [s]."""
    used = []
    for _ in range(calls):
        t = tuner.before()
        tuner.after(t, cost[t])
        used.append(t)
    return used


def test_thread_tuner_keeps_the_faster_setting(monkeypatch):
    """Every hold + 2 probe calls the tuner times both settings and keeps the faster one."""
    import os

    from rftstatic.compiled import ThreadTuner

    monkeypatch.setattr(os, "getloadavg", lambda: (0.5, 0.5, 0.5))  # an idle machine

    tuner = ThreadTuner(most=2)
    cost = {1: 3.6e-3, 2: 6.5e-3}  # the other core busy: one thread is faster

    def run(calls):
        return _tuned(tuner, cost, calls)

    period = 2 * tuner.probe + tuner.hold
    used = run(period)
    assert used[:tuner.probe] == [1] * tuner.probe and used[tuner.probe:2 * tuner.probe] == [2] * tuner.probe
    assert set(used[2 * tuner.probe:]) == {1}
    cost = {1: 3.6e-3, 2: 2.4e-3}  # the machine is idle again: back to two threads after the next check
    assert set(run(period)[2 * tuner.probe:]) == {2}


def test_thread_tuner_takes_one_thread_on_a_busy_machine(monkeypatch):
    """Above the thread count + BUSY_LOAD of load average the check keeps one thread even when the probe found
    two faster (it times the kernel alone); below it the probe decides, as on an idle machine."""
    import os

    from rftstatic.compiled import BUSY_LOAD, ThreadTuner

    load = [0.5]
    monkeypatch.setattr(os, "getloadavg", lambda: (load[0], load[0], load[0]))
    tuner = ThreadTuner(most=2)
    cost = {1: 3.6e-3, 2: 2.4e-3}  # the kernel alone: two threads faster

    def run(calls):
        return _tuned(tuner, cost, calls)

    period = 2 * tuner.probe + tuner.hold
    assert set(run(period)[2 * tuner.probe:]) == {2}  # idle: the probe decides
    load[0] = 2 + BUSY_LOAD + 0.5  # other jobs' threads besides this run's two
    assert set(run(period)[2 * tuner.probe:]) == {1}
    load[0] = 2 + BUSY_LOAD - 0.5
    assert set(run(period)[2 * tuner.probe:]) == {2}


def test_threads_from_the_environment(monkeypatch):
    from rftstatic.compiled import force_threads

    monkeypatch.setenv("RFTSTATIC_THREADS", "3")
    assert force_threads(10) == 3
    monkeypatch.setenv("RFTSTATIC_THREADS", "many")
    with pytest.raises(ValueError, match="RFTSTATIC_THREADS"):
        force_threads(10)
    monkeypatch.delenv("RFTSTATIC_THREADS")
    assert force_threads(10) == 1  # a small mesh: one thread
