"""Drape measures: shadow area, drape coefficient, fold count, sharp-fold indicators.

Definitions (the notes' "Drape measures users expect"):

- Drape coefficient (Cusick): DC = (A_shadow − A_disc) / (A_sheet − A_disc), A_shadow the
  area of the vertical (z) projection of the draped sheet. Folds overlap in projection, so
  A_shadow is the area of the *union* of the projected triangles, not of a boundary polygon.
- Number of folds: local maxima of the projected outer boundary's radius r(θ) about the
  support's axis, counted on a uniform angle grid with a prominence threshold.
- Sharp folds (Sze & Zhou 2016, §3, Figs. 1 and 8): a relative curvature |κ|h, or a dihedral
  angle between adjacent triangles, far above its neighbours' flags the non-physical folds
  RFT6 is meant to suppress.

Modules, one idea each:

- :mod:`.shadow`: :func:`~.shadow.shadow_area` (union of the projected triangles) and
  :func:`~.shadow.drape_coefficient`;
- :mod:`.boundary`: the projected outer boundary, :func:`~.boundary.boundary_loop`, and the folds
  counted on it, :func:`~.boundary.fold_count` (:class:`~.boundary.FoldProfile`);
- :mod:`.sharp`: :func:`~.sharp.dihedral_angles` and :func:`~.sharp.sharp_fold_indicator`
  (|κ| is :func:`rftstatic.element.curvature.curvature_norm`);
- :mod:`.summary`: :func:`~.summary.drape_measures`, all of them as plain values for
  ``summary.json``;
- :mod:`.intersections`: the self-intersection check, independent of any contact law:
  :func:`~.intersections.intersecting_pairs` (triangles sharing no node that pass through each
  other) and :func:`~.intersections.smallest_distance` (between non-adjacent triangles);
- :mod:`.triangles`: the input check and the half-edge keys the others share.

Lengths are in the units of ``x`` (SI inside the package) and areas in their square.
Everything is vectorised over triangles, edges, scan lines and candidate pairs; only the choice
among boundary loops (a handful) and among triangle size classes is a Python loop.
"""
