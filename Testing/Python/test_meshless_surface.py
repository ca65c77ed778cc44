"""Meshless Surface and Meshless Normals through paraview.simple: the contract's names, every Method by its
text, on the shipped torus scan (Data/scan_torus.pcd: 3000 points from 4 scanners, sigma 0.004, arrays
intensity and scanner) and on SPH Fluid particles: closed meshes, unit outward Normals, the input's arrays
approximated at the vertices, no NaN."""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402

meshfree_test.load(globals())

SOURCE = os.environ.get("MESHFREE_SOURCE_DIR", os.path.dirname(os.path.dirname(HERE)))
RING, TUBE = 1.0, 0.35


def torus_distance(x):
    return np.hypot(np.hypot(x[:, 0], x[:, 1]) - RING, x[:, 2]) - TUBE


def torus_normals(x):
    rho = np.hypot(x[:, 0], x[:, 1])
    q = x.copy()
    q[:, 0] -= RING * x[:, 0] / rho
    q[:, 1] -= RING * x[:, 1] / rho
    return q / np.linalg.norm(q, axis=1)[:, None]


def nearest(x, cloud, chunk=512):
    """Distance from every row of x to the nearest point of cloud (brute force, in chunks)."""
    return np.concatenate([np.sqrt(((x[i:i + chunk, None, :] - cloud[None, :, :]) ** 2).sum(-1).min(axis=1))
                           for i in range(0, len(x), chunk)])


def topology(mesh):
    """(boundary edges, non-manifold edges, Euler characteristic) of a triangle mesh."""
    polys = mesh.VTKObject.GetPolys()
    offsets = np.asarray(polys.GetOffsetsArray())
    assert np.all(np.diff(offsets) == 3), "not all cells are triangles"
    tri = np.asarray(polys.GetConnectivityArray()).reshape(-1, 3)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    vertices = len(np.unique(tri))
    return int((count == 1).sum()), int((count > 2).sum()), vertices - len(unique) + len(tri)


def check_mesh(mesh, label, euler):
    n = mesh.GetNumberOfPoints()
    assert n > 100 and mesh.GetNumberOfCells() > 100, (label, n)
    boundary, nonmanifold, chi = topology(mesh)
    print("%s: %d vertices, %d triangles, %d boundary edges, Euler %d"
          % (label, n, mesh.GetNumberOfCells(), boundary, chi))
    assert boundary == 0 and nonmanifold == 0, (label, boundary, nonmanifold)
    assert chi == euler, (label, chi)
    assert np.all(np.isfinite(np.asarray(mesh.Points))), label
    for name in mesh.PointData.keys():
        assert np.all(np.isfinite(np.asarray(mesh.PointData[name]))), (label, name)
    normals = np.asarray(mesh.PointData["Normals"])
    assert normals.shape == (n, 3), (label, normals.shape)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-9), label
    assert mesh.VTKObject.GetPointData().GetNormals() is not None, label


scan = simple.OpenDataFile(os.path.join(SOURCE, "Data", "scan_torus.pcd"))
cloud = meshfree_test.fetch(scan)
xyz = np.asarray(cloud.Points, dtype=float)
intensity = np.asarray(cloud.PointData["intensity"], dtype=float)

# Defaults and text enumerations.
surface = MeshlessSurface(Input=scan)
assert surface.Method == "MLS", surface.Method
assert surface.NeighborCount == 20 and surface.SupportRadius == 0 and surface.CellSize == 0
assert surface.SupportScale == 2 and surface.SurfaceLevel == 0.5
assert surface.AnisotropicKernels == 0 and surface.ProjectVertices == 1 and surface.UseInputNormals == 1
assert surface.HoleFilling == "Auto", surface.HoleFilling
for text in ("WLS", "SPH", "MLS"):
    surface.Method = text
    assert surface.Method == text
for text in ("Off", "On", "Auto"):
    surface.HoleFilling = text
    assert surface.HoleFilling == text
