"""Published reference solutions used by the tests and the validation reports.

Contents
--------
- :func:`load_sze2004` reads the ABAQUS S4R reference curves of Sze, Liu & Lo,
  "Popular benchmark problems for geometric nonlinear analysis of shells",
  Finite Elements in Analysis and Design 40 (2004) 1551-1569, shipped as CSV
  files in ``rftstatic/references/data`` (see ``SOURCES.md`` there).
- :data:`END_SHEAR`, :data:`END_MOMENT`, :data:`SLIT_ANNULAR`: the problem data
  of those three benchmarks (geometry, material, loads, reference mesh), in the
  paper's consistent dimensionless units.
- :mod:`rftstatic.references.plates`: Kirchhoff square-plate centre deflections
  (Timoshenko & Woinowsky-Krieger), with the Navier series computed here.
- :mod:`rftstatic.references.elastica`: the heavy cantilever elastica (a strip
  clamped at one end and bending under its own weight), solved with
  ``scipy.integrate.solve_bvp``.

The data are read with :mod:`importlib.resources`, so they are found wherever
the package is installed; nothing here reads outside the package.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from importlib import resources

import numpy as np

__all__ = [
    "SZE2004_NAMES",
    "CantileverStrip",
    "SlitAnnularPlate",
    "END_SHEAR",
    "END_MOMENT",
    "SLIT_ANNULAR",
    "load_sze2004",
]

SZE2004_NAMES = ("end_shear", "end_moment", "slit_annular")
"""Names accepted by :func:`load_sze2004`."""


class _IsotropicShellRigidities:
    """C and D of an isotropic shell with fields E, nu, h (C = E h / (1 - nu^2), D = E h^3 / (12 (1 - nu^2)))."""

    @property
    def C(self) -> float:
        """Membrane rigidity per unit width, E·h/(1−ν²) [force / length]."""
        return self.E * self.h / (1.0 - self.nu**2)

    @property
    def D(self) -> float:
        """Bending rigidity per unit width, E·h³/(12(1−ν²)) [force·length]."""
        return self.E * self.h**3 / (12.0 * (1.0 - self.nu**2))


@dataclass(frozen=True)
class CantileverStrip(_IsotropicShellRigidities):
    """A cantilever strip of Sze, Liu & Lo (2004), clamped at ``x = 0``.

    Attributes
    ----------
    name : str
        Benchmark name, as accepted by :func:`load_sze2004`.
    L, b, h : float
        Length, width and thickness [length].
    E : float
        Young's modulus [force / length²].
    nu : float
        Poisson's ratio [-].
    load_max : float
        Largest load: total end force [force] (``load_kind = "end_shear"``) or
        end moment [force·length] (``load_kind = "end_moment"``).
    load_kind : str
        ``"end_shear"`` (vertical force spread over the free edge, not a
        follower) or ``"end_moment"``.
    reference_mesh : tuple of int
        S4R mesh of the reference solution (along the length, across the width).
    """

    name: str
    L: float
    b: float
    h: float
    E: float
    nu: float
    load_max: float
    load_kind: str
    reference_mesh: tuple[int, int]

    @property
    def EI(self) -> float:
        """Bending stiffness of the strip, E·b·h³/12 [force·length²]."""
        return self.E * self.b * self.h**3 / 12.0



@dataclass(frozen=True)
class SlitAnnularPlate(_IsotropicShellRigidities):
    """The slit annular plate of Sze, Liu & Lo (2004).

    A radial slit at θ = 0; one side of it is clamped, the other carries a
    vertical line force.

    Attributes
    ----------
    name : str
        Benchmark name, as accepted by :func:`load_sze2004`.
    R_i, R_o : float
        Inner and outer radius [length].
    h : float
        Thickness [length].
    E : float
        Young's modulus [force / length²].
    nu : float
        Poisson's ratio [-].
    line_force_max : float
        Largest vertical line force on the loaded slit edge [force / length].
    reference_mesh : tuple of int
        S4R mesh of the reference solution (radial, circumferential).
    """

    name: str
    R_i: float
    R_o: float
    h: float
    E: float
    nu: float
    line_force_max: float
    reference_mesh: tuple[int, int]

    @property
    def total_force_max(self) -> float:
        """Largest total lifting force, line force × (R_o − R_i) [force]."""
        return self.line_force_max * (self.R_o - self.R_i)



END_SHEAR = CantileverStrip(
    name="end_shear", L=10.0, b=1.0, h=0.1, E=1.2e6, nu=0.0,
    load_max=4.0, load_kind="end_shear", reference_mesh=(16, 1),
)
"""Cantilever under an end shear force: EI = 100, P_max = 4 (Sze et al. 2004)."""

END_MOMENT = CantileverStrip(
    name="end_moment", L=12.0, b=1.0, h=0.1, E=1.2e6, nu=0.0,
    load_max=50.0 * math.pi / 3.0, load_kind="end_moment", reference_mesh=(16, 1),
)
"""Cantilever under an end moment: M_max = 2π·EI/L = 50π/3 rolls it into a circle."""

SLIT_ANNULAR = SlitAnnularPlate(
    name="slit_annular", R_i=6.0, R_o=10.0, h=0.03, E=21e6, nu=0.0,
    line_force_max=0.8, reference_mesh=(10, 80),
)
"""Slit annular plate under a lifting line force, P_max = 0.8 per length (total 3.2)."""


def load_sze2004(name: str) -> dict[str, np.ndarray]:
    """Load one reference curve of Sze, Liu & Lo (2004).

    Parameters
    ----------
    name : str
        One of ``"end_shear"``, ``"end_moment"``, ``"slit_annular"`` (the
        prefix ``"sze2004_"`` and suffix ``".csv"`` are accepted too).

    Returns
    -------
    dict of str to (n,) float ndarray
        One array per CSV column, keyed by the column header, e.g.
        ``load_fraction``, ``minus_u_tip``, ``w_tip`` for ``"end_shear"``
        (see ``data/SOURCES.md`` for every file's columns). Values are in the
        benchmark's consistent units.

    Raises
    ------
    ValueError
        If ``name`` is not one of the shipped benchmarks.
    """
    key = name.removeprefix("sze2004_").removesuffix(".csv")
    if key not in SZE2004_NAMES:
        raise ValueError(
            f"load_sze2004: unknown benchmark name = {name!r}; "
            f"use one of {', '.join(repr(n) for n in SZE2004_NAMES)}"
        )
    text = (
        resources.files(__package__).joinpath("data").joinpath(f"sze2004_{key}.csv")
        .read_text(encoding="utf-8")
    )
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], [r for r in rows[1:] if r]
    table = np.array(body, dtype=float)
    return {col.strip(): table[:, j].copy() for j, col in enumerate(header)}
