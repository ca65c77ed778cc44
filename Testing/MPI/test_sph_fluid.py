"""SPH Fluid on N ranks (pvbatch --symmetric): each particle on exactly one rank, the gathered state equal to a
serial run bit for bit, time steps and the time cache the same on every rank, backwards and forwards in time."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402

mm.load(globals())
ARRAYS = ["Velocity", "Density", "Pressure", "Acceleration", "NeighborCount"]
# A small 2D dam break: 10 x 20 particles.
scene = dict(Dimension=2, ParticleSpacing=0.02, FluidBounds=[0, 0.2, 0, 0, 0, 0.4], DomainBounds=[0, 0.8, 0, 0, 0, 0.5],
             EndTime=0.04, OutputInterval=0.02, ComputeAcceleration=1, ComputeNeighborCount=1)
fluid = SPHFluid(**scene)
serial = SPHFluid(**scene)
mm.agree(fluid.TimestepValues, "TimestepValues")
assert np.allclose(fluid.TimestepValues, [0, 0.02, 0.04]), fluid.TimestepValues


def steps_taken(proxy):
    proxy.UpdatePropertyInformation()
    return proxy.GetProperty("StepsTaken").GetElement(0)


first = {}
for t in (0.04, 0.02, 0.0, 0.04, 0.02):  # forwards, backwards, forwards again: the cache answers the repeats
    local = mm.local_output(fluid, t)
    counts = mm.all_gather([[local.GetNumberOfPoints()]])[:, 0]
    mm.check(counts.max() - counts.min() <= 1, f"unbalanced pieces {counts}")
    got = mm.gathered_points(local, ARRAYS)
    want = mm.sorted_rows(mm.rows(mm.serial_output(serial, t), ARRAYS))
    mm.check(len(got) == 200, f"t = {t}: {len(got)} particles over all ranks, expected 200")
    mm.compare_at_time(f"SPHFluid t = {t}", f"t{t}", got, want, first)
    if t == 0.04 and "t0.02" in first:  # every time has been computed once: no more steps from now on
        steps = steps_taken(fluid)
        mm.agree(steps, "StepsTaken")
steps_end = steps_taken(fluid)
mm.agree(steps_end, "StepsTaken")
mm.check(steps_end == steps > 0, f"the cache did not answer: {steps_end} steps, {steps} before")
if mm.RANK == 0:
    mm.log(f"particles per rank {counts.tolist()}, {steps} steps on every rank, none for the repeated times")
mm.finish()
