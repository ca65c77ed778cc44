"""Figure 3.5 of the thesis: MLS over 256 random points (Data/random_256.xyz, z = f), evaluated on a domain
of 10,201 points (101 x 101), as in the thesis (which took 44.43 s there; here it is interactive).
  pvpython --no-mpi fig_3_5_random256.py --out DIR"""
import figure_common as fc
from paraview import simple

if __name__ == "__main__":
    out = fc.start(__doc__)
    cloud = simple.OpenDataFile(fc.data("random_256.xyz"))
    fit = MeshlessApproximation(Input=cloud)  # noqa: F821
    fit.Method = "MLS"
    fit.BasisDegree = 2
    fit.HeightField = 1
    fit.SampleDimensions = [101, 101, 1]
    v = fc.view()
    fc.colored(simple.ExtractSurface(Input=fit), v, "Elevation")
    fc.points(cloud, v, color=(0.8, 0.1, 0.1), size=6)
    fc.save(v, out, "fig3_5_mls_256.png", ([2.5, -3.5, 3.0], [0, 0, 0.5], [0, 0, 1]))
