"""Order independence through paraview.simple (issue 24): Meshless Approximation (every method, k nearest and a fixed
radius, values, gradients and vtkValidPointMask on a grid and on a probe) and Point Neighbors give the same bits when
the input points come in another order. The cloud is a Wavelet's cell centres - a lattice, where every point's k-th
nearest neighbour is one of several at the same distance - and a random cloud; each is permuted 3 times with numpy
and read back from a file (no Programmable Filter). Meshless Surface (MLS, WLS, SPH) of a noisy sphere and of 3
permutations of it gives the same triangles (sorted vertex coordinates, bitwise) with the same values on them."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.util import numpy_support as ns  # noqa: E402
from vtkmodules.vtkCommonCore import vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter  # noqa: E402

meshfree_test.load(globals())
out_dir = meshfree_test.output_dir()


def write_cloud(path, xyz, arrays):
    """A vtkPolyData of vertices with the given point arrays, written to `path`; returns a reader of it."""
    pd = vtkPolyData()
    pts = vtkPoints()
    pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz, dtype=float), deep=1))
    pd.SetPoints(pts)
    n = len(xyz)
    verts = vtkCellArray()
    verts.SetData(ns.numpy_to_vtk(np.arange(n + 1, dtype=np.int64), deep=1),
                  ns.numpy_to_vtk(np.arange(n, dtype=np.int64), deep=1))
    pd.SetVerts(verts)
    for name, values in arrays.items():
        a = ns.numpy_to_vtk(np.ascontiguousarray(values, dtype=float), deep=1)
        a.SetName(name)
        pd.GetPointData().AddArray(a)
    w = vtkXMLPolyDataWriter()
    w.SetDataModeToBinary()
    w.SetFileName(path)
    w.SetInputData(pd)
    assert w.Write() == 1, path
    return simple.XMLPolyDataReader(FileName=[path])


# The lattice: a Wavelet's cell centres with RTData (a cell array turned point array) and a second array.
wavelet = simple.Wavelet(WholeExtent=[-6, 6, -6, 6, -6, 6])
centres = meshfree_test.fetch(simple.CellCenters(Input=simple.PointDatatoCellData(Input=wavelet), VertexCells=1))
lattice = np.asarray(centres.Points, dtype=float)
lattice_arrays = {"RTData": np.asarray(centres.PointData["RTData"], dtype=float)}
lattice_arrays["V"] = np.column_stack([lattice[:, 0] * lattice[:, 1], np.cos(0.3 * lattice[:, 2])])
rng = np.random.default_rng(5)
random = rng.random((1500, 3)) * 12.0 - 6.0
random_arrays = {"RTData": np.sin(0.5 * random[:, 0]) + random[:, 1] ** 2 + 0.5 * random[:, 2],
                 "V": np.column_stack([random[:, 0] * random[:, 1], np.cos(0.3 * random[:, 2])])}
# The probe: lattice points, edge midpoints and cell centres of the lattice (ties), and random points.
grid = np.array([[x, y, z] for x in np.arange(-5.5, 5.6, 0.75) for y in np.arange(-5.5, 5.6, 1.5)
                 for z in (-4.5, -1.0, 0.5, 3.5)])
probe = write_cloud(os.path.join(out_dir, "order_probe.vtp"), np.vstack([grid, rng.random((300, 3)) * 11 - 5.5]),
                    {"Id": np.arange(len(grid) + 300)})

COMPARED = ["RTData", "V", "RTData_gradient", "V_gradient", "vtkValidPointMask"]


def approximation(reader, method, support, with_probe):
    settings = dict(Method=method, ComputeGradients=1, **support)
    if with_probe:
        f = MeshlessApproximation(Input=reader, Probe=probe, **settings)
    else:
        f = MeshlessApproximation(Input=reader, SampleDimensions=[15, 13, 11], **settings)
    out = meshfree_test.fetch(f)
    result = {name: np.asarray(out.PointData[name]).copy() for name in COMPARED}
    simple.Delete(f)
    return result


def neighbors(reader, perm):
    """Point Neighbors' arrays, put back in the original order (row perm[i] of the original is row i here)."""
    f = PointNeighbors(Input=reader, NeighborCount=10, SearchRadius=1.2)
    out = meshfree_test.fetch(f)
    result = {}
    for name in ("MeanNeighborDistance", "NeighborsInRadius", "vtkValidPointMask"):
        values = np.asarray(out.PointData[name])
        back = np.empty_like(values)
        back[perm] = values
        result[name] = back
    simple.Delete(f)
    return result


