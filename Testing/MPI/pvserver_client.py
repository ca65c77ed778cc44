"""Client of pvserver_test.sh: connects to `mpiexec -n RANKS pvserver` on localhost, loads the plugin on the server
(remote=True), checks that each simulation's particles are spread over the ranks, each once, then fetches a fluid
and a distributed Meshless Approximation (a cloud split over the ranks, probed by a sphere) and compares them with
the same pipelines run in this client alone after disconnecting (the serial answer)."""
import os
import sys
import time

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util import numpy_support as ns

port, ranks = int(sys.argv[1]), int(sys.argv[2])
for attempt in range(120):  # the server takes a while to start on a loaded machine
    try:
        if simple.Connect("localhost", port):
            break
    except Exception:  # noqa: BLE001 - not listening yet
        pass
    time.sleep(1)
else:
    sys.exit("could not connect to pvserver on port %d" % port)
plugin = {"loaded": True}
simple.LoadPlugin(os.environ["MESHFREE_PLUGIN"], remote=True, ns=plugin)
FLUID = dict(Dimension=2, ParticleSpacing=0.02, FluidBounds=[0, 0.2, 0, 0, 0, 0.4], DomainBounds=[0, 0.8, 0, 0, 0, 0.5],
             EndTime=0.02, OutputInterval=0.02)
fluid = plugin["SPHFluid"](**FLUID)
ranks_of = simple.ProcessIdScalars(Input=fluid)
ranks_of.UpdatePipeline(0.02)
info = ranks_of.GetDataInformation()
print("SPHFluid:", info.GetNumberOfPoints(), "particles over the ranks, ProcessId range",
      ranks_of.PointData["ProcessId"].GetRange(), flush=True)
assert info.GetNumberOfPoints() == 200, info.GetNumberOfPoints()
assert ranks_of.PointData["ProcessId"].GetRange() == (0, ranks - 1)
solid = plugin["MLSDeformableSolidFromSurface"](Input=simple.Sphere(Center=[0, 0, 0.6], Radius=0.15),
                                                PhyxelSpacing=0.05, EndTime=0.02, OutputInterval=0.02)
solid.UpdatePipeline(0.02)
phyxels = solid.GetDataInformation().DataInformation.GetNumberOfPoints()
print("MLSDeformableSolidFromSurface: points (phyxels and surface) over the ranks:", phyxels, flush=True)


def approximation():
    """A cloud that arrives split over the ranks (the wavelet's cell centres), probed by a sphere."""
    wavelet = simple.Wavelet(WholeExtent=[-12, 12, -12, 12, -12, 12])
    centers = simple.CellCenters(Input=simple.PointDatatoCellData(Input=wavelet), VertexCells=1)
    probe = simple.Sphere(Radius=7.0, ThetaResolution=40, PhiResolution=30)
    return plugin["MeshlessApproximation"](Input=centers, Probe=probe, Method="MLS", PointArrays=["RTData"])


def fetched(proxy, time_value, arrays):
    """The pieces merged on the client: rows of the points and the named arrays."""
    proxy.UpdatePipeline(time_value)
    data = servermanager.Fetch(proxy)
    n = data.GetNumberOfPoints()
    columns = [ns.vtk_to_numpy(data.GetPoints().GetData()).reshape(n, 3)]
    columns += [ns.vtk_to_numpy(data.GetPointData().GetArray(a)).reshape(n, -1) for a in arrays]
    return np.hstack(columns).astype(float)


server_fluid = fetched(fluid, 0.02, ["Id", "Velocity"])
server_approx = fetched(approximation(), 0.0, ["RTData", "vtkValidPointMask"])
simple.Disconnect()

# The serial answer: the same pipelines in this process alone (builtin session).
simple.Connect()
plugin = {"loaded": True}
simple.LoadPlugin(os.environ["MESHFREE_PLUGIN"], remote=False, ns=plugin)
serial_fluid = fetched(plugin["SPHFluid"](**FLUID), 0.02, ["Id", "Velocity"])
serial_approx = fetched(approximation(), 0.0, ["RTData", "vtkValidPointMask"])


def by_key(rows, key):
    return rows[np.lexsort(rows[:, key].T[::-1])]


a, b = by_key(server_fluid, [3]), by_key(serial_fluid, [3])  # by Id
assert a.shape == b.shape, (a.shape, b.shape)
fluid_diff = float(np.max(np.abs(a - b)))
print(f"SPHFluid through pvserver ({ranks} ranks) vs serial: {len(a)} particles, max difference {fluid_diff:.3g}",
      flush=True)
assert fluid_diff == 0.0, fluid_diff
# Sphere pieces share their poles and seam (computed a rounding error apart): compare every fetched point with the
# serial value at the same place, to 1e-9.
def place(row):
    return tuple(np.round(row[:3], 9))


serial_at = {place(row): row[3:] for row in serial_approx}
assert len(serial_at) <= len(server_approx), (len(serial_at), len(server_approx))
assert {place(row) for row in server_approx} == set(serial_at), "the probe points differ"
approx_diff = max(float(np.max(np.abs(row[3:] - serial_at[place(row)]))) for row in server_approx)
scale = float(np.ptp(serial_approx[:, 3]))
print(f"MeshlessApproximation through pvserver ({ranks} ranks) vs serial: {len(serial_at)} probe points, max "
      f"difference {approx_diff:.3g} ({approx_diff / scale:.3g} of the range)", flush=True)
assert approx_diff <= 1e-9 * scale, approx_diff
print("OK", flush=True)
