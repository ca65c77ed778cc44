"""Meshless Approximation on N ranks against the serial run (`mpiexec -n N pvbatch --symmetric`).

The cloud comes from a Programmable Source that honours piece requests by index (rank r of N holds points
[r n/N, (r+1) n/N), as a reader's pieces do), or goes through RedistributeDataSet (spatial pieces). Each rank
evaluates its own part of the output: its sub-extent of the grid, or its piece of the probe. The gathered pieces
must equal the serial run (the same scene updated as piece 0 of 1 on each rank) within 1e-9 of the data's
range, for every method, with k-nearest and fixed-radius supports, values, gradients and vtkValidPointMask
(exactly), with or without GlobalIds: every fit sums its neighbours in the neighbour order (distance, then
position), whatever order the halo brings them in. Why not bitwise: the global sums (PCA, LS moments) are added
rank by rank, which changes the last bits, which badly conditioned corner fits amplify (printed per case).

  mpiexec --oversubscribe -n 2 pvbatch --symmetric test_approximation.py [--quick]
"""
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.util import numpy_support as ns  # noqa: E402

plugin = {"loaded": True}  # a dict of its own: loading into globals() would shadow builtins such as min()
mm.load(plugin)
MeshlessApproximation = plugin["MeshlessApproximation"]
QUICK = "--quick" in sys.argv

# Runs inside a Programmable Source on every rank: the same cloud everywhere, this piece's share by index.
CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkPoints, VTK_ID_TYPE
from vtkmodules.vtkCommonDataModel import vtkCellArray
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
kind, count, seed = '{kind}', {count}, {seed}
rng = np.random.default_rng(seed)
if kind == 'permuted':
    xyz = rng.random((count, 3))[np.random.default_rng(99).permutation(count)]
elif kind == 'height':
    xy = rng.random((count, 2))
    xyz = np.column_stack([xy, np.sin(3 * xy[:, 0]) * np.cos(2 * xy[:, 1])])
elif kind == 'probe':
    xyz = 0.05 + 0.9 * rng.random((count, 3))
elif kind == 'flat':
    xyz = rng.random((count, 3)) * np.array([1.0, 1.0, 0.0])
else:
    xyz = rng.random((count, 3))
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
lo, hi = piece * len(xyz) // pieces, (piece + 1) * len(xyz) // pieces
out = self.GetPolyDataOutput()
pts = vtkPoints()
pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz[lo:hi], dtype=float), deep=1))
out.SetPoints(pts)
m = hi - lo
verts = vtkCellArray()  # RedistributeDataSet drops points without cells
verts.SetData(ns.numpy_to_vtk(np.arange(m + 1, dtype=np.int64), deep=1),
              ns.numpy_to_vtk(np.arange(m, dtype=np.int64), deep=1))
out.SetVerts(verts)
x = xyz[lo:hi]
def add(name, values):
    a = ns.numpy_to_vtk(np.ascontiguousarray(values, dtype=float), deep=1)
    a.SetName(name)
    out.GetPointData().AddArray(a)
if kind == 'plain':
    # The serial index as the GlobalIds attribute: carried through RedistributeDataSet, it orders the halo.
    gids = ns.numpy_to_vtk(np.arange(lo, hi, dtype=np.int64), deep=1, array_type=VTK_ID_TYPE)
    gids.SetName('GlobalPointIds')
    out.GetPointData().SetGlobalIds(gids)
if kind == 'probe':
    add('Id', np.arange(lo, hi))
else:
    add('f', np.sin(3 * x[:, 0]) + x[:, 1] ** 2 + 0.5 * x[:, 2])
    add('v', np.column_stack([x[:, 0] * x[:, 1], np.cos(2 * x[:, 2])]))
if kind == 'sph':
    add('Mass', 1e-3 * (1 + 0.1 * np.sin(np.arange(lo, hi))))
    add('Density', 1000 + 10 * x[:, 2])
