"""Meshless Approximation, Method RBF and Auto (issue #26), through paraview.simple: the global RBF equals
SciPy's RBFInterpolator (thin-plate spline in 2D, cubic r^3 in 3D, linear tail, with and without smoothing) at the
probe's points, interpolates the data, RBF-PU (RBFGlobalLimit below N) interpolates too and stays close to it,
the field data say what ran and why, and duplicates and gradients give finite results."""
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkPolyData  # noqa: E402

try:
    from scipy.interpolate import RBFInterpolator
except ImportError:
    print("SciPy is not available to this pvpython: skipped")
    sys.exit(125)

meshfree_test.load(globals())


def halton(n, base, start=1):
    out = np.zeros(n)
    for k in range(n):
        i, f = k + start, 1.0
        while i > 0:
            f /= base
            out[k] += f * (i % base)
            i //= base
    return out


def polydata(xyz, arrays=None):
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(xyz, dtype=float), deep=1))
    pd = vtkPolyData()
    pd.SetPoints(pts)
    for name, values in (arrays or {}).items():
        a = numpy_to_vtk(np.ascontiguousarray(values, dtype=float), deep=1)
        a.SetName(name)
        pd.GetPointData().AddArray(a)
    return pd


def source(data):
    s = simple.TrivialProducer()
    s.GetClientSideObject().SetOutput(data)
    return s


def field(x):
    return np.sin(3 * x[:, 0]) * np.cos(2 * x[:, 1]) + x[:, 2] ** 2


def field_string(out, name):
    a = out.VTKObject.GetFieldData().GetAbstractArray(name)
    return a.GetValue(0) if a is not None else None


for dim, n in ((2, 150), (3, 250)):
    xyz = np.zeros((n, 3))
    for a, base in zip(range(dim), (2, 3, 5)):
        xyz[:, a] = 10.0 + 4.0 * halton(n, base)  # an offset and a scale: SciPy's kernel is in data units
    f = field(xyz)
    probe_xyz = np.zeros((300, 3))
    for a, base in zip(range(dim), (2, 3, 5)):
        probe_xyz[:, a] = 10.2 + 3.6 * halton(300, base, 1000)
    cloud = source(polydata(xyz, {"f": f}))
    probe = source(polydata(probe_xyz))
    kernel = "thin_plate_spline" if dim == 2 else "cubic"
    for smoothing in (0.0, 1e-3):
        approx = MeshlessApproximation(Input=cloud, Probe=probe, Method="RBF", Smoothing=smoothing,
                                       ComputeGradients=1, Diagnostics=1)
        out = meshfree_test.fetch(approx)
        got = np.asarray(out.PointData["f"])
        want = RBFInterpolator(xyz[:, :dim], f, kernel=kernel, degree=1, smoothing=smoothing)(probe_xyz[:, :dim])
        diff = np.abs(got - want).max()
        print("%dD RBF smoothing %g: max |MeshFree - SciPy| = %.3g" % (dim, smoothing, diff))
        assert diff <= 1e-9 * np.ptp(f), diff
        assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1)
        for name in ("f_gradient", "ConditionNumber"):
            assert np.all(np.isfinite(np.asarray(out.PointData[name]))), name
        assert np.asarray(out.PointData["ConditionNumber"]).min() >= 1.0
        assert field_string(out, "ApproximationMethod") == "RBF (global)", field_string(out, "ApproximationMethod")
        assert "RBFGlobalLimit" in field_string(out, "ApproximationMethodReason")
        simple.Delete(approx)

    # Through the data (the cloud as probe): global and RBF-PU both interpolate, with either kernel.
    for (limit, name), kernel in [(c, k) for k in ("Polyharmonic", "Wendland C2")
                                  for c in ((1000, "RBF (global)"), (0, "RBF-PU"))]:
        approx = MeshlessApproximation(Input=cloud, Probe=cloud, Method="RBF", RBFGlobalLimit=limit,
                                       RBFKernel=kernel)
        out = meshfree_test.fetch(approx)
        err = np.abs(np.asarray(out.PointData["f"]) - f).max()
        print("%dD %s (%s) through the data: max error %.3g" % (dim, name, kernel, err))
        assert err <= 1e-10 * np.ptp(f), (name, err)
        assert field_string(out, "ApproximationMethod") == name
        simple.Delete(approx)
    simple.Delete(probe)
    simple.Delete(cloud)

# Auto: for a small 2D cloud the global RBF or PU-WLS by their leave-one-out errors (the reason gives both; the
# spline needs a 1.25x lower one), PU-WLS above 150 points, MLS with smoothing above RBFGlobalLimit; it says why.
for n, smoothing, expected in ((100, 0.0, None), (200, 0.0, "PU-WLS degree 3"), (1500, 0.0, "PU-WLS degree 3"),
                               (1500, 0.01, "MLS degree 2")):
    xyz = np.column_stack([halton(n, 2), halton(n, 3), np.zeros(n)])
    cloud = source(polydata(xyz, {"f": field(xyz)}))
    approx = MeshlessApproximation(Input=cloud, Method="Auto", Smoothing=smoothing, SampleDimensions=[31, 31, 1])
    out = meshfree_test.fetch(approx)
    chosen, reason = field_string(out, "ApproximationMethod"), field_string(out, "ApproximationMethodReason")
    print("Auto, N = %d, smoothing %g: %s (%s)" % (n, smoothing, chosen, reason))
    if expected is None:
        found = re.search(r"thin-plate spline ([0-9.e+-]+), of PU-WLS degree 3 ([0-9.e+-]+)", reason)
        assert found, reason
        spline, pu = float(found.group(1)), float(found.group(2))
        expected = "RBF (global)" if spline * 1.25 < pu else "PU-WLS degree 3"
    assert chosen == expected, chosen
    assert reason and str(n) in reason, reason
    assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1)
    assert np.all(np.isfinite(np.asarray(out.PointData["f"])))
    simple.Delete(approx)
    simple.Delete(cloud)

# Duplicates (a point twice, with other values): merged with their mean, a finite result through it.
xyz = np.column_stack([halton(100, 2), halton(100, 3), np.zeros(100)])
xyz = np.vstack([xyz, xyz[7]])
f = np.append(field(xyz[:100]), field(xyz[7:8]) + 1.0)
cloud = source(polydata(xyz, {"f": f}))
at = source(polydata(xyz[7:8]))
approx = MeshlessApproximation(Input=cloud, Probe=at, Method="RBF")
out = meshfree_test.fetch(approx)
value = float(np.asarray(out.PointData["f"])[0])
assert abs(value - (f[7] + 0.5)) < 1e-10, (value, f[7] + 0.5)
print("RBF ok")
