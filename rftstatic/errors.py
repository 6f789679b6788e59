"""The errors a user meets, in one place (base layer: any module may raise them, the CLI catches them).

Each message names what is wrong (file, key, value; element, node; time, step) and what to do. The
input errors subclass :class:`ValueError`, the failures of a solve :class:`RuntimeError`.
"""

from __future__ import annotations


class SceneError(ValueError):
    """Invalid scene; the message names the file, the key and the value, and what to do."""


class MeshError(ValueError):
    """Invalid mesh input; the message names the problem and what to do."""


class MeshingError(ValueError):
    """Bad mesher input, or a front that cannot be closed.

    The message names the offending loop, value or location and says what to
    change.  It subclasses :class:`ValueError` so that callers validating
    scene input can catch both alike.
    """


class ParameterError(ValueError):
    """A bad option of a library function: ``"key: detail"``. The scene layer maps ``key`` to the scene
    key (e.g. ``h_lower`` -> ``remesh.h_lower``) and shows ``detail``."""

    def __init__(self, key: str, detail: str):
        super().__init__(f"{key}: {detail}")
        self.key, self.detail = key, detail


class PatchError(ValueError):
    """A singular patch: its six points lie (nearly) on one conic (C of Eq. 2 is singular)."""


class CheckpointError(ValueError):
    """A checkpoint that cannot be used (wrong model, unknown format, missing file)."""


class StepLimitError(ValueError):
    """An explicit run that cannot be stepped: its stable step collapsed (not a finite positive number) or it
    would need more steps than its limit. A run refused for it by a scene is an input error; the static
    route's relaxation turns it into a :class:`ConvergenceError` (the goal not reached)."""


class ConvergenceError(RuntimeError):
    """The static solve failed; ``result`` holds the last equilibrium reached (not converged)."""

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


class FallError(RuntimeError):
    """A dynamic relaxation whose sheet falls away: nothing holds it
    (:data:`rftstatic.solvers.relaxation.FALL_DIAGONALS`); the static route turns it into a
    :class:`ConvergenceError`."""


class InstabilityError(RuntimeError):
    """The explicit run became unstable; attributes ``t``, ``step``, ``dt`` and ``suggested_dt`` [s]."""

    def __init__(self, message, *, t, step, dt, suggested_dt):
        super().__init__(message)
        self.t, self.step, self.dt, self.suggested_dt = t, step, dt, suggested_dt
