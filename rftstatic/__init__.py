"""rftstatic: drape simulation with the rotation-free triangles RFT3 and RFT6.

Implements Sze & Zhou, "An efficient rotation-free triangle for drape/cloth
simulations, Part I", Int. J. Comput. Methods 13(3) 1650021 (2016), and its
predecessor Zhou & Sze, IJNME 89 (2012).

Heavy parts (plotting, linear-solver back ends, the mesher, explicit dynamics)
are imported lazily by the modules that need them, so a scene pays only for
what it uses.
"""

import os as _os

# One BLAS thread (numpy's OpenBLAS and CHOLMOD's): the package's dense products are small, and an
# idle OpenBLAS thread busy-waits. Measured, pedestal 61 x 61: 19.7 s wall / 19.9 s CPU with one thread
# against 20.8 s / 38.1 s with two: the second core was burnt for nothing (and on a shared machine taken
# from other jobs). Effective when rftstatic is imported before numpy (the CLI); an explicit user
# setting wins.
_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from rftstatic.provenance import __version__  # noqa: E402

__all__ = ["__version__"]
