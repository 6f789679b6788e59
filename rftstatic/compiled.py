"""Whether the optional compiled kernels (numba: ``element/_kernels_numba.py``, the compiled twins of
``element/kernels.py``) can be used, which a run uses (:func:`choose_kernels`), and on how many threads."""

import os
from functools import cache

PARALLEL_MIN_ELEMENTS = 1000
"""Smallest mesh whose explicit internal force is spread over threads (:class:`ThreadTuner` then keeps the faster
of one and all, and one on a busy machine: :data:`BUSY_LOAD`). The kernel alone pays on two threads from about a
thousand elements (``python -m rftstatic.bench.explicit --threads SCENE``, the fastest of 1,000 calls each, the
same force bits; the kernel vectorised across element blocks, :data:`rftstatic.element.kernels.LANES`, one thread
-> two: cusick-30's 3,840 elements 0.21-0.24 -> 0.15 ms, 2,048 elements 0.21 -> 0.16 ms, 1,536 0.13 -> 0.10 ms,
512 0.088 -> 0.083 ms, 384 0.025 -> 0.026 ms; one element at a time they were 0.59 -> 0.30, 0.40 -> 0.24,
0.24 -> 0.18, 0.14 -> 0.12 ms). The whole run before the lanes: cusick-30 near idle (load average 0.9-1.1 with
the run), five pairs one after the other, 7.6-8.0 s at the earlier limit of 4,000 (one thread) against 5.4-5.9 s
here, the same bits (validation/bench_profile.md, "Two threads for the Cusick specimen"); on a machine loaded to
4-6, before the busy rule existed, two threads had cost it 5-49 %. With the lanes: 4.1-5.4 s (validation/
bench_profile.md, "Explicit kernel, SIMD/layout")."""


STATIC_COMPILED_MIN_ELEMENTS = 3000
"""Smallest mesh whose run uses the compiled kernels (:func:`choose_kernels`): importing numba and loading
the first cached kernel cost about 1 s, more than the numpy twins lose on a small mesh in a whole solve
(measured, fresh processes, the §4.1 strip in 38 Newton iterations: 51 x 11 nodes, 1000 RFT6 elements,
2.95 s numpy against 4.3 s compiled; 101 x 5, 800 elements, 2.3 s against 3.2 s; 101 x 21, 4000
elements, 8.5 s against 6.0 s)."""

KERNELS = ("numpy", "compiled")
"""The kernel back ends of a run: the numpy twins (vectorised over elements or pairs) or the compiled
ones (numba). They agree to round-off only, so a run uses one, chosen before it starts
(:func:`choose_kernels`), whatever ran before it in the process."""



def compiled_twin(f, name: str, scope: dict, **options):
    """Put a numba-compiled copy of the kernel ``f`` into ``scope`` as ``name`` and return it: the compiled twins of
    a kernel module (``_*_numba.py``) are copies of its functions whose globals are ``scope`` (the module's names,
    with each compiled twin replacing its source as it is made, so the loops call the compiled helpers; ``options``
    e.g. ``inline="always"`` for a per-point helper). Cached on disk (numba keys the cache on ``f``'s source file and
    ``name``); ``error_model="numpy"``: no zero-division checks (the kernels divide only by values kept away from
    zero). Imports numba: call it from a module loaded only when numba is used."""
    import types

    import numba

    copy = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    copy.__qualname__ = name  # numba's cache entry is named after it
    copy.__doc__ = f.__doc__
    scope[name] = numba.njit(copy, cache=True, nogil=True, error_model="numpy", **options)
    return scope[name]

@cache
def numba_available() -> bool:
    """True when numba is installed (the ``fast`` extra); the kernels' numpy twins are used otherwise.
    Found without importing it (that alone takes 0.6 s)."""
    from importlib.util import find_spec

    return find_spec("numba") is not None


def choose_kernels(n_elements: int, *, self_contact: bool = False, long_run: bool = False,
                   requested: str | None = None) -> str:
    """The kernel back end (one of :data:`KERNELS`) of a run on a mesh of ``n_elements`` triangles.

    ``requested`` (``"numpy"`` or ``"compiled"``) decides when given (``"compiled"`` needs numba).
    Otherwise ``"compiled"`` when numba is installed and the mesh has at least
    :data:`STATIC_COMPILED_MIN_ELEMENTS` elements, or the run has self-contact (its pair kernels: a 12 x 12
    PSD projection costs 87 us per pair in numpy, so a fold of a few thousand pairs repays loading numba
    within a few tangents, and an explicit run calls them about ten times a step), or it is a ``long_run``
    (a route of thousands of evaluations: arc length, an explicit or relaxation run; sphere-30 at 17 x 17,
    512 elements, by arc length: 3,390 Newton iterations, 17.9 s numpy against 13.4 s compiled with a warm
    cache, while loading the cached kernels costs about 0.3 s); ``"numpy"`` else.
    A function of the scene alone: the same scene runs on the same kernels in any process, after any
    other run (a process-wide budget of numpy seconds, which switched to the compiled twins part-way,
    made a result depend on what had run before it)."""
    if requested is not None:
        if requested not in KERNELS:
            raise ValueError(f'kernels must be one of {", ".join(KERNELS)}, got {requested!r}')
        if requested == "compiled" and not numba_available():
            raise ValueError('kernels "compiled" need numba: pip install "rftstatic[fast]"')
        return requested
    if numba_available() and (n_elements >= STATIC_COMPILED_MIN_ELEMENTS or self_contact or long_run):
        return "compiled"
    return "numpy"


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


BUSY_LOAD = 2.0
"""Load average above the thread count at which :class:`ThreadTuner` takes one thread (other jobs' runnable
threads; this run's own threads count up to the thread count). sphere-30, whole process (``bench scenes``), two
tuned threads against ``RFTSTATIC_THREADS=1``: at load 2.9-3.1 23.8 against 33.3 s (two pay), at 4.4-6.2 40.1,
41.3, 48.9, 49.4 against 32.7, 25.5, 46.3, 40.7 s (one pays); 2 on 2 cores: one thread above a load of 4."""


def busy(threads: int) -> bool:
    """Whether the machine's 1-minute load average exceeds ``threads`` + :data:`BUSY_LOAD` (False where the
    system has no load average)."""
    try:
        return os.getloadavg()[0] > threads + BUSY_LOAD
    except OSError:
        return False


class ThreadTuner:
    """Picks, and keeps picking, the faster of one thread and ``most`` threads for a repeated call.

    On a machine shared with other jobs a parallel loop waits at its barrier for a thread that is
    not running: on the 2-core machine with one core busy, two threads took 6.5 ms per force
    kernel call of the 80 cm sheet (81 x 81) against 3.6 ms for one (2.4 ms on an idle machine).
    So the explicit loop measures:
    every :attr:`hold` calls it times :attr:`probe` calls with each setting and keeps the faster
    until the next check. The kernels' sums do not depend on the thread count, only their speed.

    A busy machine (1-minute load average above ``most`` + :data:`BUSY_LOAD`: runnable threads of other
    jobs besides this run's own) gets one thread at every check whatever the probe said: the probe times the
    kernel alone, not what its waiting second thread costs the rest of the step (measured: :data:`BUSY_LOAD`).
    An idle machine (load below that) is tuned as before.
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
                faster = 1 if self._times[1] <= self._times[self.most] else self.most
                self.threads = 1 if busy(self.most) else faster
                self._times = {1: 0.0, self.most: 0.0}
        self.calls += 1
