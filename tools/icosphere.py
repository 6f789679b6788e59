"""Write a unit icosphere (radius 1, centred at the origin, outward winding) as an OBJ file.

Deterministic: the 12 vertices of the icosahedron; each subdivision splits every triangle into four and
pushes the new edge midpoints onto the sphere (vertices in order of creation, written with 9 significant
digits). ``python tools/icosphere.py LEVEL OUT.obj`` -> 20 * 4**LEVEL triangles (level 2: 320; level 3:
1,280; level 4: 5,120). ``cases/icosphere-3.obj`` is level 3.
"""

import sys

import numpy as np


def icosphere(level: int):
    t = (1.0 + 5.0 ** 0.5) / 2.0
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = V[a] + V[b]
                V.append(m / np.linalg.norm(m))
                mid[key] = len(V) - 1
            return mid[key]

        F = [f for a, b, c in F for f in ((a, middle(a, b), middle(c, a)), (b, middle(b, c), middle(a, b)),
                                          (c, middle(c, a), middle(b, c)), (middle(a, b), middle(b, c), middle(c, a)))]
    return np.array(V), np.array(F)


def write_obj(path, V, F):
    with open(path, "w") as fh:
        fh.write(f"# unit icosphere, {len(V)} vertices, {len(F)} triangles (tools/icosphere.py)\n")
        fh.writelines(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in V)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)


if __name__ == "__main__":
    level, out = int(sys.argv[1]), sys.argv[2]
    V, F = icosphere(level)
    write_obj(out, V, F)
    print(f"{out}: {len(V)} vertices, {len(F)} triangles")
