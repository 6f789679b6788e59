"""ipctk 1.6.1 vs the project's self-contact kernels on the same pairs (sphere-mesh level-3 obstacle, flat
33x33 sheet pushed 0.2 mm above the top cap): point-triangle (obstacle vertex, sheet triangle) and edge-edge
(obstacle edge, sheet edge) distances, gradients, Hessians; and the mesh-level collision build.
Needs ipctk (``pip install ipctk``), which is not a dependency of the package; the numbers are in
validation/mesh_obstacles.md. ``PYTHONPATH=$PWD python tools/ipctk_compare.py``."""
import time
from pathlib import Path

import ipctk
import numpy as np
from rftstatic.contact.obstacles import SurfaceObstacle
from rftstatic.contact.self_contact.distance import point_triangle, edge_edge
from rftstatic.mesh.trimesh import rectangle
from scipy.spatial import cKDTree

ob = SurfaceObstacle(Path(__file__).parents[1] / "cases" / "icosphere-3.obj", units="cm", scale=5.0, translate=[0, 0, -0.05])
m = rectangle(0.3, 0.3, 33, 33, origin=(-0.15, -0.15), pattern="union-jack")
x = m.X3.copy(); r2 = (x[:, 0]**2 + x[:, 1]**2)
x[:, 2] = np.where(r2 < 0.05**2, np.sqrt(np.maximum(0.05**2 - r2, 0)) - 0.05, -0.02) + 2e-4  # on the cap
V, T = ob.V, ob.T
# pairs: obstacle vertices within 1 cm of sheet triangle centroids; obstacle edges within 1 cm of sheet edge midpoints
c = x[m.tri].mean(axis=1)
pt = cKDTree(V).sparse_distance_matrix(cKDTree(c), 0.01, output_type="ndarray")
x4pt = np.concatenate([V[pt["i"], None], x[m.tri[pt["j"]]]], axis=1)
E = m.topology.edges
mid = 0.5 * (x[E[:, 0]] + x[E[:, 1]]); omid = 0.5 * (V[ob.edges[:, 0]] + V[ob.edges[:, 1]])
ee = cKDTree(omid).sparse_distance_matrix(cKDTree(mid), 0.01, output_type="ndarray")
x4ee = np.concatenate([x[E[ee["j"]]], V[ob.edges[ee["i"]]]], axis=1)
print(f"pairs: point-triangle {len(x4pt)}, edge-edge {len(x4ee)}")

def best(f, n=3):
    ts = []
    for _ in range(n):
        t = time.perf_counter(); out = f(); ts.append(time.perf_counter() - t)
    return min(ts), out

for name, x4, ours, theirs, theirs_g, theirs_h in (
        ("point-triangle", x4pt, point_triangle, ipctk.point_triangle_distance, ipctk.point_triangle_distance_gradient,
         ipctk.point_triangle_distance_hessian),
        ("edge-edge", x4ee, edge_edge, ipctk.edge_edge_distance, ipctk.edge_edge_distance_gradient,
         ipctk.edge_edge_distance_hessian)):
    for compiled in (False, True):
        ours(x4[:10], compiled=compiled)  # load / compile
        t, (s, g, H, _) = best(lambda: ours(x4, compiled=compiled))
        print(f"{name}: rftstatic {'compiled' if compiled else 'numpy'} s+grad+hess {t*1e3:.1f} ms ({t/len(x4)*1e6:.2f} us/pair)")
    t_s, s2 = best(lambda: np.array([theirs(*p) for p in x4]))
    t_g, g2 = best(lambda: np.array([theirs_g(*p) for p in x4]))
    t_h, H2 = best(lambda: np.array([theirs_h(*p) for p in x4]))
    print(f"{name}: ipctk per-pair calls s {t_s*1e3:.1f} ms, grad {t_g*1e3:.1f} ms, hess {t_h*1e3:.1f} ms "
          f"(total {(t_s+t_g+t_h)/len(x4)*1e6:.2f} us/pair)")
    # ipctk's edge-edge distance is unmollified: compare s, grad, hess
    sc = np.maximum(np.abs(s), 1e-30)
    print(f"  agreement: max |s - s_ipc| / s = {np.max(np.abs(s - s2) / sc):.2e}, "
          f"max |grad - grad_ipc| / max|grad| = {np.max(np.abs(g.reshape(len(x4), -1) - g2)) / np.abs(g).max():.2e}, "
          f"max |hess - hess_ipc| / max|hess| = {np.max(np.abs(H - H2)) / np.abs(H).max():.2e}")

# mesh-level: ipctk builds the collisions (its default broad phase) between the sheet and the obstacle
Vall = np.vstack([x, V]); F = np.vstack([m.tri, T + len(x)])
Eall = ipctk.edges(F)
cm = ipctk.CollisionMesh(Vall, Eall, F)
dhat = 1e-3
coll = ipctk.NormalCollisions()
t, _ = best(lambda: coll.build(cm, Vall, dhat))
print(f"ipctk NormalCollisions.build (sheet + obstacle, dhat = 1 mm, includes the sheet's own pairs): {t*1e3:.1f} ms, {len(coll)} collisions")

print("--- detail")
for name, x4, ours, th_s, th_h in (("point-triangle", x4pt, point_triangle, ipctk.point_triangle_distance, ipctk.point_triangle_distance_hessian),
                                  ("edge-edge", x4ee, edge_edge, ipctk.edge_edge_distance, ipctk.edge_edge_distance_hessian)):
    s, g, H, feat = ours(x4, compiled=True)
    s2 = np.array([th_s(*p) for p in x4]); H2 = np.array([th_h(*p) for p in x4])
    ds = np.abs(s - s2) / np.abs(s).max()
    dh = np.abs(H - H2).reshape(len(x4), -1).max(axis=1) / np.abs(H).max()
    print(name, "max |ds|/max s", ds.max(), "pairs with |dH| > 1e-9:", int((dh > 1e-9).sum()), "features there", np.bincount(feat[dh > 1e-9], minlength=3))
    k = np.argmax(dh)
    print("  worst pair s", s[k], s2[k], "feature", feat[k], "|H| ours", np.abs(H[k]).max(), "ipc", np.abs(H2[k]).max())
