"""Compiled (numba) twin of :mod:`.pedestal_kernels`, made from its own code as
:mod:`rftstatic.contact.self_contact._kernels_numba` does (a copy of each function whose globals resolve to the
compiled twins; :func:`~.pedestal_kernels.vertical_one`, :func:`~.pedestal_kernels.rounded_box_one`, the per-point
:func:`~.pedestal_kernels.square_one`, :func:`~.pedestal_kernels.round_one` and
:func:`~.pedestal_kernels.distance_one` inlined into the loops: all from the one source file numba's cache is keyed
on). Imported only when numba is installed and a call is large enough
(:func:`rftstatic.contact.obstacles.pedestal_kernels.compiled_for`)."""

from rftstatic.compiled import compiled_twin
from rftstatic.contact.obstacles import pedestal_kernels

_scope = dict(vars(pedestal_kernels))
compiled_twin(pedestal_kernels.vertical_one, "vertical_one", _scope, inline="always")
compiled_twin(pedestal_kernels.rounded_box_one, "rounded_box_one", _scope, inline="always")
for _name in ("square_one", "round_one", "distance_one"):
    compiled_twin(getattr(pedestal_kernels, _name), _name, _scope, inline="always")
for _name in ("square_all", "round_all", "distances_at"):
    compiled_twin(getattr(pedestal_kernels, _name), _name, _scope)
square_all = _scope["square_all"]
round_all = _scope["round_all"]
distances_at = _scope["distances_at"]
