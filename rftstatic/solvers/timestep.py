"""Lumped mass and the stable step of the central-difference scheme (§2.4, Eq. 18-22).

Mass: each triangle's mass ``rho_A A`` is split equally among its three vertices (§2.4), times an
optional mass-scaling factor ``s`` (§6; the weight in the load is *not* scaled).

Stable step: for undamped central differences ``dt_crit = 2 / omega_max`` with ``omega_max^2`` the
largest eigenvalue of ``M^-1 K`` on the free dofs. With the lagged (asynchronous) mass damping of
Eq. 19-20, a mode ``omega`` obeys ``x_{n+1} - 2 x_n + x_{n-1} = -omega^2 dt^2 x_n - alpha dt
(x_n - x_{n-1})``, whose roots stay in the unit disc while ``omega^2 dt^2 + 2 alpha dt <= 4``:

    dt_crit = (sqrt(alpha^2 + 4 omega_max^2) - alpha) / omega_max^2      (= 2/omega_max at alpha = 0).

``omega_max`` is estimated two ways:
  - ``"bound"``: a guaranteed upper bound. With ``lambda_e`` the largest eigenvalue of each element
    matrix (bending ``A L^T D^b L``, Eq. 13, and the membrane tangent with the compressive stress
    dropped), ``x^T K x <= sum_i c_i |x_i|^2`` with ``c_i = sum_(e contains i) lambda_e``, hence
    ``omega^2 <= max_i c_i / m_i``; Gershgorin on ``M^-1 K`` (row sums of ``|K_e|`` over ``m_i``) is a
    second bound, and the smaller is used. Safe but typically 1.5-3x too high.
  - ``"lanczos"`` (default): the largest eigenvalue of ``M^-1/2 K M^-1/2`` (K from
    ``model.tangent(U, psd=True)``) by ARPACK's Lanczos iteration, falling back to power
    iteration. Ritz values approach ``omega_max^2`` from below, to the stated tolerance.
The recommended step is ``safety * dt_crit`` with ``safety = 0.9``: it covers the Lanczos tolerance
and a moderate stiffening of the membrane (geometric stiffness) during the run; the run's energy
check (``rftstatic.solvers.explicit``) catches anything beyond.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rftstatic.errors import StepLimitError

log = logging.getLogger(__name__)

SAFETY = 0.9
"""Default safety factor on the critical step (see module docstring)."""


def lumped_mass(model, mass_scale: float = 1.0) -> np.ndarray:
    """(N,) nodal masses [kg]: a third of every adjacent triangle's mass, times ``mass_scale``."""
    if not mass_scale > 0:
        raise ValueError(f"mass_scale must be > 0, got {mass_scale}")
    rho = model.material.mass_per_area
    if not rho > 0:
        raise ValueError(
            f"material {model.material.name!r} has mass_per_area = {rho} kg/m^2; explicit dynamics needs "
            "a positive areal weight (material weight [N/m^2])")
    return mass_scale * rho * model.mesh.node_area


def critical_step(omega_max: float, alpha: float = 0.0) -> float:
    """Critical step [s] of central differences with lagged mass damping ``alpha`` [1/s]."""
    if not omega_max > 0:
        return np.inf
    return float((np.sqrt(alpha * alpha + 4.0 * omega_max**2) - alpha) / omega_max**2)


@dataclass(frozen=True)
class StepEstimate:
    """A stable-step estimate.

    Attributes
    ----------
    dt : recommended step, ``safety * dt_crit`` [s]
    dt_crit : critical step for ``omega_max`` and the damping [s]
    omega_max : estimated largest angular frequency [rad/s]
    method : ``"lanczos"``, ``"power"`` or ``"bound"``
    safety : the factor applied [-]
    """

    dt: float
    dt_crit: float
    omega_max: float
    method: str
    safety: float


def element_bound(model, U=None, *, mass_scale: float = 1.0) -> float:
    """Guaranteed upper bound of ``omega_max`` [rad/s] from element eigenvalues (module docstring)."""
    mesh = model.mesh
    N = mesh.n_nodes
    U = np.zeros((N, 3)) if U is None else np.asarray(U, float)
    m = lumped_mass(model, mass_scale)
    patches = model.patches
    kb = mesh.area[:, None, None] * np.einsum("eka,kl,elb->eab", patches.L, model.material.Db, patches.L)
    lam_b = np.linalg.eigvalsh(kb)[:, -1]  # scalar 6x6; the same for each component
    c = np.bincount(patches.nodes.ravel(), np.repeat(lam_b, 6), minlength=N)
    row = np.bincount(patches.nodes.ravel(), np.abs(kb).sum(axis=2).ravel(), minlength=N)
    row = np.repeat(row[:, None], 3, axis=1)  # (N, 3) Gershgorin row sums per dof
    if model.with_membrane:
        _, ke = model.membrane.element_tangents(U, model.material.Dm, psd=True, backend=model.membrane_backend)
        fr = getattr(model, "shear_friction", None)
        if fr is not None:  # shear hysteresis at its stiffest: every element sticking (rftstatic.element.shear_friction)
            ke = ke + fr.stiffest().evaluate(U, fr.shear_angle(U), tangent=True, psd=True)[2]
        E, A = model.membrane.nodes.shape
        ke = ke.reshape(E, 3 * A, 3 * A)
        lam_m = np.linalg.eigvalsh(ke)[:, -1]
        nodes = model.membrane.nodes
        c += np.bincount(nodes.ravel(), np.repeat(lam_m, A), minlength=N)
        dofs = (3 * nodes[..., None] + np.arange(3)).ravel()
        row += np.bincount(dofs, np.abs(ke).sum(axis=2).ravel(), minlength=3 * N).reshape(N, 3)
    free = model.free
    node_free = free.any(axis=1)
    if model.contact is not None:
        blocks = model.contact.tangent_blocks(model.X3 + U)
        c += np.linalg.eigvalsh(0.5 * (blocks + blocks.transpose(0, 2, 1)))[:, -1].clip(min=0.0)
        row += np.abs(blocks).sum(axis=2)
    if not node_free.any():
        return 0.0
    w2_elem = float((c / m)[node_free].max())
    w2_gersh = float((row / m[:, None])[free].max())
    return float(np.sqrt(min(w2_elem, w2_gersh)))


