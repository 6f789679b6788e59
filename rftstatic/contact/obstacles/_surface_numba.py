"""Compiled (numba) twin of :mod:`.surface_kernels`, made from its own code as
:mod:`rftstatic.contact.self_contact._kernels_numba` does (a copy of each function whose globals resolve to
the compiled twins; :func:`~.surface_kernels.closest_one` and :func:`~.surface_kernels.nearest_one` inlined into the loops). Imported only when numba
is installed (:meth:`rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle.compiled`)."""

import types

import numba as nb

from rftstatic.contact.obstacles import surface_kernels

_scope = dict(vars(surface_kernels))


def _compile(f, name, **options):
    copy = types.FunctionType(f.__code__, _scope, name, f.__defaults__, f.__closure__)
    copy.__qualname__ = name  # numba's cache entry is named after it
    _scope[name] = nb.njit(copy, cache=True, nogil=True, error_model="numpy", **options)


_compile(surface_kernels.closest_one, "closest_one", inline="always")
_compile(surface_kernels.nearest_one, "nearest_one", inline="always")
_compile(surface_kernels.nearest_in_sets, "nearest_in_sets")
_compile(surface_kernels.signed_in_sets, "signed_in_sets")
nearest_in_sets = _scope["nearest_in_sets"]
signed_in_sets = _scope["signed_in_sets"]
