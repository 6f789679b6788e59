"""The Cusick drape tester: a 30 cm wool specimen on the 18 cm disc, on a coarse mesh of 7 rings of 80 nodes
(the scene's default is 13 x 160), and its drape coefficient in percent."""

import tempfile

from rftstatic import api

scene = api.load_scene("cusick-30", ["mesh.nodes=[7,80]"])
with tempfile.TemporaryDirectory() as out:
    result = api.run(scene, out, figures=False)

drape = result.summary["drape"]
print(f"converged: {result.converged}, folds: {drape['fold_count']}")
print(f"drape coefficient: {drape['drape_coefficient_percent']:.2f} %")
