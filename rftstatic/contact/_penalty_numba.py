"""Compiled (numba) twin of :mod:`.penalty_kernels`, made from its own code as
:mod:`rftstatic.contact.obstacles._pedestal_numba` does (a copy of each function whose globals resolve to the
compiled twins; :func:`~.penalty_kernels.slope_one` inlined into :func:`~.penalty_kernels.penalty_scatter`, both
from the one source file numba's cache is keyed on). Imported only when numba is installed and a call is large
enough (:func:`rftstatic.contact.penalty_compiled.compiled_force`)."""

from rftstatic.compiled import compiled_twin
from rftstatic.contact import penalty_kernels

_scope = dict(vars(penalty_kernels))
compiled_twin(penalty_kernels.slope_one, "slope_one", _scope, inline="always")
compiled_twin(penalty_kernels.near_nodes, "near_nodes", _scope)
compiled_twin(penalty_kernels.penalty_scatter, "penalty_scatter", _scope)
near_nodes = _scope["near_nodes"]
penalty_scatter = _scope["penalty_scatter"]
