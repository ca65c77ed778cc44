"""MLS Deformable Solid on N ranks: each phyxel on exactly one rank, both blocks on every rank (empty where there is
nothing), the gathered phyxels and surface equal to a serial run bit for bit, backwards and forwards in time.
With --from-surface: MLS Deformable Solid From Surface filling a Sphere that ParaView splits over the ranks (gathered
by the filter); each rank's Surface block is its own piece, deformed."""
import os
import sys

import numpy as np
from vtkmodules.util import numpy_support as ns

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402

mm.load(globals())
PHYXELS = ["Displacement", "Velocity", "Strain", "Stress", "VonMises", "DetJ", "Mass", "Volume"]
scene = dict(PhyxelSpacing=0.05, Container="Box", ContainerBounds=[-0.5, 0.5, -0.5, 0.5, 0.3, 1], EndTime=0.04,
             OutputInterval=0.02)
if "--from-surface" in sys.argv:
    NAME = "MLSDeformableSolidFromSurface"
    body = dict(Center=[0, 0, 0.6], Radius=0.15, ThetaResolution=16, PhiResolution=10)
    solid = MLSDeformableSolidFromSurface(Input=Sphere(**body), **scene)
    serial = MLSDeformableSolidFromSurface(Input=Sphere(**body), **scene)
else:
    NAME = "MLSDeformableSolid"
    solid = MLSDeformableSolid(Shape="Ellipsoid", SurfaceResolution=12, **scene)
    serial = MLSDeformableSolid(Shape="Ellipsoid", SurfaceResolution=12, **scene)
mm.agree(solid.TimestepValues, "TimestepValues")


def surface_rows(data):
    """Rows (point, Displacement, Normals) of the Surface block; the point order is not compared, the rows are."""
    s = mm.block(data, 1, "Surface")
    n = s.GetNumberOfPoints()
    if n == 0:
        return np.zeros((0, 9)), 0
    cols = [ns.vtk_to_numpy(s.GetPoints().GetData()), ns.vtk_to_numpy(s.GetPointData().GetArray("Displacement")),
            ns.vtk_to_numpy(s.GetPointData().GetNormals())]
    return np.hstack([c.reshape(n, 3) for c in cols]), s.GetNumberOfPolys()


results, surfaces = {}, {}
for t in (0.04, 0.0, 0.02, 0.04):
    local = mm.local_output(solid, t)
    got = mm.gathered_points(mm.block(local, 0, "Phyxels"), PHYXELS)
    whole = mm.serial_output(serial, t)
    want = mm.sorted_rows(mm.rows(mm.block(whole, 0, "Phyxels"), PHYXELS))
    mm.compare_at_time(f"{NAME} Phyxels t = {t}", f"t{t}", got, want, results)
    local_surface, local_polys = surface_rows(local)
    got_surface = np.unique(mm.all_gather(local_surface), axis=0)
    polys = mm.all_gather(np.array([[local_polys]]))[:, 0].sum()
    want_surface, want_polys = surface_rows(whole)
    mm.check(polys == want_polys, f"{polys} surface triangles over all ranks, serial {want_polys}")
    mm.compare_at_time(f"{NAME} Surface t = {t}", f"surface_t{t}", got_surface, np.unique(want_surface, axis=0),
                       surfaces)
mm.finish()
