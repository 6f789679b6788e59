"""The material-axes curvature terms of a model together: bending friction and softening on one patch pass.

A model may carry the bending friction of :mod:`rftstatic.element.hysteresis` (H1-H6), the softening of
:mod:`rftstatic.element.nonlinear_bending` (N1-N5), or both. Both are scalar laws of the same material-axes
curvature (A1 of :mod:`rftstatic.element.axis_curvature`) on the same patches and rotation T, so their energies,
element forces (A2) and tangents (A3) add, and :class:`AxisTerms` evaluates their sum for the static residual and
tangent (:class:`rftstatic.model.model.Model`) and the explicit force (:mod:`rftstatic.element.explicit_force`):

- ``"numpy"``: each term's :meth:`~rftstatic.element.axis_curvature.AxisCurvature.assemble` (the reference,
  vectorised over the elements), summed;
- ``"numba"``: the compiled loops of :mod:`rftstatic.element._axis_numba` (one pass over the elements for both
  laws; the sums in another order: equal to the reference to round-off, the tests' tolerance 1e-12 of the
  largest entry).
"""

from __future__ import annotations

import numpy as np

__all__ = ["AxisTerms", "axis_terms"]

BACKENDS = ("numpy", "numba")

_NO_MAP = np.zeros((0, 6, 3, 6, 3), dtype=np.int64)
_NO_KE = np.zeros((1, 6, 3, 6, 3))


