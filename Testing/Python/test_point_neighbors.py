"""Point Neighbors through paraview.simple: MeanNeighborDistance against numpy brute force."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402

meshfree_test.load(globals())

cloud = simple.PointSource(NumberOfPoints=2000, Radius=1.0, Center=[1e6, -2e6, 3.0])
neighbors = PointNeighbors(Input=cloud, NeighborCount=8, SearchRadius=0.2)
out = meshfree_test.fetch(neighbors)
xyz = np.asarray(out.Points, dtype=float)
mean = np.asarray(out.PointData["MeanNeighborDistance"])
count = np.asarray(out.PointData["NeighborsInRadius"])
assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1)

d = np.sqrt(((xyz[:, None, :] - xyz[None, :, :]) ** 2).sum(-1))
np.fill_diagonal(d, np.inf)
expected = np.sort(d, axis=1)[:, :8].mean(axis=1)
err = np.abs(mean - expected).max()
print("max |mean - brute force| =", err)
# Points sit 1e6 from the origin: distances of order 0.05 keep ~1e-10 absolute accuracy in doubles.
assert err < 1e-8, err
assert np.array_equal(count, (d <= 0.2).sum(axis=1)), "NeighborsInRadius differs from brute force"
