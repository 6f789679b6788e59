"""What a run of an analysis returns: the summary as written to ``summary.json`` and the solved state."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class RunResult:
    """Outcome of one analysis of a scene (:func:`rftstatic.app.registry.run`).

    Attributes
    ----------
    summary : the summary as written to ``out/summary.json`` (plain Python types, scene units)
    model : the :class:`~rftstatic.model.model.Model` of the final state (after remeshing: the last mesh)
    U : (N, 3) final displacements [m]
    extras : obstacles and probes [m] of the scene (:func:`rftstatic.scenes.build.build_model`)
    out : the output folder
    slip : the frictions' committed slips (E, k) of the final state (bending 2HB, shear 2HG:
        :meth:`rftstatic.model.model.Model.initial_slip`), what a run going on from ``U`` starts from; None without
        hysteresis, or where the analysis does not keep them (mesh sequencing)
    """

    summary: dict
    model: object
    U: np.ndarray
    extras: dict = field(default_factory=dict)
    out: Path | None = None
    slip: np.ndarray | None = None

    @property
    def converged(self) -> bool:
        """The summary's ``converged`` flag (static: equilibrium at full load; relax: at rest)."""
        return bool(self.summary.get("converged", False))
