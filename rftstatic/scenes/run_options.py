"""The options the app reads rather than a solver, declared once (:mod:`rftstatic.optionspec`): the
``[solver]`` table's mesh sequence, seeded specimens and membrane switch (:class:`RunOptions`), and the
cantilever tester's ``[cantilever]`` table (:class:`CantileverOptions`).

The static solver's own keys are :mod:`rftstatic.solvers.options`; the scene's ``[solver]`` table holds
both (:data:`SOLVER_GROUPS`), each key declared in exactly one group.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rftstatic.optionspec import check, option
from rftstatic.solvers.options import GROUPS

__all__ = ["CantileverOptions", "MAX_LEVELS", "MAX_SEEDS", "RunOptions", "SOLVER_GROUPS"]

MAX_LEVELS = 6
"""Most meshes of a sequence (the finest 2^5 = 32 times finer than the coarsest)."""

MAX_SEEDS = 100
"""Most seeded starts of one static drape."""


@dataclass(frozen=True, kw_only=True)
class RunOptions:
    """``[solver]`` keys of the app (scene keys ``solver.<name>``); ``levels = None`` is ``"auto"``."""

    levels: int | None = option(None, "mesh sequencing: meshes of the sequence, each about twice as coarse as the "
                                "next; the coarsest solved by the scene's route, the finer ones by Newton at full "
                                "load from the one below (1: none; auto: from 15,000 nodes, enough levels for a "
                                "coarsest mesh of at most 3,000)", kind="int", low=1, high=MAX_LEVELS)
    level_membrane: str = option("same", "mesh sequencing: same (the coarse levels keep the fabric) or matched "
                                 "(their membrane rigidity scaled by (h_finest / h)^2, the finest mesh's locking "
                                 "number)", choices=("same", "matched"))
    seeds: int = option(1, "static drape: run this many seeded starts (seed, seed + 1, ...), as a lab tests several "
                        "specimens; the summary reports their mean, range and fold counts", low=1, high=MAX_SEEDS)
    membrane: bool = option(True, "false: a linear Kirchhoff plate (bending only, no membrane)")
    compare: str = option("none", "static drape: also solve it from this start (a solver.start value) and keep the "
                          "stable minimum of lower energy (rftstatic.app.starts); none: the scene's route only",
                          choices=("none", "load-steps", "relax", "release"))

    def __post_init__(self):
        check(self, "solver")


SOLVER_GROUPS = (*GROUPS, RunOptions)
"""Every declared group of the scene's ``[solver]`` table."""


@dataclass(frozen=True, kw_only=True)
class CantileverOptions:
    """``[cantilever]`` of a cantilever-tester scene (Peirce; ASTM D1388, BS 3356); ``angle`` in SI [rad]."""

    angle: float = option(math.radians(41.5), "the tester's plane below the horizontal (41.5 deg in ASTM D1388 and "
                          "BS 3356)", unit="angle", low=math.radians(1.0), high=math.radians(80.0))
    growth: float = option(1.15, "overhang factor per step while the tip is above the plane", low=1.0, high=2.0,
                           open_low=True)
    tolerance: float = option(1e-7, "relative change of the overhang at which the root find stops", low=1e-12,
                              high=1e-2)
    max_solves: int = option(60, "most static solves (growth steps and root-find steps together)", low=3,
                             high=10_000)

    def __post_init__(self):
        check(self, "cantilever")
