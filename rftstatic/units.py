"""Unit systems of scene files and their conversion to the package's SI units.

The paper works in cm, gram-force (gf) and seconds; 1 gf = 9.80665e-3 N and a fabric
"weight" of 0.019 gf/cm^2 is a mass of 0.019 g/cm^2 under standard gravity.
Inside the package everything is SI (m, kg, s, N). A :class:`UnitSystem` knows the SI
value of one scene unit of length, force and time; derived quantities follow.
"""

from __future__ import annotations

from dataclasses import dataclass

STANDARD_GRAVITY = 9.80665
"""Standard acceleration of gravity [m/s^2]."""


@dataclass(frozen=True)
class UnitSystem:
    """A coherent set of scene units, given by their SI values.

    Parameters
    ----------
    name : str
        Name used in scene files (``units = "cm-gf-s"``).
    length, force, time : float
        SI value of one scene unit of length [m], force [N] and time [s].
    """

    name: str
    length: float
    force: float
    time: float = 1.0

    # derived SI factors: multiply a scene value by these to get SI
    @property
    def area(self) -> float:
        return self.length**2

    @property
    def pressure(self) -> float:
        """Force per area (fabric weight, pressure) [N/m^2 per scene unit]."""
        return self.force / self.length**2

    @property
    def line_force(self) -> float:
        """Force per length (tensile/shear rigidity, edge load) [N/m per scene unit]."""
        return self.force / self.length

    @property
    def moment(self) -> float:
        """Moment (bending/twisting rigidity per unit width x curvature) [N m per scene unit]."""
        return self.force * self.length

    @property
    def moment_length(self) -> float:
        """Moment x length (the k2 of nonlinear bending: moment per width per curvature^2) [N m^2 per scene
        unit]."""
        return self.force * self.length**2

    @property
    def acceleration(self) -> float:
        return self.length / self.time**2

    @property
    def velocity(self) -> float:
        return self.length / self.time

    @property
    def energy(self) -> float:
        return self.force * self.length

    @property
    def stiffness_volumetric(self) -> float:
        """Penalty stiffness, force per length^3 [N/m^3 per scene unit]."""
        return self.force / self.length**3

    def to_si(self, value, kind: str):
        """Convert ``value`` in scene units of ``kind`` (e.g. ``"length"``) to SI."""
        return value * getattr(self, kind)

    def from_si(self, value, kind: str):
        """Convert an SI ``value`` of ``kind`` to scene units."""
        return value / getattr(self, kind)


UNIT_SYSTEMS = {
    "cm-gf-s": UnitSystem("cm-gf-s", length=1e-2, force=STANDARD_GRAVITY * 1e-3),
    "SI": UnitSystem("SI", length=1.0, force=1.0),
    "mm-N-s": UnitSystem("mm-N-s", length=1e-3, force=1.0),
    "cm-dyn-s": UnitSystem("cm-dyn-s", length=1e-2, force=1e-5),
    # dimensionless benchmarks (Timoshenko plates, Sze et al. 2004): numbers are used as they are
    "consistent": UnitSystem("consistent", length=1.0, force=1.0),
}


def unit_system(name: str) -> UnitSystem:
    """Look up a unit system by its scene name, with an error that lists the known ones."""
    try:
        return UNIT_SYSTEMS[name]
    except KeyError:
        known = ", ".join(f'"{k}"' for k in UNIT_SYSTEMS)
        raise ValueError(f'unknown unit system "{name}"; use one of {known}') from None
