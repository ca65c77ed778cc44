"""Meshless Normals and Meshless Surface on N ranks against serial, through ParaView's pipeline.

The cloud (a noisy torus of 3,000 points with a few exact duplicates, a `Temperature` array and the point's serial
index `Id`) comes from a Programmable Source that answers piece requests by index, split evenly (piece p of P:
[pn/P, (p+1)n/P)) or unevenly with piece 0 empty. Each rank's piece of the filters' outputs is gathered on every
rank and compared with the serial output of a second proxy updated as piece 0 of 1 in the same process, and (2
ranks, --reference) with an independent `pvpython --no-mpi` run:
- Normals: every point on exactly one rank, with its serial Normals, Curvature, SurfaceVariation,
  OrientationConfidence, vtkValidPointMask (and, with ProjectPoints, coordinates), bit for bit; also pieces that
  are slabs along x of a 40,000-point cloud, where no rank may hold more than a share of the cloud (its slab and
  a halo band: LocalCloudPoints), three permutations of the cloud (split by index and in slabs) against the serial
  run of the unpermuted cloud, pieces from RedistributeDataSet, and every point on the last rank;
- Surface: the ranks' triangles together are the serial triangles, each exactly once: every triangle as its three
  vertices' (coordinates, Normals, approximated arrays), rotated to start at its smallest vertex, sorted, compared
  bit for bit.
Bitwise: Meshless Normals computes each rank's own points over its piece and a halo with the whole cloud's
neighbour-grid frame, exact medians and halo updates of the neighbours' values (see vtkMeshlessNormals.h); Meshless
Surface (MLS, WLS) does the same over slabs of space and contours each slab's lattice cells, its winding number
summing the far slabs' cubes by their gathered moments (the cases split by index, unevenly, in slabs - held shares
asserted -, permuted, redistributed, with NaN points, all on one rank; holes filled and not). Also a one-point cloud
(no hang, no output).
--measure: print the differences without failing (how far the pieces are from serial).
"""
import builtins
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402
from vtkmodules.util import numpy_support as ns  # noqa: E402

import meshfree_mpi as mm  # noqa: E402

MEASURE = "--measure" in sys.argv
# pvbatch's __main__ holds paraview.simple's names, which shadow some builtins (min) and names like split: the loop
# variables below avoid them, and soup() calls builtins.min.
plugin = {"loaded": True}  # a non-empty dict: LoadPlugin ignores an empty one
mm.load(plugin)
MeshlessNormals, MeshlessSurface = plugin["MeshlessNormals"], plugin["MeshlessSurface"]
from paraview import simple  # noqa: E402

CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
count, split, shuffle, nans, outliers = {count}, '{split}', {shuffle}, {nans}, {outliers}
rng = np.random.default_rng(14)
u, v = rng.random(count) * 2 * np.pi, rng.random(count) * 2 * np.pi
R, r = 1.0, 0.4
xyz = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1)
xyz += rng.normal(scale=0.004, size=xyz.shape)
if count > 100 and split != 'redistribute':      # exact duplicates (RedistributeDataSet merges them)
    xyz[-10:] = xyz[:10]
ident = np.arange(count, dtype=float)
if outliers:                                      # a few points far from the torus (their neighbourhoods are wide)
    xyz[count // 2:count // 2 + outliers] = np.random.default_rng(5).uniform(-3.0, 3.0, (outliers, 3))
if nans:                                          # points with a NaN coordinate: invalid, never in a halo
    xyz[np.arange(nans) * (count // nans), 1] = np.nan
if shuffle:                                       # the same cloud in another order (Id follows its point)
    perm = np.random.default_rng(shuffle).permutation(count)
    xyz, ident = xyz[perm], ident[perm]
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
if pieces == 1:
    lo, hi = 0, count
elif split in ('even', 'slab', 'redistribute'):
    lo, hi = piece * count // pieces, (piece + 1) * count // pieces
elif split == 'last':                             # every point on the last rank
    lo, hi = (0, count) if piece == pieces - 1 else (0, 0)
else:                                             # piece 0 empty, the others growing
    lo = 0 if piece == 0 else count * (piece - 1) ** 2 // (pieces - 1) ** 2
    hi = 0 if piece == 0 else count * piece ** 2 // (pieces - 1) ** 2
# slab: the pieces are slabs along x (compact in space: each rank's halo is a band along its slab's faces)
order = np.argsort(xyz[:, 0], kind='stable') if split == 'slab' and pieces > 1 else np.arange(count)
take = order[lo:hi]
out = self.GetPolyDataOutput()
pts = vtkPoints()
pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz[take]), deep=1))
out.SetPoints(pts)
if split == 'redistribute':                       # RedistributeDataSet drops points without cells
    verts = vtkCellArray()
    verts.SetData(ns.numpy_to_vtk(np.arange(len(take) + 1, dtype=np.int64), deep=1),
                  ns.numpy_to_vtk(np.arange(len(take), dtype=np.int64), deep=1))
    out.SetVerts(verts)