def _scaled_tangent(model, U, mass_scale):
    N = model.mesh.n_nodes
    U = np.zeros((N, 3)) if U is None else np.asarray(U, float)
    _, K = model.tangent(U, psd=True)
    m = np.repeat(lumped_mass(model, mass_scale), 3)[model.free.ravel()]
    d = sp.diags(1.0 / np.sqrt(m))
    return (d @ K @ d).tocsr()


def power_iteration(A, *, iterations: int = 500, rtol: float = 1e-6, seed: int = 0) -> float:
    """Largest eigenvalue of the symmetric positive semi-definite ``A`` by power iteration (Rayleigh quotient)."""
    x = np.random.default_rng(seed).standard_normal(A.shape[0])
    x /= np.linalg.norm(x)
    lam = 0.0
    for _ in range(iterations):
        y = A @ x
        lam_new = float(x @ y)
        ny = np.linalg.norm(y)
        if ny == 0:
            return 0.0
        x = y / ny
        if abs(lam_new - lam) <= rtol * abs(lam_new):
            return lam_new
        lam = lam_new
    return lam


def lanczos_omega(model, U=None, *, mass_scale: float = 1.0, tol: float = 1e-6) -> tuple[float, str]:
    """Largest angular frequency [rad/s] of ``M^-1 K`` on the free dofs, and the method that found it."""
    from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, eigsh

    A = _scaled_tangent(model, U, mass_scale)
    n = A.shape[0]
    if n == 0:
        return 0.0, "lanczos"
    if n <= 50:
        lam = float(np.linalg.eigvalsh(A.toarray())[-1])
        return float(np.sqrt(max(lam, 0.0))), "lanczos"
    try:
        v0 = np.random.default_rng(0).standard_normal(n)
        lam = float(eigsh(A, k=1, which="LA", tol=tol, v0=v0, return_eigenvectors=False)[0])
        return float(np.sqrt(max(lam, 0.0))), "lanczos"
    except (ArpackNoConvergence, ArpackError) as exc:
        log.info("Lanczos did not converge (%s); using power iteration", exc)
        return float(np.sqrt(max(power_iteration(A), 0.0))), "power"


def stable_time_step(model, U=None, *, mass_scale: float = 1.0, alpha: float = 0.0, safety: float = SAFETY,
                     method: str = "lanczos") -> StepEstimate:
    """Recommended explicit step [s] for ``model`` at displacements ``U (N, 3)`` [m] (module docstring).

    Parameters
    ----------
    model : :class:`rftstatic.model.model.Model`
    U : (N, 3) state at which the stiffness is taken [m] (default: reference)
    mass_scale : mass-scaling factor s [-]
    alpha : mass damping factor [1/s]
    safety : factor on the critical step, in (0, 1]
    method : ``"lanczos"`` (accurate estimate) or ``"bound"`` (guaranteed upper bound of omega_max)
    """
    if not 0 < safety <= 1:
        raise ValueError(f"safety factor must lie in (0, 1], got {safety}")
    if alpha < 0:
        raise ValueError(f"mass damping alpha must be >= 0 [1/s], got {alpha}")
    if method == "lanczos":
        omega, used = lanczos_omega(model, U, mass_scale=mass_scale)
    elif method == "bound":
        omega, used = element_bound(model, U, mass_scale=mass_scale), "bound"
    else:
        raise ValueError(f'time-step method must be "lanczos" or "bound", got "{method}"')
    if np.isnan(omega) or np.isinf(omega):
        raise StepLimitError(f"the stable explicit step collapsed: omega_max = {omega!r} rad/s at this state (a "
                             "stiffness or mass that is not finite)")
    if not omega > 0:
        raise ValueError("the model has no stiffness on its free dofs (omega_max = 0); cannot choose a step")
    dtc = critical_step(omega, alpha)
    return StepEstimate(dt=safety * dtc, dt_crit=dtc, omega_max=omega, method=used, safety=safety)
