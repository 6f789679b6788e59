"""The options of the remeshing drivers (:func:`~rftstatic.remesh.static_driver.remesh_static`,
:func:`~rftstatic.remesh.relax_driver.remesh_relax`), declared once.

:class:`RemeshOptions` is the mesh sizing and the remeshing schedule (a scene's ``[remesh]`` table, in SI);
:class:`RemeshRelaxOptions` the motion of the remeshed relaxation. A bad value raises
:class:`~rftstatic.errors.ParameterError` naming the field.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ParameterError
from rftstatic.mesh import GRADATION
from rftstatic.remesh.adapt import DAMPING, check_remesh_parameters
from rftstatic.remesh.transfer import METHODS
from rftstatic.solvers.relaxation import RELAX_MASS_SCALE, RELAX_REST
from rftstatic.solvers.rest import RestCriterion

__all__ = ["RemeshOptions", "RemeshRelaxOptions"]


@dataclass(frozen=True, kw_only=True)
class RemeshOptions:
    """Sizing (Eq. 29: h_new = sqrt(const / |kappa|) in [h_lower, h_upper]) and schedule of the remeshing.

    Attributes
    ----------
    const : Eq. 29 constant [m], > 0; h_lower, h_upper : element size bounds [m], 0 < h_lower <= h_upper
    gradation : largest size ratio between neighbours one element apart [-], >= 1
    max_cycles : static route: most remeshing cycles [-], >= 0
    tol : stop when the node count changes by less than this fraction [-], > 0
    kappa_h_max : static route: largest |kappa| h accepted without remeshing [-] (None: node count alone)
    transfer : "mesh", "patch" or "grid" (:mod:`rftstatic.remesh.transfer`)
    every : relax route: remesh every this many steps [-] (None: on the curvature trigger and at rest)
    kappa_h2_max : relax route: remesh when max |kappa| h^2 exceeds this [m] (None: never on curvature)
    damping : relax route: "fixed" (the stepper's alpha) or "critical" (:func:`critical_damping`)
    """

    const: float
    h_lower: float
    h_upper: float
    gradation: float = GRADATION
    max_cycles: int = 5
    tol: float = 0.05
    kappa_h_max: float | None = None
    transfer: str = METHODS[0]
    every: int | None = None
    kappa_h2_max: float | None = None
    damping: str = DAMPING[0]

    def __post_init__(self):
        check_remesh_parameters(**dataclasses.asdict(self))


@dataclass(frozen=True, kw_only=True)
class RemeshRelaxOptions:
    """The motion of :func:`~rftstatic.remesh.relax_driver.remesh_relax` (§6).

    Attributes
    ----------
    alpha : mass damping [1/s], >= 0, of the default stepper (required without ``advance``; with
        ``RemeshOptions.damping = "critical"`` its upper bound)
    mass_scale : mass scaling s of the default stepper and of the kinetic energy [-] (§6: 100)
    chunk : steps per call of the stepper [-], >= 1
    max_steps : most steps [-], >= 1 (the run returns ``converged=False`` there)
    max_remesh : most remeshes [-], >= 0
    rest : the at-rest test (:class:`~rftstatic.solvers.rest.RestCriterion`; kinetic energy against its peak
        on the present mesh, out-of-balance force against the load)
    skip_settled : a remesh triggered by ``every`` or by the curvature is skipped when the mesh is settled.
        Measured on the clamped strip (s = 100, alpha = 3/s): remeshing every 5000 steps regardless kept the
        strip swinging for 200 000 steps (each new mesh differs by a few nodes and the transfer restarts the
        oscillation, as §5 warns); skipping settled meshes, it came to rest.
    """

    alpha: float | None = None
    mass_scale: float = RELAX_MASS_SCALE
    chunk: int = 200
    max_steps: int = 100_000
    max_remesh: int = 50
    rest: RestCriterion = RELAX_REST
    skip_settled: bool = True

    def __post_init__(self):
        if self.alpha is not None and not (_real(self.alpha) and self.alpha >= 0):
            raise ParameterError("alpha", f"must be a mass damping >= 0 [1/s] or None, got {self.alpha!r}")
        if not (_real(self.mass_scale) and self.mass_scale > 0):
            raise ParameterError("mass_scale", f"must be > 0, got {self.mass_scale!r}")
        for key, least in (("chunk", 1), ("max_steps", 1), ("max_remesh", 0)):
            v = getattr(self, key)
            if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= least):
                raise ParameterError(key, f"must be an integer >= {least}, got {v!r}")
        if not isinstance(self.rest, RestCriterion):
            raise ParameterError("rest", f"must be a RestCriterion, got {self.rest!r}")


def _real(v) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and bool(np.isfinite(v))
