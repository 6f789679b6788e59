"""Compiled (numba) twin of :mod:`.surface_kernels`, made from its own code as
:mod:`rftstatic.contact.self_contact._kernels_numba` does (a copy of each function whose globals resolve to
the compiled twins; :func:`~.surface_kernels.closest_one` and :func:`~.surface_kernels.nearest_one` inlined into
the loops). Imported only when numba is installed
(:meth:`rftstatic.contact.obstacles.surface_mesh.SurfaceObstacle.compiled`)."""

from rftstatic.compiled import compiled_twin
from rftstatic.contact.obstacles import surface_kernels

_scope = dict(vars(surface_kernels))
compiled_twin(surface_kernels.closest_one, "closest_one", _scope, inline="always")
compiled_twin(surface_kernels.nearest_one, "nearest_one", _scope, inline="always")
compiled_twin(surface_kernels.nearest_in_sets, "nearest_in_sets", _scope)
compiled_twin(surface_kernels.signed_in_sets, "signed_in_sets", _scope)
nearest_in_sets = _scope["nearest_in_sets"]
signed_in_sets = _scope["signed_in_sets"]