for name, values in (('Id', ident), ('Temperature', xyz[:, 2] + 0.5 * xyz[:, 0])):
    array = ns.numpy_to_vtk(np.ascontiguousarray(values[take]), deep=1)
    array.SetName(name)
    out.GetPointData().AddArray(array)
"""
INFO_SCRIPT = """
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
self.GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
"""
NORMAL_ARRAYS = ["Normals", "Curvature", "SurfaceVariation", "OrientationConfidence", "vtkValidPointMask"]
SURFACE_ARRAYS = ["Normals", "DistanceToData", "Temperature", "vtkValidPointMask"]


def cloud(count, split, shuffle=0, nans=0, outliers=0):
    simple.SetActiveSource(None)
    return simple.ProgrammableSource(OutputDataSetType="vtkPolyData",
                                     Script=CLOUD_SCRIPT.format(count=count, split=split, shuffle=shuffle, nans=nans,
                                                                outliers=outliers),
                                     ScriptRequestInformation=INFO_SCRIPT)


def agree(value, what):
    if MEASURE:
        values = mm.all_gather(np.array([[float(value)]]))[:, 0]
        if mm.RANK == 0 and np.ptp(values) > 0:
            mm.log(f"{what} differs over ranks: {values.tolist()}")
        return
    mm.agree(value, what)


def compare(label, got, want):
    """Bitwise (see the module's doc), NaN where the serial run has NaN (a NaN input point's coordinates); --measure:
    report only."""
    if got.shape != want.shape:
        mm.log(f"{label}: shape {got.shape} on {mm.RANKS} ranks, serial {want.shape}")
        mm.check(MEASURE, f"{label}: shapes differ")
        return
    mm.check(MEASURE or np.array_equal(np.isnan(got), np.isnan(want)), f"{label}: NaN in other places than serial")
    got, want = np.nan_to_num(got, nan=0.0), np.nan_to_num(want, nan=0.0)
    diff = np.abs(got - want)
    if MEASURE:
        if mm.RANK == 0:
            rows = int(np.count_nonzero(diff.max(axis=1) > 1e-9)) if got.size else 0
            mm.log(f"{label}: max |{mm.RANKS} ranks - serial| = {diff.max() if got.size else 0:.3g} "
                   f"(per column {np.round(diff.max(axis=0), 6).tolist() if got.size else []}), {rows} of "
                   f"{len(got)} rows differ by more than 1e-9")
        return
    mm.compare(label, got, want)


def soup(polydata, names):
    """(triangles, 3 x width) table: each triangle's vertices (xyz, then the named arrays), rotated so that the
    lexicographically smallest vertex comes first (orientation kept), the triangles sorted."""
    n = polydata.GetNumberOfPoints() if polydata else 0
    cols = [np.zeros((0, 3)) if n == 0 else ns.vtk_to_numpy(polydata.GetPoints().GetData()).reshape(n, 3)]
    for name in names:
        array = polydata.GetPointData().GetArray(name) if n else None
        assert array is not None or n == 0, f"array {name} missing"
        if array is not None:
            cols.append(ns.vtk_to_numpy(array).reshape(n, array.GetNumberOfComponents()).astype(float))
    vertex = np.hstack(cols) if n else np.zeros((0, 3 + 3 + len(names) - 1))
    width = vertex.shape[1]
    polys = polydata.GetPolys() if polydata else None
    if not polys or polys.GetNumberOfCells() == 0:
        return np.zeros((0, 3 * width))
    offsets = ns.vtk_to_numpy(polys.GetOffsetsArray())
    assert np.all(np.diff(offsets) == 3), "not only triangles"
    tri = ns.vtk_to_numpy(polys.GetConnectivityArray()).reshape(-1, 3)
    out = np.empty((len(tri), 3 * width))
    for t, (a, b, c) in enumerate(tri):
        rows = [vertex[a], vertex[b], vertex[c]]
        first = builtins.min(range(3), key=lambda k: tuple(rows[k]))
        out[t] = np.concatenate([rows[(first + k) % 3] for k in range(3)])
    return out[np.lexsort(out.T[::-1])] if len(out) else out


def normals_case(label, count, split, max_share=1.0, shuffle=0, nans=0, **settings):
    # With shuffle, the pieces hold a permutation of the cloud; the serial run is of the cloud in its own order.
    source = cloud(count, split, shuffle, nans)
    # redistribute: ParaView's RedistributeDataSet makes spatial pieces (the serial run takes the source itself).
    pieces = simple.RedistributeDataSet(Input=source) if split == "redistribute" else source
    normals = MeshlessNormals(Input=pieces, **settings)
    serial = MeshlessNormals(Input=cloud(count, split, 0, nans) if shuffle else source, **settings)
    local = mm.local_output(normals, 0.0)
    got = mm.gathered_points(local, NORMAL_ARRAYS)
    want = mm.sorted_rows(mm.rows(mm.serial_output(serial, 0.0), NORMAL_ARRAYS))
    mm.check(len(want) == count, f"{label}: serial output has {len(want)} of {count} points")
    compare(f"Normals {label} ({split} split)", got, want)
    if split == "even":
        mm.reference(f"normals_{label}", np.nan_to_num(got, nan=1e300))  # NaN input coordinates: a marker
    for name in ("NoiseEstimate", "SupportRadius", "AmbiguousOrientations"):
        array = local.GetFieldData().GetArray(name)
        mm.check(array is not None, f"field {name} missing on rank {mm.RANK}")
        agree(array.GetTuple1(0), f"Normals {label} ({split} split): field {name}")
    if mm.RANKS == 1:
        return normals
    held_share(local, f"Normals {label}", split, count, max_share)
    return normals


def held_share(local, label, split, count, max_share):
    """Distributed, not gathered: each rank computes over its piece (Normals) or slab (Surface) and a halo
    (LocalCloudPoints), never more than the cloud; slabs of a large enough cloud hold well under the whole of it."""
    held = local.GetFieldData().GetArray("LocalCloudPoints")
    mm.check(held is not None and held.GetTuple1(0) <= count, f"{label}: LocalCloudPoints missing or > {count}")
    if split in ("slab", "redistribute"):
        most = mm.all_gather(np.array([[held.GetTuple1(0)]]))[:, 0].max()
        radius = local.GetFieldData().GetArray("HaloRadius").GetTuple1(0)
        attempts = local.GetFieldData().GetArray("HaloAttempts").GetTuple1(0)
        mm.check(np.isfinite(radius) and (radius > 0 or radius == -1),
                 f"{label} ({split}): HaloRadius {radius} is neither a width nor -1 (the whole cloud)")
        if mm.RANK == 0:
            mm.log(f"{label} ({split}): at most {int(most)} of {count} points on a rank "
                   f"(halo radius {radius:.3g}, {int(attempts)} attempt(s))")
        mm.check(most <= max_share * count, f"{label} ({split}): a rank held {most} of {count} points")


def surface_case(label, count, split, with_normals=False, max_share=1.0, shuffle=0, nans=0, distributed=False,
                 outliers=0, retried=False, **settings):
    # With shuffle, the pieces hold a permutation of the cloud; the serial run is of the cloud in its own order.
    source = cloud(count, split, shuffle, nans, outliers)
    pieces = simple.RedistributeDataSet(Input=source) if split == "redistribute" else source

    def make(upstream):
        upstream = MeshlessNormals(Input=upstream) if with_normals else upstream
        return MeshlessSurface(Input=upstream, **settings)

    surface = make(pieces)
    serial = make(cloud(count, split, 0, nans, outliers) if shuffle else source)
    local = mm.local_output(surface, 0.0)
    got = mm.all_gather(soup(local, SURFACE_ARRAYS))
    got = got[np.lexsort(got.T[::-1])] if len(got) else got
    want = soup(mm.serial_output(serial, 0.0), SURFACE_ARRAYS)
    mm.check(len(want) > 1000 or count < 10, f"{label}: serial surface has only {len(want)} triangles")
    compare(f"Surface {label} ({split} split): {len(want)} serial triangles, {len(got)} on {mm.RANKS} ranks",
            got, want)
    if split == "even":
        mm.reference(f"surface_{label}", got)
    cell = local.GetFieldData().GetArray("CellSize")
    agree(cell.GetTuple1(0) if cell else float("nan"), f"Surface {label} ({split} split): field CellSize")
    if distributed and mm.RANKS > 1:
        held_share(local, f"Surface {label}", split, count, max_share)
        if retried:  # the first halo fell short somewhere: the run was repeated with a wider one
            attempts = mm.all_gather(np.array([[local.GetFieldData().GetArray("HaloAttempts").GetTuple1(0)]]))[:, 0]
            mm.check(attempts.max() > 1, f"Surface {label}: no rank needed a second halo ({attempts.tolist()})")


for piece_split in ("even", "uneven"):
    normals_case("auto", 3000, piece_split)
    normals_case("viewpoint_projected", 3000, piece_split, Orientation="Viewpoint", Viewpoint=[0.0, 0.0, 3.0],
                 ProjectPoints=1)
    surface_case("mls", 3000, piece_split, distributed=True)
    surface_case("wls_input_normals", 3000, piece_split, with_normals=True, Method="WLS", distributed=True)

# Slabs of a larger cloud: the same bits, and each rank holds its slab and a band of halo only. The band is about
# 8 neighbourhood radii (0.41) each side: on 2 ranks a slab and its band are 65 % of this torus (x in [-1.4, 1.4]),
# on 3 the middle slab and its two bands 72 % (the gathered cloud was 100 %).
normals_case("slabs", 40000, "slab", max_share=0.7 if mm.RANKS == 2 else 0.8)
normals_case("slabs_projected", 40000, "slab", max_share=0.85 if mm.RANKS == 2 else 0.9, ProjectPoints=1)

# The order of the points does not matter: three permutations of the cloud, split by index and in slabs, equal the
# serial run of the cloud in its own order (Id follows each point).
for seed in (1, 2, 3):
    normals_case(f"shuffled_{seed}", 3000, "even" if seed < 3 else "slab", shuffle=seed)
# Spatial pieces from ParaView's RedistributeDataSet (no GlobalIds: the halo numbers the points rank by rank).
normals_case("redistributed", 20000, "redistribute", max_share=0.8 if mm.RANKS == 2 else 0.9)
# Points with NaN coordinates (no normal, vtkValidPointMask 0), split by index.
normals_case("with_nan", 3000, "even", nans=7)
# A fixed neighbourhood radius (no scale estimate) in slabs.
normals_case("fixed_radius", 3000, "slab", SupportRadius=0.15)
# Every point on one rank, the others empty.
normals_case("all_on_last_rank", 3000, "last")

# The surface distributed: each rank contours its slab of space over its slab's points and a halo; the ranks'
# triangles are the serial ones, bit for bit. The torus encloses a volume: by default (Auto) its holes are filled
# (the winding number over the whole cloud); Off keeps the fits alone and trims to the data.
for piece_split in ("even", "uneven"):
    surface_case("mls_open", 3000, piece_split, HoleFilling="Off", distributed=True)
    surface_case("wls_open_input_normals", 3000, piece_split, with_normals=True, Method="WLS", HoleFilling="Off",
                 distributed=True)
surface_case("filled_slabs", 40000, "slab", max_share=0.7 if mm.RANKS == 2 else 0.8, distributed=True)
surface_case("open_slabs", 40000, "slab", max_share=0.7 if mm.RANKS == 2 else 0.8, HoleFilling="Off",
             distributed=True)
for seed in (1, 2, 3):
    surface_case(f"shuffled_{seed}", 3000, "even" if seed < 3 else "slab", shuffle=seed, distributed=True)
surface_case("redistributed", 20000, "redistribute", max_share=0.8 if mm.RANKS == 2 else 0.9, distributed=True)
surface_case("with_nan", 3000, "even", nans=7, HoleFilling="Off", distributed=True)
surface_case("all_on_last_rank", 3000, "last", distributed=True)
# Far outliers: the first halo falls short, the run is repeated with a wider one (rebuilt from the last halo).
surface_case("outliers", 3000, "slab", outliers=5, retried=True, distributed=True)
# The SPH colour field of the same points taken as particles.
surface_case("sph", 3000, "even", Method="SPH", distributed=True)
surface_case("sph_slabs", 40000, "slab", Method="SPH", distributed=True, max_share=0.7 if mm.RANKS == 2 else 0.8)

# One point: no hang, nothing computed, the point on exactly one rank.
normals_case("one_point", 1, "even")
surface_case("one_point", 1, "even")
mm.finish()
