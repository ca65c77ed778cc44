#!/usr/bin/env python3
"""Meshless Approximation distributed over MPI ranks (benchmark, not a test).

10^6 cloud points in the unit cube, each rank generating only its own index share (with GlobalIds): "slabs", a
jittered lattice numbered z-major, so that index shares are slabs along z (a file sorted along z, or a cloud after
a spatial redistribution); "scattered", an R3 quasi-random sequence, so that every share spreads over the whole
cube (a file in random order: each rank then needs most points of its region from the others), approximated by MLS (degree 2, 20 neighbours) onto a 128^3
grid and onto a probe surface (a sphere of about 10^6 points, split by ParaView's pieces: longitude wedges), with 1 rank x 2 threads (the serial path) against 2
and 4 ranks x 1 thread (oversubscribed on a 2-core machine). Per configuration: the filter's wall time (the
slowest rank, from a barrier to a barrier), each rank's peak resident memory and its growth during the filter's
run (peak minus the resident memory once the cloud piece is loaded; one process per case), the cloud points a
rank owns, and the halo points received (their sum as a fraction of the cloud). On 2 cores no speed-up is expected; what should
shrink as the ranks grow is the memory per rank and the points each rank holds.

  python3 Testing/Benchmarks/bench_distributed.py [--plugin path/to/MeshFree.so] [--points 1000000] [--ranks 1 2 4]
(prints a Markdown table; the workers run as `mpiexec --oversubscribe -n R pvbatch --symmetric` this script.)
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkPoints, VTK_ID_TYPE
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
count, kind = {count}, '{kind}'
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
lo, hi = piece * count // pieces, (piece + 1) * count // pieces
g = 1.2207440846057596  # the R3 sequence: x_i = frac(0.5 + i (1/g, 1/g^2, 1/g^3))
i = np.arange(lo, hi, dtype=np.float64)[:, None]
xyz = np.mod(0.5 + i * np.array([1 / g, 1 / g ** 2, 1 / g ** 3]), 1.0)
if kind == 'slabs':
    # A jittered lattice numbered z-major: index shares are slabs along z, as a file sorted along z gives.
    side = int(round(count ** (1.0 / 3.0)))
    j = np.arange(lo, hi)
    cell = np.column_stack([j % side, (j // side) % side, j // (side * side)]).astype(float)
    xyz = (cell + 0.25 + 0.5 * xyz) / side
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


def find_plugin(plugin):
    """The MeshFree.so to load: `plugin` when given, else the one under build/; exits when there is none."""
    if plugin is None:
        here = os.path.dirname(os.path.abspath(__file__))
        found = glob.glob(os.path.join(here, "..", "..", "build", "**", "MeshFree.so"), recursive=True)
        plugin = os.path.abspath(found[0]) if found else None
    if not plugin or not os.path.exists(plugin):
        sys.exit("MeshFree.so not found: pass --plugin")
    return plugin


def resident_mb():
    """The process's resident memory now (MiB)."""
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:")) / 1024.0


def start_worker(plugin_path):
    """In a pvbatch worker: paraview.simple, the MPI controller (or None), this rank, the ranks, the plugin's proxies."""
    from paraview import simple
    from vtkmodules.vtkParallelCore import vtkMultiProcessController

    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId() if controller else 0
    ranks = controller.GetNumberOfProcesses() if controller else 1
    plugin = {"loaded": True}
    simple.LoadPlugin(plugin_path, ns=plugin)
    return simple, controller, rank, ranks, plugin


