"""Compiled (numba) twins of :mod:`rftstatic.element.kernels`, made from its own code.

Nothing is written here: each function of :mod:`~rftstatic.element.kernels` is handed to
``numba.njit`` as a copy whose global names resolve to the compiled twins (and ``prange`` to
``numba.prange``), so the compiled loops call the compiled element functions and the numpy path keeps
the plain ones. The two ``prange`` loops, over element blocks (:func:`membrane_force_blocks`, each block one call
of the serial :func:`membrane_forces`) and over the nodes (:func:`internal_force`), are compiled
twice, serial and for numba's threads (``_parallel``); both do the same sums in the same order per
element and per node. The element functions are inlined into the loops. All compiled code comes from the
one source file, so numba's cache (keyed on that file) never mixes old and new code.

Imported only when numba is installed and a compiled back end is chosen.
"""

import types

import numba as nb

from rftstatic.element import kernels

_ELEMENT = ("strain_point_gradients", "green_strain", "averaged_strain", "stress", "membrane_state",
            "strain_energy", "_deformation", "element_force", "positive_part", "element_tangent", "_gather",
            "strain_increment", "_force_and_tangent", "_gather_offset")
_LOOPS = ("membrane_energies", "membrane_forces", "membrane_tangents", "membrane_tangents_into",
          "membrane_linearised_strains", "membrane_force_blocks", "internal_force")
_THREADED = ("membrane_force_blocks", "internal_force")


def _compile(names, scope, suffix="", **options):
    """Put a compiled copy of each ``kernels.<name>`` into ``scope`` (the copies' globals).

    ``error_model="numpy"``: no zero-division checks (the kernels divide by Q >= 1 and by a radius
    kept above 1e-300), which cost the small RFT3 kernel a third of its time."""
    for name in names:
        f = getattr(kernels, name)
        copy = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
        copy.__qualname__ = name + suffix  # numba's cache entry is named after it
        copy.__doc__ = f.__doc__
        scope[name] = nb.njit(copy, cache=True, nogil=True, error_model="numpy", **options)


_serial = dict(vars(kernels))
_serial["prange"] = nb.prange
_compile(_ELEMENT, _serial, inline="always")  # inlined into the loops: no call per element
_compile(_LOOPS, _serial)
_parallel = dict(_serial)
_compile(_THREADED, _parallel, "_parallel", parallel=True)

membrane_energies = _serial["membrane_energies"]
membrane_forces = _serial["membrane_forces"]
membrane_tangents = _serial["membrane_tangents"]
membrane_tangents_into = _serial["membrane_tangents_into"]
membrane_linearised_strains = _serial["membrane_linearised_strains"]
internal_force = _serial["internal_force"]
internal_force_parallel = _parallel["internal_force"]
