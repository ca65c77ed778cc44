#!/usr/bin/env python3
"""Meshless Normals and Meshless Surface on large scan-like clouds, serial and on MPI ranks (benchmark, not a test).

The cloud: a sphere (radius 0.5) inside a torus (R = 1, r = 0.25), points spread evenly over their area (a Fibonacci
spiral on the sphere, an R2 sequence mapped to equal area on the torus), each moved along its normal by Gaussian
noise of 0.1 % of the bounding-box diagonal (sigma = 0.0024), as a range scanner's depth noise. Point i depends on i
alone, so every split gives the same cloud (with GlobalIds): --split index gives rank p the index range
[pN/P, (p+1)N/P) (spread over the cloud), --split slab (default) the p-th slab of N/P points along x (each rank makes
the whole cloud and keeps its slab: compact pieces, as RedistributeDataSet makes them).

Per case (Meshless Normals with Orientation 'Propagation' (consistent across each piece) and its other defaults; Meshless Surface, MLS, its defaults): the
filter's wall time (the slowest rank, from a barrier to a barrier), where it went (the surface's field data
SetupSeconds, ContourSeconds, ProjectionSeconds, ApproximationSeconds), each rank's peak resident memory and its
growth during the filter (peak minus the resident memory once the cloud is loaded), the points a rank owns and the
points it held while computing (field data `LocalCloudPoints` of a distributed filter: its piece and halo;
`GatheredPoints` when reported; a filter that gathers the cloud on every rank holds all of it). Serial is 1 rank x 2 threads; ranks are oversubscribed on a
2-core machine, so time is not the figure there: memory and points per rank are.

  python3 Testing/Benchmarks/bench_scale.py [--plugin path/to/MeshFree.so] [--points 1000000 10000000]
      [--ranks 1 2 4] [--cases normals surface]
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# The pvbatch worker's start, the piece-aware source's information script, the plugin lookup and the memory probe
# are bench_distributed.py's.
from bench_distributed import INFO_SCRIPT, find_plugin, resident_mb, start_worker  # noqa: E402

CLOUD_SCRIPT = """
import numpy as np
from vtkmodules.util import numpy_support as ns
from vtkmodules.vtkCommonCore import vtkPoints, VTK_ID_TYPE
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
count, split = {count}, '{split}'
info = self.GetOutputInformation(0)
piece = info.Get(sddp.UPDATE_PIECE_NUMBER()) if info.Has(sddp.UPDATE_PIECE_NUMBER()) else 0
pieces = info.Get(sddp.UPDATE_NUMBER_OF_PIECES()) if info.Has(sddp.UPDATE_NUMBER_OF_PIECES()) else 1
lo, hi = piece * count // pieces, (piece + 1) * count // pieces
if split == 'slab' and pieces > 1:
    lo, hi = 0, count  # every point made, then this piece's slab along x kept (below)
R, r, rs = 1.0, 0.25, 0.5
area_sphere, area_torus = 4 * np.pi * rs * rs, 4 * np.pi * np.pi * R * r
ns_count = int(round(count * area_sphere / (area_sphere + area_torus)))
i = np.arange(lo, hi, dtype=np.int64)
xyz = np.empty((i.size, 3))
nrm = np.empty((i.size, 3))
s = i < ns_count
k = i[s].astype(np.float64)
z = 1.0 - 2.0 * (k + 0.5) / ns_count
phi = k * np.pi * (3.0 - np.sqrt(5.0))
rho = np.sqrt(np.maximum(0.0, 1.0 - z * z))
nrm[s] = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
xyz[s] = rs * nrm[s]
t = ~s
k = (i[t] - ns_count).astype(np.float64)
g = 1.32471795724474602596  # the R2 sequence
u, w = np.mod(0.5 + k / g, 1.0), np.mod(0.5 + k / (g * g), 1.0)
theta = 2 * np.pi * u
v = 2 * np.pi * w  # equal area: solve (R v + r sin v) / (2 pi R) = w for v by Newton
for _ in range(8):
    v -= (R * v + r * np.sin(v) - 2 * np.pi * R * w) / (R + r * np.cos(v))
