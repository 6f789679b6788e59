"""Compiled (numba) twin of :mod:`.pedestal_kernels`, made from its own code as
:mod:`rftstatic.contact.self_contact._kernels_numba` does (a copy of each function whose globals resolve to the
compiled twins; :func:`~.pedestal_kernels.vertical_one` and :func:`~.pedestal_kernels.rounded_box_one` inlined
into the loops). Imported only when numba is installed and a call is large enough
(:func:`rftstatic.contact.obstacles.pedestal_kernels.compiled_for`)."""

import types

import numba as nb

from rftstatic.contact.obstacles import pedestal_kernels

_scope = dict(vars(pedestal_kernels))


def _compile(f, name, **options):
    copy = types.FunctionType(f.__code__, _scope, name, f.__defaults__, f.__closure__)
    copy.__qualname__ = name  # numba's cache entry is named after it
    _scope[name] = nb.njit(copy, cache=True, nogil=True, error_model="numpy", **options)


_compile(pedestal_kernels.vertical_one, "vertical_one", inline="always")
_compile(pedestal_kernels.rounded_box_one, "rounded_box_one", inline="always")
_compile(pedestal_kernels.square_all, "square_all")
_compile(pedestal_kernels.round_all, "round_all")
square_all = _scope["square_all"]
round_all = _scope["round_all"]
