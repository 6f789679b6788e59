"""Write a square table top as a closed box (outward winding) as an OBJ file: the top face at z = 0, centred on
the z axis, 12 triangles (two per face; flat faces need no more: the obstacle's distance to them is exact).

``python tools/table.py SIDE THICKNESS OUT.obj`` (file units, e.g. cm) -> a SIDE x SIDE x THICKNESS box.
``cases/table-top.obj`` (the ``table-cloth`` scene's table) is ``python tools/table.py 24 2 cases/table-top.obj``.
"""

import sys

import numpy as np


def table_top(side: float, thickness: float):
    """``(V (8, 3), F (12, 3))``: the box ``[-side/2, side/2]^2 x [-thickness, 0]``, faces wound outward."""
    h = 0.5 * side
    V = np.array([[x, y, z] for z in (-thickness, 0.0) for y in (-h, h) for x in (-h, h)], float)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return V, F


def write_obj(path, V, F, side, thickness):
    with open(path, "w") as fh:
        fh.write(f"# table top {side:g} x {side:g} x {thickness:g}, top face at z = 0 (tools/table.py)\n")
        fh.writelines(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in V)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)


if __name__ == "__main__":
    side, thickness, out = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    V, F = table_top(side, thickness)
    write_obj(out, V, F, side, thickness)
    print(f"{out}: {len(V)} vertices, {len(F)} triangles")