class AxisTerms:
    """Bending friction and/or softening of one mesh's patches (module docstring).

    Parameters
    ----------
    friction : :class:`rftstatic.element.hysteresis.BendingFriction` or None
    softening : :class:`rftstatic.element.nonlinear_bending.BendingSoftening` or None (not both None)
    backend : ``"numpy"`` or ``"numba"``
    """

    def __init__(self, friction, softening, *, backend: str = "numpy"):
        if backend not in BACKENDS:
            raise ValueError(f'axis-curvature backend must be one of {", ".join(BACKENDS)}, got "{backend}"')
        terms = [t for t in (friction, softening) if t is not None]
        if not terms:
            raise ValueError("AxisTerms needs a bending friction or a softening term")
        base = terms[0]
        for t in terms[1:]:
            if not (np.array_equal(t.nodes, base.nodes) and np.array_equal(t.T, base.T)
                    and np.array_equal(t.L, base.L) and np.array_equal(t.area, base.area)):
                raise ValueError("the friction and softening terms must share the patches and the rotation T")
        self.friction, self.softening, self.backend = friction, softening, backend
        self._dofs = (3 * np.asarray(base.nodes)[..., None] + np.arange(3)).ravel()  # scatter of fe (E, 6, 3)
        if backend == "numba":
            from rftstatic.element import _axis_numba

            self._nb = _axis_numba
            self._geom = (np.ascontiguousarray(base.nodes, dtype=np.int64), np.ascontiguousarray(base.L, dtype=float),
                          np.ascontiguousarray(base.area, dtype=float), np.ascontiguousarray(base.T, dtype=float))
            two = np.zeros(2)
            fr, sf = friction, softening
            self._laws = (np.asarray(fr.K, float) if fr else two, np.asarray(fr.M0, float) if fr else two,
                          np.asarray(fr.y, float) if fr else two, np.asarray(sf.k2, float) if sf else two,
                          np.asarray(sf.kappa_floor, float) if sf else np.full(2, np.inf), fr is not None,
                          sf is not None)

    def _slip(self, slip):
        if self.friction is None:
            return np.zeros((0, 2))
        return self.friction.initial_slip() if slip is None else np.ascontiguousarray(slip, dtype=float)

    def _numpy_terms(self, Ub, x, slip, tangent, psd):
        out = []
        if self.friction is not None:
            out.append(self.friction.evaluate(Ub, x, self._slip(slip), tangent=tangent, psd=psd))
        if self.softening is not None:
            out.append(self.softening.evaluate(Ub, x, tangent=tangent, psd=psd))
        return out

    def evaluate(self, Ub, x, slip=None, *, tangent=False, psd=False):
        """Energy [J] (A1), element forces ``(E, 6, 3)`` [N] (A2) and, with ``tangent``, element tangents
        ``(E, 6, 3, 6, 3)`` [N/m] (A3) of the terms' sum at ``Ub`` (what L acts on) and positions ``x (N, 3)`` [m],
        the friction at the committed ``slip (E, 2)`` [1/m] (None: the virgin state); ``psd`` as
        :meth:`~rftstatic.element.axis_curvature.AxisCurvature.assemble`. Without ``tangent`` the element forces
        are the reference's on either back end (the compiled forces go straight to the nodes: :meth:`add_forces`)."""
        if self.backend == "numpy" or not tangent:
            terms = self._numpy_terms(Ub, x, slip, tangent, psd)
            W, fe, ke = terms[0]
            for Wt, ft, kt in terms[1:]:
                W, fe, ke = W + Wt, fe + ft, (ke + kt if tangent else None)
            return W, fe, ke
        E = len(self._geom[0])
        fe, ke = np.empty((E, 6, 3)), np.empty((E, 6, 3, 6, 3))
        W = self._nb.tangents(self._geom, *self._args(Ub, x, slip), bool(psd), fe, ke, _NO_MAP, np.empty(0))
        return float(W), fe, ke

    def add_tangents(self, Ub, x, emap, data, slip=None, *, psd=False):
        """Add the element tangents (A3) into sparse matrix values ``data`` (in place) at the positions ``emap
        (E, 6, 3, 6, 3)`` (int64; :meth:`rftstatic.model.assembly.AssemblyPlan.element_map` of the patches); return
        the element forces ``(E, 6, 3)`` [N]; other arguments as :meth:`evaluate`. The compiled back end adds each
        element's block as it is made (no ``(E, 6, 3, 6, 3)`` array)."""
        if self.backend == "numpy":
            _, fe, ke = self.evaluate(Ub, x, slip, tangent=True, psd=psd)
            data += np.bincount(emap.ravel(), ke.ravel(), minlength=len(data))
            return fe
        fe = np.empty((len(self._geom[0]), 6, 3))
        self._nb.tangents(self._geom, *self._args(Ub, x, slip), bool(psd), fe, _NO_KE, emap, data)
        return fe

    def _args(self, Ub, x, slip):
        return np.ascontiguousarray(Ub, dtype=float), np.ascontiguousarray(x, dtype=float), self._slip(slip), self._laws

    def add_forces(self, Ub, x, f, slip=None) -> float:
        """Add the terms' nodal forces [N] into ``f (N, 3)`` (in place); return their energy [J]; arguments as
        :meth:`evaluate`."""
        if self.backend == "numba":
            return float(self._nb.add_forces(self._geom, *self._args(Ub, x, slip), f))
        W = 0.0
        for Wt, fe, _ in self._numpy_terms(Ub, x, slip, False, False):
            f += np.bincount(self._dofs, fe.ravel(), minlength=f.size).reshape(f.shape)
            W += Wt
        return W

    def energy(self, Ub, x, slip=None) -> float:
        """The terms' energy [J] (A1); arguments as :meth:`evaluate`."""
        if self.backend == "numba":
            return self.add_forces(Ub, x, np.zeros(np.shape(x)), slip)
        return sum(t[0] for t in self._numpy_terms(Ub, x, slip, False, False))

    def curvature(self, Ub, x) -> np.ndarray:
        """Warp and weft curvatures in material axes ``(E, 2)`` [1/m] (A1)."""
        if self.backend == "numpy":
            return (self.friction or self.softening).curvature(Ub, x)[:, :2]
        km = np.empty((len(self._geom[0]), 2))
        self._nb.curvatures(self._geom[0], self._geom[1], self._geom[3], np.ascontiguousarray(Ub, dtype=float),
                            np.ascontiguousarray(x, dtype=float), km)
        return km

    def commit(self, Ub, x, slip) -> tuple[np.ndarray, float]:
        """The friction's return mapping at a converged step (H4,
        :meth:`~rftstatic.element.hysteresis.BendingFriction.return_map`): the new slip ``(E, 2)`` [1/m] and the
        energy dissipated [J]."""
        return self.friction.return_map(self.curvature(Ub, x), slip)


def axis_terms(friction, softening, *, backend: str = "numpy") -> AxisTerms | None:
    """:class:`AxisTerms` of the terms given, or None when both are None."""
    if friction is None and softening is None:
        return None
    return AxisTerms(friction, softening, backend=backend)
