"""Figure 5.8 of the thesis: "dynamics with 65,536 particles" - an SPH fluid block of 64 x 64 x 16
particles collapsing in a closed box (a dam break), coloured by speed, at the end time.
  pvpython --no-mpi fig_5_8_sph.py --out DIR [--end-time T] [--particles N]
--end-time: simulated seconds (default 0.25); --particles: 65536 (default, the thesis), or a smaller
N = 4 k^3 (e.g. 8192, 1024) for a quick run: the same block, sampled more coarsely.
The script checks what it shows: the data rendered is the state at the end time (its time stamp, and
speeds of the order of g t once the dam has started to break), every speed is finite."""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_common as fc  # noqa: E402
from paraview import simple  # noqa: E402

GRAVITY = 9.81


def option(name, default, kind):
    if name in sys.argv:
        i = sys.argv.index(name)
        value = kind(sys.argv[i + 1])
        del sys.argv[i:i + 2]
        return value
    return default


def figure(out, end, particles):
    # The block is 4k x 4k x k particles (k = 16: the thesis' 65,536), always 1.28 x 1.28 x 0.32 m.
    k = round((particles / 16.0) ** (1.0 / 3.0))
    if 16 * k ** 3 != particles:
        sys.exit("--particles must be 16 k^3 (1024, 8192, 65536, ...), not %d" % particles)
    h = 0.32 / k
    fluid = SPHFluid()  # noqa: F821
    fluid.ParticleSpacing = h
    fluid.FluidBounds = [0, 1.28 - 1e-9, 0, 1.28 - 1e-9, 0, 0.32 - 1e-9]
    fluid.DomainBounds = [-0.01, 2.56, -0.01, 1.29, -0.01, 1.0]
    fluid.EndTime = end
    fluid.OutputInterval = end
    speed = simple.Calculator(Input=fluid, ResultArrayName="Speed", Function="mag(Velocity)")

    # Time: the view shows the data at the animation time, which starts at the first time step (t = 0, all
    # speeds zero). Move the scene, its time keeper and the view to the end time, and update the whole
    # pipeline there, before colouring (the colour range comes from the data at that time).
    scene = simple.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = end
    simple.GetTimeKeeper().Time = end
    v = fc.view()
    v.ViewTime = end
    speed.UpdatePipeline(end)
    d = fc.colored(speed, v, "Speed")
    d.SetRepresentationType("Points")
    d.PointSize = 2
    path = fc.save(v, out, "fig5_8_sph_%d.png" % particles, ([1.3, -2.8, 1.6], [1.2, 0.6, 0.1], [0, 0, 1]))

    # What was rendered: the filter's output at `end` (its time stamp), the data the representation holds
    # (its own information carries no time: its speeds must be those of `end`), and the colour map's range
    # (set from the data when coloured: a range of (0, 1e-38) meant the colours were set up at t = 0).
    info = speed.GetDataInformation().DataInformation
    assert info.GetHasTime() and abs(info.GetTime() - end) < 1e-9, \
        "the Calculator's data is at t = %s, not at the requested %s" % (info.GetTime(), end)
    assert info.GetNumberOfPoints() == particles, (info.GetNumberOfPoints(), particles)
    computed = info.GetPointDataInformation().GetArrayInformation("Speed").GetComponentRange(0)
    rendered = d.GetRepresentedDataInformation().GetPointDataInformation().GetArrayInformation("Speed")
    rendered = rendered.GetComponentRange(0)
    lut = simple.GetColorTransferFunction("Speed")
    colours = (lut.RGBPoints[0], lut.RGBPoints[-4])
    low, high = computed
    print("t = %g s: %d particles, speed %.4g .. %.4g m/s (g t = %.4g), colour range %.4g .. %.4g"
          % (end, particles, low, high, GRAVITY * end, colours[0], colours[1]))
    assert math.isfinite(low) and math.isfinite(high) and low >= 0, (low, high)
    assert all(abs(a - b) <= 1e-12 * (1 + abs(b)) for a, b in zip(rendered, computed)), (rendered, computed)
    assert all(abs(a - b) <= 1e-9 * (1 + abs(b)) for a, b in zip(colours, computed)), (colours, computed)
    if end > 0:
        # Released from rest under gravity: the free surface falls and spreads at speeds of order g t.
        assert high > 0.25 * GRAVITY * end, "speeds %g..%g at t = %g: still at rest?" % (low, high, end)
        assert high < 10 * GRAVITY * end + 1.0, "speeds %g..%g at t = %g: blown up?" % (low, high, end)
    return path


if __name__ == "__main__":
    end = option("--end-time", 0.25, float)
    particles = option("--particles", 65536, int)
    out = fc.start(__doc__)
    figure(out, end, particles)
