"""Meshless Approximation through paraview.simple: the contract's names, the default grid, every method by
its text, accuracy on Franke's F1, gradients, diagnostics, PointArrays, a probe, HeightField."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIntArray, vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter  # noqa: E402

meshfree_test.load(globals())


def halton(i, base):
    f, r = 1.0, 0.0
    while i > 0:
        f /= base
        r += f * (i % base)
        i //= base
    return r


def franke(x, y):
    return (0.75 * np.exp(-((9 * x - 2) ** 2 + (9 * y - 2) ** 2) / 4)
            + 0.75 * np.exp(-(9 * x + 1) ** 2 / 49 - (9 * y + 1) / 10)
            + 0.5 * np.exp(-((9 * x - 7) ** 2 + (9 * y - 3) ** 2) / 4)
            - 0.2 * np.exp(-(9 * x - 4) ** 2 - (9 * y - 7) ** 2))


def write_cloud(path, n, height=False):
    xy = np.array([[halton(i + 1, 2), halton(i + 1, 3)] for i in range(n)])
    f = franke(xy[:, 0], xy[:, 1])
    pts = vtkPoints()
    pts.SetDataTypeToDouble()
    verts = vtkCellArray()
    arrays = {"F": vtkDoubleArray(), "L": vtkDoubleArray(), "V": vtkDoubleArray(), "I": vtkIntArray()}
    for name, a in arrays.items():
        a.SetName(name)
    arrays["V"].SetNumberOfComponents(3)
    for i, (x, y) in enumerate(xy):
        pts.InsertNextPoint(x, y, f[i] if height else 0.0)
        verts.InsertNextCell(1)
        verts.InsertCellPoint(i)
        arrays["F"].InsertNextValue(f[i])
        arrays["L"].InsertNextValue(2 * x - 3 * y + 1)
        arrays["V"].InsertNextTuple3(x, y, x * y)
        arrays["I"].InsertNextValue(int(10 * x))
    pd = vtkPolyData()
    pd.SetPoints(pts)
    pd.SetVerts(verts)
    for a in arrays.values():
        pd.GetPointData().AddArray(a)
    w = vtkXMLPolyDataWriter()
    w.SetDataModeToBinary()  # the appended mode of this VTK cannot be read back with vertex cells
    w.SetFileName(path)
    w.SetInputData(pd)
    assert w.Write() == 1
    return path


def points_of(out):
    data = out.VTKObject
    return np.array([data.GetPoint(i) for i in range(data.GetNumberOfPoints())])


out_dir = meshfree_test.output_dir()
cloud = simple.XMLPolyDataReader(FileName=[write_cloud(os.path.join(out_dir, "approx_cloud.vtp"), 1000)])

# Defaults: MLS, degree 2, Wendland, 20 neighbours, 101 x 101 x 1 image over the input's bounds.
f = MeshlessApproximation(Input=cloud)
assert f.Method == "MLS" and f.BasisDegree == 2 and f.WeightFunction == "Wendland" and f.NeighborCount == 20
out = meshfree_test.fetch(f)
assert out.VTKObject.IsA("vtkImageData"), out.VTKObject.GetClassName()
assert out.VTKObject.GetDimensions() == (101, 101, 1), out.VTKObject.GetDimensions()
pts = points_of(out)
for name in ("F", "L", "V", "I", "vtkValidPointMask"):
    assert name in out.PointData.keys(), (name, out.PointData.keys())
assert "F_gradient" not in out.PointData.keys() and "ConditionNumber" not in out.PointData.keys()
assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1)
err = np.asarray(out.PointData["F"]) - franke(pts[:, 0], pts[:, 1])
rms = math.sqrt(np.mean(err ** 2))
print("MLS degree 2, N = 1000, Franke F1 rms", rms)
assert rms <= 5e-4, rms
lerr = np.abs(np.asarray(out.PointData["L"]) - (2 * pts[:, 0] - 3 * pts[:, 1] + 1))
print("linear max error", lerr.max(), "at", pts[lerr.argmax()])
assert lerr.max() < 1e-9
v = np.asarray(out.PointData["V"])
assert v.shape == (101 * 101, 3)
assert np.abs(v[:, 2] - pts[:, 0] * pts[:, 1]).max() < 1e-9  # x y is in the quadratic basis

# Every method by its text; gradients and diagnostics.
for method in ("LS", "WLS", "MLS", "PU-WLS", "SPH"):
    f.Method = method
    f.ComputeGradients = 1
    f.Diagnostics = 1
    out = meshfree_test.fetch(f)
    keys = out.PointData.keys()
    for name in ("F_gradient", "L_gradient", "V_gradient", "NeighborCount", "ConditionNumber"):
        assert name in keys, (method, name)
    assert out.PointData["V_gradient"].VTKObject.GetNumberOfComponents() == 9
    for name in keys:
        assert np.all(np.isfinite(np.asarray(out.PointData[name]))), (method, name)
    assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1), method
    g = np.asarray(out.PointData["L_gradient"])
    if method != "SPH":
        assert np.abs(g - np.array([2.0, -3.0, 0.0])).max() < 1e-7, (method, np.abs(g - [2, -3, 0]).max())
    cond = np.asarray(out.PointData["ConditionNumber"])
    assert cond.min() >= 1.0 - 1e-9, (method, cond.min())
    if method in ("MLS", "SPH"):
        counts = np.asarray(out.PointData["NeighborCount"])
        assert counts.min() == 20 and counts.max() == 20, (method, counts.min(), counts.max())
    print(method, "ok")

# PointArrays limits the work to the arrays named.
f.Method = "MLS"
f.ComputeGradients = 0
f.Diagnostics = 0
f.PointArrays = ["F"]
out = meshfree_test.fetch(f)
assert "F" in out.PointData.keys() and "V" not in out.PointData.keys() and "L" not in out.PointData.keys()
f.PointArrays = []

# A probe: the output is the probe with the arrays at its points.
line = simple.Line(Point1=[0.1, 0.2, 0.0], Point2=[0.9, 0.7, 0.0], Resolution=50)
probed = MeshlessApproximation(Input=cloud, Probe=line)
out = meshfree_test.fetch(probed)
assert out.VTKObject.IsA("vtkPolyData") and out.VTKObject.GetNumberOfPoints() == 51
p = points_of(out)
assert np.abs(np.asarray(out.PointData["F"]) - franke(p[:, 0], p[:, 1])).max() < 1e-2

# HeightField: z = f(x, y) from a 2.5D cloud, as a surface with Elevation.
cloud25 = simple.XMLPolyDataReader(FileName=[write_cloud(os.path.join(out_dir, "approx_cloud25.vtp"), 2000, True)])
surface = MeshlessApproximation(Input=cloud25, HeightField=1, SampleDimensions=[41, 41, 41])
out = meshfree_test.fetch(surface)
assert out.VTKObject.IsA("vtkStructuredGrid"), out.VTKObject.GetClassName()
assert out.VTKObject.GetNumberOfPoints() == 41 * 41
p = points_of(out)
z = np.asarray(out.PointData["Elevation"])
assert np.abs(p[:, 2] - z).max() == 0.0
zerr = np.abs(z - franke(p[:, 0], p[:, 1])).max()
print("HeightField max error", zerr)
assert zerr < 2e-3, zerr
print("all ok")
