"""Checks of the scan benchmark's scorer and virtual scanner (scans_score.py, virtual_scan.py; issue 23), run by
ctest as benchmark.scans_score (a few seconds; numpy + scipy, e.g. under pvpython). Exit 77 when numpy or scipy is
missing. Each check compares with an independent computation (dense sampling, brute force, analytic counts)."""
import os
import sys

try:
    import numpy as np
    import scipy  # noqa: F401
except ImportError:
    print("numpy/scipy missing: skipped")
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scans_score as S  # noqa: E402
import virtual_scan as V  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


rng = np.random.default_rng(5)

# 1. closest point on a triangle: on the triangle, and no dense sample of the triangle is closer
a, b, c = rng.normal(size=(3, 200, 3))
p = rng.normal(size=(200, 3)) * 2
q = S.closest_on_triangles(p, a, b, c)
worst_gap, worst_bary = 0.0, 0.0
u, v = np.meshgrid(np.linspace(0, 1, 120), np.linspace(0, 1, 120))
keep = (u + v) <= 1
u, v = u[keep], v[keep]
for i in range(200):
    samples = a[i] + u[:, None] * (b[i] - a[i]) + v[:, None] * (c[i] - a[i])
    best = np.linalg.norm(samples - p[i], axis=1).min()
    worst_gap = max(worst_gap, np.linalg.norm(q[i] - p[i]) - best)
    m = np.stack([b[i] - a[i], c[i] - a[i]], axis=1)
    bary = np.linalg.lstsq(m, q[i] - a[i], rcond=None)[0]
    worst_bary = max(worst_bary, -bary.min(), bary.sum() - 1, np.linalg.norm(m @ bary - (q[i] - a[i])))
check(worst_gap <= 1e-12, "closest point never farther than a dense sample of the triangle (gap %.1e)" % worst_gap)
check(worst_bary <= 1e-9, "closest point lies on the triangle (barycentric excess %.1e)" % worst_bary)

# 2. certified KD-tree distance = brute force over every triangle, on an uneven mesh (long and short triangles)
n_lat, n_lon = 14, 40
th = np.linspace(0.05, np.pi - 0.05, n_lat) ** 1.3 / np.pi ** 0.3
ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
T, P = np.meshgrid(th, ph, indexing="ij")
verts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1).reshape(-1, 3)
tris = []
for i in range(n_lat - 1):
    for j in range(n_lon):
        k0, k1 = i * n_lon + j, i * n_lon + (j + 1) % n_lon
        tris += [(k0, k1, k0 + n_lon), (k1, k1 + n_lon, k0 + n_lon)]
tris = np.array(tris)
pts = rng.normal(size=(400, 3))
pts *= (rng.uniform(0.2, 2.0, 400) / np.linalg.norm(pts, axis=1))[:, None]
fast = S.TriangleDistance(verts, tris).distance(pts, k=4)
brute = np.array([np.linalg.norm(x - S.closest_on_triangles(np.repeat(x[None], len(tris), 0), verts[tris[:, 0]],
                                                            verts[tris[:, 1]], verts[tris[:, 2]]), axis=1).min()
                  for x in pts])
check(np.abs(fast - brute).max() <= 1e-12, "KD-tree distance equals brute force (max diff %.1e)" %
      np.abs(fast - brute).max())

# 3. topology: an octahedron is one closed piece (chi 2); without a face it has a 3-edge border (chi 1); two
#    octahedra are two pieces; duplicated vertices (as marching cubes writes them) are welded first
octa_v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
octa_t = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
soup_v = octa_v[octa_t.ravel()]
soup_t = np.arange(len(soup_v)).reshape(-1, 3)
v, t, nan = S.clean_mesh(soup_v, soup_t)
topo = S.topology(v, t)
check((topo["euler"], topo["boundary_edges"], topo["pieces"], topo["vertices"]) == (2, 0, 1, 6),
      "welded octahedron: chi 2, no border, 1 piece, 6 vertices (%s)" % topo)
topo = S.topology(octa_v, octa_t[1:])
check((topo["euler"], topo["boundary_edges"]) == (1, 3), "octahedron less a face: chi 1, 3 boundary edges")
two_v = np.concatenate([octa_v, octa_v * 0.5 + 5])
two_t = np.concatenate([octa_t, octa_t[:4] + 6])
topo = S.topology(two_v, two_t)
check((topo["pieces"], topo["stray_triangles"]) == (2, 4), "two pieces, the smaller one's 4 triangles stray")
bad_v = octa_v.copy()
bad_v[0] = np.nan
v, t, nan = S.clean_mesh(bad_v, octa_t)
check(nan == 1 and len(t) == 4, "a NaN vertex is counted and its triangles dropped")

# 4. analytic shapes: points moved along the true normal by d are at distance |d|
for shape in (V.Sphere([0.3, 0, 0], 1.0), V.Torus([0, 0, 0.2], 1.0, 0.35), V.Capsule([0, 0, 0], [1, 0.5, 0], 0.3)):
    s = shape.sample(2000, rng)
    d = rng.uniform(-0.1, 0.1, 2000)
    moved = s + d[:, None] * shape.normal(s)
    err = np.abs(np.abs(shape.sdf(moved)) - np.abs(d)).max()
    check(err < 1e-12 and np.abs(shape.sdf(s)).max() < 1e-12,
          "%s: samples on the surface, distance along the normal exact (%.1e)" % (type(shape).__name__, err))

