"""SPH Fluid With Obstacles on N ranks: the obstacle surface arrives split over the ranks (Sphere) or whole on rank 0
(Box) and is gathered; the gathered fluid equals a serial run bit for bit, each particle on exactly one rank."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402

mm.load(globals())
ARRAYS = ["Velocity", "Density", "Pressure"]
scene = dict(Dimension=2, ParticleSpacing=0.02, FluidBounds=[0, 0.2, 0, 0, 0, 0.4], DomainBounds=[0, 0.8, 0, 0, 0, 0.5],
             EndTime=0.04, OutputInterval=0.02)
sphere = dict(Center=[0.35, 0, 0.06], Radius=0.06, ThetaResolution=24, PhiResolution=12)
box = dict(Center=[0.35, 0, 0.05], XLength=0.1, YLength=0.2, ZLength=0.1)

fluid = SPHFluidWithObstacles(Obstacles=Sphere(**sphere), **scene)
serial = SPHFluidWithObstacles(Obstacles=Sphere(**sphere), **scene)
mm.agree(fluid.TimestepValues, "TimestepValues")
for obstacle in ("Sphere", "Box"):
    if obstacle == "Box":  # a new obstacle restarts the simulation on every rank
        fluid.Obstacles = Box(**box)
        serial.Obstacles = Box(**box)
    results = {}
    for t in (0.04, 0.0, 0.02, 0.04):
        got = mm.gathered_points(mm.local_output(fluid, t), ARRAYS)
        want = mm.sorted_rows(mm.rows(mm.serial_output(serial, t), ARRAYS))
        mm.compare_at_time(f"SPHFluidWithObstacles ({obstacle}) t = {t}", f"{obstacle}_t{t}", got, want, results)
    count = len(results[f"{obstacle}_t0.0"])
    mm.check(count > 150, f"{obstacle}: {count} particles")
mm.finish()
