"""MLS Deformable Solid: time steps, exact states, the checkpoint cache, invalidation, output names and arrays."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from vtkmodules.numpy_interface import dataset_adapter as dsa  # noqa: E402

meshfree_test.load(globals())


def state(proxy, t):
    proxy.UpdatePipeline(t)
    proxy.UpdatePropertyInformation()
    data = sm.Fetch(proxy)
    return data, proxy.GetPropertyValue("SimulatedSteps")


def phyxels(data):
    return dsa.WrapDataObject(data.GetBlock(0))


def make(**kw):
    # A pure source: whatever is active, the built-in shape is used (test_source_inputs.py checks that).
    settings = dict(EndTime=0.6, OutputInterval=0.05, PhyxelSpacing=0.05)
    settings.update(kw)
    return MLSDeformableSolid(**settings)


solid = make()
times = list(solid.TimestepValues)
assert len(times) == 13 and abs(times[0]) < 1e-15 and abs(times[-1] - 0.6) < 1e-12, times
assert np.allclose(np.diff(times), 0.05), times

# Output structure: two named blocks, every array with its component count, finite values.
data, steps = state(solid, 0.3)
assert steps == 6, steps
assert data.GetNumberOfBlocks() == 2
assert data.GetMetaData(0).Get(data.NAME()) == "Phyxels"
assert data.GetMetaData(1).Get(data.NAME()) == "Surface"
assert abs(data.GetInformation().Get(data.DATA_TIME_STEP()) - 0.3) < 1e-12
p = phyxels(data)
n = p.GetNumberOfPoints()
assert n > 50, n
components = dict(Displacement=3, Velocity=3, Strain=6, Stress=6, VonMises=1, DetJ=1, Mass=1, Volume=1, Id=1)
for name, comps in components.items():
    array = np.asarray(p.PointData[name])
    assert array.shape[0] == n, name
    assert (array.ndim == 1 and comps == 1) or array.shape[1] == comps, (name, array.shape)
    assert np.all(np.isfinite(array)), name
assert np.array_equal(np.asarray(p.PointData["Id"]), np.arange(n))
# Mass adds up to density x volume of the ellipsoid (4/3 pi a b c), volumes to that volume.
volume = 4.0 / 3.0 * np.pi * 0.2 * 0.15 * 0.15
assert abs(np.sum(p.PointData["Volume"]) / volume - 1) < 1e-9
assert abs(np.sum(p.PointData["Mass"]) / (1000 * volume) - 1) < 1e-9
# The body fell: displacement consistent with the points.
surface = dsa.WrapDataObject(data.GetBlock(1))
assert surface.GetNumberOfPoints() == 990 and surface.GetNumberOfCells() == 1976
normals = np.asarray(surface.PointData["Normals"])
assert np.allclose(np.linalg.norm(normals, axis=1), 1.0)
assert np.all(np.isfinite(surface.PointData["Displacement"]))
positions_03 = np.array(p.Points)

# Scrubbing back: an earlier time comes from the cache (nothing simulated) and is exact.
data, steps = state(solid, 0.1)
assert steps == 0, steps
positions_01 = np.array(phyxels(data).Points)
data, steps = state(solid, 0.3)
assert steps == 0, steps
assert np.array_equal(np.array(phyxels(data).Points), positions_03)
# A requested time between reported steps: the state at exactly that time, simulated from the reported time
# before it (one partial interval, not checkpointed), the same when asked again, the checkpoints undisturbed.
data, steps = state(solid, 0.099)
assert abs(data.GetInformation().Get(data.DATA_TIME_STEP()) - 0.099) < 1e-15
assert steps == 1, steps
positions_099 = np.array(phyxels(data).Points)
assert not np.array_equal(positions_099, positions_01)
data, steps = state(solid, 0.1)
assert steps == 0 and np.array_equal(np.array(phyxels(data).Points), positions_01), steps
data, steps = state(solid, 0.099)
assert steps == 1 and np.array_equal(np.array(phyxels(data).Points), positions_099), steps
# Going further simulates only the missing intervals.
data, steps = state(solid, 0.4)
assert steps == 2, steps

# The same time reached by another path (a fresh source going straight to 0.3) gives the same state.
fresh = make()
data, steps = state(fresh, 0.3)
assert steps == 6
assert np.array_equal(np.array(phyxels(data).Points), positions_03)

# A property change invalidates the cache: the stiffer body differs and is simulated from t = 0.
solid.YoungModulus = 4e5
data, steps = state(solid, 0.3)
assert steps == 6, steps
assert not np.array_equal(np.array(phyxels(data).Points), positions_03)

# Time 0 is the rest state (displacement zero, velocity the initial one).
moving = make(InitialVelocity=[0.5, 0, 0])
data, steps = state(moving, 0.0)
p = phyxels(data)
assert np.all(np.asarray(p.PointData["Displacement"]) == 0)
assert np.allclose(np.asarray(p.PointData["Velocity"]), [0.5, 0, 0])

# Every container keeps the phyxels inside; a closed surface as the variant's Input is filled and embedded.
for container in ("Box", "Cylinder"):
    box = make(Container=container, ContainerBounds=[-0.3, 0.3, -0.3, 0.3, 0.0, 1.0], InitialVelocity=[2, 1, 0])
    x = np.array(phyxels(state(box, 0.6)[0]).Points)
    assert np.all(np.isfinite(x))
    if container == "Box":
        assert np.all(x[:, :2] >= -0.3) and np.all(x[:, :2] <= 0.3) and np.all(x[:, 2] >= 0)
    else:
        assert np.all(np.hypot(x[:, 0], x[:, 1]) <= 0.3 + 1e-12) and np.all(x[:, 2] >= 0)

sphere = simple.Sphere(Radius=0.2, Center=[0, 0, 0.5], ThetaResolution=24, PhiResolution=24)
filled = MLSDeformableSolidFromSurface(Input=sphere, EndTime=0.1, OutputInterval=0.05, PhyxelSpacing=0.05)
data, steps = state(filled, 0.1)
p = phyxels(data)
rest = np.array(p.Points) - np.asarray(p.PointData["Displacement"])
assert np.all(np.linalg.norm(rest - [0, 0, 0.5], axis=1) < 0.2), "phyxels outside the input surface"
assert p.GetNumberOfPoints() > 0.7 * (4.0 / 3.0 * np.pi * 0.2 ** 3) / 0.05 ** 3
assert data.GetNumberOfBlocks() == 2
s = dsa.WrapDataObject(data.GetBlock(1))
assert s.GetNumberOfPoints() == sphere.GetDataInformation().GetNumberOfPoints()
print("MLS Deformable Solid pipeline behaves")