"""
INFO_SCRIPT = """
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
self.GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
"""


def cloud_source(kind, count, seed):
    simple.SetActiveSource(None)
    return simple.ProgrammableSource(OutputDataSetType="vtkPolyData", ScriptRequestInformation=INFO_SCRIPT,
                                     Script=CLOUD_SCRIPT.format(kind=kind, count=count, seed=seed))


ARRAYS = ["f", "v", "f_gradient", "v_gradient", "vtkValidPointMask"]


def table(data, keyed_by_id):
    """(n, 1 + w): the key (the probe's Id, or the grid point's global index), then every compared array."""
    n = data.GetNumberOfPoints()
    if keyed_by_id:
        key = ns.vtk_to_numpy(data.GetPointData().GetArray("Id")).astype(float) if n else np.zeros(0)
    else:
        e = data.GetExtent()
        i, j, k = np.meshgrid(np.arange(e[0], e[1] + 1), np.arange(e[2], e[3] + 1), np.arange(e[4], e[5] + 1),
                              indexing="ij")
        key = (i + 1000 * j + 1000000 * k).transpose(2, 1, 0).ravel().astype(float)  # x fastest, as VTK orders
    cols = [key.reshape(-1, 1)]
    for name in ARRAYS:
        array = data.GetPointData().GetArray(name)
        mm.check(array is not None or n == 0, f"{name} missing on a piece")
        width = {"f": 1, "v": 2, "f_gradient": 3, "v_gradient": 6, "vtkValidPointMask": 1}[name]
        cols.append(ns.vtk_to_numpy(array).reshape(n, width).astype(float) if n else np.zeros((0, width)))
    return np.hstack(cols)


def compare_keyed(label, got, want, relative):
    """Every gathered row equals the serial row of its key (grid points on piece borders come twice); every key
    is there. Values within `relative` x the serial values' range, vtkValidPointMask exactly."""
    keys, index = np.unique(want[:, 0], return_index=True)
    mm.check(len(keys) == len(want), f"{label}: serial keys are not unique")
    mm.check(np.array_equal(np.unique(got[:, 0]), keys), f"{label}: {len(np.unique(got[:, 0]))} of {len(keys)} "
             "output points evaluated over the ranks")
    rows = want[index[np.searchsorted(keys, got[:, 0])]]
    values = want[:, 1:-1]
    scale = float(np.ptp(values[:, :3])) if len(values) else 1.0
    diff = float(np.max(np.abs(got[:, 1:-1] - rows[:, 1:-1]))) if len(got) else 0.0
    mask_ok = np.array_equal(got[:, -1], rows[:, -1])
    if mm.RANK == 0:
        mm.log(f"{label}: {len(keys)} points, max |{mm.RANKS} ranks - serial| = {diff:.3g} "
               f"({diff / scale if scale else 0:.3g} of the range), masks {'equal' if mask_ok else 'DIFFER'}")
    mm.check(mask_ok, f"{label}: vtkValidPointMask differs from serial")
    mm.check(diff <= relative * scale, f"{label}: max |N ranks - serial| = {diff} > {relative} x {scale}")
    return diff / scale if scale else 0.0


def run_case(label, cloud, method, support, probe, relative=1e-9, serial_cloud=None):
    """The approximation of `cloud` on N ranks against the serial run on `serial_cloud` (default: the same; a
    RedistributeDataSet updated as one piece on every rank would still redistribute, so it gets the source)."""
    settings = dict(Method=method, ComputeGradients=1, PointArrays=["f", "v"], SampleDimensions=[13, 11, 9],
                    **support)
    inputs = dict(Probe=probe) if probe is not None else {}
    approx = MeshlessApproximation(Input=cloud, **inputs, **settings)
    serial = MeshlessApproximation(Input=serial_cloud or cloud, **inputs, **settings)
    start = time.time()
    local = mm.local_output(approx, 0.0)
    elapsed = time.time() - start
    got = mm.all_gather(table(local, probe is not None))
    want = table(mm.serial_output(serial, 0.0), probe is not None)
    chosen = local.GetFieldData().GetAbstractArray("ApproximationMethod")
    if mm.RANK == 0 and method == "Auto" and chosen is not None:
        mm.log(f"{label}: Auto chose {chosen.GetValue(0)}")
    field = local.GetFieldData().GetArray("HaloPoints")
    mm.check(field is not None or mm.RANKS == 1, "no HaloPoints field array in a distributed run")
    halo = field.GetValue(0) if field is not None else 0
    halos = mm.all_gather(np.array([[float(halo)]]))
    if mm.RANK == 0:
        mm.log(f"{label}: {elapsed:.2f} s, halo points per rank {halos[:, 0].astype(int).tolist()}")
    worst = compare_keyed(label, got, want, relative)
    for proxy in (approx, serial):
        simple.Delete(proxy)
    return worst


def surface_rows(data):
    """A height field's rows: the grid index, the moved point, vtkValidPointMask."""
    n = data.GetNumberOfPoints()
    if n == 0:
        return np.zeros((0, 5))
    e = data.GetExtent()
    j, i = np.meshgrid(np.arange(e[2], e[3] + 1), np.arange(e[0], e[1] + 1), indexing="ij")
    key = (i + 1000 * j).ravel().astype(float)
    pts = ns.vtk_to_numpy(data.GetPoints().GetData()).astype(float)
    mask = ns.vtk_to_numpy(data.GetPointData().GetArray("vtkValidPointMask")).astype(float)
    return np.column_stack([key, pts, mask])


METHODS = ["LS", "WLS", "MLS", "PU-WLS", "SPH", "RBF"]  # RBF on 1,500-3,000 points: RBF-PU (the PU-WLS halo)
SUPPORTS = {"k-nearest": dict(NeighborCount=20), "radius": dict(SupportRadius=0.2)}


