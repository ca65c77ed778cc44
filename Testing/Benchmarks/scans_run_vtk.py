"""VTK (9.2, as in ParaView 5.11) as a peer of the scan benchmark (bench_scans.py, issue 23); one case per process.

    pvpython --no-mpi scans_run_vtk.py signed IN.vtp OUT.vtp [--k 20] [--dims 200] [--radius 3]
        positions only -> vtkPCANormalEstimation (k nearest, GRAPH_TRAVERSAL orientation: Hoppe's propagation)
        -> vtkSignedDistance (the range-scan method of Curless & Levoy 1996: signed distance to the oriented
        points within radius x the cell size, on a dims^3-cell box around the cloud padded by radius cells)
        -> vtkExtractSurface (the zero set, only where the distance was defined: open where data are missing)
    pvpython --no-mpi scans_run_vtk.py normals IN.vtp OUT.vtp [--k 20]
        vtkPCANormalEstimation alone (GRAPH_TRAVERSAL orientation)

Runs under pvpython or Debian's python3 with python3-paraview. Prints one JSON line: the seconds of each stage
without file input/output (algo_s = their sum) and the memory they took (algo_mb, surface_memory.py).
"""
import argparse
import json
import os
import sys
import time

os.environ.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from surface_memory import AlgorithmMemory  # noqa: E402
from vtkmodules.vtkFiltersPoints import (vtkExtractSurface, vtkPCANormalEstimation,  # noqa: E402
                                         vtkSignedDistance)
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLPolyDataWriter  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["signed", "normals"])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--k", type=int, default=20)
    ap.add_argument("--dims", type=int, default=200)
    ap.add_argument("--radius", type=float, default=3.0)
    a = ap.parse_args()
    r = vtkXMLPolyDataReader()
    r.SetFileName(a.inp)
    r.Update()
    times = {}
    memory = AlgorithmMemory()
    memory.start()
    t0 = time.perf_counter()
    normals = vtkPCANormalEstimation()
    normals.SetInputConnection(r.GetOutputPort())
    normals.SetSampleSize(a.k)
    normals.SetNormalOrientationToGraphTraversal()
    normals.Update()
    times["normals_s"] = time.perf_counter() - t0
    out = normals.GetOutput()
    grid = {}
    if a.mode == "signed":
        b = out.GetBounds()
        size = max(b[1] - b[0], b[3] - b[2], b[5] - b[4])
        cell = size / a.dims
        pad = (a.radius + 2) * cell
        bounds = [b[0] - pad, b[1] + pad, b[2] - pad, b[3] + pad, b[4] - pad, b[5] + pad]
        dims = [int(round((bounds[2 * i + 1] - bounds[2 * i]) / cell)) + 1 for i in range(3)]
        t0 = time.perf_counter()
        dist = vtkSignedDistance()
        dist.SetInputData(out)
        dist.SetRadius(a.radius * cell)
        dist.SetDimensions(*dims)
        dist.SetBounds(*bounds)
        dist.Update()
        times["distance_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        surf = vtkExtractSurface()
        surf.SetInputConnection(dist.GetOutputPort())
        surf.SetRadius(a.radius * cell)
        surf.ComputeNormalsOff()
        surf.Update()
        times["extract_s"] = time.perf_counter() - t0
        out = surf.GetOutput()
        grid = dict(dims=dims, cell=cell)
    algo_mb = memory.stop()
    w = vtkXMLPolyDataWriter()
    w.SetFileName(a.out)
    w.SetInputData(out)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.Write()
    print(json.dumps(dict(times, algo_s=sum(times.values()), algo_mb=algo_mb, points_out=out.GetNumberOfPoints(),
                          polys_out=out.GetNumberOfPolys(), **grid)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
