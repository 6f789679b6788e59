"""The stability matrix (issue 7 item 3): does every solver either converge correctly or stop clearly?

Each *cell* is one solve at an extreme of stiffness ratio, mesh, load or time step. A cell runs in
a fresh child interpreter (spawned, never forked: :mod:`rftstatic.validate.stability.runner`) with
a wall-time budget, after which it is killed, so nothing can hang the report; every exception is
caught there and recorded by type and message. Outcomes:

- ``pass``: converged, and within the tolerance of its reference where one exists (heavy elastica
  for strips, Timoshenko/Navier for plates, the exact circle for the end-moment roll-up, a run at
  half the step for explicit runs, ``sqrt(s)`` for mass scaling);
- ``converged``: converged, no reference (pedestal drapes);
- ``expected stop``: stopped with the error that is the right behaviour (``InstabilityError`` above the
  critical step, with a suggested step that then runs; ``PatchError``/``MeshError`` naming the element
  for a degenerate patch);
- ``limitation``: stopped with a clear error (``ConvergenceError``) although a solution exists, or
  converged outside the tolerance on a model that warned at construction that this mesh is outside
  its accuracy (RFT6 membrane locking, :func:`rftstatic.model.model.locking_number`);
- ``FAIL``: a hang (budget exceeded), a crash (an unexpected exception type, or the process died), or a
  wrong answer reported as converged (error above tolerance). The benchmark passes without FAIL cells.

Cells record how the solver helped itself: load steps, cutbacks, Newton iterations, and the
tangent modes (``exact``, ``psd``: compressive stress dropped, ``shift``: Levenberg-Marquardt shift,
``reused``: modified Newton steps).

Strip cells use Kang & Yu's wool strip of §4.1 (5 x 1 cm, clamped, own weight); the stiffness ratio
C/B [1/cm^2] scales all membrane rigidities with B fixed (wool: C_warp/B_warp = 1.35e4 /cm^2).
Tip error = |computed - elastica tip| / L, the computed tip the mean of the nodes at x = L.

Modules: :mod:`~rftstatic.validate.stability.cell_functions` (what a cell computes),
:mod:`~rftstatic.validate.stability.matrix` (the cells, their budgets and tolerances, the verdict),
:mod:`~rftstatic.validate.stability.runner` (a cell in a child process),
:mod:`~rftstatic.validate.stability.report` (:func:`run`: the matrix and its report).
"""

from rftstatic.validate.stability.cell_functions import (
    end_moment_cell,
    explicit_dt_cell,
    mass_scale_cell,
    pedestal_cell,
    plate_cell,
    scene_override_cell,
    strip_cell,
)
from rftstatic.validate.stability.matrix import Cell, cells, plate_tolerance, strip_tolerance, verdict
from rftstatic.validate.stability.report import run
from rftstatic.validate.stability.runner import run_cell

__all__ = ["Cell", "cells", "end_moment_cell", "explicit_dt_cell", "mass_scale_cell", "pedestal_cell", "plate_cell",
           "plate_tolerance", "run", "run_cell", "scene_override_cell", "strip_cell", "strip_tolerance", "verdict"]
