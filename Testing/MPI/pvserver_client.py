"""Client of pvserver_test.sh: connects to `mpiexec -n RANKS pvserver` on localhost, loads the plugin on the server
(remote=True) and checks that each simulation's particles are spread over the ranks, each once."""
import os
import sys
import time

from paraview import simple

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
simple.LoadPlugin(os.environ["MESHFREE_PLUGIN"], remote=True, ns=globals())
fluid = SPHFluid(Dimension=2, ParticleSpacing=0.02, FluidBounds=[0, 0.2, 0, 0, 0, 0.4],
                 DomainBounds=[0, 0.8, 0, 0, 0, 0.5], EndTime=0.02, OutputInterval=0.02)
ranks_of = ProcessIdScalars(Input=fluid)
ranks_of.UpdatePipeline(0.02)
info = ranks_of.GetDataInformation()
print("SPHFluid:", info.GetNumberOfPoints(), "particles over the ranks, ProcessId range",
      ranks_of.PointData["ProcessId"].GetRange(), flush=True)
assert info.GetNumberOfPoints() == 200, info.GetNumberOfPoints()
assert ranks_of.PointData["ProcessId"].GetRange() == (0, ranks - 1)
solid = MLSDeformableSolidFromSurface(Input=Sphere(Center=[0, 0, 0.6], Radius=0.15), PhyxelSpacing=0.05,
                                      EndTime=0.02, OutputInterval=0.02)
solid.UpdatePipeline(0.02)
phyxels = solid.GetDataInformation().DataInformation.GetNumberOfPoints()
print("MLSDeformableSolidFromSurface: points (phyxels and surface) over the ranks:", phyxels, flush=True)
simple.Disconnect()
print("OK", flush=True)
