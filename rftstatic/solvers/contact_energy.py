"""The energy the explicit loop's contact corrections take from the sheet (``contact_loss``), measured as the
central-difference scheme (Eq. 20-22, :mod:`rftstatic.solvers.explicit`) measures energy.

The scheme keeps the half-step energy

    E_(n+1/2) = 1/2 v_(n+1/2) . M v_(n+1/2) + 1/2 (Phi(D_n) + Phi(D_(n+1))),   Phi = stored energy - P . D     (C0)

to O(dt^3) a step (less the damping's work). A contact correction of the step changes it; with
``g = dt M^-1 (P - F(D_n))`` (N, 3) [m/s], the step's velocity increment from the forces (zero on supported dofs):

* a velocity correction ``v_b -> v_a`` made before the position update ``D_(n+1) = D_n + dt v_(n+1/2)`` (Coulomb
  impulses of the penalty contact and between the sheet's layers, the self-contact step filter) by

      dE = sum M (v_a - v_b) . (v_a + v_b - g) / 2                                                          (C1)

* the kinematic contact (§6.3), which after the position update moves ``D_(n+1)`` by ``du`` and sets
  ``v_b -> v_a``, by

      dE = sum M (v_a - v_b) . (v_a + v_b + g) / 2 - sum M g . du / dt                                      (C2)

  (the change of E_(n+1/2) plus the energy the next step's update would otherwise create from the mismatch
  ``D_(n+1) - D_n != dt v_(n+1/2)``; Phi to first order in ``du``, its gradient ``F - P = -M g / dt``).

``contact_loss`` adds ``-dE`` (plus, on moving obstacles, the work their impulses did on the sheet, which the run
books as the bodies' work ``body_work``: what is lost is the bodies' work less the sheet's gain). A node resting on
an obstacle or sticking by friction loses nothing (``v_b = g``, ``v_a = 0``; kinematic: ``du = -dt g`` too), an
impact at ``v0`` on a fixed obstacle under no force loses ``1/2 m v0^2``. The kinetic energy ``1/2 M (|v_b|^2 -
|v_a|^2)`` alone, booked before, counted the weight's velocity increment of every resting node once a step: a
20 x 20 cm sheet lying on the pedestal (11 x 11 nodes, mass scale 100) booked 3.6e-4 J/s at rest, twice the
gravity's whole work by 10 s. With C1-C2 the balance's error goes to zero with the step: a 4 x 4 cm wool sheet
dropped 2 mm onto a square pedestal, a round one and the floor (0.05 s) keeps it to 1.1e-2, 3.3e-3, 4.6e-4 of
gravity's work at the stable step, 5.8e-4, 2.2e-4, 1.1e-4 at a quarter of it (second order on the pedestals'
edges; first order on the floor, where every node's impact falls inside one step).

Shapes: ``mass (N,)`` [kg] (lumped, mass scaled), velocities and ``g (N, 3)`` [m/s], ``free (N, 3)`` bool.
"""

from __future__ import annotations

import numpy as np


def impulse_change(mass, v_before, v_after, g, free) -> float:
    """``dE`` [J] of a velocity correction before the position update (C1), over the free dofs."""
    dv = np.where(free, v_after - v_before, 0.0)
    return 0.5 * float(np.einsum("n,ni,ni->", mass, dv, v_after + v_before - g))


def kinematic_change(mass, v_before, v_after, du, g, dt, free) -> float:
    """``dE`` [J] of the kinematic contact's correction after the position update (C2): ``du`` (N, 3) [m] the
    projection's move, over the free dofs."""
    dv = np.where(free, v_after - v_before, 0.0)
    return (0.5 * float(np.einsum("n,ni,ni->", mass, dv, v_after + v_before + g))
            - float(np.einsum("n,ni,ni->", mass, g, np.where(free, du, 0.0))) / dt)


def kinematic_step(model, obstacles, U, V, mass, acc, friction=None, dt=0.0, g=None, sweep=None) -> int:
    """The kinematic contact after the position update of an explicit step (§6.3,
    :func:`rftstatic.contact.kinematic.kinematic_contact`), in place on ``U``, ``V`` (N, 3) [m, m/s]; adds its
    ``-dE`` (C2, ``g`` the step's velocity increment from the forces; None: zero) to ``acc["contact"]``. Returns
    the number of nodes in contact."""
    from rftstatic.contact.kinematic import kinematic_contact

    X3 = model.X3
    x = X3 + U
    x_new, v_new, n_active = kinematic_contact(obstacles, x, V, friction, dt, x_old=x - dt * V,  # the step: U += dt V
                                               sweep=sweep)
    if n_active:
        # the projection along the normal must not give a supported dof a velocity (a node held in
        # x, y on a sphere would otherwise keep a spurious, never damped in-plane speed)
        v_new *= model.free
        acc["contact"] -= kinematic_change(mass, V, v_new, x_new - x, np.zeros_like(V) if g is None else g, dt,
                                           model.free)
        np.subtract(x_new, X3, out=U)
        V[...] = v_new
    return n_active
