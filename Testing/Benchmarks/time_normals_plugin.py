"""Meshless Normals' time through the plugin (issue 23's speed class: 0.3 s per 100k points idle, <= 5 s per 1M):
a noisy unit sphere (normal noise 0.005 of the radius), a fresh MeshlessNormals per run, best and median wall
seconds of R UpdatePipeline()s, with ComputeCurvature 1 and 0, the process' CPU seconds and page faults beside.

    pvpython --no-mpi Testing/Benchmarks/time_normals_plugin.py PLUGIN.so N [R] [curvature 0|1 ...]
    e.g. ... build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so 100000 5 1 0
"""
import sys, time, os, resource
import numpy as np
from paraview.simple import *
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.util.numpy_support import numpy_to_vtk
plugin, n = sys.argv[1], int(sys.argv[2])
reps = int(sys.argv[3]) if len(sys.argv) > 3 else 5
curvs = [int(c) for c in sys.argv[4:]] or [1, 0]
LoadPlugin(plugin, remote=False, ns=globals())
rng = np.random.default_rng(1)
p = rng.normal(size=(n, 3)); p /= np.linalg.norm(p, axis=1)[:, None]
p *= (1.0 + 0.005 * rng.normal(size=n))[:, None]
pd = vtkPolyData(); pts = vtkPoints(); pts.SetData(numpy_to_vtk(p, deep=1)); pd.SetPoints(pts)
src = TrivialProducer(); src.GetClientSideObject().SetOutput(pd)
def usage():
    r = resource.getrusage(resource.RUSAGE_SELF); return r.ru_utime + r.ru_stime, r.ru_minflt
for c in curvs:
    walls, cpus, faults = [], [], []
    for r in range(reps):
        f = MeshlessNormals(Input=src, ComputeCurvature=c)
        t0, (c0, f0) = time.perf_counter(), usage()
        f.UpdatePipeline()
        t1, (c1, f1) = time.perf_counter(), usage()
        walls.append(t1 - t0); cpus.append(c1 - c0); faults.append(f1 - f0)
        Delete(f)
    print("n=%d curvature=%d best wall %.3f s (its cpu %.3f) median wall %.3f, min cpu %.3f, faults %d, load %.2f"
          % (n, c, min(walls), cpus[walls.index(min(walls))], sorted(walls)[len(walls)//2], min(cpus), min(faults),
             os.getloadavg()[0]), flush=True)
