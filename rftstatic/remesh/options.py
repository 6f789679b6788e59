"""The options of the remeshing drivers (:func:`~rftstatic.remesh.static_driver.remesh_static`,
:func:`~rftstatic.remesh.relax_driver.remesh_relax`), declared once.

:class:`RemeshOptions` is the mesh sizing and the remeshing schedule (a scene's ``[remesh]`` table, in SI,
declared as data: :mod:`rftstatic.optionspec`; a bad value raises :class:`~rftstatic.errors.ParameterError`
naming ``remesh.<field>``); :class:`RemeshRelaxOptions` the motion of the remeshed relaxation (set by the app,
not a scene table; a bad value names the field).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rftstatic.errors import ParameterError
from rftstatic.mesh import GRADATION
from rftstatic.optionspec import REQUIRED, check, option
from rftstatic.remesh.adapt import DAMPING
from rftstatic.remesh.transfer import METHODS
from rftstatic.solvers.rest import RELAX_MASS_SCALE, RELAX_REST, RestCriterion

__all__ = ["RemeshOptions", "RemeshRelaxOptions"]


@dataclass(frozen=True, kw_only=True)
class RemeshOptions:
    """Sizing (Eq. 29: h_new = sqrt(const / |kappa|) in [h_lower, h_upper]) and schedule of the remeshing: a
    scene's ``[remesh]`` table, in SI. Each field is declared once (:func:`rftstatic.optionspec.option`, ranges
    in SI); a bad value raises :class:`~rftstatic.errors.ParameterError` naming ``remesh.<field>``. Beyond the
    ranges: h_lower <= h_upper.

    Attributes
    ----------
    const, h_lower, h_upper : Eq. 29 constant and element size bounds [m], required
    gradation, max_cycles, tol, kappa_h_max, transfer, every, kappa_h2_max, damping : as their help says
        (:func:`~rftstatic.remesh.transfer.transfer_fields` for ``transfer``, :func:`critical_damping` for
        ``damping = "critical"``)
    """

    const: float = option(REQUIRED, "const of Eq. 29, |kappa| h^2 = const", kind="float", unit="length", low=0.0,
                          open_low=True)
    h_lower: float = option(REQUIRED, "smallest element size", kind="float", unit="length", low=0.0, open_low=True)
    h_upper: float = option(REQUIRED, "largest element size", kind="float", unit="length", low=0.0, open_low=True)
    gradation: float = option(GRADATION, "largest size ratio between neighbours one element apart", low=1.0)
    max_cycles: int = option(5, "static route: most remeshing cycles", low=0)
    tol: float = option(0.05, "stop when the node count changes by less than this fraction", low=0.0,
                        open_low=True)
    kappa_h_max: float | None = option(None, 'static route: largest |kappa| h accepted without remeshing ("auto": '
                                       "the node count alone decides)", kind="float", low=0.0, open_low=True)
    transfer: str = option(METHODS[0], "mesh (interpolation on the old mesh), patch (its RF patch quadratics) or "
                           "grid (background grid, as the paper)", choices=METHODS)
    every: int | None = option(None, 'relax route: remesh every this many steps ("auto": on the curvature '
                               "trigger and at rest only)", kind="int", low=1)
    kappa_h2_max: float | None = option(None, 'relax route: remesh when max |kappa| h^2 exceeds this ("auto": '
                                        "never on curvature)", kind="float", unit="length", low=0.0, open_low=True)
    damping: str = option(DAMPING[0], "relax route: fixed (dynamics.alpha) or critical (for the hanging sheet's "
                          "slowest swing, at most dynamics.alpha)", choices=DAMPING)

    def __post_init__(self):
        check(self, "remesh")
        if self.h_lower > self.h_upper:
            raise ParameterError("remesh.h_lower", f"h_lower = {self.h_lower} exceeds h_upper = {self.h_upper}; "
                                 "Eq. 29 clips h_target to [h_lower, h_upper]: swap them")


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
