"""UNTESTED (see ../README.md): it crashed inside the SPH Fluid source when last run.
Figure 5.8 of the thesis: "dynamics with 65,536 particles" - an SPH fluid block of 64 x 64 x 16
particles collapsing in a closed box (a dam break), coloured by speed, at EndTime.
  pvpython --no-mpi fig_5_8_sph.py --out DIR [--end-time T]  (default 0.25 s of simulated time)"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import figure_common as fc  # noqa: E402
from paraview import simple

if __name__ == "__main__":
    end = 0.25
    if "--end-time" in sys.argv:
        i = sys.argv.index("--end-time")
        end = float(sys.argv[i + 1])
        del sys.argv[i:i + 2]
    out = fc.start(__doc__)
    h = 0.02
    fluid = SPHFluid()  # noqa: F821
    fluid.ParticleSpacing = h
    fluid.FluidBounds = [0, 64 * h - 1e-9, 0, 64 * h - 1e-9, 0, 16 * h - 1e-9]
    fluid.DomainBounds = [-0.01, 2.56, -0.01, 1.29, -0.01, 1.0]
    fluid.EndTime = end
    fluid.OutputInterval = end
    v = fc.view()
    fluid.UpdatePipeline(end)
    speed = simple.Calculator(Input=fluid, ResultArrayName="Speed", Function="mag(Velocity)")
    d = fc.colored(speed, v, "Speed")
    d.SetRepresentationType("Points")
    d.PointSize = 2
    v.ViewTime = end
    fc.save(v, out, "fig5_8_sph_65536.png", ([1.3, -2.8, 1.6], [1.2, 0.6, 0.1], [0, 0, 1]))
