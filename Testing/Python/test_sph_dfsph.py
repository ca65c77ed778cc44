"""SPH Fluid with Solver 'DFSPH' from pvpython: the same arrays as WCSPH, the solver's field data, the time cache,
the obstacle variant, and the CUDA request falling back to the CPU."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())


def column(end, interval):
    """The 2D water column collapsing with DFSPH at the tolerances of these checks."""
    fluid = SPHFluid(Dimension=2, ParticleSpacing=0.01, FluidBounds=[0, 0.1, 0, 0, 0, 0.2],
                     DomainBounds=[0, 0.4, 0, 0, 0, 0.3], Viscosity=0.01, EndTime=end, OutputInterval=interval)
    fluid.Solver = 'DFSPH'
    fluid.DensityTolerance = 0.01
    fluid.DivergenceTolerance = 0.1
    fluid.MaximumIterations = 100
    return fluid


src = column(0.1, 0.025)

for t in (0.1, 0.05, 0.0):
    out = meshfree_test.fetch(src, t)
    n = out.GetNumberOfPoints()
    assert n == 200, n
    for name in ("Velocity", "Density", "Pressure", "Id"):
        assert name in out.PointData.keys(), name
    for name in ("Velocity", "Density", "Pressure"):
        assert np.all(np.isfinite(np.asarray(out.PointData[name]))), name
    x = np.asarray(out.Points)
    assert np.all((x[:, 0] > 0) & (x[:, 0] < 0.4) & (x[:, 2] > 0) & (x[:, 2] < 0.3))
    fd = out.GetFieldData()
    assert fd.GetAbstractArray("Solver").GetValue(0) == "DFSPH"
    for name in ("DensityIterations", "DivergenceIterations", "AverageDensityError"):
        assert fd.GetArray(name) is not None and fd.GetArray(name).GetNumberOfTuples() == 2, name

out = meshfree_test.fetch(src, 0.1)
fd = out.GetFieldData()
assert fd.GetArray("DensityIterations").GetValue(1) > 0  # the mean per step over the interval
error = fd.GetArray("AverageDensityError").GetValue(0)
assert 0 <= error <= 0.0001 + 1e-12, error  # DensityTolerance 0.01 % reached
assert np.asarray(out.Points)[:, 0].max() > 0.1  # the column has started to spread
# Incompressible, over the whole collapse rather than at one instant (one particle's compression at one instant is
# a draw of the trajectory): outputs every 5 ms over 0.2 s, no particle compressed by 2 % at any of the 40 instants,
# and at most one particle-instant in a hundred by 1 %. (Measured: the relaxed Jacobi solver this replaced reached
# 3.0 % and exceeded 1 % at 16 of 40 instants; the projected CG reaches 1.7 %.)
fine = column(0.2, 0.005)
densities = np.array([np.asarray(meshfree_test.fetch(fine, 0.005 * (i + 1)).PointData["Density"]) for i in range(40)])
assert densities.max() < 1000 * 1.02, densities.max()
assert np.mean(densities > 1000 * 1.01) <= 0.01, np.mean(densities > 1000 * 1.01)
del fine


def steps_taken():
    src.UpdatePropertyInformation()
    return src.GetProperty("StepsTaken").GetElement(0)


before = steps_taken()
for t in (0.025, 0.075, 0.1, 0.0):
    meshfree_test.fetch(src, t)
assert steps_taken() == before, (steps_taken(), before)  # served by the cache
src.DensityTolerance = 0.02
meshfree_test.fetch(src, 0.025)
assert steps_taken() > before  # a solver property empties the cache

# WCSPH reports the same field data (iterations 0).
src.Solver = 'WCSPH'
out = meshfree_test.fetch(src, 0.05)
assert out.GetFieldData().GetAbstractArray("Solver").GetValue(0) == "WCSPH"
assert out.GetFieldData().GetArray("DensityIterations").GetValue(0) == 0

# CUDA requested: DFSPH runs on the CPU (and says so in Backend).
src.Solver = 'DFSPH'
src.Backend = 'CUDA'
out = meshfree_test.fetch(src, 0.025)
assert out.GetFieldData().GetAbstractArray("Backend").GetValue(0).startswith("CPU")
src.Backend = 'Auto'

# The obstacle variant: a box in the flow; no particle inside it.
box = Box(XLength=0.04, YLength=0.1, ZLength=0.04, Center=[0.2, 0, 0.02])
tri = Triangulate(Input=box)
obs = SPHFluidWithObstacles(Obstacles=tri, Dimension=2, ParticleSpacing=0.01, FluidBounds=[0, 0.1, 0, 0, 0, 0.2],
                            DomainBounds=[0, 0.4, 0, 0, 0, 0.3], EndTime=0.2, OutputInterval=0.1)
obs.Solver = 'DFSPH'
out = meshfree_test.fetch(obs, 0.2)
x = np.asarray(out.Points)
inside = (np.abs(x[:, 0] - 0.2) < 0.02 - 1e-6) & (x[:, 2] < 0.04 - 1e-6)
assert not inside.any(), x[inside]
assert out.GetFieldData().GetAbstractArray("Solver").GetValue(0) == "DFSPH"
print("SPH Fluid DFSPH OK")
