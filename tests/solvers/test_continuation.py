"""Arc-length path following with inertia tracking: counts against dense eigenvalues, a bifurcation
against Euler's load and the elastica's post-buckled branch."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.special import ellipk

pytest.importorskip("sksparse")

from rftstatic.solvers.continuation import solve_arc_length  # noqa: E402
from rftstatic.solvers.inertia import InertiaSolver, count_negative, lowest_modes  # noqa: E402
from rftstatic.solvers.options import StaticOptions  # noqa: E402


@pytest.mark.parametrize("shift", [0.0, 0.003, 0.02, 0.2])
def test_negative_pivots_equal_negative_eigenvalues_of_a_shifted_laplacian(shift):
    # 2-D Laplacian (12 x 11 grid: simple eigenvalues) minus a shift: indefinite, a known spectrum
    T12, T11 = (sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n)) for n in (12, 11))
    A = (sp.kronsum(T12, T11) - shift * 8.0 * sp.eye(132)).tocsc()
    ev = np.linalg.eigvalsh(A.toarray())
    fac = InertiaSolver().factor(A)
    assert fac.negative == np.count_nonzero(ev < 0)
    assert fac.method == ("cholesky" if fac.negative == 0 else "ldl")
    vals, vecs = lowest_modes(A, fac, 3)
    nearest = np.sort(ev[np.argsort(np.abs(ev))[:3]])
    assert np.allclose(vals, nearest, rtol=1e-8, atol=1e-10)
    assert np.allclose(np.linalg.norm(A @ vecs - vecs * vals, axis=0), 0.0, atol=1e-8)


def test_negative_pivots_of_a_random_symmetric_matrix():
    rng = np.random.default_rng(3)
    B = sp.random(80, 80, density=0.05, random_state=rng)
    A = (B + B.T + sp.diags(rng.uniform(-1.0, 3.0, 80))).tocsc()
    assert count_negative(A) == np.count_nonzero(np.linalg.eigvalsh(A.toarray()) < 0)


def euler_strip(nx=21, ny=5, overload=1.5):
    """A wool strip (5 x 1 cm, no weight) simply supported at both ends (all translations held at x = 0;
    z and y at x = L, which slides), compressed by an end load of ``overload`` x Euler's load
    pi^2 B / L^2 per unit width (B_12 = 0: a beam in cylindrical bending)."""
    from rftstatic.material import preset
    from rftstatic.mesh.trimesh import rectangle
    from rftstatic.model.model import Model, Supports, edge_load

    L, W = 0.05, 0.01
    mesh = rectangle(L, W, nx, ny, origin=(0.0, -W / 2))
    mat = preset("wool-kang-yu", weight=0.0)
    X = mesh.X
    left, right = np.isclose(X[:, 0], 0.0), np.isclose(X[:, 0], L)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[left] = True
    fixed[right, 1:] = True
    ends = np.flatnonzero(right)
    ends = ends[np.argsort(X[ends, 1])]
    Ncr = np.pi**2 * mat.Db[0, 0] / L**2
    load = edge_load(mesh, np.c_[ends[:-1], ends[1:]], (-overload * Ncr, 0.0, 0.0))
    empty = np.zeros(0, np.int64)
    return Model(mesh, mat, supports=Supports(empty, empty.copy(), fixed), load=load), L


def test_arc_length_detects_euler_bifurcation_and_follows_the_elastica():
    overload = 1.5
    model, L = euler_strip(overload=overload)
    res = solve_arc_length(model, options=StaticOptions.from_keys(progress=False, rtol=1e-8))
    assert res.converged and res.lam == 1.0
    crit = res.path["critical_points"]
    assert crit and crit[0]["kind"] == "bifurcation"
    assert crit[0]["negative_before"] == 0 and crit[0]["negative_after"] == 1
    # Euler's load within the mesh's discretisation error (21 x 5 nodes: ~1 %)
    assert crit[0]["lam"] * overload == pytest.approx(1.0, rel=0.03)
    switch = res.path["switches"][0]
    assert switch["negative_after"] == 0
    # the two halves of the symmetric branch have the same energy
    e = [b["energy"] for b in switch["branches"]]
    assert e[0] == pytest.approx(e[1], rel=1e-6)
    assert res.path["final_negative"] == 0
    # post-buckled elastica, pinned-pinned: P / P_cr = (2 K(k) / pi)^2, midspan deflection k L / K(k)
    k = brentq(lambda k: (2 * ellipk(k * k) / np.pi) ** 2 - overload, 1e-6, 0.999)
    w_exact = k * L / ellipk(k * k)
    mid = np.isclose(model.mesh.X[:, 0], L / 2)
    w = np.abs(res.U[mid, 2]).mean()
    assert w == pytest.approx(w_exact, rel=0.03)


class _VonMisesTruss:
    """Two bars (axial stiffness EA [N], from (-a, 0, 0) and (a, 0, 0)) meeting at an apex at height h
    [m], loaded downwards at the apex (P [N]); only the apex's vertical displacement u is free. The
    path is known in closed form: lam P = -dE/du, E(u) = (EA / L0) (L(u) - L0)^2, L(u) = sqrt(a^2 + (h + u)^2);
    the load factor has a maximum (limit point) and the truss snaps through to the inverted branch."""

    def __init__(self, a=1.0, h=0.2, EA=1.0, P=None):
        from types import SimpleNamespace

        self.a, self.h, self.EA, self.L0 = a, h, EA, np.hypot(a, h)
        X = np.array([[-a, 0.0], [a, 0.0], [0.0, 0.0]])
        self.X3 = np.c_[X, [0.0, 0.0, h]]
        self.mesh = SimpleNamespace(n_nodes=3, X=X, X3=self.X3, element_size=np.array([0.05]),
                                    node_area=np.ones(3))
        self.free = np.zeros((3, 3), bool)
        self.free[2, 2] = True
        self.fixed = ~self.free
        self.load = np.zeros((3, 3))
        self.load[2, 2] = -(P if P is not None else 1.5 * self.limit_load())
        self.contact = self.self_contact = None
        self.load_terms = []
        self.with_membrane = False
        self.material = SimpleNamespace(weight=0.0)
        self.plan = SimpleNamespace(free_dofs=np.array([8]))
        self.element = "truss"

    def force(self, u):
        L = np.hypot(self.a, self.h + u)
        return 2 * self.EA / self.L0 * (L - self.L0) * (self.h + u) / L

    def stiffness(self, u):
        L = np.hypot(self.a, self.h + u)
        return 2 * self.EA / self.L0 * ((self.h + u) ** 2 / L**2 + (L - self.L0) * self.a**2 / L**3)

    def limit_load(self):
        from scipy.optimize import minimize_scalar

        return -minimize_scalar(self.force, bounds=(-self.h, 0.0), method="bounded").fun

    def positions(self, U):
        return self.X3 + U

    def energies(self, U, lam=1.0, *, candidates=None, pairs=None, branches=None, slip=None):
        L = np.hypot(self.a, self.h + U[2, 2])
        E = self.EA / self.L0 * (L - self.L0) ** 2
        W = lam * float(np.sum(self.load * U))
        return {"bending": E, "membrane": 0.0, "contact": 0.0, "self_contact": 0.0, "external_work": W,
                "total": E - W}

    def potential(self, U, lam=1.0, **kw):
        return self.energies(U, lam)["total"]

    def internal_force(self, U, **kw):
        f = np.zeros((3, 3))
        f[2, 2] = self.force(U[2, 2])
        return f

    def residual(self, U, lam=1.0, **kw):
        return self.internal_force(U) - lam * self.load

    def tangent(self, U, *, psd=False, shift=0.0, lam=1.0, candidates=None, stress=None, pairs=None, slip=None):
        k = self.stiffness(U[2, 2])
        if psd:
            k = max(k, 0.0)
        return self.internal_force(U), sp.csr_matrix([[k + shift]])


def test_arc_length_passes_the_limit_point_of_a_von_mises_truss_and_snaps_to_the_inverted_branch():
    truss = _VonMisesTruss()
    P = -truss.load[2, 2]
    res = solve_arc_length(truss, options=StaticOptions.from_keys(progress=False, rtol=1e-10, iteration="displacement"))
    assert res.converged and res.lam == 1.0
    crit = res.path["critical_points"][0]
    assert crit["kind"] == "limit" and crit["negative_after"] == 1
    # the load factor at the limit point: lam_max = P_max / P = 1 / 1.5, located to ~1e-3
    lam_max = truss.limit_load() / P
    steps = res.path["steps"]
    assert max(s["lam"] for s in steps if s["s"] <= crit["s"]) == pytest.approx(lam_max, rel=2e-3)
    # every path point lies on the closed-form path lam P = -f(u) (checked through the final state) and
    # the end is the inverted equilibrium: -f(u) = P with u < -2 h, stable (dE/du rising)
    u_exact = brentq(lambda u: -truss.force(u) - P, -10 * truss.h, -2 * truss.h)
    assert res.U[2, 2] == pytest.approx(u_exact, rel=1e-8)
    assert res.path["final_negative"] == 0 and truss.stiffness(res.U[2, 2]) > 0


def test_solve_static_takes_the_arc_length_route_and_checks_stability():
    from rftstatic.solvers.static import solve_static

    model, _ = euler_strip()
    res = solve_static(model, options=StaticOptions.from_keys(progress=False, continuation="arc-length", relax_fallback=False))
    assert res.route == "arc-length" and res.converged and res.stable
    assert res.path["steps"][0]["event"] == "start" and res.path["final_negative"] == 0
    with pytest.raises(ValueError, match="continuation"):
        StaticOptions.from_keys(continuation="riks")
