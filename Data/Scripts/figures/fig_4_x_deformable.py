"""Figures 4.6-4.8 of the thesis: MLS deformable solids falling into containers (table 4.3's materials).
  4.6: an octahedron of about 299 phyxels (Data/octahedron_299.pcd shows the thesis' sampling) in a box;
  4.7: an ellipsoid of about 568 phyxels in a box;
  4.8: the ellipsoid of 715 phyxels with its closed surface of 990 vertices and 1976 triangles
       (Data/ellipsoid_715_surface.ply as the solid's input) in a cylinder.
Each PNG shows the rest state (left) and the state at EndTime (right).
  pvpython --no-mpi fig_4_x_deformable.py --out DIR [--figure 4.6|4.7|4.8]"""
import sys

import figure_common as fc
from paraview import simple

CAMERA = ([0, -11, 3.5], [0, 0, 0.8], [0, 0, 1])


def solid(figure):
    if figure == "4.8":
        surface = simple.OpenDataFile(fc.data("ellipsoid_715_surface.ply"))
        s = MLSDeformableSolid(Input=surface)  # noqa: F821
        s.PhyxelSpacing = 0.11856
        s.Container = "Cylinder"
        s.ContainerBounds = [-1.6, 1.6, -1.6, 1.6, -1.2, 3.0]
        s.YoungModulus, s.PoissonRatio, s.Density, s.WeightFunction = 100.0, 0.2, 5.0, "Poly6"
    else:
        s = MLSDeformableSolid()  # noqa: F821
        if figure == "4.6":
            s.Shape = "Octahedron"
            s.ShapeBounds = [-1, 1, -1, 1, 0.5, 2.51]
            s.PhyxelSpacing = 0.16
            s.YoungModulus, s.PoissonRatio, s.Density, s.WeightFunction = 10000.0, 0.1, 10.0, "W5"
        else:
            s.Shape = "Ellipsoid"
            s.ShapeBounds = [-1, 1, -0.6, 0.6, 1.0, 2.0]
            s.PhyxelSpacing = 0.1299
            s.YoungModulus, s.PoissonRatio, s.Density, s.WeightFunction = 100.0, 0.2, 5.0, "Poly6"
        s.Container = "Box"
        s.ContainerBounds = [-2.5, 2.5, -2.5, 2.5, -1.5, 4.0]
    s.VolumeStiffness = 100.0
    s.NeighborCount = 10
    s.Integrator = "SymplecticEuler"
    s.TimeStep = 0.001
    s.Damping = 0.5
    s.EndTime = 1.0
    s.OutputInterval = 0.1
    return s


def figure(out, which):
    s = solid(which)
    v = fc.view((1200, 600))
    for t, dx in ((0.0, -2.6), (1.0, 2.6)):
        frozen = simple.ForceTime(Input=s, ForcedTime=t, IgnorePipelineTime=1)
        shifted = simple.Transform(Input=frozen)
        shifted.Transform.Translate = [dx, 0, 0]
        phyxels = simple.ExtractBlock(Input=shifted, Selectors=["/Root/Phyxels"])
        d = fc.colored(phyxels, v, "VonMises")
        d.SetRepresentationType("Points")
        d.RenderPointsAsSpheres = 1
        d.PointSize = 6
        if which == "4.8":
            surf = simple.ExtractBlock(Input=shifted, Selectors=["/Root/Surface"])
            sd = simple.Show(surf, v)
            sd.Opacity = 0.35
    return fc.save(v, out, "fig%s_solid.png" % which.replace(".", "_"), CAMERA)


if __name__ == "__main__":
    chosen = None
    if "--figure" in sys.argv:
        i = sys.argv.index("--figure")
        chosen = sys.argv[i + 1]
        del sys.argv[i:i + 2]
    out = fc.start(__doc__)
    for f in [chosen] if chosen else ["4.6", "4.7", "4.8"]:
        figure(out, f)
