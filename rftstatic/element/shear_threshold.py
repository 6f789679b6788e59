"""Shear hysteresis that grows with the shear angle: the friction threshold of KES 2HG and 2HG5 (S7-S10).

KES-FB1 reads the shear loop's width at two angles: ``2HG`` at 0.5 deg and ``2HG5`` at 5 deg [gf/cm]. Real fabrics
have 2HG5 > 2HG (typically 1.5-3 x): the loop widens as the yarns jam at their crossings. The friction element of
:mod:`rftstatic.element.shear_friction` takes a threshold that grows with the shear angle ``gamma`` (S2),

    tau_0(gamma) = tau_a + (tau_b - tau_a) r(x),   x = clip((|gamma| - gamma_a) / (gamma_b - gamma_a), 0, 1),
    r(x) = x^2 (3 - 2 x)                                                                                  (S7)

with ``tau_a = 2HG / 2``, ``tau_b = 2HG5 / 2`` and ``gamma_a, gamma_b`` the shear angles of the KES readings
(:data:`KES_ANGLES`): constant below 0.5 deg and beyond 5 deg, even in gamma, C1 (r'(0) = r'(1) = 0: the force below
is continuous and Newton's tangent exists; tau_0'' jumps at the two ends, as the Huber tangent jumps at the yield).
On the slipping branches of a KES cycle the friction force is ``+/- tau_0(gamma)``, so the loop's width at 0.5 deg
is 2HG and at 5 deg 2HG5, where tau_0' = 0 (the variational term of S9 vanishes there).

Variational update (the incremental potential of (S3), with the threshold taken at the end-of-step angle): with the
committed slip ``s_n`` held, ``e = gamma - s_n`` the trial stick angle and ``K`` the stick stiffness,

    psi(gamma) = min_ds [K (e - ds)^2 / 2 + tau_0(gamma) |ds|] = Huber(e; K, tau_0(gamma))             (S8)

(:func:`rftstatic.element.hysteresis.friction_law`, H3 with ``M_0 -> tau_0(gamma)``, ``y = tau_0(gamma) / K``). Its
derivatives in gamma, with ``d = |e| - min(|e|, y)`` the slip increment's size (dHuber/dtau_0 = d: the minimiser's
envelope), are the friction force per width and its slope

    tau_f = psi' = clip(K e, -tau_0, tau_0) + tau_0'(gamma) d                                            (S9)
    psi'' = K  (stick, |e| <= y),   2 tau_0' sign(e) + tau_0'' d - tau_0'^2 / K  (slip)                  (S10)

and the return mapping (S6) commits ``ds = e - clip(e, -y, y)`` and dissipates ``A tau_0(gamma) |ds|``, so the energy
balance of an explicit run closes as before (the step's potential change is the stick energy's change plus the
dissipation). The term ``tau_0' d`` is the update's consistency term: it is zero at the start of a step and of the
order of the step's slip (the rate form's force is ``+/- tau_0(gamma)``); the relaxation commits after every explicit
step. On a slipping branch that moves towards smaller |gamma| (back from a larger shear) the threshold falls and
psi'' < 0: with the elastic G in parallel the unloading slope is ``G - tau_0'`` (rate form), negative where tau_0'
exceeds G; the ``psd`` tangent drops the negative part. With ``tau_b = tau_a`` (no 2HG5) this is (S3) and (H3) to the
bit (tau_0' = tau_0'' = 0).

Written with ufuncs only, so that one source serves numpy arrays and the compiled loop of
:mod:`rftstatic.element._shear_numba` (scalars), as :func:`~rftstatic.element.hysteresis.friction_law` does.
"""

from __future__ import annotations

import math

import numpy as np

from rftstatic.element.hysteresis import friction_law

__all__ = ["KES_ANGLES", "growing_friction_law", "max_slope", "threshold"]

KES_ANGLES = (math.tan(math.radians(0.5)), math.tan(math.radians(5.0)))
"""``(gamma_a, gamma_b)`` [-]: the shear angles (S2) of the KES-FB1 readings 2HG and 2HG5, the tester's simple shear
at 0.5 and 5 deg (simple shear by an angle phi has the engineering Green shear strain 2 E_12 = tan phi)."""


def threshold(g, ta, tb, ga, gb):
    """``tau_0(gamma)`` (S7) [N/m] and its first and second derivatives in gamma [N/m] at shear angles ``g`` [-],
    for the thresholds ``ta`` (below ``ga``) and ``tb`` (beyond ``gb``) [N/m]."""
    w = gb - ga
    x = np.minimum(np.maximum((np.abs(g) - ga) / w, 0.0), 1.0)
    dt = tb - ta
    tau = ta + dt * (x * x * (3.0 - 2.0 * x))
    d1 = dt * (6.0 * x * (1.0 - x) / w) * np.sign(g)
    d2 = dt * (6.0 * (1.0 - 2.0 * x) / (w * w)) * ((x > 0.0) & (x < 1.0))
    return tau, d1, d2


def growing_friction_law(e, g, K, ta, tb, ga, gb):
    """Incremental potential psi (S8) [N/m], friction force per width tau_f (S9) [N/m] and psi'' (S10) [N/m] at trial
    stick angles ``e = gamma - s_n`` and shear angles ``g = gamma`` [-], for the stick stiffness ``K`` [N/m] and the
    threshold (S7) of :func:`threshold`; and the threshold tau_0(gamma) itself [N/m]."""
    tau, d1, d2 = threshold(g, ta, tb, ga, gb)
    psi, m, k = friction_law(e, K, tau, tau / K)
    ae = np.abs(e)
    d = ae - np.minimum(ae, tau / K)
    return psi, m + d1 * d, k + (d > 0.0) * (2.0 * d1 * np.sign(e) + d2 * d - d1 * d1 / K), tau


def max_slope(ta, tb, ga, gb) -> float:
    """``max |tau_0'|`` [N/m] of (S7): ``1.5 |tb - ta| / (gb - ga)`` (r' peaks at x = 1/2)."""
    return 1.5 * abs(tb - ta) / (gb - ga)