worst = 0.0
cases = 0
failures = []
for cloud_name, xyz, arrays in (("lattice", lattice, lattice_arrays), ("random", random, random_arrays)):
    n = len(xyz)
    perms = [np.arange(n)] + [np.random.default_rng(seed).permutation(n) for seed in (1, 2, 3)]
    readers = [write_cloud(os.path.join(out_dir, f"order_{cloud_name}_{k}.vtp"), xyz[p],
                           {name: values[p] for name, values in arrays.items()}) for k, p in enumerate(perms)]
    scale = float(np.ptp(arrays["RTData"]))
    for method in ("LS", "WLS", "MLS", "PU-WLS", "SPH"):
        for support_name, support in (("k nearest", dict(NeighborCount=20)), ("radius", dict(SupportRadius=2.5))):
            for with_probe in (False, True):
                label = f"{cloud_name}, {method}, {support_name}, {'probe' if with_probe else 'grid'}"
                want = approximation(readers[0], method, support, with_probe)
                assert np.mean(want["vtkValidPointMask"]) > 0.5, label
                for k in (1, 2, 3):
                    got = approximation(readers[k], method, support, with_probe)
                    diff = max(float(np.max(np.abs(got[name] - want[name]))) for name in COMPARED)
                    worst = max(worst, diff / scale)
                    cases += 1
                    if diff > 0:
                        print(f"{label}, permutation {k}: max difference {diff:.3g} ({diff / scale:.3g} of the range)")
                    failures += [(label, k, name) for name in COMPARED if not np.array_equal(got[name], want[name])]
    want = neighbors(readers[0], perms[0])
    for k in (1, 2, 3):
        got = neighbors(readers[k], perms[k])
        cases += 1
        failures += [(cloud_name, "Point Neighbors", k, name) for name, values in want.items()
                     if not np.array_equal(got[name], values)]
    for reader in readers:
        simple.Delete(reader)


def triangle_set(out):
    """The surface's triangles as a set: each one's vertex coordinates from its smallest vertex on (winding kept),
    the rows sorted; and the point arrays at those vertices in the same order."""
    pts = np.asarray(out.Points, dtype=float)
    conn = np.asarray(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    rows, values = [], []
    arrays = [np.asarray(out.PointData[name], dtype=float).reshape(len(pts), -1) for name in ("RTData", "V")]
    for tri in conn:
        first = min(range(3), key=lambda c: tuple(pts[tri[c]]))
        order = [tri[(first + c) % 3] for c in range(3)]
        rows.append(tuple(pts[order].ravel()))
        values.append(tuple(np.concatenate([a[order].ravel() for a in arrays])))
    index = sorted(range(len(rows)), key=lambda r: rows[r])
    return np.array([rows[r] for r in index]), np.array([values[r] for r in index])


# Meshless Surface (MLS, WLS, SPH): the same triangles, bit for bit, and the same values on them.
rng = np.random.default_rng(9)
sphere = rng.normal(size=(1500, 3))
sphere /= np.linalg.norm(sphere, axis=1)[:, None]
sphere += rng.normal(scale=0.003, size=sphere.shape)
sphere_arrays = {"RTData": sphere[:, 0] + 2 * sphere[:, 2], "V": np.column_stack([sphere[:, 1], sphere[:, 0] ** 2])}
perms = [np.arange(len(sphere))] + [np.random.default_rng(seed).permutation(len(sphere)) for seed in (1, 2, 3)]
readers = [write_cloud(os.path.join(out_dir, f"order_sphere_{k}.vtp"), sphere[p],
                       {name: values[p] for name, values in sphere_arrays.items()}) for k, p in enumerate(perms)]
for method in ("MLS", "WLS", "SPH"):
    results = []
    for reader in readers:
        f = MeshlessSurface(Input=reader, Method=method)
        results.append(triangle_set(meshfree_test.fetch(f)))
        simple.Delete(f)
    assert len(results[0][0]) > 500, (method, len(results[0][0]))
    for k in (1, 2, 3):
        cases += 1
        same = results[k][0].shape == results[0][0].shape and np.array_equal(results[k][0], results[0][0])
        if not same:
            failures.append(("sphere", "Meshless Surface", method, k, "triangles"))
        elif not np.array_equal(results[k][1], results[0][1]):
            failures.append(("sphere", "Meshless Surface", method, k, "point arrays"))
for reader in readers:
    simple.Delete(reader)
print(f"{cases} permuted runs, largest difference {worst:.3g} of the range; {len(failures)} arrays differ")
assert not failures, failures[:10]
