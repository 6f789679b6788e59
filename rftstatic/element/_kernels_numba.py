"""Compiled (numba) twins of :mod:`rftstatic.element.kernels`, made from its own code.

Nothing is written here: each function of :mod:`~rftstatic.element.kernels` is handed to
``numba.njit`` as a copy whose global names resolve to the compiled twins (and ``prange`` to
``numba.prange``, :func:`~rftstatic.element.kernels.lanes` to ``range`` over the last axis,
:func:`~rftstatic.element.kernels._scratch` to an array on the stack), so the compiled loops call the compiled
element functions and the numpy path keeps the plain ones. The two ``prange`` loops, over element ranges
(:func:`membrane_force_blocks`, each range one call of the serial :func:`membrane_force_lanes`) and over the
nodes (:func:`internal_force`), are compiled twice, serial and for numba's threads (``_parallel``); both do
the same sums in the same order per element and per node. The explicit force's loops are compiled once per
element type (RFT6, RFT3: its sizes constants, :data:`~rftstatic.element.kernels._Q`), so that LLVM unrolls
every loop but the lane loops and vectorises those across a block of elements. The element functions are
inlined into the loops. All compiled code comes from the one source file, so numba's cache (keyed on that
file) never mixes old and new code.

Imported only when numba is installed and a compiled back end is chosen.
"""

import types

import numba as nb
import numpy as np
from numba.core import cgutils
from numba.extending import intrinsic

from rftstatic.element import kernels

_ELEMENT = ("strain_point_gradients", "green_strain", "averaged_strain", "stress", "membrane_state",
            "strain_energy", "_deformation", "element_force", "positive_part", "element_tangent", "_gather",
            "strain_increment", "_force_and_tangent", "_gather_offset", "_one", "_gather_lanes")
_LOOPS = ("membrane_energies", "membrane_forces", "membrane_tangents", "membrane_tangents_into",
          "membrane_linearised_strains")
_EXPLICIT = ("membrane_force_lanes", "membrane_force_blocks", "internal_force")
_THREADED = ("membrane_force_blocks", "internal_force")
_ELEMENT_SIZES = {"rft6": (3, 6), "rft3": (1, 3)}
"""``(Q, A)`` of each element type; the explicit loops' compiled copies are named after the key."""


@intrinsic(prefer_literal=True)
def _stack(typingctx, shape):
    """``kernels._scratch``: a C-contiguous float64 array of ``shape`` (integer constants) on the stack."""
    if not isinstance(shape, nb.types.BaseTuple) or not all(isinstance(t, nb.types.IntegerLiteral) for t in shape):
        return None
    dims = tuple(t.literal_value for t in shape)
    arrty = nb.types.Array(nb.types.float64, len(dims), "C")

    def codegen(context, builder, signature, args):
        data = cgutils.alloca_once(builder, context.get_value_type(nb.types.float64), size=int(np.prod(dims)))
        strides = [8 * int(np.prod(dims[k + 1:])) for k in range(len(dims))]
        const = [context.get_constant(nb.types.intp, v) for v in dims + tuple(strides)]
        ary = context.make_array(arrty)(context, builder)
        context.populate_array(ary, data=data, shape=cgutils.pack_array(builder, const[:len(dims)]),
                               strides=cgutils.pack_array(builder, const[len(dims):]),
                               itemsize=context.get_constant(nb.types.intp, 8), meminfo=None)
        return ary._getvalue()

    return arrty(shape), codegen


def _lanes(x):
    """``kernels.lanes``: the lane indices, ``range`` over the last axis."""
    return range(x.shape[-1])


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


def compile_in_place(scope, inline, loops, key, **options):
    """Replace each function named in ``inline`` (inlined into the loops) and ``loops`` in ``scope`` (a module's
    globals) by its compiled copy named ``NAME_<key>`` for numba's cache (``cache=True``): a module whose loops
    link code of other files names them after a hash of that code (``key``), since numba keys a cached function on
    its own file only. The copies' globals are ``scope``, so that they call each other's compiled copies."""
    for name in tuple(inline) + tuple(loops):
        f = scope[name]
        copy = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
        copy.__qualname__ = f"{name}_{key}"
        copy.__doc__ = f.__doc__
        scope[name] = nb.njit(copy, inline="always" if name in inline else "never", **options)


_base = dict(vars(kernels))
_base.update(prange=nb.prange, _scratch=_stack, lanes=nb.njit(_lanes, cache=True, nogil=True, inline="always"))
_twins = {}
"""``{(Q, A): scope}``: the compiled twins of each element type (sizes ``kernels._Q, _A``), and in the scope also
``internal_force_parallel``."""
for _key, (_q, _a) in _ELEMENT_SIZES.items():
    _scope = dict(_base, _Q=_q, _A=_a)
    _compile(_ELEMENT, _scope, "_" + _key, inline="always")  # inlined into the loops: no call per element
    _compile(_LOOPS + _EXPLICIT, _scope, "_" + _key)
    _threaded = dict(_scope)
    _compile(_THREADED, _threaded, f"_{_key}_parallel", parallel=True)
    _scope["internal_force_parallel"] = _threaded["internal_force"]
    _twins[_q, _a] = _scope


def _twin(G):
    """The compiled twins for the elements of ``G (E, Q, A, 2)``."""
    return _twins[G.shape[1], G.shape[2]]


def membrane_energies(nodes, G, area, D, Dm, U, We):
    """:func:`rftstatic.element.kernels.membrane_energies`, compiled for the element of ``G``."""
    return _twin(G)["membrane_energies"](nodes, G, area, D, Dm, U, We)


def membrane_forces(nodes, G, area, D, Dm, U, fe, start, stop):
    """:func:`rftstatic.element.kernels.membrane_forces`, compiled for the element of ``G``."""
    return _twin(G)["membrane_forces"](nodes, G, area, D, Dm, U, fe, start, stop)


def membrane_tangents(nodes, G, area, D, Dm, U, psd, S, fe, ke):
    """:func:`rftstatic.element.kernels.membrane_tangents`, compiled for the element of ``G``."""
    return _twin(G)["membrane_tangents"](nodes, G, area, D, Dm, U, psd, S, fe, ke)


def membrane_tangents_into(nodes, G, area, D, Dm, U, psd, S, emap, fe, data):
    """:func:`rftstatic.element.kernels.membrane_tangents_into`, compiled for the element of ``G``."""
    return _twin(G)["membrane_tangents_into"](nodes, G, area, D, Dm, U, psd, S, emap, fe, data)


def membrane_linearised_strains(nodes, G, D, U, dU, out):
    """:func:`rftstatic.element.kernels.membrane_linearised_strains`, compiled for the element of ``G``."""
    return _twin(G)["membrane_linearised_strains"](nodes, G, D, U, dU, out)


def explicit_kernel(Q: int, A: int, parallel: bool):
    """:func:`~rftstatic.element.kernels.internal_force` compiled for elements of ``Q`` strain points and ``A``
    nodes, serial or on numba's threads."""
    return _twins[Q, A]["internal_force_parallel" if parallel else "internal_force"]
