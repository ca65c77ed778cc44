"""Figures 4.6-4.8 of the thesis: MLS deformable solids falling into containers (table 4.3's materials).
  4.6: an octahedron of about 299 phyxels (Data/octahedron_299.pcd shows the thesis' sampling) in a box;
  4.7: an ellipsoid of about 568 phyxels in a box;
  4.8: the ellipsoid of 715 phyxels with its closed surface of 990 vertices and 1976 triangles
       (Data/ellipsoid_715_surface.ply as the solid's input) in a cylinder.
Each PNG shows the rest state (left) and the state at EndTime (right).
  pvpython --no-mpi fig_4_x_deformable.py --out DIR [--figure 4.6|4.7|4.8]
The script checks what it shows (an AssertionError otherwise): the phyxel count is the one of the lattice
rule (a cubic lattice of PhyxelSpacing centred in the shape's bounds, the points inside the shape or the
surface), computed here on its own; every point and value is finite; the solid fell and stayed in its
container; the embedded surface follows the phyxels (same displacement of the centroid, every surface vertex
near a phyxel). The counts are this lattice's; the spacings are chosen to come closest to the thesis'
(299, 568, 715 came from its own samplings; Data/*.pcd holds those clouds):
  4.6: 377 phyxels (the lattice count jumps to 280 at spacing 0.1615, which leaves the apexes 1.8 spacings
  from the nearest phyxel); 4.7: 576; 4.8: 728."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_common as fc  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.numpy_interface import dataset_adapter as dsa  # noqa: E402

CAMERA = ([0, -11, 3.5], [0, 0, 0.8], [0, 0, 1])


def solid(figure):
    if figure == "4.8":
        surface = simple.OpenDataFile(fc.data("ellipsoid_715_surface.ply"))
        s = MLSDeformableSolidFromSurface(Input=surface)  # noqa: F821
        s.PhyxelSpacing = 0.13
        s.Container = "Cylinder"
        s.ContainerBounds = [-1.6, 1.6, -1.6, 1.6, -1.2, 3.0]
        s.YoungModulus, s.PoissonRatio, s.Density, s.WeightFunction = 100.0, 0.2, 5.0, "Poly6"
    else:
        s = MLSDeformableSolid()  # noqa: F821  (a pure source: it never takes the active source)
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


def lattice(bounds, spacing):
    """The solid's phyxel lattice: round(extent / spacing) points per axis, centred in the bounds."""
    axes = []
    for a in range(3):
        lo, hi = bounds[2 * a], bounds[2 * a + 1]
        n = max(1, int((hi - lo) / spacing + 0.5))
        axes.append(0.5 * (lo + hi) - 0.5 * (n - 1) * spacing + spacing * np.arange(n))
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)


def expected_phyxels(s, surface):
    """How many lattice points lie inside the shape (built-in) or the input surface (convex: inside every
    face's plane), with the distance of the closest one to the boundary (an ambiguous count if tiny)."""
    if surface is None:
        b = np.array(s.ShapeBounds)
        p = lattice(b, s.PhyxelSpacing)
        q = (p - 0.5 * (b[0::2] + b[1::2])) / (0.5 * (b[1::2] - b[0::2]))
        v = np.abs(q).sum(1) if s.Shape == "Octahedron" else (q ** 2).sum(1)
        return int((v <= 1 + 1e-9).sum()), float(np.abs(v - 1).min())
    pts, tris = surface
    p = lattice(np.column_stack([pts.min(0), pts.max(0)]).reshape(-1), s.PhyxelSpacing)
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    depth = ((n * a).sum(1)[None, :] - p @ n.T).min(1)
    return int((depth > 0).sum()), float(np.abs(depth).min())


def blocks(source):
    data = sm.Fetch(source)
    out = {}
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        out[it.GetCurrentMetaData().Get(data.NAME())] = dsa.WrapDataObject(it.GetCurrentDataObject())
        it.GoToNextItem()
    return out


def check(which, s, frozen, surface):
    spacing = s.PhyxelSpacing
    rest, end = blocks(frozen[0]), blocks(frozen[1])
    want, ambiguity = expected_phyxels(s, surface)
    centroid = {}
    for t, state in (("rest", rest), ("end", end)):
        assert set(state) >= {"Phyxels", "Surface"}, (which, t, list(state))
        phyxels = np.asarray(state["Phyxels"].Points)
        got = len(phyxels)
        assert got == want or ambiguity < 1e-6, "%s, %s: %d phyxels, the lattice gives %d" % (which, t, got, want)
        for name, block in state.items():
            assert np.all(np.isfinite(np.asarray(block.Points))), (which, t, name)
            for array in block.PointData.keys():
                assert np.all(np.isfinite(np.asarray(block.PointData[array]))), (which, t, name, array)
        surf = np.asarray(state["Surface"].Points)
        # Every surface vertex near a phyxel (at rest the surface is at most about a spacing outside).
        near = np.sqrt(((surf[:, None, :] - phyxels[None, :, :]) ** 2).sum(-1)).min(1).max()
        assert near < 1.5 * spacing, "%s, %s: a surface vertex %.3g from the nearest phyxel" % (which, t, near)
        centroid[t] = (phyxels.mean(0), surf.mean(0))
        box = np.array(s.ContainerBounds)
        assert np.all(phyxels >= box[0::2] - 0.5 * spacing) and np.all(phyxels <= box[1::2] + 0.5 * spacing), \
            (which, t, phyxels.min(0), phyxels.max(0))
    moved_phyxels = centroid["end"][0] - centroid["rest"][0]
    moved_surface = centroid["end"][1] - centroid["rest"][1]
    assert moved_phyxels[2] < -0.5, "%s: the solid did not fall (%s)" % (which, moved_phyxels)
    assert np.linalg.norm(moved_surface - moved_phyxels) < 0.25 * spacing, (which, moved_phyxels, moved_surface)
    print("fig %s: %d phyxels (lattice rule: %d), fell %.3f, surface followed within %.3g"
          % (which, len(np.asarray(end["Phyxels"].Points)), want, -moved_phyxels[2],
             np.linalg.norm(moved_surface - moved_phyxels)))


def figure(out, which):
    s = solid(which)
    surface = None
    if which == "4.8":
        ply = sm.Fetch(s.Input)
        conn = np.asarray(dsa.WrapDataObject(ply).VTKObject.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        surface = (np.asarray(dsa.WrapDataObject(ply).Points, dtype=float), conn)
    v = fc.view((1200, 600))
    frozen = []
    for t, dx in ((0.0, -2.6), (1.0, 2.6)):
        frozen.append(simple.ForceTime(Input=s, ForcedTime=t, IgnorePipelineTime=1))
        shifted = simple.Transform(Input=frozen[-1])
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
    check(which, s, frozen, surface)
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
