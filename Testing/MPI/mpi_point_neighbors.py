"""Point Neighbors on N ranks against the serial run, through ParaView's pipeline.

  pvbatch mpi_point_neighbors.py --reference DIR                                   # serial: writes DIR/*.npy
  mpiexec -n 2 pvbatch --symmetric mpi_point_neighbors.py --reference DIR          # compares with them
(root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; more ranks than cores: --oversubscribe.)

The cloud comes from a Programmable Source that honours piece requests by index (rank r of N holds points
[r*n/N, (r+1)*n/N), as a reader's pieces do), optionally through RedistributeDataSet (a collective filter that
moves the points to spatial regions). Each rank's output is gathered on rank 0 by the points' OriginalId and must
equal the serial output bit for bit (MeanNeighborDistance, NeighborsInRadius, vtkValidPointMask). The serial run
is also checked against a numpy brute force. Cases: a random cloud with duplicates and a lattice (distance
ties), fewer points than ranks, one point, no point.
"""
import argparse
import os
import sys

import numpy as np
from paraview import simple
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkParallelCore import vtkMultiProcessController

ap = argparse.ArgumentParser()
ap.add_argument("--reference", required=True, help="folder of the serial results")
args = ap.parse_args()
os.makedirs(args.reference, exist_ok=True)

ctrl = vtkMultiProcessController.GetGlobalController()
myrank, nranks = (ctrl.GetLocalProcessId(), ctrl.GetNumberOfProcesses()) if ctrl else (0, 1)
plugin = {"loaded": True}  # a non-empty dict: LoadPlugin ignores an empty one; globals() would shadow min()
simple.LoadPlugin(os.environ["MESHFREE_PLUGIN"], remote=False, ns=plugin)
PointNeighbors = plugin["PointNeighbors"]

# Runs inside the Programmable Source on every rank: the same cloud everywhere, this piece's share by index.
CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonDataModel import vtkCellArray
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
case = '{case}'
if case in ('random', 'duplicates'):
    rng = np.random.default_rng(5)
    xyz = rng.random((2500, 3))
    if case == 'duplicates':
        xyz[2400:] = xyz[:100]                   # 100 exact duplicates
elif case == 'lattice':
    g = np.arange(9) * 0.1                       # equal distances everywhere: ties
    xyz = np.stack(np.meshgrid(g, g, g, indexing='ij'), -1).reshape(-1, 3)
    xyz = xyz[np.random.default_rng(1).permutation(len(xyz))]
elif case == 'two':
    xyz = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 2.0]])
elif case == 'one':
    xyz = np.array([[0.5, 0.25, 0.125]])
else:
    xyz = np.zeros((0, 3))
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
lo, hi = piece * len(xyz) // pieces, (piece + 1) * len(xyz) // pieces
out = self.GetPolyDataOutput()
from vtkmodules.vtkCommonCore import vtkPoints
pts = vtkPoints()
pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz[lo:hi], dtype=float), deep=1))
out.SetPoints(pts)
m = hi - lo
verts = vtkCellArray()                           # RedistributeDataSet drops points without cells
verts.SetData(ns.numpy_to_vtk(np.arange(m + 1, dtype=np.int64), deep=1),
              ns.numpy_to_vtk(np.arange(m, dtype=np.int64), deep=1))
