"""Stress through paraview.simple: hostile clouds written as .xyz/.pcd files, opened with OpenDataFile and fed
to every MeshFree filter (approximation, neighbours, surface, normals) with every enumeration text; the sources stepped over all their time steps with
extreme settings; malformed files opened in ParaView. Each case: no crash, no NaN/Inf in any fetched point
or array, the expected message in VTK's output (captured with a vtkStringOutputWindow), a defined result."""
import math
import os
import sys
import time
import traceback

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Python"))
import meshfree_test  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow  # noqa: E402
from vtkmodules.numpy_interface import dataset_adapter as dsa  # noqa: E402

meshfree_test.load(globals())

# pvpython sends print() through the output window too: report on the real stderr, capture VTK's text.
OUT = sys.__stderr__


def report_exception(kind, value, tb):
    # The captured window would swallow a traceback: write it where ctest sees it ("Traceback" fails).
    OUT.write("".join(traceback.format_exception(kind, value, tb)))
    OUT.flush()


sys.excepthook = report_exception
window = vtkStringOutputWindow()
vtkOutputWindow.SetInstance(window)
vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
failures = []
cases = 0
current = ""
start = time.time()


mark = 0  # captured text before this position belongs to earlier cases


def begin(name):
    global current, cases, mark
    current = name
    cases += 1
    mark = len(window.GetOutput())
    if os.environ.get("MESHFREE_STRESS_VERBOSE"):
        OUT.write("case: %s\n" % name)
        OUT.flush()


def check(ok, what):
    if not ok:
        text = captured()
        failures.append(current + ": " + what)
        OUT.write("ERROR: [%s] %s\n  captured: %s\n" % (current, what, text[:1500].replace("ERROR:", "error:")))
    return ok


def captured():
    return window.GetOutput()[mark:]


def expect_message(word):
    text = captured()
    check("Warning" in text or "ERROR" in text, "no error or warning reported")
    check(word in text, "no message mentions '%s'" % word)


def expect_no_error():
    check("ERROR" not in captured(), "an unexpected error was reported")


def blocks(data):
    """Every vtkDataSet inside a (possibly composite) data object."""
    if data is None:
        return []
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        out = []
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            out.append(it.GetCurrentDataObject())
            it.GoToNextItem()
        return out
    return [data]


def check_finite(data, only=None):
    """Points and floating-point point arrays finite (only the arrays named in `only`, when given)."""
    for ds in blocks(data):
        if ds is None or not ds.IsA("vtkDataSet"):
            continue
        w = dsa.WrapDataObject(ds)
        if ds.GetNumberOfPoints() > 0 and hasattr(w, "Points") and w.Points is not None:
            check(np.all(np.isfinite(np.asarray(w.Points))), "non-finite point")
        for name in w.PointData.keys():
            if only is not None and name not in only:
                continue
            a = np.asarray(w.PointData[name])
            if a.dtype.kind == "f":
                check(np.all(np.isfinite(a)), "non-finite values in %s" % name)


def fetch(proxy, t=None):
    if t is None:
        proxy.UpdatePipeline()
    else:
        proxy.UpdatePipeline(t)
    return sm.Fetch(proxy)


def tmp(name):
    return os.path.join(meshfree_test.output_dir(), "stress_py_" + name)


def write_xyz(path, pts, values):
    with open(path, "w") as f:
        for p, v in zip(pts, values):
            f.write("%r %r %r %r\n" % (p[0], p[1], p[2], v))


# Hostile clouds as files.
rng = np.random.default_rng(7)
base = rng.random((150, 3))
clouds = {
    "one-point": base[:1],
    "duplicates": np.repeat(base[:1], 60, axis=0),
    "collinear": np.outer(rng.random(80), [1.0, 0.5, -0.25]) + [0, 0.1, 0.7],
    "coplanar": np.column_stack([base[:, 0], base[:, 1], 0.3 * base[:, 0] - 0.6 * base[:, 1] + 0.4]),
    "offset-1e6": base + 1e6,
    "scale-1e-6": base * 1e-6,
    "scale-1e6": base * 1e6,
    "nan-values": base,
}

