"""Figures 3.1-3.4 of the thesis: the 9-point example of sec. 3.4 (Data/thesis_9points.xyz, z = f)
approximated by LS (3.1), WLS around the origin (3.2), MLS (3.3) and SPH (3.4) with the quadratic basis
[1, x, y, x^2, xy, y^2], as height fields z = f(x, y) on a 101 x 101 grid.
  pvpython --no-mpi fig_3_x_approximation.py --out DIR [--method LS|WLS|MLS|SPH]   (default: all four)"""
import sys

import figure_common as fc
from paraview import simple

CAMERA = ([3.2, -4.0, 3.0], [0, 0, 0], [0, 0, 1])
FIGURES = {"LS": "fig3_1_ls.png", "WLS": "fig3_2_wls.png", "MLS": "fig3_3_mls.png", "SPH": "fig3_4_sph.png"}


def figure(out, method):
    cloud = simple.OpenDataFile(fc.data("thesis_9points.xyz"))
    fit = MeshlessApproximation(Input=cloud)  # noqa: F821 (from the plugin)
    fit.Method = method
    fit.BasisDegree = 2
    fit.HeightField = 1
    fit.NeighborCount = 9
    fit.SampleDimensions = [101, 101, 1]
    v = fc.view()
    fc.colored(simple.ExtractSurface(Input=fit), v, "Elevation")
    fc.points(cloud, v, color=(0.8, 0.1, 0.1), size=12)
    return fc.save(v, out, FIGURES[method], CAMERA)


if __name__ == "__main__":
    methods = [a for a in FIGURES if "--method" in sys.argv and a == sys.argv[sys.argv.index("--method") + 1]]
    if "--method" in sys.argv:
        i = sys.argv.index("--method")
        del sys.argv[i:i + 2]
    out = fc.start(__doc__)
    for m in methods or list(FIGURES):
        figure(out, m)