nrm[t] = np.column_stack([np.cos(v) * np.cos(theta), np.cos(v) * np.sin(theta), np.sin(v)])
xyz[t] = np.column_stack([(R + r * np.cos(v)) * np.cos(theta), (R + r * np.cos(v)) * np.sin(theta), r * np.sin(v)])
def uniform(seed):  # splitmix64 of (i, seed): independent of the split
    x = (i.astype(np.uint64) * np.uint64(2) + np.uint64(seed)) * np.uint64(0x9E3779B97F4A7C15)
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    x = x ^ (x >> np.uint64(31))
    return ((x >> np.uint64(11)).astype(np.float64) + 0.5) / float(1 << 53)
noise = 0.001 * np.sqrt(2.5 ** 2 + 2.5 ** 2 + 0.5 ** 2) * np.sqrt(-2 * np.log(uniform(1))) * np.cos(2 * np.pi * uniform(2))
xyz += noise[:, None] * nrm
if split == 'slab' and pieces > 1:  # slabs of equal counts along x: compact pieces, as RedistributeDataSet gives
    order = np.argsort(xyz[:, 0], kind='stable')
    keep = np.sort(order[piece * count // pieces:(piece + 1) * count // pieces])
    xyz, i = xyz[keep], i[keep]
    del order, nrm
out = self.GetPolyDataOutput()
pts = vtkPoints()
pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(xyz), deep=1))
out.SetPoints(pts)
ids = ns.numpy_to_vtk(i, deep=1, array_type=VTK_ID_TYPE)
ids.SetName('GlobalPointIds')
out.GetPointData().SetGlobalIds(ids)
"""
STAGES = ("SetupSeconds", "ContourSeconds", "ProjectionSeconds", "ApproximationSeconds")


def reset_peak():
    """Resets the process's resident high-water mark (Linux: clear_refs 5) so that the peak read after the filter is
    the filter's, not the cloud generator's; False where the kernel does not allow it."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def peak_since_reset_mb():
    """The resident high-water mark since reset_peak() (MiB)."""
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM:")) / 1024.0


def field_value(data, name):
    array = data.GetFieldData().GetArray(name)
    return float(array.GetValue(0)) if array is not None and array.GetNumberOfTuples() > 0 else None