# Every method runs on the scan with its defaults: a finite mesh with the scan's arrays, accurate where the
# scan sampled the torus. (The scanners missed its underside - 22 % of its area is over 0.1 from any point;
# the cloud encloses a volume, so HoleFilling 'Auto' closes it for MLS and WLS: see below.)
for text in ("MLS", "WLS", "SPH"):
    surface.Method = text
    mesh = meshfree_test.fetch(surface)
    assert mesh.GetNumberOfCells() > 100, text
    assert {"Normals", "intensity", "scanner"} <= set(mesh.PointData.keys()), (text, mesh.PointData.keys())
    assert all(np.all(np.isfinite(np.asarray(mesh.PointData[k]))) for k in mesh.PointData.keys()), text
    assert np.all(np.isfinite(np.asarray(mesh.Points))), text
    assert mesh.FieldData["SurfaceMethod"].GetValue(0) == text, text
    assert float(mesh.FieldData["CellSize"][0]) > 0, text
    if text != "SPH":  # the SPH surface of a surface scan is a shell around it, not the torus
        x = np.asarray(mesh.Points)
        near = nearest(x, xyz) < 0.03
        rms = np.sqrt(np.mean(torus_distance(x[near]) ** 2))
        print("%s defaults: rms distance to the torus %.4f over the %d vertices near the scan"
              % (text, rms, near.sum()))
        assert near.sum() > 500 and rms < 0.003, (text, near.sum(), rms)
        # DistanceToData: the distance from each vertex to the nearest point of the scan.
        d = np.asarray(mesh.PointData["DistanceToData"])
        assert np.allclose(d, nearest(x, xyz), atol=1e-9), text
        # HoleFilling 'Auto' decided the cloud encloses a volume and closed the underside.
        assert float(mesh.FieldData["HolesFilled"][0]) == 1, text
        assert float(mesh.FieldData["OpenShare"][0]) < 0.45, text
        check_mesh(mesh, "scan, defaults, " + text, euler=0)
        assert d.max() > 0.1, (text, d.max())  # the film across the underside, away from the data
        # HoleFilling 'Off' leaves it open, its border near the data's: the border vertices' median distance to
        # the scan within 2.5 spacings (0.13; measured 0.07 MLS; the fits alone: medians 0.31 MLS, 0.19 WLS).
        surface.HoleFilling = "Off"
        mesh = meshfree_test.fetch(surface)
        surface.HoleFilling = "Auto"
        boundary, _, _ = topology(mesh)
        tri = np.asarray(mesh.VTKObject.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        unique, count = np.unique(edges, axis=0, return_counts=True)
        border = np.asarray(mesh.PointData["DistanceToData"])[np.unique(unique[count == 1])]
        print("%s, HoleFilling Off: %d boundary edges, border median distance to the scan %.3f"
              % (text, boundary, np.median(border)))
        assert boundary > 0 and float(mesh.FieldData["HolesFilled"][0]) == 0, text
        assert np.median(border) < 0.13, (text, np.median(border))

# A support wide enough to bridge the unseen underside: closed tori for MLS and WLS. Over the gap WLS stays
# near the torus; MLS (spheres fitted to the gap's rims) bulges out by up to 0.25, so only WLS is held to an
# rms over the whole mesh.
surface.NeighborCount = 30
surface.SupportScale = 3
for text, near_bound, rms_bound in (("WLS", 0.003, 0.015), ("MLS", 0.012, None)):
    surface.Method = text
    mesh = meshfree_test.fetch(surface)
    check_mesh(mesh, "scan, " + text, euler=0)
    x = np.asarray(mesh.Points)
    near = nearest(x, xyz) < 0.03
    rms, rms_near = np.sqrt(np.mean(torus_distance(x) ** 2)), np.sqrt(np.mean(torus_distance(x[near]) ** 2))
    print("  rms distance to the torus %.4f, %.4f near the scan" % (rms, rms_near))
    assert rms_near < near_bound and (rms_bound is None or rms < rms_bound), (text, rms, rms_near)
    outward = (np.asarray(mesh.PointData["Normals"]) * torus_normals(x)).sum(axis=1)
    assert np.mean(outward > 0) > 0.98, (text, np.mean(outward > 0))
    # intensity at the vertices near the scan: about the mean of the scan's values around them.
    values = np.asarray(mesh.PointData["intensity"])
    around = np.sqrt(((x[near, None, :] - xyz[None, :, :]) ** 2).sum(-1)) < 0.06
    local = (around * intensity[None, :]).sum(1) / np.maximum(around.sum(1), 1)
    error = np.median(np.abs(values[near] - local)[around.sum(1) > 0])
    print("  intensity: median |vertex - local mean of the scan| = %.3f over %d vertices" % (error, near.sum()))
    assert error < 0.1, (text, error)
    # Over the bridged gap the values stay within the scan's range (a linear fit alone overshot to [-0.82, 1.24]).
    assert values.min() >= intensity.min() and values.max() <= intensity.max(), (text, values.min(), values.max())

# Meshless Normals on the scan: unit, outward, curvature; ProjectPoints moves the points onto the surface.
normals = MeshlessNormals(Input=scan)
assert normals.Orientation == "Auto" and normals.NeighborCount == 20 and normals.ProjectPoints == 0
for text in ("Propagation", "Viewpoint", "InputNormals", "Auto"):
    normals.Orientation = text
    assert normals.Orientation == text
out = meshfree_test.fetch(normals)
for name in ("Normals", "Curvature", "SurfaceVariation", "OrientationConfidence", "vtkValidPointMask",
             "intensity", "scanner"):
    assert name in out.PointData.keys(), (name, out.PointData.keys())
n = np.asarray(out.PointData["Normals"])
assert np.all(np.asarray(out.PointData["vtkValidPointMask"]) == 1)
assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-9)
cosines = (n * torus_normals(xyz)).sum(axis=1)
print("normals: %.1f %% outward, mean angle error %.2f degrees"
      % (100 * np.mean(cosines > 0), np.degrees(np.arccos(np.clip(cosines, -1, 1))).mean()))
