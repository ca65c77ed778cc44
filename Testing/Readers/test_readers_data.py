"""Data/: make_data.py regenerates every file byte for byte (seeded), and every file opens in pvpython with
the counts of the thesis (9, 256 points; 299, 568, 715 phyxels; a closed 990-vertex, 1976-triangle surface)."""
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.environ["MESHFREE_SOURCE_DIR"], "Testing", "Python"))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402

source = os.environ["MESHFREE_SOURCE_DIR"]
data = os.path.join(source, "Data")
script = os.path.join(data, "Scripts", "make_data.py")
check = subprocess.run([sys.executable if os.path.basename(sys.executable).startswith("python") else "/usr/bin/python3",
                        script, "--check"], capture_output=True, text=True)
print(check.stdout, check.stderr)
assert check.returncode == 0, "Data/ differs from what make_data.py generates"

meshfree_test.load(globals())


def cloud(name, reader="MeshFreeXYZReader"):
    r = simple.OpenDataFile(os.path.join(data, name))
    assert r.GetXMLName() == reader, (name, r.GetXMLName())
    d = meshfree_test.fetch(r)
    assert d.GetNumberOfVerts() == d.GetNumberOfPoints()
    return d


d = cloud("thesis_9points.xyz")
assert d.GetNumberOfPoints() == 9
xyz = np.asarray(d.Points)
assert np.array_equal(xyz[:, 2], np.asarray(d.PointData["f"]))
assert sorted(map(tuple, xyz[:, :2].astype(int))) == sorted(
    [(1, 1), (1, -1), (-1, 1), (-1, -1), (0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)])

d = cloud("random_256.xyz")
xyz = np.asarray(d.Points)
assert d.GetNumberOfPoints() == 256 and np.all(np.abs(xyz[:, :2]) <= 1) and np.all((xyz[:, 2] >= 0) & (xyz[:, 2] <= 1))

counts = {"octahedron_299.pcd": 299, "ellipsoid_568.pcd": 568, "ellipsoid_715.pcd": 715}
for name, n in counts.items():
    d = cloud(name, "MeshFreePCDReader")
    assert d.GetNumberOfPoints() == n, (name, d.GetNumberOfPoints())
phyxels = np.asarray(cloud("ellipsoid_715.pcd", "MeshFreePCDReader").Points, dtype=float)

surface = meshfree_test.fetch(simple.OpenDataFile(os.path.join(data, "ellipsoid_715_surface.ply")))
assert surface.GetNumberOfPoints() == 990 and surface.GetNumberOfCells() == 1976
conn = np.asarray(surface.VTKObject.GetPolys().GetConnectivityArray()).reshape(-1, 3)
edges = np.sort(np.concatenate([conn[:, [0, 1]], conn[:, [1, 2]], conn[:, [2, 0]]]), axis=1)
_, uses = np.unique(edges, axis=0, return_counts=True)
assert np.all(uses == 2), "the surface is not closed (every edge must bound exactly two triangles)"
# Outward orientation: the signed volume is positive; and every phyxel lies inside.
p = np.asarray(surface.Points, dtype=float)
volume = np.einsum("ij,ij->i", p[conn[:, 0]], np.cross(p[conn[:, 1]], p[conn[:, 2]])).sum() / 6
assert volume > 0, volume
a, b, c = np.abs(p).max(axis=0)
assert np.all((phyxels[:, 0] / a) ** 2 + (phyxels[:, 1] / b) ** 2 + (phyxels[:, 2] / c) ** 2 < 1)

scan = cloud("scan_torus.pcd", "MeshFreePCDReader")
assert scan.GetNumberOfPoints() == 3000
pts = np.asarray(scan.Points, dtype=float)
# Scan-like: on the torus (R = 1, r = 0.35) up to the noise.
tube = np.hypot(np.hypot(pts[:, 0], pts[:, 1]) - 1.0, pts[:, 2])
assert abs(np.median(tube) - 0.35) < 0.005 and np.max(np.abs(tube - 0.35)) < 0.05
assert set(np.unique(np.asarray(scan.PointData["scanner"]))) == {0, 1, 2, 3}
print("OK")
