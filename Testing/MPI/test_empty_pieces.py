"""More ranks than particles: a 2-particle fluid and a 2-particle obstacle-free fluid on 3 ranks. The ranks with empty
pieces take part in everything (no hang), every particle is on exactly one rank, the output equals serial, and an
empty piece still carries every array. Also an obstacle on a rank that has no particle."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402

mm.load(globals())
ARRAYS = ["Velocity", "Density", "Pressure"]
scene = dict(Dimension=2, ParticleSpacing=0.02, FluidBounds=[0, 0.02, 0, 0, 0, 0.02],
             DomainBounds=[0, 0.2, 0, 0, 0, 0.2], EndTime=0.02, OutputInterval=0.01)
for name, make in (("SPHFluid", lambda: SPHFluid(**scene)),
                   ("SPHFluidWithObstacles", lambda: SPHFluidWithObstacles(
                       Obstacles=Sphere(Center=[0.1, 0, 0.1], Radius=0.03), **scene))):
    fluid, serial = make(), make()
    for t in (0.02, 0.0, 0.01):
        local = mm.local_output(fluid, t)
        for array in ARRAYS + ["Id"]:
            assert local.GetPointData().GetArray(array) is not None, f"{array} missing on rank {mm.RANK}"
        got = mm.gathered_points(local, ARRAYS)
        want = mm.sorted_rows(mm.rows(mm.serial_output(serial, t), ARRAYS))
        count = len(want)
        mm.check(0 < count < mm.RANKS or mm.RANKS == 1, f"{count} particles: not a case of empty pieces")
        mm.compare(f"{name} ({count} particles) t = {t}", got, want)
        mm.reference(f"{name}_t{t}", got)
mm.finish()
