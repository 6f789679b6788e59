"""Damping laws of dynamic relaxation (§6) beyond the viscous mass damping of Eq. 27: FIRE and kinetic damping.

The explicit loop (:mod:`rftstatic.solvers.explicit`, Eq. 20-22) with ``alpha = 0`` is undamped; a law here acts on
its half-step velocities after each velocity update (Eq. 21), before the position update (Eq. 22), on the free
dofs. The step stays the explicit solver's stable step (:func:`rftstatic.solvers.timestep.stable_time_step`, with
the mass scaling): the central-difference scheme is only conditionally stable, so FIRE's step growth is not used
(its ``dt_max`` is that stable step, and the run starts there).

FIRE (Bitzek et al., PRL 97, 170201, 2006; FIRE 2.0 of Guenole et al., Comput. Mater. Sci. 173, 109584, 2020), with
the force ``F = P - F_int(D_n)`` and the masses ``M`` (lumped, mass scaled) in the metric ``|x|_M^2 = x . M x``:

    power  p = F . v_(n-1/2)
    p > 0: v_(n+1/2) = (1 - a) v + a |v|_M g / |g|_M,  g = M^-1 F,  v = v_(n-1/2) + dt g     (velocity mixing)
           after ``delay`` steps with p > 0 in a row: a <- a f_alpha
    p <= 0: v = 0 at t_n, a = a_start: v_(n+1/2) = dt g / 2 (the consistent start from rest)

The restart from rest takes half a kick, not FIRE's whole one, and FIRE 2.0's back-step ``D_n - dt v_(n-1/2) / 2``
is left out: at the stable step of the central differences (``omega dt`` up to 2) a stiff mode reset at every step
grows by ``|1 - omega^2 dt^2|`` a step with the whole kick (3.2x at ``omega dt = 1.8``; with the back-step 2.8x:
cusick-30 blew up in 15 steps), by ``|1 - omega^2 dt^2 / 2| < 1`` with the half kick.

The mixing never raises ``|v|_M`` (a convex combination of two vectors of its length). The kinetic energy a law
takes at step n (that of the mean of the two half-step velocities, without the law less with it) enters the run's
``dissipated`` (as the damping term) at step n, the rest of the law's change of the scheme's energy at step n + 1
(:func:`rftstatic.solvers.explicit._apply_law`), keeping ``total`` balanced at every sample.

Kinetic damping (Cundall 1976; Barnes, Int. J. Space Struct. 14, 1999): undamped motion, the kinetic energy of the
half-step velocities ``T_(n+1/2)`` watched at every step; when it falls (``T_(n+1/2) < T_(n-1/2)``), it has passed
a peak, which lies within dt / 2 of ``D_n``: the motion starts again from rest there (``v_(n+1/2) = dt g / 2``).
Barnes's back-correction of the position to the peak of the parabola through the last three values is left out:
at the stable step a stiff mode's kinetic energy swings within a step and the parabola's peak is no estimate (the
5 cm strip from a rough start gained 1.3e-3 J of a 1.4e-3 J scale with it, tests/solvers/test_damping.py).

Both laws zero the velocities again and again, so the kinetic energy of a sample says little of rest; the rest test
of the relaxation (:class:`~rftstatic.solvers.rest.AtRest`) gets :meth:`DampingLaw.rest_kinetic`: the largest
kinetic energy of the samples since the reset before the last one (the last complete swing and the current).
The law's state lives in the run's records (``acc["law"]``, checkpointed with them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ParameterError

__all__ = ["DAMPINGS", "DampingLaw", "make_law"]

DAMPINGS = ("viscous", "fire", "kinetic", "viscous-fire")
"""The damping laws of an explicit run: mass damping ``alpha`` (Eq. 27, the default), FIRE, kinetic damping, and
the mass damping until the kinetic energy has fallen to :data:`HANDOFF` of its peak, FIRE after."""

HANDOFF = 0.1
"""Kinetic energy / its peak [-] at which ``"viscous-fire"`` hands the motion from the mass damping to FIRE."""


@dataclass(frozen=True)
class DampingLaw:
    """A velocity law of the explicit loop (module docstring): ``"fire"`` or ``"kinetic"``.

    Attributes
    ----------
    name : ``"fire"`` or ``"kinetic"``
    a_start : FIRE's mixing factor after a reset [-], in (0, 1) (FIRE 2.0: 0.25; Bitzek et al.: 0.1)
    f_alpha : FIRE's factor on the mixing factor per step of positive power after the delay [-], in (0, 1]
    delay : FIRE's steps of positive power before the mixing factor decays [-] (N_delay, FIRE 2.0: 20)
    after : the law takes over from the mass damping ``alpha`` once the kinetic energy of a sample has fallen to this
        fraction of its peak [-], in [0, 1) (0: from the start)
    """

    name: str
    a_start: float = 0.1
    f_alpha: float = 0.99
    delay: int = 5
    after: float = 0.0

    def __post_init__(self):
        if self.name not in DAMPINGS[1:3]:
            raise ParameterError("damping", f'"{self.name}" is no velocity law; use one of {", ".join(DAMPINGS[1:3])}')
        if not 0.0 < self.a_start < 1.0:
            raise ParameterError("a_start", f"must lie in (0, 1), got {self.a_start!r}")
        if not 0.0 <= self.after < 1.0:
            raise ParameterError("after", f"must lie in [0, 1), got {self.after!r}")
        if not 0.0 < self.f_alpha <= 1.0:
            raise ParameterError("f_alpha", f"must lie in (0, 1], got {self.f_alpha!r}")

    def begin(self, acc: dict) -> dict:
        """The law's state in the run's records ``acc`` (new, or the one a resumed run saved)."""
        return acc.setdefault("law", {"a": self.a_start, "positive": 0, "resets": 0, "kin": [0.0, 0.0],
                                      "swing": 0.0, "last_swing": 0.0, "on": self.after == 0.0})

    def switch(self, s: dict, kinetic: float) -> None:
        """Take over from the mass damping when a sample's kinetic energy ``kinetic`` [J] has fallen to ``after``
        of the samples' peak."""
        s["peak"] = max(s.get("peak", 0.0), kinetic)
        if kinetic <= self.after * s["peak"] and s["peak"] > 0.0:
            s["on"] = True

    def __call__(self, s: dict, U, V, Vnew, g, mass, free, dt) -> float:
        """Apply the law at step n: ``V`` = v_(n-1/2), ``Vnew`` = v_(n+1/2) of the undamped update (in place),
        ``g = dt M^-1 F`` (N, 3) [m/s] (zero on held dofs), ``U`` = D_n [m] (moved in place by a reset), ``mass``
        (N,) [kg], ``free`` (N, 3) bool, ``dt`` [s]; returns the kinetic energy taken [J]: that of step n as the run
        measures it (mean of the two half-step velocities) without the law less that with it."""
        before = _kinetic_energy(mass, V, Vnew)
        if self.name == "fire":
            self._fire(s, U, V, Vnew, g, mass, free, dt)
        else:
            self._kinetic(s, U, V, Vnew, g, mass, free, dt)
        return before - _kinetic_energy(mass, V, Vnew)

    def _fire(self, s, U, V, Vnew, g, mass, free, dt) -> None:
        power = float(np.einsum("n,ni,ni->", mass, g, V))  # dt F . v
        if power <= 0.0:
            np.multiply(g, 0.5, out=Vnew)
            s["a"], s["positive"] = self.a_start, 0
            self._reset(s)
            return
        v2 = float(np.einsum("n,ni,ni->", mass, Vnew, Vnew))
        g2 = float(np.einsum("n,ni,ni->", mass, g, g))
        a = s["a"]
        if g2 > 0.0:
            Vnew *= 1.0 - a
            Vnew += (a * np.sqrt(v2 / g2)) * g
        s["positive"] += 1
        if s["positive"] > self.delay:
            s["a"] = a * self.f_alpha

    def _kinetic(self, s, U, V, Vnew, g, mass, free, dt) -> None:
        t_new = 0.5 * float(np.einsum("n,ni,ni->", mass, Vnew, Vnew))
        t_now = s["kin"][1]
        s["kin"] = [t_now, t_new]
        if not t_new < t_now:
            return
        np.multiply(g, 0.5, out=Vnew)  # from rest at D_n, within dt / 2 of the peak
        s["kin"] = [0.0, 0.0]
        self._reset(s)

    @staticmethod
    def _reset(s) -> None:
        s["resets"] += 1
        s["last_swing"], s["swing"] = s["swing"], 0.0

    @staticmethod
    def rest_kinetic(s: dict, kinetic: float) -> float:
        """The kinetic energy [J] the rest test sees at a sample of kinetic energy ``kinetic`` [J]: the largest
        since the reset before the last one (module docstring)."""
        s["swing"] = max(s["swing"], kinetic)
        return max(s["swing"], s["last_swing"])


def _kinetic_energy(mass, V, Vnew) -> float:
    """Kinetic energy [J] at step n from the half-step velocities ``V``, ``Vnew`` (N, 3) [m/s] and ``mass`` (N,)
    [kg], as the explicit run's samples measure it (their mean)."""
    vbar = 0.5 * (V + Vnew)
    return 0.5 * float(np.einsum("n,ni,ni->", mass, vbar, vbar))


def make_law(damping: str) -> DampingLaw | None:
    """The velocity law of ``damping`` (one of :data:`DAMPINGS`); None for viscous damping (the loop's own)."""
    if damping not in DAMPINGS:
        raise ParameterError("damping", f'"{damping}" is unknown; use one of {", ".join(DAMPINGS)}')
    if damping == "viscous-fire":
        return DampingLaw("fire", after=HANDOFF)
    return None if damping == "viscous" else DampingLaw(damping)
