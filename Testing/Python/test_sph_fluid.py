"""SPH Fluid source from pvpython: contract names, reported times, arrays, Id stable, particles contained."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())

src = SPHFluid(Dimension=2, ParticleSpacing=0.01, FluidBounds=[0, 0.1, 0, 0, 0, 0.2],
               DomainBounds=[0, 0.4, 0, 0, 0, 0.3], SmoothingLength=0, RestDensity=1000, GasStiffness=0,
               Viscosity=0.01, SurfaceTension=0, Gravity=[0, 0, -9.81], TimeStep=0.002, CFLNumber=0.25,
               EndTime=0.1, OutputInterval=0.025)
src.EquationOfState = 'Tait'
times = list(src.TimestepValues)
assert np.allclose(times, [0, 0.025, 0.05, 0.075, 0.1]), times

ids0 = None
for t in (0.1, 0.05, 0.0):
    out = meshfree_test.fetch(src, t)
    n = out.GetNumberOfPoints()
    assert n == 200, n
    for name in ("Velocity", "Density", "Pressure", "Id"):
        assert name in out.PointData.keys(), name
    v = np.asarray(out.PointData["Velocity"])
    assert v.shape == (n, 3) and np.all(np.isfinite(v))
    x = np.asarray(out.Points)
    assert np.all((x[:, 0] > 0) & (x[:, 0] < 0.4) & (x[:, 2] > 0) & (x[:, 2] < 0.3))
    ids = np.sort(np.asarray(out.PointData["Id"]))
    assert ids0 is None or np.array_equal(ids, ids0)
    ids0 = ids
# The column has started to fall and spread by t = 0.1.
out = meshfree_test.fetch(src, 0.1)
assert np.asarray(out.Points)[:, 0].max() > 0.1


def steps_taken():
    src.UpdatePropertyInformation()
    return src.GetProperty("StepsTaken").GetElement(0)


# Every output time is cached: revisiting them takes no step; a property change invalidates the cache.
assert abs(src.ArtificialViscosity[0] - 0.02) < 1e-12 if hasattr(src.ArtificialViscosity, "__getitem__") \
    else abs(src.ArtificialViscosity - 0.02) < 1e-12
before = steps_taken()
assert before > 0, before
for t in (0.025, 0.075, 0.1, 0.0):
    meshfree_test.fetch(src, t)
assert steps_taken() == before, (steps_taken(), before)
src.ArtificialViscosity = 0.05
meshfree_test.fetch(src, 0.025)
assert steps_taken() > before
print("SPH Fluid OK")
