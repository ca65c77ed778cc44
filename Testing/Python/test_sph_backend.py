"""SPH Fluid Backend: CUDA gives the CPU's particles bit for bit, on the device where one is
usable (field data Backend "CUDA (...)", no warning), else on the CPU with a warning saying why; Auto is the default
(the CPU for this small job), and field data Backend says what ran."""
import os
import sys

import numpy as np
from paraview import servermanager as sm
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())

# While a pipeline updates, warnings go to a string, to be checked (pvpython's own output, tracebacks included,
# goes through the output window too: the console's is put back at once).
console = vtkOutputWindow.GetInstance()
log = vtkStringOutputWindow()


def fluid(**backend):
    src = SPHFluid(Dimension=2, ParticleSpacing=0.01, FluidBounds=[0, 0.1, 0, 0, 0, 0.2],
                   DomainBounds=[0, 0.4, 0, 0, 0, 0.3], Gravity=[0, 0, -9.81], TimeStep=0.002, CFLNumber=0.25,
                   EndTime=0.05, OutputInterval=0.025, **backend)
    src.EquationOfState = 'Tait'
    return src


def run(src, time=0.05):
    vtkOutputWindow.SetInstance(log)
    try:
        src.UpdatePipeline(time)
        return sm.Fetch(src)
    finally:
        vtkOutputWindow.SetInstance(console)


def backend_of(data):
    array = data.GetFieldData().GetAbstractArray("Backend")
    assert array is not None and array.GetNumberOfValues() == 1
    return array.GetValue(0)


def arrays(data):
    wrapped = meshfree_test.dsa.WrapDataObject(data)
    out = {"Points": np.asarray(wrapped.Points)}
    for name in ("Velocity", "Density", "Pressure", "Id"):
        out[name] = np.asarray(wrapped.PointData[name])
    return out


auto = fluid()
assert auto.Backend == 'Auto', auto.Backend
auto_out = run(auto)
assert backend_of(auto_out).startswith("CPU (oneTBB, "), backend_of(auto_out)

mark = len(log.GetOutput())
cpu_out = run(fluid(Backend='CPU'))
assert "Backend" not in log.GetOutput()[mark:], log.GetOutput()[mark:]
cuda_out = run(fluid(Backend='CUDA'))
warnings = log.GetOutput()[mark:]
print(warnings)
on_device = backend_of(cuda_out).startswith("CUDA (")
if on_device:
    assert "Backend CUDA" not in warnings, warnings
else:
    assert "Backend CUDA is not usable here" in warnings and "the CPU ran the simulation" in warnings, warnings
    assert backend_of(cuda_out).startswith("CPU (oneTBB, "), backend_of(cuda_out)
assert "ERROR" not in warnings, warnings
assert backend_of(cpu_out).startswith("CPU (oneTBB, "), backend_of(cpu_out)

cpu, cuda = arrays(cpu_out), arrays(cuda_out)
assert cpu["Points"].shape[0] == 200, cpu["Points"].shape
for name, values in cpu.items():
    assert values.dtype == cuda[name].dtype and values.tobytes() == cuda[name].tobytes(), name
for name, values in arrays(auto_out).items():
    assert values.tobytes() == cpu[name].tobytes(), name

# The warning is given once per cause, not on every update.
mark = len(log.GetOutput())
cuda_src = fluid(Backend='CUDA')
run(cuda_src)
run(cuda_src, 0.025)
assert log.GetOutput()[mark:].count("Backend CUDA") == (0 if on_device else 1), log.GetOutput()[mark:]
print("SPH Fluid Backend OK:", backend_of(cuda_out))