out.SetVerts(verts)
ids = ns.numpy_to_vtk(np.arange(lo, hi, dtype=float), deep=1)
ids.SetName('OriginalId')
out.GetPointData().AddArray(ids)
"""
INFO_SCRIPT = """
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
self.GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
"""
NAMES = ["MeanNeighborDistance", "NeighborsInRadius", "vtkValidPointMask"]


def gather(local):
    """Rows (OriginalId, arrays...) of every rank, on rank 0 sorted by OriginalId; None elsewhere."""
    if nranks == 1:
        return local[np.argsort(local[:, 0], kind="stable")]
    ncol = local.shape[1]
    if myrank > 0:
        ctrl.Send(ns.numpy_to_vtk(np.ascontiguousarray(local).ravel(), deep=1), 0, 8101)
        return None
    parts = [local]
    for r in range(1, nranks):
        got = vtkDoubleArray()
        ctrl.Receive(got, r, 8101)
        parts.append(ns.vtk_to_numpy(got).reshape(-1, ncol))
    rows = np.vstack(parts)
    return rows[np.argsort(rows[:, 0], kind="stable")]


def brute_force(xyz, k, radius):
    """MeanNeighborDistance as the filter sums it (ascending distances, left to right) and NeighborsInRadius."""
    d2 = ((xyz[:, None, 0] - xyz[None, :, 0]) ** 2 + (xyz[:, None, 1] - xyz[None, :, 1]) ** 2) \
        + (xyz[:, None, 2] - xyz[None, :, 2]) ** 2
    count = (d2 <= radius * radius).sum(axis=1) - 1
    np.fill_diagonal(d2, np.inf)
    near = np.sqrt(np.sort(d2, axis=1)[:, :k])
    near = near[:, :int(np.minimum(k, len(xyz) - 1))]
    mean = np.cumsum(near, axis=1)[:, -1] / near.shape[1] if near.shape[1] > 0 else np.zeros(len(xyz))
    return mean, count


failures = []
# RedistributeDataSet merges coincident points: the cloud with duplicates goes by index only.
for case, k, radius in [("random", 10, 0.08), ("duplicates", 10, 0.08), ("lattice", 6, 0.1), ("two", 10, 3.0),
                        ("one", 4, 1.0), ("none", 4, 1.0)]:
    for redistribute in ([False, True] if nranks > 1 and case != "duplicates" else [False]):
        simple.SetActiveSource(None)
        source = simple.ProgrammableSource(OutputDataSetType="vtkPolyData", Script=CLOUD_SCRIPT.format(case=case),
                                           ScriptRequestInformation=INFO_SCRIPT)
        cloud = simple.RedistributeDataSet(Input=source) if redistribute else source
        neighbors = PointNeighbors(Input=cloud, NeighborCount=k, SearchRadius=radius)
        neighbors.UpdatePipeline()
        out = neighbors.GetClientSideObject().GetOutputDataObject(0)  # this rank's piece
        n = out.GetNumberOfPoints()
        cols = [ns.vtk_to_numpy(out.GetPointData().GetArray("OriginalId")).astype(float)] if n else [np.zeros(0)]
        for name in NAMES:
            cols.append(ns.vtk_to_numpy(out.GetPointData().GetArray(name)).astype(float) if n else np.zeros(0))
        local = np.column_stack(cols) if n else np.zeros((0, 1 + len(NAMES)))
        xyz = ns.vtk_to_numpy(out.GetPoints().GetData()).astype(float) if n else np.zeros((0, 3))
        rows = gather(local)
        label = f"{case}{' after RedistributeDataSet' if redistribute else ''}, {nranks} rank(s)"
        if rows is None:
            continue
        path = os.path.join(args.reference, f"point_neighbors_{case}.npy")
        if nranks == 1:
            np.save(path, rows)
            order = np.argsort(cols[0], kind="stable")
            mean, count = brute_force(xyz[order], k, radius)
            err = np.abs(mean - rows[:, 1]).max() if len(mean) else 0.0
            print(f"{label}: {len(rows)} points; max |serial - brute force| = {err:.3g}", flush=True)
            if err > 1e-12 or not np.array_equal(count, rows[:, 2]):
                failures.append(f"{label}: serial differs from the brute force ({err})")
            continue
        if not os.path.exists(path):
            failures.append(f"{label}: no serial reference {path}")
            continue
        ref = np.load(path)
        if ref.shape != rows.shape or not np.array_equal(ref[:, 0], rows[:, 0]):
            failures.append(f"{label}: points {rows.shape[0]} (ids {rows[:5, 0]}...), serial {ref.shape[0]}")
            print("FAIL", failures[-1], flush=True)
            continue
        diff = np.abs(ref - rows).max(axis=0) if len(rows) else np.zeros(rows.shape[1])
        print(f"{label}: {len(rows)} points; max |N ranks - serial|: " +
              ", ".join(f"{name} {d:.3g}" for name, d in zip(NAMES, diff[1:])), flush=True)
        if not np.array_equal(ref, rows):
            failures.append(f"{label}: differs from serial {diff[1:]}")

if failures:
    print("FAILED:\n  " + "\n  ".join(failures), flush=True)
    sys.exit(1)
if myrank == 0:
    print("Point Neighbors: every case equals the serial run" if nranks > 1 else "serial references written")
