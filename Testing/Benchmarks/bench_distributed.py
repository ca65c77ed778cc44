#!/usr/bin/env python3
"""Meshless Approximation distributed over MPI ranks (benchmark, not a test).

10^6 cloud points (an R3 quasi-random sequence in the unit cube, each rank generating only its own index share,
with GlobalIds) approximated by MLS (degree 2, 20 neighbours) onto a 128^3 grid and onto a probe surface (a
sphere of about 10^6 points, split by ParaView's pieces), with 1 rank x 2 threads (the serial path) against 2
and 4 ranks x 1 thread (oversubscribed on a 2-core machine). Per configuration: the filter's wall time (the
slowest rank, from a barrier to a barrier), each rank's peak resident memory, the cloud points a rank owns, and
the halo points received (their sum as a fraction of the cloud). On 2 cores no speed-up is expected; what should
shrink as the ranks grow is the memory per rank and the points each rank holds.

  python3 Testing/Benchmarks/bench_distributed.py [--plugin path/to/MeshFree.so] [--points 1000000] [--ranks 1 2 4]
(prints a Markdown table; the workers run as `mpiexec --oversubscribe -n R pvbatch --symmetric` this script.)
"""
import argparse
import glob
import json
import os
import subprocess
import sys

CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkPoints, VTK_ID_TYPE
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
count = {count}
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
lo, hi = piece * count // pieces, (piece + 1) * count // pieces
g = 1.2207440846057596  # the R3 sequence: x_i = frac(0.5 + i (1/g, 1/g^2, 1/g^3))
i = np.arange(lo, hi, dtype=np.float64)[:, None]
xyz = np.mod(0.5 + i * np.array([1 / g, 1 / g ** 2, 1 / g ** 3]), 1.0)
out = self.GetPolyDataOutput()
pts = vtkPoints()
pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz), deep=1))
out.SetPoints(pts)
f = ns.numpy_to_vtk(np.sin(3 * xyz[:, 0]) + xyz[:, 1] ** 2 + 0.5 * xyz[:, 2], deep=1)
f.SetName('f')
out.GetPointData().AddArray(f)
ids = ns.numpy_to_vtk(np.arange(lo, hi, dtype=np.int64), deep=1, array_type=VTK_ID_TYPE)
ids.SetName('GlobalPointIds')
out.GetPointData().SetGlobalIds(ids)
"""
INFO_SCRIPT = """
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
self.GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
"""


def worker(args):
    import resource
    import time

    from paraview import simple
    from vtkmodules.vtkParallelCore import vtkMultiProcessController

    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId() if controller else 0
    ranks = controller.GetNumberOfProcesses() if controller else 1
    plugin = {"loaded": True}
    simple.LoadPlugin(args.plugin, ns=plugin)
    cloud = simple.ProgrammableSource(OutputDataSetType="vtkPolyData", ScriptRequestInformation=INFO_SCRIPT,
                                      Script=CLOUD_SCRIPT.format(count=args.points))
    cloud.UpdatePipeline()
    owned = cloud.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints()
    rows = []
    for case in ("grid 128^3", "probe sphere"):
        settings = dict(Input=cloud, Method="MLS", NeighborCount=20, PointArrays=["f"])
        if case.startswith("grid"):
            approx = plugin["MeshlessApproximation"](SampleDimensions=[128, 128, 128], **settings)
        else:
            probe = simple.Sphere(Center=[0.5, 0.5, 0.5], Radius=0.4, ThetaResolution=1000, PhiResolution=1000)
            approx = plugin["MeshlessApproximation"](Probe=probe, **settings)
            probe.UpdatePipeline()
        if controller:
            controller.Barrier()
        start = time.perf_counter()
        approx.UpdatePipeline()
        if controller:
            controller.Barrier()
        elapsed = time.perf_counter() - start
        out = approx.GetClientSideObject().GetOutputDataObject(0)
        field = out.GetFieldData().GetArray("HaloPoints")
        rows.append(dict(case=case, rank=rank, ranks=ranks, seconds=elapsed, owned=owned,
                         evaluated=out.GetNumberOfPoints(), halo=field.GetValue(0) if field else 0,
                         rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0))
        simple.Delete(approx)
    print("ROWS " + json.dumps(rows), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plugin", default=None, help="MeshFree.so (default: found under build/)")
    ap.add_argument("--points", type=int, default=1000000)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.plugin is None:
        here = os.path.dirname(os.path.abspath(__file__))
        found = glob.glob(os.path.join(here, "..", "..", "build", "**", "MeshFree.so"), recursive=True)
        args.plugin = os.path.abspath(found[0]) if found else None
    if not args.plugin or not os.path.exists(args.plugin):
        sys.exit("MeshFree.so not found: pass --plugin")
    if args.worker:
        worker(args)
        return
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    table = []
    for ranks in args.ranks:
        threads = 2 if ranks == 1 else 1
        run_env = dict(env, MESHFREE_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
        command = ["mpiexec", "--oversubscribe", "-n", str(ranks), "pvbatch", "--symmetric", os.path.abspath(__file__),
                   "--worker", "--plugin", args.plugin, "--points", str(args.points)]
        result = subprocess.run(command, env=run_env, capture_output=True, text=True)
        rows = [r for line in result.stdout.splitlines() if line.startswith("ROWS ")
                for r in json.loads(line[5:])]
        if result.returncode != 0 or not rows:
            sys.exit(f"{' '.join(command)} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
        for case in dict.fromkeys(r["case"] for r in rows):
            mine = [r for r in rows if r["case"] == case]
            table.append((case, ranks, threads, max(r["seconds"] for r in mine), max(r["rss_mb"] for r in mine),
                          max(r["owned"] for r in mine), sum(r["halo"] for r in mine),
                          max(r["evaluated"] for r in mine)))
    print(f"Meshless Approximation, MLS degree 2, 20 neighbours, {args.points:,} cloud points\n")
    print("| output | ranks x threads | time (s, slowest rank) | peak memory per rank (MB, largest) | cloud points "
          "per rank (largest) | halo points (all ranks) | halo / cloud | output points per rank (largest) |")
    print("|---|---|---|---|---|---|---|---|")
    for case, ranks, threads, seconds, rss, owned, halo, evaluated in table:
        print(f"| {case} | {ranks} x {threads} | {seconds:.2f} | {rss:.0f} | {owned:,} | {halo:,.0f} | "
              f"{halo / args.points:.1%} | {evaluated:,} |")


if __name__ == "__main__":
    main()
