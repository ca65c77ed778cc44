"""Shared helpers of the mpi tests (`mpiexec -n N pvbatch --symmetric script`: the script runs on every rank).

Each rank updates its proxies (ParaView asks piece = rank of N), reads its own piece from the proxy's VTK object and
gathers every rank's rows on every rank (vtkMultiProcessController.AllGatherV), so every rank checks the whole
result and exits with the same status. A serial result is computed on each rank by a second proxy of the same
scene updated as piece 0 of 1 (no gather, whole input), and, with --reference, compared with an independent
`pvpython --no-mpi` run of the same script (--write-reference).
"""
import argparse
import os
import sys

import numpy as np
from paraview import simple
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import VTK_DOUBLE, vtkDoubleArray
from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController

ARGS = argparse.ArgumentParser()
ARGS.add_argument("--reference", help="npz written by a serial run (--write-reference) to compare with")
ARGS.add_argument("--write-reference", help="serial run: write the gathered results here and stop")
args, _ = ARGS.parse_known_args()

controller = vtkMultiProcessController.GetGlobalController()
RANK = controller.GetLocalProcessId() if controller else 0
RANKS = controller.GetNumberOfProcesses() if controller else 1
_saved = {}


def log(*items):
    print(f"[rank {RANK}/{RANKS}]", *items, flush=True)


def load(namespace):
    path = os.environ.get("MESHFREE_PLUGIN")
    if not path or not os.path.exists(path):
        log("MESHFREE_PLUGIN is not set to the built plugin:", path)
        sys.exit(1)
    simple.LoadPlugin(path, ns=namespace)


def all_gather(table):
    """Rows of every rank's (n, w) table, in rank order, on every rank."""
    table = np.ascontiguousarray(table, dtype=float)
    width = table.shape[1]
    if RANKS == 1:
        return table
    send = ns.numpy_to_vtk(table.ravel(), deep=1, array_type=VTK_DOUBLE)
    recv = vtkDoubleArray()
    controller.AllGatherV(send, recv)
    return ns.vtk_to_numpy(recv).reshape(-1, width).copy()


def agree(value, what):
    """Asserts that a number (or flat array) is the same on every rank."""
    v = np.atleast_1d(np.asarray(value, dtype=float))
    allv = all_gather(v.reshape(1, -1))
    assert np.array_equal(allv, np.repeat(allv[:1], len(allv), axis=0)), f"{what} differs over ranks: {allv}"


def check(ok, message):
    """Asserts on every rank after agreeing: all ranks fail together (no rank waits for a dead one)."""
    bad = all_gather(np.array([[0.0 if ok else 1.0]]))
    assert bad.max() == 0, f"{message} (failed on ranks {np.nonzero(bad[:, 0])[0].tolist()})"


def rows(polydata, names):
    """(n, w) table: Id first, then the points, then the named point arrays (all components)."""
    n = polydata.GetNumberOfPoints() if polydata else 0
    cols = [np.zeros((0, 1)) if n == 0 else ns.vtk_to_numpy(polydata.GetPointData().GetArray("Id")).reshape(n, 1)]
    cols.append(np.zeros((0, 3)) if n == 0 else ns.vtk_to_numpy(polydata.GetPoints().GetData()).reshape(n, 3))
    for name in names:
        array = polydata.GetPointData().GetArray(name) if polydata else None
        assert array is not None or n == 0, f"array {name} missing"
        if array is not None:
            assert array.GetNumberOfTuples() == n
            cols.append(ns.vtk_to_numpy(array).reshape(n, array.GetNumberOfComponents()).astype(float))
    return np.hstack(cols)


def block(data, index, name):
    """Block `index` of a multiblock output, checked to be there and named `name` (an empty piece on some ranks)."""
    assert data.IsA("vtkMultiBlockDataSet"), data.GetClassName()
    assert data.GetNumberOfBlocks() > index, (data.GetNumberOfBlocks(), index)
    assert data.GetMetaData(index).Get(data.NAME()) == name, data.GetMetaData(index).Get(data.NAME())
    b = data.GetBlock(index)
    assert b is not None and b.IsA("vtkPolyData"), f"block {name} missing on rank {RANK}"
    return b


def local_output(proxy, time):
    """This rank's piece at `time`, as ParaView computes it (piece = rank of RANKS)."""
    proxy.UpdatePipeline(time)
    return proxy.GetClientSideObject().GetOutputDataObject(0)


def serial_output(proxy, time):
    """The whole output at `time` computed on this rank alone: piece 0 of 1, so nothing is split or gathered."""
    algorithm = proxy.GetClientSideObject()
    algorithm.UpdateTimeStep(time, 0, 1, 0)
    return algorithm.GetOutputDataObject(0)


def gathered_points(polydata, names):
    """Every rank's rows, sorted by Id; asserts that each Id is on exactly one rank."""
    table = all_gather(rows(polydata, names))
    ids = table[:, 0]
    check(len(np.unique(ids)) == len(ids), "an Id is on more than one rank")
    return table[np.argsort(ids, kind="stable")]


def sorted_rows(table):
    return table[np.argsort(table[:, 0], kind="stable")] if len(table) else table


def compare(label, got, want, tolerance=0.0):
    """max |got - want| over the whole table, asserted <= tolerance (0: bitwise); returns it."""
    check(got.shape == want.shape, f"{label}: shape {got.shape} on {RANKS} ranks, serial {want.shape}")
    diff = float(np.max(np.abs(got - want))) if got.size else 0.0
    if RANK == 0:
        log(f"{label}: {len(got)} rows, max |{RANKS} ranks - serial| = {diff:.3g}")
    check(diff <= tolerance, f"{label}: max |{RANKS} ranks - serial| = {diff} > {tolerance}")
    return diff


def compare_at_time(label, key, got, want, seen):
    """compare(); a `key` (time) seen before must give the same rows again (the cache answers); the first time,
    the rows go to reference()."""
    compare(label, got, want)
    if key in seen:
        check(np.array_equal(seen[key], got), f"{label}: differs when requested again")
    else:
        seen[key] = got
        reference(key, got)


def reference(label, table):
    """Serial run (--write-reference): keep `table`; MPI run (--reference): compare with the serial run's."""
    if args.write_reference:
        _saved[label] = table
    elif args.reference:
        want = np.load(args.reference)[label]
        compare(label + " vs pvpython --no-mpi", table, want)


def finish():
    if args.write_reference:
        np.savez(args.write_reference, **_saved)
        log("serial reference written:", args.write_reference, sorted(_saved))
    if controller and RANKS > 1:
        controller.Barrier()
    log("OK")
