"""Meshless Approximation Backend: Auto is the default; CPU and CUDA give the same bits for MLS (values and
gradients); where the device cannot run (here: no GPU, or a build without CUDA) Backend CUDA gives a warning with the
reason and the CPU result, never an error, and the field data array Backend says what ran ("CPU (...)", or on a GPU
machine "CUDA (...)"). A method without a device path (SPH) warns that it ran on the CPU."""
import os
import sys

import numpy as np
from paraview import servermanager as sm
from paraview import simple
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkOutputWindow, vtkPoints, vtkStringOutputWindow
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())

console = vtkOutputWindow.GetInstance()
log = vtkStringOutputWindow()


def write_cloud(path, n):
    rng = np.random.default_rng(15)
    xyz = rng.uniform(-1.0, 1.0, size=(n, 3))
    pts = vtkPoints()
    pts.SetDataTypeToDouble()
    verts = vtkCellArray()
    f = vtkDoubleArray()
    f.SetName("F")
    for i, (x, y, z) in enumerate(xyz):
        pts.InsertNextPoint(x, y, z)
        verts.InsertNextCell(1)
        verts.InsertCellPoint(i)
        f.InsertNextValue(np.sin(3 * x) + y * z)
    pd = vtkPolyData()
    pd.SetPoints(pts)
    pd.SetVerts(verts)
    pd.GetPointData().AddArray(f)
    w = vtkXMLPolyDataWriter()
    w.SetDataModeToBinary()
    w.SetFileName(path)
    w.SetInputData(pd)
    assert w.Write() == 1
    return path


def run(f):
    vtkOutputWindow.SetInstance(log)
    try:
        f.UpdatePipeline()
        return sm.Fetch(f)
    finally:
        vtkOutputWindow.SetInstance(console)


def backend_of(data):
    array = data.GetFieldData().GetAbstractArray("Backend")
    assert array is not None and array.GetNumberOfValues() == 1
    return array.GetValue(0)


def arrays(data):
    wrapped = meshfree_test.dsa.WrapDataObject(data)
    return {name: np.asarray(wrapped.PointData[name]) for name in ("F", "F_gradient", "vtkValidPointMask")}


cloud_file = write_cloud(os.path.join(meshfree_test.output_dir(), "backend_cloud.vtp"), 3000)
cloud = simple.XMLPolyDataReader(FileName=[cloud_file])


def approximation(**settings):
    return MeshlessApproximation(Input=cloud, SampleDimensions=[21, 21, 21], ComputeGradients=1, **settings)


auto = approximation()
assert auto.Backend == 'Auto', auto.Backend
auto_out = run(auto)

mark = len(log.GetOutput())
cpu_out = run(approximation(Backend='CPU'))
assert "Backend" not in log.GetOutput()[mark:], log.GetOutput()[mark:]
assert backend_of(cpu_out).startswith("CPU ("), backend_of(cpu_out)

mark = len(log.GetOutput())
cuda_out = run(approximation(Backend='CUDA'))
warnings = log.GetOutput()[mark:]
print(warnings)
assert "ERROR" not in warnings, warnings
if backend_of(cuda_out).startswith("CPU ("):
    # No usable device (or no CUDA in this build): a warning with the reason, the CPU result.
    assert "Backend CUDA: the CPU evaluated (" in warnings, warnings
else:
    assert backend_of(cuda_out).startswith("CUDA ("), backend_of(cuda_out)

cpu, cuda, auto_arrays = arrays(cpu_out), arrays(cuda_out), arrays(auto_out)
assert cpu["F"].shape[0] == 21 ** 3 and cpu["F_gradient"].shape == (21 ** 3, 3), cpu["F_gradient"].shape
for name, values in cpu.items():
    assert values.dtype == cuda[name].dtype and values.tobytes() == cuda[name].tobytes(), name
    assert values.tobytes() == auto_arrays[name].tobytes(), name

# SPH has no device path: CUDA warns and the CPU evaluates.
mark = len(log.GetOutput())
sph_out = run(approximation(Method='SPH', Backend='CUDA'))
warnings = log.GetOutput()[mark:]
assert "only MLS has a device path" in warnings, warnings
assert backend_of(sph_out).startswith("CPU ("), backend_of(sph_out)
print("backend:", backend_of(cuda_out))