for name, pts in clouds.items():
    values = np.sin(3 * pts[:, 0] / max(1e-300, np.abs(pts).max())) + 0.5
    if name == "nan-values":
        values = values.copy()
        values[::11] = np.nan
        values[5::11] = np.inf
    path = tmp(name + ".xyz")
    write_xyz(path, pts, values)
    reader = simple.OpenDataFile(path)
    check(reader is not None, "OpenDataFile gave no reader for .xyz")
    for method in ["LS", "WLS", "MLS", "PU-WLS", "SPH"]:
        for weight in ["Gaussian", "Wendland", "InverseDistance", "Poly6"]:
            begin("%s %s %s" % (name, method, weight))
            f = MeshlessApproximation(Input=reader)
            f.Method = method
            f.WeightFunction = weight
            f.NeighborCount = 500  # more than the cloud
            f.ComputeGradients = 1
            f.Diagnostics = 1
            f.SampleDimensions = [6, 6, 6]
            data = fetch(f)
            check(data is not None and data.GetNumberOfPoints() > 0, "no output grid")
            check_finite(data)
            expect_no_error()
            mask = data.GetPointData().GetArray("vtkValidPointMask") if data else None
            check(mask is not None, "no vtkValidPointMask")
            if name == "nan-values":
                expect_message("NaN/Inf")
            simple.Delete(f)
    begin(name + " PointNeighbors")
    n = PointNeighbors(Input=reader)
    n.NeighborCount = 1000
    n.SearchRadius = 1e300
    data = fetch(n)
    check_finite(data, only=("MeanNeighborDistance", "NeighborsInRadius"))
    expect_no_error()
    counts = data.GetPointData().GetArray("NeighborsInRadius")
    check(counts is not None and counts.GetRange()[0] == data.GetNumberOfPoints() - 1,
          "a radius covering the cloud does not count every other point")
    simple.Delete(n)
    # Surface reconstruction and normals: every method and orientation, absurd supports.
    for method in ["MLS", "WLS", "SPH"]:
        for support in [0.0, 1e300]:
            begin("%s MeshlessSurface %s SupportRadius %g" % (name, method, support))
            f = MeshlessSurface(Input=reader, Method=method, NeighborCount=1000, SupportRadius=support,
                                AnisotropicKernels=1 if method == "SPH" else 0)
            data = fetch(f)
            check(data is not None, "no output")
            check_finite(data)
            expect_no_error()
            if name == "nan-values" and data.GetNumberOfPoints() > 0:
                expect_message("NaN/Inf")
            simple.Delete(f)
    for orientation in ["Auto", "Propagation", "Viewpoint"]:
        begin("%s MeshlessNormals %s" % (name, orientation))
        f = MeshlessNormals(Input=reader, Orientation=orientation, ProjectPoints=1, NeighborCount=1000)
        data = fetch(f)
        check(data is not None and data.GetNumberOfPoints() == len(pts), "not every point in the output")
        # The input's own arrays pass through as they are (NaN values included): check what the filter adds.
        check_finite(data, only=("Normals", "Curvature", "SurfaceVariation", "OrientationConfidence"))
        expect_no_error()
        simple.Delete(f)
    begin(name + " MeshlessNormals InputNormals without Normals")
    f = MeshlessNormals(Input=reader, Orientation="InputNormals")
    fetch(f)
    expect_message("Normals")
    simple.Delete(f)
    simple.Delete(reader)

# The kernel source: every kernel by its text, extreme supports.
probe_kernel = MeshFreeKernel()
kernel_names = list(probe_kernel.GetProperty("Kernel").Available)
simple.Delete(probe_kernel)
check(len(kernel_names) == 12, "the Kernel enumeration does not list 12 kernels")
for kernel in kernel_names:
    for radius in [1e-150, 1e-6, 1e6, 1e150]:
        begin("MeshFreeKernel %s SupportRadius %g" % (kernel, radius))
        k = MeshFreeKernel(Kernel=kernel, SupportRadius=radius, Dimension=3, Resolution=11)
        data = fetch(k)
        check_finite(data)
        if abs(math.log10(radius)) <= 10:
            expect_no_error()
            check(data.GetPointData().GetArray("Value") is not None, "no Value array")
        elif data.GetPointData().GetArray("Value") is None:
            # 1/h^3 (or its Laplacian's 1/h^5) leaves double's range: refused, with the support named.
            expect_message("support radius")
        simple.Delete(k)