def main():
    # In a function: a Programmable Source's script runs in this module's globals and may rebind their names.
    results = {}
    plain_cloud = cloud_source("plain", 1500 if QUICK else 3000, 7)
    probe_source = cloud_source("probe", 700, 11)
    redistributed = simple.RedistributeDataSet(Input=plain_cloud) if mm.RANKS > 1 else None
    splits = [("by index", plain_cloud)]
    if redistributed and not QUICK:
        splits.append(("after RedistributeDataSet", redistributed))
    for split, cloud in splits:
        for method in METHODS:
            for support_name, support in SUPPORTS.items():
                for output in ("grid", "probe"):
                    if QUICK and output == "probe" and method in ("LS", "WLS"):
                        continue
                    label = f"{method}, {support_name}, {output}, cloud {split}"
                    results[label] = run_case(label, cloud, method, support,
                                              probe_source if output == "probe" else None, serial_cloud=plain_cloud)

    # Without GlobalIds a redistributed cloud's halo is ordered rank by rank: the serial run on a permutation of
    # the cloud, which gives the same bits as the serial run (checked here), so the bound is the same 1e-9.
    if redistributed and not QUICK:
        count = 1500
        noids = simple.RedistributeDataSet(Input=cloud_source("noids", count, 7))
        same, permuted = cloud_source("noids", count, 7), cloud_source("permuted", count, 7)
        for method in METHODS:
            for support_name, support in SUPPORTS.items():
                label = f"{method}, {support_name}, grid, cloud after RedistributeDataSet without GlobalIds"
                settings = dict(Method=method, ComputeGradients=1, PointArrays=["f", "v"],
                                SampleDimensions=[13, 11, 9], **support)
                one = table(mm.serial_output(MeshlessApproximation(Input=same, **settings), 0.0), False)
                other = table(mm.serial_output(MeshlessApproximation(Input=permuted, **settings), 0.0), False)
                scale = float(np.ptp(one[:, 1:4]))
                moved = float(np.max(np.abs(one[:, 1:-1] - other[:, 1:-1]))) / scale
                if mm.RANK == 0:
                    mm.log(f"{label}: serial on a permuted cloud moves by {moved:.3g} of the range")
                mm.check(np.array_equal(one[:, 1:], other[:, 1:]), f"{label}: serial on a permuted cloud differs")
                results[label] = run_case(label, noids, method, support, None, serial_cloud=same)

    # RBF as one global fit (600 points <= RBFGlobalLimit: every rank gathers the cloud) and Auto.
    small_cloud = cloud_source("plain", 600, 19)
    for method in ("RBF", "Auto"):
        for output in ("grid", "probe"):
            label = f"{method}, global, {output}"
            results[label] = run_case(label, small_cloud, method, SUPPORTS["k-nearest"],
                                      probe_source if output == "probe" else None)

    # Auto on a small 2D cloud (120 points <= 150): every rank gathers the cloud for the leave-one-out choice
    # between the thin-plate spline and PU-WLS, and makes the serial run's choice.
    flat_cloud = cloud_source("flat", 120, 23)
    for output in ("grid", "probe"):
        label = f"Auto, 2D cloud (leave-one-out choice), {output}"
        results[label] = run_case(label, flat_cloud, "Auto", SUPPORTS["k-nearest"],
                                  probe_source if output == "probe" else None)

    # Auto on a 3D cloud above RBFGlobalLimit: every rank gathers the sampled neighbourhoods of the leave-one-out
    # estimate (r^3 or PU-WLS of degree 3), makes the serial run's choice and evaluates it through the halo.
    for count, seed in ((1500, 29),) if QUICK else ((1500, 29), (3000, 31)):
        label = f"Auto, 3D cloud of {count} points (sampled leave-one-out choice), grid"
        results[label] = run_case(label, cloud_source("plain", count, seed), "Auto", SUPPORTS["k-nearest"], None)

    # SPH with Mass and Density (given volumes), and height fields.
    sph_cloud = cloud_source("sph", 2000, 3)
    results["SPH, volumes from Mass/Density"] = run_case("SPH, volumes from Mass/Density", sph_cloud, "SPH",
                                                         SUPPORTS["k-nearest"], None)
    height = cloud_source("height", 1500, 5)
    for method in ("MLS", "PU-WLS"):
        label = f"{method}, height field"
        approx = MeshlessApproximation(Input=height, Method=method, HeightField=1, SampleDimensions=[21, 17, 1])
        serial = MeshlessApproximation(Input=height, Method=method, HeightField=1, SampleDimensions=[21, 17, 1])
        local = mm.local_output(approx, 0.0)

        got = mm.all_gather(surface_rows(local))
        want = surface_rows(mm.serial_output(serial, 0.0))
        results[label] = compare_keyed(label, got, want, 1e-9)

    # Fewer points than ranks, one point, no point, an empty probe: every rank takes part, nothing hangs.
    for count in (2, 1, 0):
        tiny = cloud_source("plain", count, 13)
        for method in METHODS:
            label = f"{method}, {count}-point cloud"
            results[label] = run_case(label, tiny, method, SUPPORTS["k-nearest"], None)
    empty_probe = cloud_source("probe", 0, 17)
    results["MLS, empty probe"] = run_case("MLS, empty probe", plain_cloud, "MLS", SUPPORTS["k-nearest"],
                                           empty_probe)

    worst = np.max(np.array(list(results.values())))
    if mm.RANK == 0:
        mm.log(f"Meshless Approximation: {len(results)} cases, largest |{mm.RANKS} ranks - serial| = {worst:.3g} "
               "of the data's range")
    mm.finish()


main()
