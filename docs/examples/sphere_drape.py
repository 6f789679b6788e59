"""Drape a 30 cm wool sheet over a sphere (§4.5 of the paper) on a coarse 17 x 17 mesh with the Python API,
and print the drape coefficient."""

import tempfile

from rftstatic import api

scene = api.load_scene("sphere-30", ["mesh.nodes=[17,17]"])   # cases/sphere-30.toml with one key changed
with tempfile.TemporaryDirectory() as out:
    result = api.run(scene, out, figures=False)                # solve, write summary.json and deformed.vtu

drape = result.summary["drape"]
print(f"converged: {result.converged}, nodes: {result.U.shape[0]}, folds: {drape['fold_count']}")
print(f"drape coefficient: {drape['drape_coefficient']:.4f}")