# 5. the virtual scanner: near the surface (noise and misregistration only), underside unseen, single view open
pts, nrm, view, spec = V.scan("vscan_sphere", 4000, seed=1)
dist = V.Assembly.from_spec(spec["shapes"]).distance(pts)
check(dist.max() < 8 * spec["noise"] * spec["diagonal"], "virtual sphere scan within 8 sigma of the sphere")
check(pts[:, 2].min() > -0.95, "virtual sphere scan never sees the bottom (min z %.3f)" % pts[:, 2].min())
check(spec["views"] == 6 and len(np.unique(view)) == 6, "six views")

# 5b. a reference with a hole, a mesh over all of it lifted by h (uneven: fine in one half, coarse in the other):
# the inner scores leave out the vertices over the hole (closest reference point on its rim), the area-weighted
# scores do not depend on where the triangles are small
def grid_mesh(nx, ny, x0, x1, z=0.0):
    xs, ys = np.meshgrid(np.linspace(x0, x1, nx), np.linspace(0, 1, ny), indexing="ij")
    pts = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)], axis=1)
    idx = np.arange(nx * ny).reshape(nx, ny)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    return pts, np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])

rp, rt = grid_mesh(21, 21, 0, 1)
centre = rp[rt].mean(axis=1)
rt = rt[~((np.abs(centre[:, 0] - 0.5) < 0.2) & (np.abs(centre[:, 1] - 0.5) < 0.2))]  # a 0.4 x 0.4 hole
reference = S.TriangleDistance(rp, rt)
h = 0.01
fine, fine_t = grid_mesh(61, 121, 0, 0.5, h)
coarse, coarse_t = grid_mesh(6, 11, 0.5, 1, h)
mp = np.concatenate([fine, coarse])
mt = np.concatenate([fine_t, coarse_t + len(fine)])
data = np.stack([rng.uniform(0, 1, 20000), rng.uniform(0, 1, 20000), np.zeros(20000)], axis=1)
r = S.score_mesh(mp, mt, data, reference, delta=0.05, cover_samples=20000)
cv = S.clean_mesh(mp, mt)[0]
on_rim = (np.abs(cv[:, 0] - 0.5) <= 0.2 + 1e-12) & (np.abs(cv[:, 1] - 0.5) <= 0.2 + 1e-12)  # over the hole or its rim
on_edge = (np.minimum(cv[:, 0], cv[:, 1]) < 1e-12) | (np.maximum(cv[:, 0], cv[:, 1]) > 1 - 1e-12)  # the outer border
check(r["rms"] > 2 * h, "vertices over the hole measure the rim (rms %.3g > 2 h)" % r["rms"])
check(abs(r["inner_rms"] - h) < 1e-9 and abs(r["inner_p99"] - h) < 1e-9,
      "inner scores = the lift h where the reference has surface (%.6g)" % r["inner_rms"])
check(abs(r["inner_share"] - (1 - (on_rim | on_edge).mean())) < 1e-12,
      "inner share leaves out the vertices over the hole and the borders (%.4f against %.4f)"
      % (r["inner_share"], 1 - (on_rim | on_edge).mean()))
check(abs(r["area_rms"] - h) < 1e-9, "area-weighted inner rms = the lift h (%.6g)" % r["area_rms"])
flat = S.score_mesh(mp, mt, data, S.TriangleDistance(rp, grid_mesh(21, 21, 0, 1)[1]), delta=0.05, cover_samples=20000)
check(abs(flat["area_rms"] - h) < 1e-9 and abs(flat["rms"] - h) < 1e-9 and abs(flat["inner_rms"] - h) < 1e-9
      and abs(flat["inner_share"] - (1 - on_edge.mean())) < 1e-12,
      "without a hole every score is the lift h, only the outer border left out (%.6g, %.6g, share %.4f)"
      % (flat["area_rms"], flat["rms"], flat["inner_share"]))
bumpy = mp.copy()
bumpy[:len(fine), 2] = 2 * h  # the fine half lifted twice as high: vertex rms weighs it by its vertex count
b = S.score_mesh(bumpy, mt, data, S.TriangleDistance(rp, grid_mesh(21, 21, 0, 1)[1]), delta=0.05, cover_samples=40000)
expected_area = np.sqrt(0.5 * (2 * h) ** 2 + 0.5 * h ** 2)
check(abs(b["area_rms"] - expected_area) < 0.03 * expected_area and b["rms"] > 1.2 * expected_area,
      "area-weighted rms weighs the halves by area (%.4g against %.4g), the vertex rms by vertices (%.4g)"
      % (b["area_rms"], expected_area, b["rms"]))

# 6. normal scores: the true normals score 0 degrees; half of them flipped is half consistent
g = V.Sphere([0, 0, 0], 1).sample(1000, rng)
r = S.score_normals(g, g)
check(r["ang_mean"] < 1e-6 and r["consistent"] == 1.0 and r["outward"] == 1.0, "exact normals: 0 degrees, all outward")
flip = g.copy()
flip[:500] *= -1
r = S.score_normals(flip, g)
check(r["ang_mean"] < 1e-6 and r["consistent"] == 0.5, "half flipped: same angle, half consistent")

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
