"""rftstatic: drape simulation with the rotation-free triangles RFT3 and RFT6.

Implements Sze & Zhou, "An efficient rotation-free triangle for drape/cloth
simulations, Part I", Int. J. Comput. Methods 13(3) 1650021 (2016), and its
predecessor Zhou & Sze, IJNME 89 (2012).

Heavy parts (plotting, linear-solver back ends, the mesher, explicit dynamics)
are imported lazily by the modules that need them, so a scene pays only for
what it uses.
"""

import os as _os
import sys as _sys

# One BLAS thread (numpy's OpenBLAS and CHOLMOD's): the package's dense products are small, and an
# idle OpenBLAS thread busy-waits. Measured, pedestal 61 x 61: 19.7 s wall / 19.9 s CPU with one thread
# against 20.8 s / 38.1 s with two: the second core was burnt for nothing (and on a shared machine taken
# from other jobs). The environment variable acts when rftstatic is imported before numpy (the CLI); an
# explicit user setting wins. When numpy came first (a script or notebook that imports numpy, then
# rftstatic), its OpenBLAS already has its threads, and OpenBLAS spreads a dot product or norm of more than
# 10,000 entries (the Newton iteration's vectors on a drape's 16,000 free dofs) over them: on a busy machine
# each such call then waits for a time slice of the other thread. Measured (validation/bench_profile.md,
# "numpy's BLAS threads"): pedestal-round-50's Newton walk from its relaxed state at load average 3, 42.3 s
# with numpy imported first against 17.6 s with one thread. So threadpoolctl sets numpy's BLAS to one
# thread then (the same limit; no effect on numba's or CHOLMOD's OpenMP threads).
if "OPENBLAS_NUM_THREADS" not in _os.environ:
    _os.environ["OPENBLAS_NUM_THREADS"] = "1"
    if "numpy" in _sys.modules:
        try:
            from threadpoolctl import threadpool_limits as _limits
        except ImportError:  # pragma: no cover - threadpoolctl is a dependency
            pass
        else:
            _limits(1, user_api="blas")

from rftstatic.provenance import __version__  # noqa: E402

__all__ = ["__version__"]