def worker(args):
    import resource
    import time

    simple, controller, rank, ranks, plugin = start_worker(args.plugin)
    rows = []
    kind, case = args.kind, args.case
    cloud = simple.ProgrammableSource(OutputDataSetType="vtkPolyData", ScriptRequestInformation=INFO_SCRIPT,
                                      Script=CLOUD_SCRIPT.format(count=args.points, kind=kind))
    cloud.UpdatePipeline()
    owned = cloud.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints()
    settings = dict(Input=cloud, Method="MLS", NeighborCount=20, PointArrays=["f"])
    if case == "grid":
        approx = plugin["MeshlessApproximation"](SampleDimensions=[128, 128, 128], **settings)
    else:
        probe = simple.Sphere(Center=[0.5, 0.5, 0.5], Radius=0.4, ThetaResolution=1000, PhiResolution=1000)
        probe.UpdatePipeline()
        approx = plugin["MeshlessApproximation"](Probe=probe, **settings)
    start_mb = resident_mb()
    if controller:
        controller.Barrier()
    start = time.perf_counter()
    approx.UpdatePipeline()
    if controller:
        controller.Barrier()
    elapsed = time.perf_counter() - start
    out = approx.GetClientSideObject().GetOutputDataObject(0)
    field = out.GetFieldData().GetArray("HaloPoints")
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    rows.append(dict(case=f"{'grid 128^3' if case == 'grid' else 'probe sphere'}, cloud in {kind}", rank=rank,
                     ranks=ranks, seconds=elapsed, owned=owned, evaluated=out.GetNumberOfPoints(),
                     halo=field.GetValue(0) if field else 0, rss_mb=peak_mb, growth_mb=peak_mb - start_mb))
    with open(os.path.join(args.out, f"rank{rank}.json"), "w") as f:
        json.dump(rows, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plugin", default=None, help="MeshFree.so (default: found under build/)")
    ap.add_argument("--points", type=int, default=1000000)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    ap.add_argument("--kind", default="slabs", help=argparse.SUPPRESS)
    ap.add_argument("--case", default="grid", help=argparse.SUPPRESS)
    args = ap.parse_args()
    args.plugin = find_plugin(args.plugin)
    if args.worker:
        worker(args)
        return
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    table = []
    for kind in ("slabs", "scattered"):
        for case in ("grid", "probe"):
            for ranks in args.ranks:
                threads = 2 if ranks == 1 else 1
                run_env = dict(env, MESHFREE_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
                out = tempfile.mkdtemp(prefix="bench_distributed_")
                command = ["mpiexec", "--oversubscribe", "-n", str(ranks), "pvbatch", "--symmetric",
                           os.path.abspath(__file__), "--worker", "--plugin", args.plugin, "--points",
                           str(args.points), "--out", out, "--kind", kind, "--case", case]
                result = subprocess.run(command, env=run_env, capture_output=True, text=True)
                rows = []
                for name in sorted(glob.glob(os.path.join(out, "rank*.json"))):
                    with open(name) as f:
                        rows += json.load(f)
                shutil.rmtree(out, ignore_errors=True)
                if result.returncode != 0 or not rows:
                    sys.exit(f"{' '.join(command)} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
                table.append((rows[0]["case"], ranks, threads, max(r["seconds"] for r in rows),
                              max(r["rss_mb"] for r in rows), max(r["growth_mb"] for r in rows),
                              max(r["owned"] for r in rows), sum(r["halo"] for r in rows),
                              max(r["evaluated"] for r in rows)))
    print(f"Meshless Approximation, MLS degree 2, 20 neighbours, {args.points:,} cloud points\n")
    print("| output | ranks x threads | time (s, slowest rank) | peak memory per rank (MB) | growth during the "
          "filter per rank (MB) | cloud points per rank | halo points (all ranks) | halo / cloud | output points "
          "per rank |")
    print("|---|---|---|---|---|---|---|---|---|")
    for case, ranks, threads, seconds, rss, growth, owned, halo, evaluated in table:
        print(f"| {case} | {ranks} x {threads} | {seconds:.2f} | {rss:.0f} | {growth:.0f} | {owned:,} | {halo:,.0f} | "
              f"{halo / args.points:.1%} | {evaluated:,} |")
    print("\n(per rank: the largest over the ranks)")


if __name__ == "__main__":
    main()
