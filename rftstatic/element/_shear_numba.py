"""Compiled (numba) nodal force of the shear friction (:mod:`rftstatic.element.shear_friction`): the explicit path.

One loop over the membrane's elements evaluates what
:meth:`~rftstatic.element.shear_friction.ShearFriction.nodal_force` evaluates with numpy (the reference, which the
tests compare it with): the displacement gradients at the Q strain points, the averaged Green strain (Eq. 14,
RFT6: Eq. 24-26) and its warp-weft shear angle (S2), the friction force per width (S3) at the committed slip, and
the element's nodal forces (S4) as ``f_a = A/Q sum_q g_qa . (S_f F_q)``, summed into the nodes in element order.
Nothing of the law or the strain is written here: the friction law is
:func:`rftstatic.element.shear_threshold.growing_friction_law` (S7-S10, calling
:func:`rftstatic.element.hysteresis.friction_law`, H2-H3; ufuncs on scalars) and the strain
:func:`rftstatic.element.kernels.averaged_strain`, each compiled as it stands. The loop is serial (its scatter
adds into shared nodes); its sums run in a fixed order and differ from numpy's sparse products by round-off
(the tests' tolerance: 1e-12 of the largest entry).

Arrays, element axis first (each element's data contiguous): ``nodes (E, A)`` int64, ``G (E, Q, A, 2)`` [1/m]
the strain-point gradients (the membrane's ``G_last`` transposed), ``area (E,)`` [m^2], ``t (3,)``, ``offset
(E, A, 3)`` [m] the reference offsets of a sewn mesh (``(0, A, 3)`` without), ``U (N, 3)`` [m], ``slip (E,)``
[-], ``law (5,)`` the law's stick stiffness K [N/m], thresholds tau_a, tau_b [N/m] and angles gamma_a, gamma_b [-]
(S7), ``f (N, 3)`` [N] added into. As in :mod:`rftstatic.element._axis_numba` the loop is compiled at import as a
copy named after a hash of the code it links from other files (:data:`CODE_KEY`), so that numba's cache, keyed on
this file only, never loads a loop built from older code.

Imported only when numba is installed and the run's kernels are compiled (:mod:`rftstatic.element.shear_friction`).
"""

import hashlib
import marshal
import types

import numba as nb

from rftstatic.element import kernels, shear_threshold
from rftstatic.element._kernels_numba import _stack, compile_in_place
from rftstatic.element.hysteresis import friction_law as _friction_py

_JIT = dict(cache=True, nogil=True, error_model="numpy")
_friction = nb.njit(inline="always", **_JIT)(_friction_py)
_threshold = nb.njit(inline="always", **_JIT)(shear_threshold.threshold)
# shear_threshold.growing_friction_law calling the compiled threshold and friction law
_law = nb.njit(inline="always", **_JIT)(types.FunctionType(
    shear_threshold.growing_friction_law.__code__,
    {**vars(shear_threshold), "threshold": _threshold, "friction_law": _friction}, "growing_friction_law"))
_green = nb.njit(inline="always", **_JIT)(kernels.green_strain)
# kernels.averaged_strain calling the compiled green_strain
_averaged = nb.njit(inline="always", **_JIT)(types.FunctionType(
    kernels.averaged_strain.__code__, {**vars(kernels), "green_strain": _green}, "averaged_strain"))

CODE_KEY = hashlib.sha1(b"".join(marshal.dumps(f.__code__) for f in (
    _friction_py, shear_threshold.threshold, shear_threshold.growing_friction_law, kernels.green_strain,
    kernels.averaged_strain))).hexdigest()[:12]
"""Hash of the linked code (the friction law and its threshold, the Green strain and its average), in the loop's
cache name."""


def _gradients(e, nodes, G, offset, U, u, H):
    """The displacement gradients ``H[q, J, i, 0]`` [-] of element ``e`` at its Q strain points (Eq. 24-25), its
    nodes' displacements (plus a sewn mesh's offsets) gathered into ``u (A, 3)`` first."""
    Q, A = G.shape[1], G.shape[2]
    for a in range(A):
        for i in range(3):
            u[a, i] = U[nodes[e, a], i] + offset[e, a, i] if offset.shape[0] > 0 else U[nodes[e, a], i]
    for q in range(Q):
        for J in range(2):
            for i in range(3):
                s = 0.0
                for a in range(A):
                    s += G[e, q, a, J] * u[a, i]
                H[q, J, i, 0] = s


def _shear_angle(t, H, Q):
    """``gamma = t . eps`` [-] (S2) of the averaged Green strain of ``H[:Q]``."""
    exx, eyy, gxy = _averaged(H[:Q], 0)
    return t[0] * exx + t[1] * eyy + t[2] * gxy


def shear_force(nodes, G, area, t, offset, U, slip, law, f):
    """Add the friction's nodal forces (S4) into ``f (N, 3)`` [N]; return its energy ``sum_e A_e psi_e`` [J]
    (module docstring)."""
    Q, A = G.shape[1], G.shape[2]
    K, ta, tb, ga, gb = law[0], law[1], law[2], law[3], law[4]
    H = _stack((3, 2, 3, 1))
    u = _stack((6, 3))
    fe = _stack((6, 3))
    W = 0.0
    for e in range(nodes.shape[0]):
        _gradients(e, nodes, G, offset, U, u, H)
        gamma = _shear_angle(t, H, Q)
        psi, tau, _, _ = _law(gamma - slip[e], gamma, K, ta, tb, ga, gb)
        W += area[e] * psi
        w = area[e] * tau / Q
        sxx, syy, sxy = w * t[0], w * t[1], w * t[2]
        fe[:A] = 0.0
        for q in range(Q):
            for i in range(3):
                fx = H[q, 0, i, 0] + (1.0 if i == 0 else 0.0)
                fy = H[q, 1, i, 0] + (1.0 if i == 1 else 0.0)
                px = sxx * fx + sxy * fy
                py = sxy * fx + syy * fy
                for a in range(A):
                    fe[a, i] += G[e, q, a, 0] * px + G[e, q, a, 1] * py
        for a in range(A):
            for i in range(3):
                f[nodes[e, a], i] += fe[a, i]
    return W


def shear_angles(nodes, G, t, offset, U, gamma):
    """Fill ``gamma (E,)`` [-] with every element's shear angle (S2), for the return mapping (S6)."""
    Q = G.shape[1]
    H = _stack((3, 2, 3, 1))
    u = _stack((6, 3))
    for e in range(nodes.shape[0]):
        _gradients(e, nodes, G, offset, U, u, H)
        gamma[e] = _shear_angle(t, H, Q)


_INLINE = ("_gradients", "_shear_angle")
_LOOPS = ("shear_force", "shear_angles")

compile_in_place(globals(), _INLINE, _LOOPS, CODE_KEY, **_JIT)


__all__ = ["CODE_KEY", "shear_angles", "shear_force"]
