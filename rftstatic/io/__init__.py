"""Layer ``io``: what a run writes: summary.json, VTU/PVD files, PNG views and charts, all atomically.

- :mod:`.files`: JSON, VTU and PVD writers and :func:`~.files.atomic_write`;
- :mod:`.figure`: what every figure shares (bare figure, atomic PNG, limits, labels, DPI);
- :mod:`.surface`: the shaded triangle surface (cameras, lighting, colours, depth sort);
- :mod:`.views`: side, top and isometric views of a drape (:func:`~.views.plot_views`);
- :mod:`.charts`: boundary overlays, side profiles, convergence with slope triangles, histories,
  load-deflection curves;
- :mod:`.animation`: a GIF of the drape over time (:func:`~.animation.animate`);
- :mod:`.outlines`: obstacle outlines and the callables that draw them in the views;
- :mod:`.drape_figures`: the validation reports' drape figures (obstacle drawers, boundaries, Fig. 8);
- :mod:`.solids`: what the sheet rests on (obstacles, a tester's disc) as triangulated surfaces to draw;
- :mod:`.viewer`: the interactive 3-D view of a run, ``view.html`` (plotly), from its files;
- :mod:`.results`: what a solved run writes (VTU, PNG views, view.html, summary.json).

matplotlib, plotly and meshio are imported inside the functions only, so importing this layer stays light.
Imports from ``scenes`` and below.
"""
