"""Garments: sewing patterns read, checked, meshed with matching seam nodes and placed in space; a dress form.

What is supported now:

- the pattern model (:mod:`.pattern`): panels with outlines (and holes) of straight edges, circular
  arcs and quadratic/cubic Bézier curves (:mod:`.curves`), a grain line (warp direction) and a placement
  (translation, Euler rotation); seams joining two panel edges (``sew``, ``fold``, ``open``;
  ``reversed`` or ``aligned``); SI inside, checked on construction (zero-length edges,
  self-intersecting outlines, missing panels or edges, an edge in two seams, seam edges differing
  by more than 5 % in length), each error a :class:`~.pattern.PatternError` naming file, panel and edge;
- readers (:mod:`.readers`): GarmentCode's JSON specification (circle arcs and relative quadratic
  and cubic Bézier curvature, ``units_in_meter``, ``right_wrong`` stitches) and a small TOML form
  (polygons with arcs and holes, grain, placement, ``panel:edge`` seams, ``units`` m/cm/mm);
- meshing (:mod:`.meshing`): each panel by the advancing-front mesher with the same number of nodes
  along both sides of every seam (uniform by arc length), node pairs per seam, one combined mesh
  with panel ids and per-element grain angles, the panels placed in space, and the check that no
  two placed panels intersect or overlap.
- the dress form (:mod:`.body`): a closed torso surface of elliptical sections from body measurements
  (bust, waist, hip and neck girths at their heights, shoulder breadth), written as an OBJ file a
  ``type = "mesh"`` obstacle reads.

- sewing (:mod:`.sewing`): the placed panels as one mesh whose elements keep their flat panel shapes, seam springs
  that close the seams in damped explicit runs on the form, and the merge of each seam's two sides into one node
  (the ``garment`` analysis, :mod:`rftstatic.app.garment`, then solves the garment's static equilibrium).

Not yet: size charts, ``fold`` seams, moving bodies.
"""

from rftstatic.garment.meshing import CombinedMesh, PatternMesh, check_placement, mesh_pattern, place
from rftstatic.garment.pattern import Edge, Panel, Pattern, PatternError, Seam
from rftstatic.garment.readers import read_garmentcode, read_pattern, read_toml

__all__ = ["Edge", "Panel", "Pattern", "PatternError", "Seam", "PatternMesh", "CombinedMesh", "mesh_pattern", "place",
           "check_placement", "read_pattern", "read_garmentcode", "read_toml"]
