"""Read a scene, change a key the way ``--set`` does, and list the declared options of its [solver] table
with the Python API; print how many [solver] keys there are and the Newton tolerance the scene uses."""

from rftstatic import api

scene = api.load_scene("strip", ["solver.rtol=1e-7"])
print(f"scene: {scene.name}, units: {scene.data.get('units')}, element: {scene.data.get('element')}")
rows = api.option_rows("solver")
for row in rows[:3]:
    print(f"  {row['key']}: {row['help']}")
print(f"solver keys: {len(rows)}")
print(f"solver.rtol: {scene.get('solver.rtol')}")
