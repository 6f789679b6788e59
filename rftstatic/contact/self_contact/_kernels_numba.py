"""Compiled (numba) twins of the self-contact loops, made from their own code (:mod:`.geometry`: pair
distances and derivatives, step bound, near-pair cut; :mod:`.kernels`: PSD projection, node motion;
:mod:`.grid`: the broad phase's cell list).

As :mod:`rftstatic.element._kernels_numba`: each function is handed to ``numba.njit`` as a copy whose
global names resolve to the compiled twins, so the loops call the compiled per-pair functions
(inlined) and the plain source stays plain Python; the geometry's ``select`` resolves to the compiled
:func:`.geometry.select_one` (``a if c else b``). Each loop inlines only functions of its own file, the
one numba's cache is keyed on (its source hash), so that an edit of that file recompiles the loop.
The key holds no compile options: after changing the ``njit`` options
(:func:`rftstatic.compiled.compiled_twin`), delete the index files
``__pycache__/<module>.*.nbi`` of the three modules, or the old machine code is loaded again. Serial: the
machines share their cores, and the loops are short next to the solver's (the broad phase's join alone
runs ranges of its boxes on threads for a large sheet, :func:`.broad_phase._join_on_threads`). Imported only
when numba is installed and chosen (:func:`rftstatic.contact.self_contact.distance.compiled_for`).
"""

from rftstatic.compiled import compiled_twin
from rftstatic.contact.self_contact import geometry, grid, kernels

_INLINE = {geometry: ("_unit_clamp", "segment_param", "_end_point_param", "pt_closest", "ee_closest",
                      "pt_classify", "ee_classify", "pair_derivatives"),
           kernels: (), grid: ("_grow",)}
_LOOPS = {geometry: ("distances_all", "derivatives_all", "ccd_all", "distances_by_index"),
          kernels: ("jacobi_eigen", "psd_project_one", "psd_project_all", "midrange_motion", "step_motions",
                    "largest_norm"),
          grid: ("boxes", "frame", "cell_ranges", "cell_list", "join")}

_scopes = {}
for _module in (geometry, kernels, grid):
    _scope = dict(vars(_module))
    if _module is geometry:
        compiled_twin(geometry.select_one, "select", _scope, inline="always")
    for _name in _INLINE[_module]:
        compiled_twin(getattr(_module, _name), _name, _scope, inline="always")
    for _name in _LOOPS[_module]:
        compiled_twin(getattr(_module, _name), _name, _scope)
    _scopes[_module] = _scope

distances_all = _scopes[geometry]["distances_all"]
derivatives_all = _scopes[geometry]["derivatives_all"]
psd_project_all = _scopes[kernels]["psd_project_all"]
ccd_all = _scopes[geometry]["ccd_all"]
midrange_motion = _scopes[kernels]["midrange_motion"]
step_motions = _scopes[kernels]["step_motions"]
largest_norm = _scopes[kernels]["largest_norm"]
distances_by_index = _scopes[geometry]["distances_by_index"]
boxes = _scopes[grid]["boxes"]
frame = _scopes[grid]["frame"]
cell_ranges = _scopes[grid]["cell_ranges"]
cell_list = _scopes[grid]["cell_list"]
join = _scopes[grid]["join"]
