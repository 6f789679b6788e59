"""The ``[solver]`` keys that the app reads rather than the solver: the mesh sequence, the seeded specimens
and the membrane switch of the model, declared once (:mod:`rftstatic.optionspec`).

The static solver's own keys are :mod:`rftstatic.solvers.options`; the scene's ``[solver]`` table holds
both (:data:`SOLVER_GROUPS`), each key declared in exactly one group.
"""

from __future__ import annotations

from dataclasses import dataclass

from rftstatic.optionspec import check, option
from rftstatic.solvers.options import GROUPS

__all__ = ["MAX_LEVELS", "MAX_SEEDS", "RunOptions", "SOLVER_GROUPS"]

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

    def __post_init__(self):
        check(self, "solver")


SOLVER_GROUPS = (*GROUPS, RunOptions)
"""Every declared group of the scene's ``[solver]`` table."""
