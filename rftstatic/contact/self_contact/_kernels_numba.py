"""Compiled (numba) twins of the self-contact loops, made from their own code (:mod:`.kernels`:
distances, derivatives, PSD projection, step bound; :mod:`.grid`: the broad phase's cell list).

As :mod:`rftstatic.element._kernels_numba`: each function is handed to ``numba.njit`` as a copy whose
global names resolve to the compiled twins, so the loops call the compiled per-pair functions
(inlined) and the plain source stays plain Python. Serial: the machines share their cores, and the
loops are short next to the solver's. Imported only when numba is installed and chosen
(:func:`rftstatic.contact.self_contact.distance.compiled_for`).
"""

import types

import numba as nb

from rftstatic.contact.self_contact import grid, kernels

_INLINE = {kernels: ("segment_param", "pt_classify", "ee_classify", "pair_derivatives"), grid: ("_grow",)}
_LOOPS = {kernels: ("distances_all", "derivatives_all", "jacobi_eigen", "psd_project_one", "psd_project_all",
                    "ccd_all", "midrange_motion", "distances_by_index"),
          grid: ("boxes", "cell_list", "join")}


def _compile(module, names, scope, **options):
    """Put a compiled copy of each ``module.<name>`` into ``scope`` (the copies' globals)."""
    for name in names:
        f = getattr(module, name)
        copy = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
        copy.__qualname__ = name
        copy.__doc__ = f.__doc__
        scope[name] = nb.njit(copy, cache=True, nogil=True, error_model="numpy", **options)


_scopes = {}
for _module in (kernels, grid):
    _scope = dict(vars(_module))
    _compile(_module, _INLINE[_module], _scope, inline="always")
    _compile(_module, _LOOPS[_module], _scope)
    _scopes[_module] = _scope

distances_all = _scopes[kernels]["distances_all"]
derivatives_all = _scopes[kernels]["derivatives_all"]
psd_project_all = _scopes[kernels]["psd_project_all"]
ccd_all = _scopes[kernels]["ccd_all"]
midrange_motion = _scopes[kernels]["midrange_motion"]
distances_by_index = _scopes[kernels]["distances_by_index"]
boxes = _scopes[grid]["boxes"]
cell_list = _scopes[grid]["cell_list"]
join = _scopes[grid]["join"]