# The solid, stepped over every time step: stiff, oversized step, implicit, cylinder.
for integrator in ["SymplecticEuler", "Implicit"]:
    begin("MLSDeformableSolid stiff, huge step, " + integrator)
    s = MLSDeformableSolid()
    s.Shape = "Box"
    s.ShapeBounds = [-0.1, 0.1, -0.1, 0.1, 0.2, 0.4]
    s.PhyxelSpacing = 0.05
    s.YoungModulus = 1e9
    s.PoissonRatio = 0.45
    s.Integrator = integrator
    s.TimeStep = 0.05
    s.Container = "Cylinder"
    s.ContainerBounds = [-0.3, 0.3, -0.3, 0.3, 0.0, 1.0]
    s.EndTime = 0.2
    s.OutputInterval = 0.05
    s.UpdatePipelineInformation()
    times = list(s.TimestepValues)
    check(len(times) == 5, "TimestepValues are not 0, 0.05, ..., 0.2")
    for t in times:
        data = fetch(s, t)
        check_finite(data)
        phyxels = blocks(data)[0] if blocks(data) else None
        check(phyxels is not None and phyxels.GetNumberOfPoints() > 0, "no phyxels at t = %g" % t)
        if phyxels is not None:
            p = np.asarray(dsa.WrapDataObject(phyxels).Points)
            r = np.hypot(p[:, 0], p[:, 1])
            check(np.all(r <= 0.3 + 1e-9) and np.all(p[:, 2] >= -1e-9), "a phyxel left the cylinder")
    expect_no_error()
    if integrator == "SymplecticEuler":
        expect_message("sub-steps")
    simple.Delete(s)

# The fluid with an oversized fixed step and a stiff gas, over every time step.
begin("SPHFluid TimeStep 1, CFLNumber 0, Tait, GasStiffness 1e8")
fl = SPHFluid()
fl.Dimension = 2
fl.ParticleSpacing = 0.025
fl.EquationOfState = "Tait"
fl.GasStiffness = 1e8
fl.TimeStep = 1.0
fl.CFLNumber = 0.0
fl.EndTime = 0.01
fl.OutputInterval = 0.005
fl.UpdatePipelineInformation()
for t in fl.TimestepValues:
    data = fetch(fl, t)
    check_finite(data)
    check(data.GetNumberOfPoints() > 0, "no particles at t = %g" % t)
    p = np.asarray(dsa.WrapDataObject(data).Points)
    check(np.all(p[:, 0] >= -1e-9) and np.all(p[:, 0] <= 0.8 + 1e-9) and np.all(p[:, 2] >= -1e-9)
          and np.all(p[:, 2] <= 0.5 + 1e-9), "a particle left the domain")
expect_no_error()
expect_message("TimeStep")
simple.Delete(fl)

# Malformed files opened in ParaView: a clear error naming the file and an empty output.
bad = {
    "truncated.pcd": b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 9\nHEIGHT 1\n"
                     b"POINTS 9\nDATA binary\n\x00\x00\x80?",
    "garbage.pcd": bytes(range(256)) * 4,
    "binary.xyz": b"\x00\x01\x02\xff\xfe\n\x00\x00",
    "text.pts": b"this is not\na point cloud\n",
}
# Cases pending another owner's fix run only with MESHFREE_STRESS_PENDING=1 (none today: the binary .xyz
# that ParaView's PLOT3D reader took and aborted on is now claimed and refused by the XYZ reader, 714c919).
PENDING = set()
for name, content in bad.items():
    if name in PENDING and not os.environ.get("MESHFREE_STRESS_PENDING"):
        OUT.write("NOT RUN here (pending a READERS fix, set MESHFREE_STRESS_PENDING=1): OpenDataFile %s\n" % name)
        continue
    begin("OpenDataFile " + name)
    path = tmp(name)
    with open(path, "wb") as f:
        f.write(content)
    try:
        r = simple.OpenDataFile(path)
    except RuntimeError as e:
        # Defined: no reader claims the file (CanReadFile says no), and ParaView says so.
        check("No reader found" in str(e), "unexpected failure: %s" % e)
        os.remove(path)
        continue
    check(r is not None, "no reader for " + name)
    if r is None:
        continue
    data = fetch(r)
    check_finite(data)
    if name != "text.pts":  # a text file without numbers is an empty cloud (checked in StressReaders)
        check(data.GetNumberOfPoints() == 0, "points from a malformed file")
        expect_message(os.path.basename(path))
    simple.Delete(r)
    os.remove(path)

OUT.write("stress_proxies: %d cases, %d failures, %.1f s\n" % (cases, len(failures), time.time() - start))
vtkOutputWindow.SetInstance(None)
sys.exit(1 if failures else 0)
