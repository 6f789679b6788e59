"""Compiled (numba) twin of :mod:`.penalty_kernels`, made from its own code as
:mod:`rftstatic.contact.obstacles._pedestal_numba` does (a copy of each function whose globals resolve to the
compiled twins; :func:`~.penalty_kernels.slope_one` inlined into :func:`~.penalty_kernels.penalty_scatter`, both
from the one source file numba's cache is keyed on). Imported only when numba is installed and a call is large
enough (:func:`rftstatic.contact.penalty_compiled.compiled_force`)."""

import types

import numba as nb

from rftstatic.contact import penalty_kernels

_scope = dict(vars(penalty_kernels))


def _compile(f, name, **options):
    copy = types.FunctionType(f.__code__, _scope, name, f.__defaults__, f.__closure__)
    copy.__qualname__ = name  # numba's cache entry is named after it
    _scope[name] = nb.njit(copy, cache=True, nogil=True, error_model="numpy", **options)


_compile(penalty_kernels.slope_one, "slope_one", inline="always")
_compile(penalty_kernels.near_nodes, "near_nodes")
_compile(penalty_kernels.penalty_scatter, "penalty_scatter")
near_nodes = _scope["near_nodes"]
penalty_scatter = _scope["penalty_scatter"]
