"""VTK (9.2, as in ParaView 5.11) as a surface-reconstruction peer; one case per process (bench_surface.py).

    python3 surface_run_vtk.py normals IN.vtp OUT.vtp [--k 20]
        vtkPCANormalEstimation, k nearest neighbours, GRAPH_TRAVERSAL orientation (Hoppe's propagation)
    python3 surface_run_vtk.py hoppe   IN.vtp OUT.vtp [--k 20]
        vtkSurfaceReconstructionFilter (Hoppe 1992: signed distance to the nearest tangent plane, its default
        grid and its own normal orientation; positions only) contoured at 0 by vtkFlyingEdges3D
    python3 surface_run_vtk.py sph     IN.vtp OUT.vtp --spacing H [--cell 0.5] [--level 0.5]
        the SPH colour field c(x) = sum_j V_j W(|x - x_j|, H) (vtkSPHInterpolator, Wendland quintic kernel of
        spatial step H, particle volume V_j = H^3, Shepard normalisation off) on a dense vtkImageData of cell
        size cell * H covering the particles plus the kernel's support, contoured at level by vtkFlyingEdges3D:
        what a ParaView user does today

Runs under Debian's python3 (python3-paraview) or pvpython. Prints one JSON line: the seconds of each stage
without file input/output (algo_s = their sum), the memory they took (algo_mb, surface_memory.py) and the
grid used.
"""
import argparse
import json
import math
import os
import sys
import time

os.environ.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")

from surface_memory import AlgorithmMemory  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData, vtkStaticPointLocator  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D  # noqa: E402
from vtkmodules.vtkFiltersPoints import (vtkPCANormalEstimation, vtkSPHInterpolator,  # noqa: E402
                                         vtkWendlandQuinticKernel)
from vtkmodules.vtkImagingHybrid import vtkSurfaceReconstructionFilter  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLPolyDataWriter  # noqa: E402


def read_points(path):
    r = vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    pd = vtkPolyData()  # positions only: a given Normals array is not passed on
    pd.SetPoints(r.GetOutput().GetPoints())
    return pd


def write(data, path):
    w = vtkXMLPolyDataWriter()
    w.SetFileName(path)
    w.SetInputData(data)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.SetCompressorTypeToNone()
    if not w.Write():
        sys.exit("could not write " + path)


def update(alg, times, key):
    t0 = time.perf_counter()
    alg.Update()
    times[key] = time.perf_counter() - t0
    return alg.GetOutput()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mode", choices=["normals", "hoppe", "sph"])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--k", type=int, default=20)
    ap.add_argument("--spacing", type=float, default=0.0, help="SPH particle spacing H")
    ap.add_argument("--cell", type=float, default=0.5, help="SPH grid cell, in spacings")
    ap.add_argument("--level", type=float, default=0.5, help="SPH colour-field iso-level")
    a = ap.parse_args()
    pd = read_points(a.inp)
    times, info = {}, {}
    memory = AlgorithmMemory()
    memory.start()
    if a.mode == "normals":
        f = vtkPCANormalEstimation()
        f.SetInputData(pd)
        f.SetSampleSize(a.k)
        f.SetNormalOrientationToGraphTraversal()
        out = update(f, times, "normals_s")
    elif a.mode == "hoppe":
        f = vtkSurfaceReconstructionFilter()
        f.SetInputData(pd)
        f.SetNeighborhoodSize(a.k)
        image = update(f, times, "distance_s")
        c = vtkFlyingEdges3D()
        c.SetInputData(image)
        c.SetValue(0, 0.0)
        out = update(c, times, "contour_s")
        info["grid"] = list(image.GetDimensions())
    else:
        if a.spacing <= 0:
            sys.exit("sph needs --spacing")
        h, step = a.spacing, a.cell * a.spacing
        ones = numpy_to_vtk(__import__("numpy").ones(pd.GetNumberOfPoints()), deep=True)
        ones.SetName("colour")
        pd.GetPointData().AddArray(ones)
        kernel = vtkWendlandQuinticKernel()
        kernel.SetSpatialStep(h)
        margin = kernel.GetCutoffFactor() * h + step
        b = pd.GetBounds()
        lo = [b[2 * i] - margin for i in range(3)]
        dims = [int(math.ceil((b[2 * i + 1] + margin - lo[i]) / step)) + 1 for i in range(3)]
        image = vtkImageData()
        image.SetOrigin(*lo)
        image.SetSpacing(step, step, step)
        image.SetDimensions(*dims)
        t0 = time.perf_counter()
        locator = vtkStaticPointLocator()
        locator.SetDataSet(pd)
        locator.BuildLocator()
        times["locator_s"] = time.perf_counter() - t0
        f = vtkSPHInterpolator()
        f.SetInputData(image)
        f.SetSourceData(pd)
        f.SetKernel(kernel)
        f.SetLocator(locator)
        f.ShepardNormalizationOff()  # c = sum_j V_j W_j, V_j = H^3 (the kernel's default volume)
        f.SetNullPointsStrategyToNullValue()
        f.PassPointArraysOff()
        field = update(f, times, "field_s")
        field.GetPointData().SetActiveScalars("colour")
        c = vtkFlyingEdges3D()
        c.SetInputData(field)
        c.SetValue(0, a.level)
        out = update(c, times, "contour_s")
        info["grid"] = dims
    algo_mb = memory.stop()
    write(out, a.out)
    times["algo_s"] = sum(times.values())
    times["algo_mb"] = algo_mb
    times.update(info)
    print(json.dumps(times), flush=True)


if __name__ == "__main__":
    main()
