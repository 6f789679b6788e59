"""Whether the optional compiled kernels (numba: ``element/_kernels_numba.py``, the compiled twins of
``element/kernels.py``) can be used, and on how many threads."""

import os
from functools import cache

PARALLEL_MIN_ELEMENTS = 4000
"""Smallest mesh whose explicit internal force is spread over threads: below it, waking the threads
costs more than the work."""


STATIC_COMPILED_MIN_ELEMENTS = 3000
"""Smallest mesh whose static membrane kernels (energy, force, tangent) run compiled when numba has not
been loaded yet: importing numba and loading the first cached kernel cost about 1 s, more than the numpy
twins lose on a small mesh in a whole solve (measured, fresh processes, the §4.1 strip in 38 Newton
iterations: 51 x 11 nodes, 1000 RFT6 elements, 2.95 s numpy against 4.3 s compiled; 101 x 5, 800
elements, 2.3 s against 3.2 s; 101 x 21, 4000 elements, 8.5 s against 6.0 s)."""


@cache
def numba_available() -> bool:
    """True when numba is installed (the ``fast`` extra); the kernels' numpy twins are used otherwise.
    Found without importing it (that alone takes 0.6 s)."""
    from importlib.util import find_spec

    return find_spec("numba") is not None


def compiled_loaded() -> bool:
    """Whether the compiled kernels are already loaded in this process (then they cost nothing more)."""
    import sys

    return "rftstatic.element._kernels_numba" in sys.modules


NUMPY_BUDGET_S = 1.0
"""Seconds the "auto" back end may spend in the numpy twins before it loads the compiled kernels (about
what loading costs): a process that solves one small scene never pays for numba, one that solves many
(a validation report, a study) pays at most twice the cheaper choice (the ski-rental rule). The
sze2004 report's small cantilevers took 0.37 s instead of 0.04 s each on the numpy twins alone.

The seconds are modelled, not read from the clock: each numpy call charges its rows (elements, pairs,
nodes) times a cost per row measured once (:func:`charged_numpy`), so the switch to the compiled twins
falls at the same call in every run of the same command. The twins agree to round-off only, and a
clock-charged budget made runs of one command differ there: pedestal-square-20 on 33 x 33 by
arc-length, three runs each (2026-12-02, the machine loaded by two other jobs): total energy
-9.770568309163982, ...4037, ...4005 gf cm with the clock, ...4037 three times with the numpy twins
throughout, ...3998 three times with this budget; on the 7,800-step path of the 31 x 240 round
pedestal such a difference picked another fold branch."""

_numpy_seconds = [0.0]


def charge_numpy(seconds: float) -> None:
    """Count ``seconds`` (modelled: rows times a cost per row, :data:`NUMPY_BUDGET_S`) spent in a numpy
    twin chosen by the "auto" back end."""
    _numpy_seconds[0] += seconds


def numpy_budget_spent() -> bool:
    """Whether the numpy twins chosen by "auto" back ends have used up :data:`NUMPY_BUDGET_S` in this process."""
    return _numpy_seconds[0] > NUMPY_BUDGET_S


def charged_numpy(loaded, per_row: float):
    """Decorator: a call of the wrapped function charges ``per_row`` seconds [s] per row of its first array
    argument to the numpy budget (:func:`charge_numpy`) when ``loaded()`` (whether the compiled twins are
    in this process) is false before and after the call, i.e. when it ran the numpy twin. Nested charged
    calls count once."""
    import functools

    import numpy as np

    def rows(args, kwargs) -> int:
        for a in (*args, *kwargs.values()):
            if isinstance(a, np.ndarray):
                return len(a) if a.ndim else 1
        return 0

    def wrap(f):
        @functools.wraps(f)
        def charged(*args, **kwargs):
            if _depth[0] or loaded():
                return f(*args, **kwargs)
            _depth[0] += 1
            try:
                return f(*args, **kwargs)
            finally:
                _depth[0] -= 1
                if not loaded():
                    charge_numpy(per_row * rows(args, kwargs))
        return charged
    return wrap


_depth = [0]


def static_kernels_compiled(n_elements: int) -> bool:
    """Whether the static membrane kernels of a mesh of ``n_elements`` run compiled ("auto" back end):
    numba installed, and the mesh large enough to repay loading it (:data:`STATIC_COMPILED_MIN_ELEMENTS`),
    the kernels loaded already, or the numpy twins used up :data:`NUMPY_BUDGET_S` in this process."""
    return numba_available() and (n_elements >= STATIC_COMPILED_MIN_ELEMENTS or compiled_loaded()
                                  or _numpy_seconds[0] > NUMPY_BUDGET_S)


def force_threads(n_elements: int) -> int:
    """Most threads for the explicit internal force of a mesh of ``n_elements`` triangles.

    ``RFTSTATIC_THREADS`` (an integer >= 1) decides when set; otherwise every core numba may use
    (``NUMBA_NUM_THREADS``, itself at most the machine's cores) for meshes of at least
    :data:`PARALLEL_MIN_ELEMENTS`, and one thread below.
    """
    fixed = fixed_threads()
    if fixed is not None:
        return fixed
    if not numba_available() or n_elements < PARALLEL_MIN_ELEMENTS:
        return 1
    import numba

    return max(1, int(numba.config.NUMBA_NUM_THREADS))


def fixed_threads() -> int | None:
    """``RFTSTATIC_THREADS`` as an integer >= 1, or None when unset."""
    text = os.environ.get("RFTSTATIC_THREADS", "").strip()
    if not text:
        return None
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"RFTSTATIC_THREADS must be an integer >= 1, got {text!r}; unset it for the default")
    return n


class ThreadTuner:
    """Picks, and keeps picking, the faster of one thread and ``most`` threads for a repeated call.

    On a machine shared with other jobs a parallel loop waits at its barrier for a thread that is
    not running: on the 2-core machine with one core busy, two threads took 6.5 ms per force
    kernel call of the 80 cm sheet (81 x 81) against 3.6 ms for one (2.4 ms on an idle machine).
    So the explicit loop measures:
    every :attr:`hold` calls it times :attr:`probe` calls with each setting and keeps the faster
    until the next check. The kernels' sums do not depend on the thread count, only their speed.
    """

    probe = 10
    hold = 2000

    def __init__(self, most: int):
        self.most = most
        self.calls = 0
        self.threads = most
        self._times = {1: 0.0, most: 0.0}

    def before(self) -> int:
        """Threads for the next call."""
        k = self.calls % (2 * self.probe + self.hold)
        if k < self.probe:
            return 1
        if k < 2 * self.probe:
            return self.most
        return self.threads

    def after(self, threads: int, seconds: float) -> None:
        """Record the time of the call just made with ``threads``."""
        k = self.calls % (2 * self.probe + self.hold)
        if k < 2 * self.probe:
            self._times[threads] += seconds
            if k == 2 * self.probe - 1:
                self.threads = 1 if self._times[1] <= self._times[self.most] else self.most
                self._times = {1: 0.0, self.most: 0.0}
        self.calls += 1