assert np.all(cosines > 0)
assert np.degrees(np.arccos(np.clip(cosines, -1, 1))).mean() < 5
curvature = np.asarray(out.PointData["Curvature"])
assert np.all(np.isfinite(curvature)) and np.median(curvature) > 0  # the torus is convex on most of its area
for name in ("NoiseEstimate", "SupportRadius", "AmbiguousOrientations"):
    assert name in out.FieldData.keys(), name
# ProjectPoints moves the points onto the MLS surface: closer to the torus, with automatic or fixed radii.
normals.ProjectPoints = 1
projected = np.asarray(meshfree_test.fetch(normals).Points)
before, after = np.abs(torus_distance(xyz)), np.abs(torus_distance(projected))
print("ProjectPoints: rms distance to the torus %.4f -> %.4f"
      % (np.sqrt(np.mean(before ** 2)), np.sqrt(np.mean(after ** 2))))
assert np.sqrt(np.mean(after ** 2)) < 0.7 * np.sqrt(np.mean(before ** 2))
normals.SupportRadius = 0.1
out = meshfree_test.fetch(normals)
valid = np.asarray(out.PointData["vtkValidPointMask"]) == 1
after = np.abs(torus_distance(np.asarray(out.Points)[valid]))
print("ProjectPoints, SupportRadius 0.1: rms %.4f -> %.4f on %d points"
      % (np.sqrt(np.mean(before[valid] ** 2)), np.sqrt(np.mean(after ** 2)), valid.sum()))
assert valid.sum() > 2900 and np.sqrt(np.mean(after ** 2)) < 0.7 * np.sqrt(np.mean(before[valid] ** 2))
normals.SupportRadius = 0

# The normals feed the surface (its input Normals are used): the same closed torus.
normals.ProjectPoints = 0
chained = MeshlessSurface(Input=normals, Method="WLS", NeighborCount=30, SupportScale=3)
mesh = meshfree_test.fetch(chained)
check_mesh(mesh, "Meshless Normals -> Meshless Surface", euler=0)
assert "Curvature" in mesh.PointData.keys()

# SPH: the surface of a block of fluid particles, with the particles' arrays at the vertices.
simple.SetActiveSource(None)
fluid = SPHFluid(Dimension=3, ParticleSpacing=0.02, FluidBounds=[0, 0.2, 0, 0.2, 0, 0.2],
                 DomainBounds=[0, 0.4, 0, 0.4, 0, 0.4], EndTime=0.01, OutputInterval=0.01)
particles = meshfree_test.fetch(fluid, 0.0)
fluid_surface = MeshlessSurface(Input=fluid, Method="SPH")
mesh = meshfree_test.fetch(fluid_surface, 0.0)
check_mesh(mesh, "SPH block of %d particles" % particles.GetNumberOfPoints(), euler=2)
for name in ("Velocity", "Density", "Pressure", "Id"):
    assert name in mesh.PointData.keys(), (name, mesh.PointData.keys())
    assert np.asarray(mesh.PointData[name]).shape[1:] == np.asarray(particles.PointData[name]).shape[1:], name
x = np.asarray(mesh.Points)
centre = np.asarray(particles.Points).mean(axis=0)
outward = (np.asarray(mesh.PointData["Normals"]) * (x - centre)).sum(axis=1)
assert np.all(outward > 0), np.mean(outward > 0)
density = np.asarray(mesh.PointData["Density"])
print("SPH block: Density at the vertices %.1f .. %.1f" % (density.min(), density.max()))
assert density.min() > 0
