"""MeshFree Kernel source: every kernel is selectable by name, finite, and radially symmetric."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402

meshfree_test.load(globals())

names = ["Gaussian", "Wendland", "InverseDistance", "Poly6", "W2", "W3", "W4", "W5", "Lucy", "Spiky",
         "Viscosity", "CubicSpline"]
for name in names:
    for dim in (1, 2, 3):
        src = MeshFreeKernel(Kernel=name, Dimension=dim, SupportRadius=2.0, Resolution=61)
        out = meshfree_test.fetch(src)
        value = np.asarray(out.PointData["Value"]).reshape(61, 61)  # [y, x]
        assert np.all(np.isfinite(value)), (name, dim)
        # Symmetric under x -> -x; in 2D and 3D also under x <-> y. The grid's mirrored coordinates agree
        # only to rounding, so the tolerance is relative to the peak.
        tol = 1e-10 * np.abs(value).max()
        assert np.allclose(value, value[:, ::-1], rtol=0, atol=tol), (name, dim)
        if dim > 1:
            assert np.allclose(value, value.T, rtol=0, atol=tol), (name, dim)
        # Compact support: zero on the plane's border, which lies beyond h (in 1D only x counts).
        assert np.all(value[:, 0] == 0) and np.all(value[:, -1] == 0), (name, dim)
        if dim > 1:
            assert np.all(value[0, :] == 0) and np.all(value[-1, :] == 0), (name, dim)
        simple.Delete(src)
print("all kernels sampled")