def worker(args):
    import resource
    import time

    simple, controller, rank, ranks, plugin = start_worker(args.plugin)
    cloud = simple.ProgrammableSource(OutputDataSetType="vtkPolyData", ScriptRequestInformation=INFO_SCRIPT,
                                      Script=CLOUD_SCRIPT.format(count=args.points, split=args.split))
    cloud.UpdatePipeline()
    owned = cloud.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints()
    if args.case == "normals":
        algorithm = plugin["MeshlessNormals"](Input=cloud, Orientation=1)
    else:
        algorithm = plugin["MeshlessSurface"](Input=cloud, Method=0)
    start_mb = resident_mb()
    reset = reset_peak()  # the filter's own peak, not the cloud generator's
    if controller:
        controller.Barrier()
    start = time.perf_counter()
    algorithm.UpdatePipeline()
    if controller:
        controller.Barrier()
    elapsed = time.perf_counter() - start
    out = algorithm.GetClientSideObject().GetOutputDataObject(0)
    peak_mb = peak_since_reset_mb() if reset else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    held = field_value(out, "LocalCloudPoints")  # a distributed filter: its piece and halo
    held = field_value(out, "GatheredPoints") if held is None else held
    if held is None:
        halo = field_value(out, "HaloPoints")
        held = owned + halo if halo is not None else float(args.points)  # today's filters gather the cloud
    row = dict(rank=rank, ranks=ranks, seconds=elapsed, owned=owned, held=held, rss_mb=peak_mb,
               growth_mb=peak_mb - start_mb, output=out.GetNumberOfPoints(),
               stages={name: field_value(out, name) for name in STAGES},
               halo={name: field_value(out, name) for name in ("HaloRadius", "HaloNeeded", "HaloAttempts")})
    with open(os.path.join(args.out, f"rank{rank}.json"), "w") as f:
        json.dump(row, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plugin", default=None, help="MeshFree.so (default: found under build/)")
    ap.add_argument("--points", type=int, nargs="+", default=[1000000, 10000000])
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--cases", nargs="+", default=["normals", "surface"], choices=["normals", "surface"])
    ap.add_argument("--split", default="slab", choices=["slab", "index"],
                    help="pieces: slabs of equal counts along x (compact, as after RedistributeDataSet; default) or "
                         "index ranges (the generator's order: spread over the cloud)")
    ap.add_argument("--serial-only-above", type=int, default=2000000,
                    help="clouds larger than this run serially only (default 2,000,000: 24 GB machines)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    ap.add_argument("--case", default="normals", help=argparse.SUPPRESS)
    args = ap.parse_args()
    args.plugin = find_plugin(args.plugin)
    if args.worker:
        args.points = args.points[0]
        worker(args)
        return
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    table = []
    for points in args.points:
        for case in args.cases:
            for ranks in args.ranks:
                if ranks > 1 and points > args.serial_only_above:
                    continue
                threads = 2 if ranks == 1 else 1
                run_env = dict(env, MESHFREE_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
                out = tempfile.mkdtemp(prefix="bench_scale_")
                command = ["mpiexec", "--oversubscribe", "-n", str(ranks), "pvbatch", "--symmetric",
                           os.path.abspath(__file__), "--worker", "--plugin", args.plugin, "--points", str(points),
                           "--out", out, "--case", case, "--split", args.split]
                result = subprocess.run(command, env=run_env, capture_output=True, text=True)
                rows = []
                for name in sorted(glob.glob(os.path.join(out, "rank*.json"))):
                    with open(name) as f:
                        rows.append(json.load(f))
                shutil.rmtree(out, ignore_errors=True)
                if result.returncode != 0 or not rows:
                    sys.exit(f"{' '.join(command)} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
                stages = rows[0]["stages"]
                halos = [r.get("halo") or {} for r in rows]
                attempts = max((h.get("HaloAttempts") or 0) for h in halos)
                radius, needed = halos[0].get("HaloRadius"), halos[0].get("HaloNeeded")
                halo = ("-" if not attempts else
                        f"{radius:.3g} ({needed:.3g}), {attempts:.0f} attempt(s)" if needed is not None else
                        f"{radius:.3g}, {attempts:.0f} attempt(s)")
                where = ", ".join(f"{k[:-7].lower()} {v:.1f}" for k, v in stages.items() if v is not None)
                table.append((points, case, ranks, threads, max(r["seconds"] for r in rows),
                              max(r["rss_mb"] for r in rows), max(r["growth_mb"] for r in rows),
                              max(r["owned"] for r in rows), max(r["held"] for r in rows),
                              sum(r["output"] for r in rows), where or "-", halo))
                print(table[-1], file=sys.stderr, flush=True)
    print("| points | filter | ranks x threads | time (s, slowest rank) | where the time went (s, rank 0) | peak "
          "memory per rank (MB) | growth during the filter per rank (MB) | points owned per rank | points held per "
          "rank | held / owned | output points (all ranks) | halo radius (needed), attempts (most on a rank) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for points, case, ranks, threads, seconds, rss, growth, owned, held, output, where, halo in table:
        print(f"| {points:,} | {case} | {ranks} x {threads} | {seconds:.1f} | {where} | {rss:.0f} | {growth:.0f} | "
              f"{owned:,} | {held:,.0f} | {held / max(owned, 1):.2f} | {output:,} | {halo} |")
    print("\n(per rank: the largest over the ranks; memory growth is the algorithm's, peak includes pvbatch and "
          "the cloud)")


if __name__ == "__main__":
    main()
