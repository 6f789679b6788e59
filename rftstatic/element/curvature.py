"""The magnitude of an RF triangle's curvature, the one norm that sizes elements and flags sharp folds.

Eq. 7 gives each triangle a constant curvature vector in Voigt form, with the engineering twist
(as the strains of Eq. 14):

    kappa = (k_xx, k_yy, 2 k_xy)                                                   [1/m]

Its magnitude is the Frobenius norm of the symmetric curvature tensor [[k_xx, k_xy], [k_xy, k_yy]]:

    |kappa| = sqrt(k_xx^2 + k_yy^2 + 2 k_xy^2)
            = sqrt(kappa_0^2 + kappa_1^2 + kappa_2^2 / 2)                          [1/m]

(the third Voigt component holds 2 k_xy, so its square is halved back). This equals
sqrt(k_1^2 + k_2^2) of the principal curvatures, so it does not depend on the orientation of the
in-plane axes (the warp direction). It is the |kappa| of

- the relative curvature |kappa| h of §2.2 and §5.1 (h the mean side length; non-dimensional), shown
  in the figures and used as a sharp-fold indicator (§3, Figs. 1 and 8);
- the refinement criterion |kappa| h^2 of Eq. 28 and the size field |kappa| h_new^2 = const of Eq. 29.

The paper writes |kappa| of "the curvature vector of Eq. 7" without defining the norm; the plain
Euclidean norm of the Voigt vector, sqrt(kappa_0^2 + kappa_1^2 + kappa_2^2), would count the twist
twice and change with the axes, so the tensor norm is used.
"""

from __future__ import annotations

import numpy as np

__all__ = ["curvature_norm"]


def curvature_norm(kappa: np.ndarray) -> np.ndarray:
    """|kappa| = sqrt(k_xx^2 + k_yy^2 + 2 k_xy^2) of every element [1/m].

    Parameters
    ----------
    kappa : (E, 3) array_like
        Element curvature vectors (k_xx, k_yy, 2 k_xy) [1/m] of Eq. 7, as returned by
        :func:`rftstatic.element.patch.curvature` and :meth:`rftstatic.model.model.Model.curvature`.

    Returns
    -------
    (E,) ndarray
        Frobenius norm of the curvature tensor [1/m], invariant under in-plane rotation of the axes.

    Raises
    ------
    ValueError
        If ``kappa`` is not an (E, 3) array.
    """
    k = np.asarray(kappa, dtype=float)
    if k.ndim != 2 or k.shape[1] != 3:
        raise ValueError(f"curvature_norm: kappa.shape = {k.shape}, expected (E, 3) = "
                         "(k_xx, k_yy, 2 k_xy) [1/m] per element")
    return np.sqrt(k[:, 0] ** 2 + k[:, 1] ** 2 + 0.5 * k[:, 2] ** 2)
