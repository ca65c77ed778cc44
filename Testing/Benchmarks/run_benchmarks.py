"""MeshFree benchmarks (issue #7): run time against error, side by side with the tools a user would pick instead.

    MESHFREE_PLUGIN=<build>/lib/paraview-5.11/plugins/MeshFree/MeshFree.so \\
      pvpython --no-mpi Testing/Benchmarks/run_benchmarks.py [--quick | --smoke] [--out DIR] [--only PARTS]
      [--threads N] [--rbf-global-limit N] [--sizes N1,N2,...]

The plugin comes from $MESHFREE_PLUGIN, else from <source>/build. --out defaults to
<build>/benchmark-results. --only takes a comma list of approximation,sph,solid (default: all three).
--threads N puts every tool on N threads (default: all cores; on a machine shared with other work, --threads 1
gives a fair comparison, since OpenMP and other fork-join pools wait for descheduled threads at every barrier).
Writes approximation.csv, sph.csv, solid.csv, pareto.md and the PNGs (bench_report.py draws them), and
wins_losses.md: per field and N, the peers both faster and more accurate than MeshFree's most accurate setting.
Issue 26's table: --quick --sizes 100,300,1000,3000,10000 --rbf-global-limit 3000 --only approximation.

approximation.csv  method,peer,n,degree,rms_error,max_error,seconds,evals_per_second
  method   "<field>/<method and its settings>". Fields: F1..F10 are Renka & Brown's ten bivariate test functions
           (ACM TOMS 25(1), 1999, Algorithm 792; F1-F6 are Franke's 1979 set), on Halton points (bases 2, 3) in
           [0,1]^2; F1_3d is Franke's F1 extended to three variables (below) on Halton points (bases 2, 3, 5)
           in [0,1]^3, and F2_3d..F10_3d are the other nine made trivariate by a cyclic mean,
           (Fk(x, y) + Fk(y, z) + Fk(z, x)) / 3 (this benchmark's construction, not from the literature: each
           keeps its bivariate character - cliff, saddle, peaks, sphere, oscillation - along every axis). Settings: k = neighbours, r<c>h = radius c x the mean spacing h = N^(-1/dim),
           n = N closest points, p = Shepard power, s = Gaussian sharpness, step<c>h = SPH smoothing length.
  peer     0 for MeshFree's MeshlessApproximation filter (every method and degree, Wendland weight, 20
           neighbours: the filter's defaults; RBF as rbf_tps (2D) / rbf_r3 (3D) at its default RBFGlobalLimit
           1,000 - global below, RBF-PU above -, rbf_global forced global up to --rbf-global-limit, rbf_pu forced
           RBF-PU, and auto), 1 for other tools, measured in the same process:
             vtk_*    VTK's vtkPointInterpolator with the Gaussian, Shepard, Linear and Voronoi kernels and
                      vtkSPHInterpolator with the quintic, cubic, quartic and Wendland quintic SPH kernels
                      (Shepard-normalised), VTK_SMP_BACKEND_IN_USE=STDThread;
             scipy_*  scipy.interpolate.RBFInterpolator (thin-plate spline + linear polynomial, global and with
                      k local neighbours) and scipy.interpolate.griddata (linear, and cubic Clough-Tocher in 2D).
           Each peer's free parameter (radius, sharpness, power, point count, smoothing length, neighbours) is
           tuned for the lowest rms error on F1 at each N and dimension (scan printed in the log), and that
           setting is reported for every field. Global RBF runs up to N = 10,000 (dense O(N^2) memory and
           O(N^3) time), and in --quick up to N = 1,000 (--rbf-global-limit changes it).
  degree   polynomial degree (VTK kernels 0, RBF tail 1, griddata linear 1, cubic 3; MeshFree SPH 0).
  rms_error, max_error  over the evaluation set: the 101 x 101 grid (2D) or 21^3 grid (3D) of [0,1]^dim, the
           points inside the convex hull of the data (so that griddata is defined everywhere); the same points
           for every method at a given N.
  seconds  median wall time (warm-up excluded; 3 to 30 repetitions, as many as fit in 1 s, 5 s in the full run)
           to produce one field on the evaluation set from the point
           cloud, setup included (locators, trees, triangulations, solves): VTK algorithms' Update(), SciPy's
           constructor and call. Measured with the first field; no method but Auto has a cost that depends on
           the field's values, so the other fields' rows repeat it (their errors come from one evaluation of all
           fields). Auto (whose choice for small 2D clouds depends on the values) is timed and evaluated on
           each field alone.
  evals_per_second  evaluation points / seconds.

sph.csv  case,dimension,resolution,particles,steps,seconds,rms_error,max_error,particle_steps_per_second
  dam_break    2D column a x 2a, resolution a/dx; front x/a against Martin & Moyce (1952, Table 2, n^2 = 2) at
               their times T = t sqrt(2g/a); relative error of the front (rms and max over the times reached).
               The log also prints the errors with the experiment's time origin corrected by 0.175 (SPH at
               T - 0.175 against the table at T, as Lethe compares; see TestSPHDamBreak.cxx).
               Water (mu = 1e-3), artificial viscosity 0.05 where the source has it, front measured at the bed,
               the fluid's defaults otherwise (as Testing/Core/TestSPHDamBreak.cxx).
  hydrostatic  2D column of height H, resolution H/dx, settled for 20 sqrt(H/g) (as TestSPHFluid's
               HydrostaticColumn2D): relative L2 error of the pressure against rho0 g (H - z) (rms_error) and
               max |p - rho0 g (H - z)| / (rho0 g H) (max_error).
  throughput   3D dam break, particle-steps per second after a warm-up; no reference, errors empty.
  seconds is the wall time of the simulation requests through the SPHFluid source (output conversion
  included); steps are counted by the source.

solid.csv  case,integrator,resolution,phyxels,steps,seconds,rms_error,max_error,phyxel_steps_per_second
  cantilever   beam L = 0.8, h = b = 0.08 under self-weight (rho 1000, E 1e4, nu 0, g 0.005), clamped by
               FixedBounds on a block [-h, 0], relaxed to rest by damping (0.8/s) for 60 s (as
               Testing/Core/TestElasticCantilever.cxx); resolution = phyxels across h. Error of the deflection
               profile against Euler-Bernoulli + Timoshenko shear (kappa 5/6), relative to the reference tip
               deflection: rms over the beam's phyxel layers and max. SymplecticEuler runs at the stable step,
               Implicit (backward Euler) at 0.25 s (0.1 s in --smoke); steps follow the source's rule (below).
  throughput   a falling cube in a box, phyxel-steps per second after a warm-up (symplectic at the stable
               step; implicit at 10x the stable step).

Timings on a shared machine are noisy; compare rows of one run (same process), not runs.
"""
import argparse
import math
import os
import platform
import sys
import time

os.environ.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")
# --threads N: every tool on N threads (MeshFree's core, VTK's SMP pool, BLAS under SciPy). Set before
# numpy, VTK or the plugin load their thread pools.
THREADS = None
for _i, _a in enumerate(sys.argv):
    if _a.startswith("--threads"):
        THREADS = int(_a.split("=", 1)[1] if "=" in _a else sys.argv[_i + 1])
if THREADS:
    for _v in ("MESHFREE_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[_v] = str(THREADS)

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bench_machine  # noqa: E402
import bench_report  # noqa: E402

PLUGIN_REL = os.path.join("lib", "paraview-5.11", "plugins", "MeshFree", "MeshFree.so")


def log(*args):
    print(*args, flush=True)


# ---------------------------------------------------------------------------------------------- setup
def find_plugin():
    path = os.environ.get("MESHFREE_PLUGIN")
    if path:
        if not os.path.exists(path):
            sys.exit("MESHFREE_PLUGIN=%s does not exist" % path)
        return path
    path = os.path.join(SOURCE, "build", PLUGIN_REL)
    if os.path.exists(path):
        return path
    sys.exit("Set MESHFREE_PLUGIN to the built MeshFree.so (not found at %s)" % path)


def build_dir_of(plugin):
    # <build>/lib/paraview-5.11/plugins/MeshFree/MeshFree.so
    d = os.path.dirname(os.path.abspath(plugin))
    for _ in range(4):
        d = os.path.dirname(d)
    return d


def machine_description():
    return "%s, Python %s" % (bench_machine.describe(), platform.python_version())


def timed(run, repeats, budget, most=30):
    """Warm-up call, then timed calls: at least `repeats`, and more (up to `most`) while they fit in `budget`
    seconds, stopping once `budget` is spent; a warm-up slower than the budget is its own single sample.
    Returns (the fastest call's seconds, last result). The fastest, not the median: on a machine shared with
    other work a slower call measures the interference, not the method (Python's timeit documentation gives
    the same reason), and the times compared here are milliseconds, where a median moved by 2x between runs
    at load 3; every method and every peer is timed alike."""
    t0 = time.perf_counter()
    result = run()
    first = time.perf_counter() - t0
    if first > budget or repeats <= 0:
        return first, result
    count = max(repeats, min(most, int(budget / max(first, 1e-6))))
    samples = []
    for _ in range(count):
        t0 = time.perf_counter()
        result = run()
        samples.append(time.perf_counter() - t0)
        if sum(samples) > budget:
            break
    return min(samples), result


# ---------------------------------------------------------------------------------------------- fields
def halton(n, base):
    i = np.arange(1, n + 1, dtype=np.int64)
    out = np.zeros(n)
    f = 1.0
    while np.any(i > 0):
        f /= base
        out += f * (i % base)
        i //= base
    return out


def _f1(x, y):
    return (0.75 * np.exp(-((9 * x - 2) ** 2 + (9 * y - 2) ** 2) / 4)
            + 0.75 * np.exp(-(9 * x + 1) ** 2 / 49 - (9 * y + 1) / 10)
            + 0.5 * np.exp(-((9 * x - 7) ** 2 + (9 * y - 3) ** 2) / 4)
            - 0.2 * np.exp(-(9 * x - 4) ** 2 - (9 * y - 7) ** 2))


def _f9(x, y):
    t1, t2 = np.exp((10 - 20 * x) / 3), np.exp((10 - 20 * y) / 3)
    t3, t4 = 1 / (1 + t1), 1 / (1 + t2)
    return ((20.0 / 3) ** 3 * t1 * t2) ** 2 * (t3 * t4) ** 5 * (t1 - 2 * t3) * (t2 - 2 * t4)


def _f10(x, y):
    t = np.sqrt((80 * x - 40) ** 2 + (90 * y - 45) ** 2)
    return np.exp(-0.04 * t) * np.cos(0.15 * t)


# Renka & Brown (1999), Algorithm 792: F1 exponential, F2 cliff, F3 saddle, F4 gentle, F5 steep, F6 sphere,
# F7 trig, F8 synergistic Gaussian, F9 cloverleaf asymmetric peak/valley, F10 cosine peak.
FIELDS_2D = {
    "F1": _f1,
    "F2": lambda x, y: (np.tanh(9 * (y - x)) + 1) / 9,
    "F3": lambda x, y: (1.25 + np.cos(5.4 * y)) / (6 + 6 * (3 * x - 1) ** 2),
    "F4": lambda x, y: np.exp(-81 / 16 * ((x - 0.5) ** 2 + (y - 0.5) ** 2)) / 3,
    "F5": lambda x, y: np.exp(-81 / 4 * ((x - 0.5) ** 2 + (y - 0.5) ** 2)) / 3,
    "F6": lambda x, y: np.sqrt(np.maximum(64 - 81 * ((x - 0.5) ** 2 + (y - 0.5) ** 2), 0)) / 9 - 0.5,
    "F7": lambda x, y: 2 * np.cos(10 * x) * np.sin(10 * y) + np.sin(10 * x * y),
    "F8": lambda x, y: (np.exp(-0.5 * (5 - 10 * x) ** 2) + 0.75 * np.exp(-0.5 * (5 - 10 * y) ** 2)
                        * (1 + np.exp(-0.5 * (5 - 10 * x) ** 2))),
    "F9": _f9,
    "F10": _f10,
}


def franke3d(x, y, z):
    """Franke's F1 with a third variable in each term (the trivariate form used in 3D scattered-data tests)."""
    return (0.75 * np.exp(-((9 * x - 2) ** 2 + (9 * y - 2) ** 2 + (9 * z - 2) ** 2) / 4)
            + 0.75 * np.exp(-(9 * x + 1) ** 2 / 49 - (9 * y + 1) / 10 - (9 * z + 1) / 10)
            + 0.5 * np.exp(-((9 * x - 7) ** 2 + (9 * y - 3) ** 2 + (9 * z - 5) ** 2) / 4)
            - 0.2 * np.exp(-(9 * x - 4) ** 2 - (9 * y - 7) ** 2 - (9 * z - 5) ** 2))


def cyclic3d(f):
    """A bivariate test function made trivariate: (f(x, y) + f(y, z) + f(z, x)) / 3."""
    return lambda x, y, z: (f(x, y) + f(y, z) + f(z, x)) / 3.0


FIELDS_3D = {"F1_3d": franke3d}
FIELDS_3D.update({k + "_3d": cyclic3d(f) for k, f in FIELDS_2D.items() if k != "F1"})


# ---------------------------------------------------------------------------------------------- approximation
class Problem:
    """One point cloud (dim, N), its evaluation set and every field's exact values, in numpy and VTK form."""

    def __init__(self, dim, n, fields, grid):
        from scipy.spatial import Delaunay
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkPolyData

        self.dim, self.n = dim, n
        xyz = np.zeros((n, 3))
        for a, base in zip(range(dim), (2, 3, 5)):
            xyz[:, a] = halton(n, base)
        axes = [np.linspace(0.0, 1.0, grid)] * dim
        mesh = np.meshgrid(*axes, indexing="ij")
        e = np.zeros((mesh[0].size, 3))
        for a in range(dim):
            e[:, a] = mesh[a].ravel()
        inside = Delaunay(xyz[:, :dim]).find_simplex(e[:, :dim]) >= 0
        self.eval = np.ascontiguousarray(e[inside])
        self.xyz = xyz
        self.h = n ** (-1.0 / dim)
        self.fields = fields
        self.names = list(fields)
        args = lambda p: [p[:, a] for a in range(dim)]  # noqa: E731
        self.values = {k: np.ascontiguousarray(f(*args(xyz))) for k, f in fields.items()}
        self.exact = {k: f(*args(self.eval)) for k, f in fields.items()}

        def polydata(points):
            pts = vtkPoints()
            pts.SetData(numpy_to_vtk(points, deep=1))
            pd = vtkPolyData()
            pd.SetPoints(pts)
            return pd

        self.cloud = polydata(xyz)
        self.probe = polydata(self.eval)
        self.vtk_values = {}
        for k, v in self.values.items():
            arr = numpy_to_vtk(v, deep=1)
            arr.SetName(k)
            self.vtk_values[k] = arr

    def set_fields(self, names):
        pd = self.cloud.GetPointData()
        while pd.GetNumberOfArrays():
            pd.RemoveArray(0)
        for k in names:
            pd.AddArray(self.vtk_values[k])
        self.cloud.Modified()

    def errors(self, name, values):
        e = np.asarray(values, dtype=float) - self.exact[name]
        if not np.all(np.isfinite(e)):
            return float("inf"), float("inf")
        return float(np.sqrt(np.mean(e * e))), float(np.abs(e).max())


def vtk_output_values(output, names):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    out = {}
    for k in names:
        arr = output.GetPointData().GetArray(k)
        out[k] = vtk_to_numpy(arr).astype(float).ravel() if arr is not None else None
    return out


class Method:
    """A configured evaluator: run(problem, names) -> {field: values on problem.eval}; prepare(problem), when
    given, does the untimed set-up of a reused object (the plugin's proxy properties and inputs)."""

    def __init__(self, name, peer, degree, run, prepare=None):
        self.name, self.peer, self.degree, self.run = name, peer, degree, run
        self.prepare = prepare or (lambda problem: None)


RBF_GLOBAL_DEFAULT = 1000  # the filter's default RBFGlobalLimit


def meshfree_methods(filt, proxy, dim, n=0, rbf_global_limit=3000):
    """Every method and degree at the filter's defaults (Wendland, 20 neighbours); in 3D, degree 3 (20 basis
    functions, as many as the default neighbours) also with 40 neighbours. RBF at its default (global up to
    RBFGlobalLimit = 1,000 points, RBF-PU above), forced global (up to rbf_global_limit points) and forced
    RBF-PU; Auto."""
    out = []

    def make(method, degree, k, limit=RBF_GLOBAL_DEFAULT):
        def prepare(problem):
            proxy.Method = method  # pushed to the VTK object at once
            proxy.BasisDegree = degree
            proxy.NeighborCount = k
            if proxy.GetProperty("RBFGlobalLimit") is not None:
                proxy.RBFGlobalLimit = limit
                proxy.Smoothing = 0.0
            filt.SetInputDataObject(0, problem.cloud)
            filt.SetInputDataObject(1, problem.probe)

        def run(problem, names):
            filt.Modified()
            filt.Update()
            return vtk_output_values(filt.GetOutputDataObject(0), names)
        return run, prepare

    for method in ("LS", "WLS", "MLS", "PU-WLS"):
        for degree in range(4):
            out.append(Method("%s_wendland_k20" % method.lower(), 0, degree, *make(method, degree, 20)))
            if dim == 3 and degree == 3 and method in ("MLS", "PU-WLS"):
                out.append(Method("%s_wendland_k40" % method.lower(), 0, degree, *make(method, degree, 40)))
    out.append(Method("sph_wendland_k20", 0, 0, *make("SPH", 2, 20)))
    if proxy.GetProperty("RBFGlobalLimit") is not None:
        out.append(Method("rbf_tps" if dim == 2 else "rbf_r3", 0, 1, *make("RBF", 2, 20)))
        if RBF_GLOBAL_DEFAULT < n <= rbf_global_limit:
            out.append(Method("rbf_global", 0, 1, *make("RBF", 2, 20, 20000)))
        if n <= RBF_GLOBAL_DEFAULT:
            out.append(Method("rbf_pu", 0, 1, *make("RBF", 2, 20, 0)))
        out.append(Method("auto", 0, 2, *make("Auto", 2, 20)))
    return out


def vtk_point_interpolator(kernel_factory):
    from vtkmodules.vtkFiltersPoints import vtkPointInterpolator

    def run(problem, names):
        alg = vtkPointInterpolator()
        alg.SetKernel(kernel_factory(problem))
        alg.SetInputData(problem.probe)
        alg.SetSourceData(problem.cloud)
        alg.Update()
        return vtk_output_values(alg.GetOutput(), names)
    return run


def vtk_sph_interpolator(kernel_class, factor):
    from vtkmodules.vtkFiltersPoints import vtkSPHInterpolator

    def run(problem, names):
        kernel = kernel_class()
        kernel.SetDimension(problem.dim)
        kernel.SetSpatialStep(factor * problem.h)
        alg = vtkSPHInterpolator()
        alg.SetKernel(kernel)
        alg.SetShepardNormalization(True)
        alg.SetInputData(problem.probe)
        alg.SetSourceData(problem.cloud)
        alg.Update()
        return vtk_output_values(alg.GetOutput(), names)
    return run


def vtk_peer_families(dim):
    """{family: [candidate Method, ...]}: the scan each peer is tuned over (lowest F1 rms wins)."""
    from vtkmodules import vtkFiltersPoints as fp

    fam = {}

    def gaussian(c, s):
        def k(problem):
            kern = fp.vtkGaussianKernel()
            kern.SetKernelFootprintToRadius()
            kern.SetRadius(c * problem.h)
            kern.SetSharpness(s)
            return kern
        return k

    fam["vtk_gaussian"] = [Method("vtk_gaussian_r%gh_s%g" % (c, s), 1, 0, vtk_point_interpolator(gaussian(c, s)))
                           for c in (1.5, 2.0, 3.0, 4.0) for s in (2.0, 4.0)]

    def shepard(p, n):
        def k(problem):
            kern = fp.vtkShepardKernel()
            kern.SetKernelFootprintToNClosest()
            kern.SetNumberOfPoints(n)
            kern.SetPowerParameter(p)
            return kern
        return k

    fam["vtk_shepard"] = [Method("vtk_shepard_p%g_n%d" % (p, n), 1, 0, vtk_point_interpolator(shepard(p, n)))
                          for p in (2.0, 3.0, 5.0) for n in (4, 8, 16)]

    def linear(n):
        def k(problem):
            kern = fp.vtkLinearKernel()
            kern.SetKernelFootprintToNClosest()
            kern.SetNumberOfPoints(n)
            return kern
        return k

    fam["vtk_linear"] = [Method("vtk_linear_n%d" % n, 1, 0, vtk_point_interpolator(linear(n))) for n in (2, 3, 4, 8)]
    fam["vtk_voronoi"] = [Method("vtk_voronoi", 1, 0, vtk_point_interpolator(lambda problem: fp.vtkVoronoiKernel()))]
    for label, cls in (("quintic", fp.vtkSPHQuinticKernel), ("cubic", fp.vtkSPHCubicKernel),
                       ("quartic", fp.vtkSPHQuarticKernel), ("wendland", fp.vtkWendlandQuinticKernel)):
        fam["vtk_sph_" + label] = [Method("vtk_sph_%s_step%gh" % (label, c), 1, 0, vtk_sph_interpolator(cls, c))
                                   for c in (0.6, 0.8, 1.0, 1.25, 1.6, 2.0)]
    return fam


def scipy_peer_families(dim, n, global_limit):
    from scipy.interpolate import RBFInterpolator, griddata

    def stack(problem, names):
        return np.stack([problem.values[k] for k in names], axis=1)

    def unstack(values, names):
        values = np.asarray(values).reshape(len(values), -1)
        return {k: values[:, i] for i, k in enumerate(names)}

    def rbf(k):
        def run(problem, names):
            interp = RBFInterpolator(problem.xyz[:, :dim], stack(problem, names), neighbors=k,
                                     kernel="thin_plate_spline", degree=1)
            return unstack(interp(problem.eval[:, :dim]), names)
        return run

    def grid(method):
        def run(problem, names):
            return unstack(griddata(problem.xyz[:, :dim], stack(problem, names), problem.eval[:, :dim],
                                    method=method), names)
        return run

    fam = {}
    if n <= global_limit:
        fam["scipy_rbf_global"] = [Method("scipy_rbf_global_tps", 1, 1, rbf(None))]
    fam["scipy_rbf_local"] = [Method("scipy_rbf_local_tps_k%d" % k, 1, 1, rbf(k)) for k in (20, 50) if k < n]
    fam["scipy_griddata_linear"] = [Method("scipy_griddata_linear", 1, 1, grid("linear"))]
    if dim == 2:
        fam["scipy_griddata_cubic"] = [Method("scipy_griddata_cubic", 1, 3, grid("cubic"))]
    return fam


def run_approximation(cfg):
    from paraview import simple
    from vtkmodules.vtkCommonCore import vtkSMPTools

    vtkSMPTools.SetBackend("STDThread")
    if THREADS:
        vtkSMPTools.Initialize(THREADS)
    log("VTK SMP backend: %s, %d threads" % (vtkSMPTools.GetBackend(), vtkSMPTools.GetEstimatedNumberOfThreads()))
    sphere = simple.Sphere()  # a placeholder input: the VTK object is fed directly below
    proxy = simple.MeshlessApproximation(Input=sphere)
    proxy.WeightFunction = "Wendland"
    proxy.NeighborCount = 20
    filt = proxy.GetClientSideObject()  # the VTK object, fed directly: no client-server traffic in the timing
    rows = []
    cases = [(2, n, FIELDS_2D if not cfg.smoke else {k: FIELDS_2D[k] for k in ("F1", "F2")}, 101 if not cfg.smoke else 41)
             for n in cfg.sizes_2d]
    cases += [(3, n, FIELDS_3D if not cfg.smoke else {k: FIELDS_3D[k] for k in ("F1_3d", "F2_3d")},
               21 if not cfg.smoke else 11) for n in cfg.sizes_3d]
    for dim, n, fields, grid in cases:
        t0 = time.perf_counter()
        problem = Problem(dim, n, fields, grid)
        first = problem.names[0]
        log("\n=== %dD, N = %d, %d evaluation points, fields %s (setup %.1f s)" % (
            dim, n, len(problem.eval), ",".join(problem.names), time.perf_counter() - t0))
        chosen = list(meshfree_methods(filt, proxy, dim, n, cfg.rbf_global_limit))
        families = dict(vtk_peer_families(dim))
        families.update(scipy_peer_families(dim, n, cfg.rbf_global_limit))
        problem.set_fields([first])
        for fam, candidates in families.items():
            if len(candidates) == 1:
                chosen.append(candidates[0])
                continue
            scan = []
            for m in candidates:
                m.prepare(problem)
                vals = m.run(problem, [first])[first]
                rms = problem.errors(first, vals)[0] if vals is not None else float("inf")
                scan.append((rms, m))
            scan.sort(key=lambda s: s[0])
            log("  tune %-22s %s" % (fam, "  ".join("%s %.3g" % (m.name[len(fam) + 1:], r) for r, m in scan)))
            chosen.append(scan[0][1])
        for m in chosen:
            # Auto chooses from the values (small 2D clouds: leave-one-out errors), so its time and result depend
            # on the field: each field is timed and evaluated alone. Every other method's cost does not depend on
            # the values: timed with the first field, all fields evaluated at once.
            per_field = m.name == "auto"
            measured = {}
            for name in (problem.names if per_field else [first]):
                problem.set_fields([name])
                m.prepare(problem)
                measured[name] = timed(lambda: m.run(problem, [name]), cfg.repeats, cfg.budget)
            if not per_field:
                out = measured[first][1]
                if len(problem.names) > 1:
                    problem.set_fields(problem.names)
                    out = m.run(problem, problem.names)
                measured = {name: (measured[first][0], out) for name in problem.names}
            for name in problem.names:
                seconds, out = measured[name]
                vals = out.get(name)
                if vals is None:
                    log("  %s: no output array %s" % (m.name, name))
                    rms = mx = float("inf")
                else:
                    rms, mx = problem.errors(name, vals)
                rows.append(dict(method="%s/%s" % (name, m.name), peer=m.peer, n=n, degree=m.degree, rms_error=rms,
                                 max_error=mx, seconds=seconds, evals_per_second=len(problem.eval) / seconds))
            r = [q for q in rows if q["method"] == "%s/%s" % (first, m.name) and q["n"] == n][-1]
            log("  %-32s d%d  %s rms %.3g  max %.3g  %.4f s  %.3g evals/s" % (
                m.name, m.degree, first, r["rms_error"], r["max_error"], r["seconds"], r["evals_per_second"]))
    simple.Delete(proxy)
    simple.Delete(sphere)
    return rows


# ---------------------------------------------------------------------------------------------- wins and losses
ACCURACY_MARGIN = 0.01  # "more accurate": an rms error lower by more than 1% (identical methods tie)
AUTO_FACTOR = 2.0  # issue 26's target for Auto: within 2x of the best setting's error at no more than 2x its time


def wins_losses(rows):
    """Markdown: for every field and N, MeshFree's most accurate fixed setting (lowest rms error) and the peers that
    are both faster and more accurate than it (a peer win), then Auto against that best setting. Rows of one
    run (same process, same evaluation points)."""
    groups = {}
    for r in rows:
        field, _, name = r["method"].partition("/")
        groups.setdefault((field, int(r["n"])), []).append((name, r))
    lines = ["| field | N | MeshFree's most accurate setting: rms, s | peers faster and more accurate (rms, s) | "
             "most accurate peer: rms, s | Auto: rms, s (x best's rms, x best's time) |",
             "|---|---|---|---|---|---|"]
    wins = total = auto_total = auto_within = 0
    auto_misses = []
    for (field, n) in sorted(groups, key=lambda k: (k[0].endswith("_3d"), len(k[0]), k[0], k[1])):
        rs = groups[(field, n)]
        ours = [(name, r) for name, r in rs if r["peer"] == 0 and math.isfinite(r["rms_error"])]
        peers = [(name, r) for name, r in rs if r["peer"] == 1 and math.isfinite(r["rms_error"])]
        if not ours:
            continue
        # The most accurate setting is a fixed one (Auto is a choice among them; tied with the setting it chose, it
        # must not become its own reference).
        bname, best = min([q for q in ours if q[0] != "auto"] or ours, key=lambda q: q[1]["rms_error"])
        beating = [(name, r) for name, r in peers
                   if r["seconds"] < best["seconds"] and r["rms_error"] < (1 - ACCURACY_MARGIN) * best["rms_error"]]
        total += 1
        wins += 1 if beating else 0
        pname, pbest = min(peers, key=lambda q: q[1]["rms_error"]) if peers else ("-", None)
        auto = [r for name, r in ours if name == "auto"]
        auto_text = "-"
        if auto:
            a = auto[0]
            auto_text = "%.2g, %.3g (%.2fx, %.2fx)" % (a["rms_error"], a["seconds"], a["rms_error"] / best["rms_error"],
                                                       a["seconds"] / best["seconds"])
            auto_total += 1
            if a["rms_error"] <= AUTO_FACTOR * best["rms_error"] and a["seconds"] <= AUTO_FACTOR * best["seconds"]:
                auto_within += 1
            else:
                auto_misses.append("%s at N = %d" % (field, n))
                auto_text += " **miss**"
        lines.append("| %s | %d | %s d%d: %.2g, %.3g | %s | %s | %s |" % (
            field, n, bname, best["degree"], best["rms_error"], best["seconds"],
            "; ".join("**%s** (%.2g, %.3g)" % (name, r["rms_error"], r["seconds"]) for name, r in beating) or "none",
            "%s: %.2g, %.3g" % (pname, pbest["rms_error"], pbest["seconds"]) if pbest else "-", auto_text))
    head = ("Peer wins (a peer both faster and more accurate - rms lower by more than %d%% - than MeshFree's most "
            "accurate setting at that field and N): %d of %d cases.\n\n" % (100 * ACCURACY_MARGIN, wins, total))
    head += ("Auto within %gx of the most accurate setting's rms error at no more than %gx its time: %d of %d cases%s."
             "\n\n" % (AUTO_FACTOR, AUTO_FACTOR, auto_within, auto_total,
                        " (misses: %s)" % ", ".join(auto_misses) if auto_misses else ""))
    return head + "\n".join(lines) + "\n"


def wins_losses_compact(rows):
    """Markdown: one row per field, one column per N; each cell 'b / a': MeshFree's most accurate setting's rms
    error over the most accurate peer's (below 1: MeshFree is more accurate), and Auto's rms error over that
    setting's, with a mark where a peer wins (faster and more accurate) or Auto misses (more than AUTO_FACTOR x
    the error or the time)."""
    groups = {}
    for r in rows:
        field, _, name = r["method"].partition("/")
        groups.setdefault((field, int(r["n"])), []).append((name, r))
    fields = sorted({f for f, _ in groups}, key=lambda f: (f.endswith("_3d"), len(f), f))
    sizes = sorted({n for _, n in groups})
    lines = ["| field | " + " | ".join("N = {:,}".format(n) for n in sizes) + " |",
             "|---|" + "---|" * len(sizes)]
    for field in fields:
        cells = []
        for n in sizes:
            rs = groups.get((field, n), [])
            ours = [r for name, r in rs if r["peer"] == 0 and math.isfinite(r["rms_error"]) and name != "auto"]
            peers = [r for name, r in rs if r["peer"] == 1 and math.isfinite(r["rms_error"])]
            if not ours or not peers:
                cells.append("-")
                continue
            best = min(ours, key=lambda r: r["rms_error"])
            peer = min(peers, key=lambda r: r["rms_error"])
            win = any(r["seconds"] < best["seconds"] and r["rms_error"] < (1 - ACCURACY_MARGIN) * best["rms_error"]
                      for r in peers)
            text = "%.2f" % (best["rms_error"] / peer["rms_error"]) + (" **peer wins**" if win else "")
            auto = [r for name, r in rs if name == "auto" and r["peer"] == 0]
            if auto:
                a = auto[0]
                miss = a["rms_error"] > AUTO_FACTOR * best["rms_error"] or a["seconds"] > AUTO_FACTOR * best["seconds"]
                text += " / %.2f" % (a["rms_error"] / best["rms_error"]) + (" **Auto misses**" if miss else "")
            cells.append(text)
        lines.append("| %s | %s |" % (field, " | ".join(cells)))
    return ("Per field and N: MeshFree's most accurate setting's rms error / the most accurate peer's, then Auto's / "
            "that setting's (a peer win: a peer both faster and more accurate by more than %d%%; an Auto miss: more "
            "than %gx the error or the time).\n\n" % (100 * ACCURACY_MARGIN, AUTO_FACTOR) + "\n".join(lines) + "\n")


# ---------------------------------------------------------------------------------------------- SPH
def fetch_points(proxy):
    """Points of the source's current output (after an update) as an (n, 3) array."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    return vtk_to_numpy(output_of(proxy).GetPoints().GetData()).astype(float)


def output_of(proxy):
    """The source's output data object in this process (builtin session: no client-server copy, and exactly
    the state of the time last requested by UpdatePipeline)."""
    return proxy.GetClientSideObject().GetOutputDataObject(0)


def info_int(proxy, name):
    """An information-only integer property of a proxy, or None when the proxy has no such property."""
    prop = proxy.SMProxy.GetProperty(name)
    if prop is None:
        return None
    proxy.UpdatePropertyInformation()
    return int(prop.GetElement(0))


def fixed_step_count(duration, dt):
    """Steps SPHFluid::Advance takes over `duration` with a fixed step dt (CFLNumber 0): full steps, then one
    step to the target, or two equal halves rather than a sliver at the end."""
    t, k = 0.0, 0
    while t < duration:
        remaining = duration - t
        d = dt
        if d >= remaining:
            d = remaining
        elif d > 0.5 * remaining:
            d = 0.5 * remaining
        t = duration if d == remaining else t + d
        k += 1
    return k


class SPHRun:
    """An SPHFluid source with a step counter: the source's StepsTaken property when the plugin has it
    (adaptive CFL steps, as the core tests), else a fixed step (CFLNumber 0) of `fallback_dt`, below the
    CFL limit, whose steps the script counts itself."""

    def __init__(self, fallback_dt, times, artificial_viscosity=None, **props):
        from paraview import simple
        self.src = simple.SPHFluid(**props)
        if artificial_viscosity is not None and self.src.SMProxy.GetProperty("ArtificialViscosity") is not None:
            self.src.ArtificialViscosity = artificial_viscosity
        self.adaptive = self.src.SMProxy.GetProperty("StepsTaken") is not None
        if not self.adaptive:
            self.src.CFLNumber = 0.0
            self.src.TimeStep = fallback_dt
        self.dt = fallback_dt
        self.times = [0.0] + list(times)  # the output times, ascending
        self.reached = 0.0
        self.counted = 0

    def update(self, t):
        self.src.UpdatePipeline(t)
        if not self.adaptive:
            for a, b in zip(self.times[:-1], self.times[1:]):
                if self.reached < b <= t + 1e-12:
                    self.counted += fixed_step_count(b - a, self.dt)
            self.reached = max(self.reached, t)

    def steps(self):
        return info_int(self.src, "StepsTaken") if self.adaptive else self.counted

    def mode(self):
        return "adaptive CFL 0.25, steps from the source" if self.adaptive else \
            "fixed dt %.3g s (the source cannot report its steps), steps counted by the script" % self.dt

    def delete(self):
        from paraview import simple
        simple.Delete(self.src)


MARTIN_MOYCE_T = (0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51, 2.65, 2.83, 2.98, 3.11, 3.33)
MARTIN_MOYCE_Z = (1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00, 3.22, 3.44, 3.67, 3.89, 4.11)
MARTIN_MOYCE_ORIGIN = 0.175  # Lethe's time-origin correction of the experiment (see Testing/Core/TestSPHDamBreak.cxx)


def bed_front(x, dx):
    """Leading edge of the fluid on the floor (z = 0), as a wave gauge just above the bed sees it (as
    Testing/Core/TestSPHDamBreak.cxx): the largest x of the particles whose centre lies within 1.5 dx of the
    floor and that have at least 3 other particles within 2 dx (a detached droplet does not count)."""
    from scipy.spatial import cKDTree
    low = x[x[:, 2] < 1.5 * dx]
    if len(low) == 0:
        return float(x[:, 0].max())
    tree = cKDTree(x[:, [0, 2]])
    counts = np.array([len(n) - 1 for n in tree.query_ball_point(low[:, [0, 2]], 2.0 * dx)])
    attached = low[counts >= 3]
    return float((attached if len(attached) else low)[:, 0].max())


def sph_dam_break(resolution, t_max):
    a, g = 0.1, 9.81
    dx = a / resolution
    scale = math.sqrt(2 * g / a)
    step_T = 0.05
    pairs = [(T, Z) for T, Z in zip(MARTIN_MOYCE_T, MARTIN_MOYCE_Z) if T <= t_max + 1e-9]
    last = int(math.ceil(pairs[-1][0] / step_T)) + 1
    interval = step_T / scale
    run = SPHRun(0.5 * 0.25 * 2 * dx / math.sqrt(100 * g * 2 * a), [k * interval for k in range(1, last + 1)],
                 artificial_viscosity=0.05, Dimension=2, ParticleSpacing=dx, FluidBounds=[0, a, 0, 0, 0, 2 * a],
                 DomainBounds=[0, 5 * a, 0, 0, 0, 2.5 * a], SmoothingLength=0, RestDensity=1000, GasStiffness=0,
                 Viscosity=1e-3, SurfaceTension=0, Gravity=[0, 0, -g], TimeStep=1e-3, CFLNumber=0.25,
                 OutputInterval=interval, EndTime=last * interval)
    fronts = {}
    t0 = time.perf_counter()
    errors = []
    particles = 0
    corrected = []  # against the experiment's corrected time origin (TestSPHDamBreak.cxx): SPH at T - 0.175

    def front_at(T):
        nonlocal particles
        j = int(math.floor(T / step_T + 1e-9))
        for k in (j, j + 1):
            if k not in fronts:
                run.update(k * interval)
                x = fetch_points(run.src)
                particles = len(x)
                fronts[k] = (bed_front(x, dx) + 0.5 * dx) / a
        w = T / step_T - j
        return (1 - w) * fronts[j] + w * fronts[j + 1]

    for T, Z in pairs:
        if T > 0.5:
            corrected.append(front_at(T - MARTIN_MOYCE_ORIGIN) / Z - 1)
        errors.append(front_at(T) / Z - 1)
    seconds = time.perf_counter() - t0
    steps = run.steps()
    log("  dam break a/dx = %d (%s): %d particles, T <= %.2f, front error %s (time origin corrected by %.3f: %s),"
        " %d steps, %.1f s" % (resolution, run.mode(), particles, pairs[-1][0],
                               " ".join("%+.0f%%" % (100 * v) for v in errors), MARTIN_MOYCE_ORIGIN,
                               " ".join("%+.0f%%" % (100 * v) for v in corrected), steps, seconds))
    run.delete()
    e = np.array(errors)
    return dict(case="dam_break", dimension=2, resolution=resolution, particles=particles, steps=steps,
                seconds=seconds, rms_error=float(np.sqrt(np.mean(e * e))), max_error=float(np.abs(e).max()),
                particle_steps_per_second=particles * steps / seconds)


def sph_hydrostatic(resolution, settle):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    H, g, rho0, mu = 0.4, 9.81, 1000.0, 100.0
    dx = H / resolution
    h, k = 2.5 * dx, 1.2 * 100 * g * H
    end = settle * math.sqrt(H / g)
    run = SPHRun(0.5 * min(0.25 * h / math.sqrt(k), 0.125 * h * h * rho0 / mu), [end],
                 Dimension=2, ParticleSpacing=dx, FluidBounds=[0, 0.2, 0, 0, 0, H], DomainBounds=[0, 0.2, 0, 0, 0, 0.5],
                 SmoothingLength=h, RestDensity=rho0, GasStiffness=k, Viscosity=mu, SurfaceTension=0,
                 Gravity=[0, 0, -g], TimeStep=1e-3, CFLNumber=0.25, OutputInterval=end, EndTime=end)
    t0 = time.perf_counter()
    run.update(end)
    x = fetch_points(run.src)
    seconds = time.perf_counter() - t0
    steps = run.steps()
    p = vtk_to_numpy(output_of(run.src).GetPointData().GetArray("Pressure")).astype(float)
    exact = rho0 * g * (H - x[:, 2])
    l2 = float(np.sqrt(np.sum((p - exact) ** 2) / np.sum(exact ** 2)))
    mx = float(np.abs(p - exact).max() / (rho0 * g * H))
    log("  hydrostatic H/dx = %d (%s): %d particles, t = %.2f s, pressure L2 %.4f, max %.4f, %d steps, %.1f s" % (
        resolution, run.mode(), len(x), end, l2, mx, steps, seconds))
    run.delete()
    return dict(case="hydrostatic", dimension=2, resolution=resolution, particles=len(x), steps=steps,
                seconds=seconds, rms_error=l2, max_error=mx, particle_steps_per_second=len(x) * steps / seconds)


def sph_throughput(block, span):
    dx, g = 0.01, 9.81
    bx, by, bz = block
    run = SPHRun(0.5 * 0.25 * 2 * dx / math.sqrt(100 * g * bz * dx), [span, 2 * span],
                 Dimension=3, ParticleSpacing=dx, FluidBounds=[0, bx * dx, 0, by * dx, 0, bz * dx],
                 DomainBounds=[0, 3 * bx * dx, 0, by * dx, 0, 1.5 * bz * dx], SmoothingLength=0, RestDensity=1000,
                 GasStiffness=0, Viscosity=1e-3, SurfaceTension=0, Gravity=[0, 0, -g], TimeStep=1e-3,
                 CFLNumber=0.25, OutputInterval=span, EndTime=2 * span)
    run.update(span)  # warm-up: buffers grown, flow started
    s0 = run.steps()
    t0 = time.perf_counter()
    run.update(2 * span)
    seconds = time.perf_counter() - t0
    steps = run.steps() - s0
    particles = bx * by * bz
    log("  throughput 3D %d particles (%s): %d steps in %.2f s = %.3g particle-steps/s" % (
        particles, run.mode(), steps, seconds, particles * steps / seconds))
    run.delete()
    return dict(case="throughput", dimension=3, resolution=bx, particles=particles, steps=steps, seconds=seconds,
                rms_error=None, max_error=None, particle_steps_per_second=particles * steps / seconds)


def run_sph(cfg):
    rows = []
    log("\n=== SPH fluid")
    for r in cfg.dam_break_resolutions:
        rows.append(sph_dam_break(r, cfg.dam_break_t_max))
    for r in cfg.hydrostatic_resolutions:
        rows.append(sph_hydrostatic(r, cfg.hydrostatic_settle))
    for b in cfg.sph_blocks:
        rows.append(sph_throughput(b, cfg.sph_span))
    return rows


# ---------------------------------------------------------------------------------------------- solid
BEAM_L, BEAM_H, BEAM_RHO, BEAM_E, BEAM_G = 0.8, 0.08, 1000.0, 1e4, 0.005


def beam_reference(s):
    """Euler-Bernoulli deflection under the uniform self-weight q at abscissa s, plus Timoshenko shear."""
    L, H, E = BEAM_L, BEAM_H, BEAM_E
    q, inertia, shear_modulus, kappa = BEAM_RHO * BEAM_G * H * H, H ** 4 / 12, E / 2, 5.0 / 6
    bending = q * s * s * (6 * L * L - 4 * L * s + s * s) / (24 * E * inertia)
    return bending + q * (L * s - 0.5 * s * s) / (kappa * shear_modulus * H * H)


def info_double(proxy, name):
    prop = proxy.SMProxy.GetProperty(name)
    proxy.UpdatePropertyInformation()
    return float(prop.GetElement(0))


def solid_steps(proxy, intervals, interval, time_step, implicit):
    """Integration steps the MLSDeformableSolid source takes for `intervals` output intervals: each interval
    is cut into ceil(interval / step) equal steps, step = TimeStep capped by the stable step (symplectic) or
    TimeStep, 20 x the stable step when 0 (implicit). Its SimulatedSteps property counts intervals."""
    stable = info_double(proxy, "StableTimeStep")
    if implicit:
        step = time_step if time_step > 0 else 20 * stable
    else:
        step = min(time_step, stable) if time_step > 0 else stable
    return intervals * max(1, int(math.ceil(interval / step - 1e-9)))


def solid_output(src, t):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    src.UpdatePipeline(t)
    mb = output_of(src)
    phyxels = mb.GetBlock(0)
    x = vtk_to_numpy(phyxels.GetPoints().GetData()).astype(float)
    u = vtk_to_numpy(phyxels.GetPointData().GetArray("Displacement")).astype(float)
    return x, u


def solid_cantilever(resolution, integrator, end, implicit_dt):
    from paraview import simple
    H, L = BEAM_H, BEAM_L
    spacing = H / resolution
    src = simple.MLSDeformableSolid(Shape="Box", ShapeBounds=[-H, L, 0, H, 0, H], PhyxelSpacing=spacing,
                                    YoungModulus=BEAM_E, PoissonRatio=0.0, Density=BEAM_RHO, VolumeStiffness=0.0,
                                    HourglassStiffness=0.05, Gravity=[0, 0, -BEAM_G], Damping=0.8,
                                    Container="None", SelfContact=0, FixedBounds=[-1, 0, -1, 1, -1, 1],
                                    Integrator=integrator, TimeStep=implicit_dt if integrator == "Implicit" else 0.0,
                                    EndTime=end, OutputInterval=end)
    t0 = time.perf_counter()
    x, u = solid_output(src, end)
    seconds = time.perf_counter() - t0
    steps = solid_steps(src, 1, end, implicit_dt if integrator == "Implicit" else 0.0, integrator == "Implicit")
    simple.Delete(src)
    rest = x - u
    layers = np.unique(np.round(rest[:, 0] / spacing * 2).astype(int))
    tip_ref = beam_reference(rest[:, 0].max())
    errs, tip = [], None
    for key in layers:
        sel = np.round(rest[:, 0] / spacing * 2).astype(int) == key
        s = rest[sel, 0].mean()
        if s <= 0:
            continue  # the clamp
        w = -u[sel, 2].mean()
        errs.append((w - beam_reference(s)) / tip_ref)
        tip = (w, beam_reference(s))
    e = np.array(errs)
    log("  cantilever %s, %d across: %d phyxels, %d steps, %.1f s: tip %.5f m vs %.5f m (%+.1f %%), profile rms %.3f" % (
        integrator, resolution, len(x), steps, seconds, tip[0], tip[1], 100 * (tip[0] / tip[1] - 1),
        float(np.sqrt(np.mean(e * e)))))
    return dict(case="cantilever", integrator=integrator, resolution=resolution, phyxels=len(x), steps=steps,
                seconds=seconds, rms_error=float(np.sqrt(np.mean(e * e))), max_error=float(np.abs(e).max()),
                phyxel_steps_per_second=len(x) * steps / seconds)


def solid_throughput(edge, integrator, steps_wanted):
    from paraview import simple
    a = 0.01
    bounds = [-edge * a / 2, edge * a / 2, -edge * a / 2, edge * a / 2, 0.05, 0.05 + edge * a]
    probe = simple.MLSDeformableSolid(Shape="Box", ShapeBounds=bounds, PhyxelSpacing=a, VolumeStiffness=1e4,
                                      EndTime=1e-3, OutputInterval=1e-3)
    probe.UpdatePipeline(0.0)
    stable = info_double(probe, "StableTimeStep")
    simple.Delete(probe)
    dt = stable * (10 if integrator == "Implicit" else 1)
    span = dt * steps_wanted
    # The box container the solid had by default until issue 16, kept so that the figures stay comparable.
    src = simple.MLSDeformableSolid(Shape="Box", ShapeBounds=bounds, PhyxelSpacing=a, VolumeStiffness=1e4,
                                    Integrator=integrator, TimeStep=dt, InitialVelocity=[0, 0, -1],
                                    Container="Box", ContainerBounds=[-0.5, 0.5, -0.5, 0.5, 0.0, 1.0],
                                    EndTime=2 * span, OutputInterval=span)
    src.UpdatePipeline(span)  # warm-up
    t0 = time.perf_counter()
    src.UpdatePipeline(2 * span)
    seconds = time.perf_counter() - t0
    steps = solid_steps(src, 1, span, dt, integrator == "Implicit")
    n = int(info_double(src, "NumberOfPhyxels"))
    simple.Delete(src)
    log("  throughput %s %d phyxels: dt %.3g s, %d steps in %.2f s = %.3g phyxel-steps/s" % (
        integrator, n, dt, steps, seconds, n * steps / seconds))
    return dict(case="throughput", integrator=integrator, resolution=edge, phyxels=n, steps=steps, seconds=seconds,
                rms_error=None, max_error=None, phyxel_steps_per_second=n * steps / seconds)


def run_solid(cfg):
    rows = []
    log("\n=== MLS deformable solid")
    for integrator, resolutions in (("SymplecticEuler", cfg.beam_symplectic), ("Implicit", cfg.beam_implicit)):
        for r in resolutions:
            rows.append(solid_cantilever(r, integrator, cfg.beam_end, cfg.beam_implicit_dt))
    for integrator in ("SymplecticEuler", "Implicit"):
        for edge in cfg.solid_edges:
            rows.append(solid_throughput(edge, integrator, cfg.solid_steps if integrator != "Implicit" else
                                         max(2, cfg.solid_steps // 4)))
    return rows


# ---------------------------------------------------------------------------------------------- main
class Config:
    def __init__(self, mode):
        self.smoke = mode == "smoke"
        if mode == "full":
            self.sizes_2d, self.sizes_3d = (100, 1000, 10000, 100000), (100, 1000, 10000, 100000)
            self.repeats, self.budget, self.rbf_global_limit = 5, 5.0, 10000
            self.dam_break_resolutions, self.dam_break_t_max = (10, 20, 40), 3.4
            self.hydrostatic_resolutions, self.hydrostatic_settle = (10, 20, 40), 20.0
            self.sph_blocks, self.sph_span = ((16, 8, 16), (32, 16, 32), (64, 32, 32), (64, 64, 64)), 0.02
            self.beam_symplectic, self.beam_implicit, self.beam_end, self.beam_implicit_dt = (2, 4, 6), (2, 4, 6), 60.0, 0.25
            self.solid_edges, self.solid_steps = (10, 20, 30, 46), 20
        elif mode == "quick":
            self.sizes_2d, self.sizes_3d = (1000, 10000), (1000, 10000)
            self.repeats, self.budget, self.rbf_global_limit = 3, 1.0, 1000
            self.dam_break_resolutions, self.dam_break_t_max = (10, 20, 40), 3.4
            self.hydrostatic_resolutions, self.hydrostatic_settle = (10, 20, 40), 20.0
            self.sph_blocks, self.sph_span = ((16, 8, 16), (32, 16, 32), (64, 32, 32)), 0.01
            self.beam_symplectic, self.beam_implicit, self.beam_end, self.beam_implicit_dt = (2, 4), (2, 4), 60.0, 0.25
            self.solid_edges, self.solid_steps = (10, 20), 20
        else:  # smoke: the program works and writes well-formed files; sizes too small to mean anything
            self.sizes_2d, self.sizes_3d = (100, 300), (200,)
            self.repeats, self.budget, self.rbf_global_limit = 1, 0.1, 300
            self.dam_break_resolutions, self.dam_break_t_max = (5,), 1.0
            self.hydrostatic_resolutions, self.hydrostatic_settle = (10,), 2.0
            self.sph_blocks, self.sph_span = ((8, 4, 8),), 0.002
            self.beam_symplectic, self.beam_implicit, self.beam_end, self.beam_implicit_dt = (2,), (2,), 5.0, 0.1
            self.solid_edges, self.solid_steps = (6,), 4


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="N = 1,000 and 10,000, small simulations (minutes)")
    mode.add_argument("--smoke", action="store_true", help="tiny sizes: checks the program, not the speed")
    parser.add_argument("--out", help="output folder (default <build>/benchmark-results)")
    parser.add_argument("--only", default="approximation,sph,solid", help="comma list of parts to run")
    parser.add_argument("--rbf-global-limit", type=int,
                        help="largest N for SciPy's global RBF (default 10,000; 1,000 with --quick)")
    parser.add_argument("--threads", type=int, help="threads for every tool (OpenMP, VTK SMP, BLAS); default: "
                        "all cores. 1 gives a fair same-threads comparison on a loaded machine")
    parser.add_argument("--sizes", help="comma list of N replacing the mode's (2D and 3D), e.g. 100000")
    parser.add_argument("--no-plots", action="store_true")
    args = parser.parse_args()
    cfg = Config("smoke" if args.smoke else "quick" if args.quick else "full")
    if args.sizes:
        cfg.sizes_2d = cfg.sizes_3d = tuple(int(v) for v in args.sizes.split(","))
    if args.rbf_global_limit is not None:
        cfg.rbf_global_limit = args.rbf_global_limit
    plugin = find_plugin()
    out = args.out or os.path.join(build_dir_of(plugin), "benchmark-results")
    os.makedirs(out, exist_ok=True)
    parts = [p.strip() for p in args.only.split(",") if p.strip()]

    from paraview import simple
    simple.LoadPlugin(plugin, remote=False)  # its proxies appear in paraview.simple
    machine = machine_description()
    machine += ", %s thread(s) per tool" % (THREADS or os.cpu_count())
    log("MeshFree benchmarks (%s) -> %s\nplugin %s\nmachine: %s, load average %s" % (
        "smoke" if cfg.smoke else "quick" if args.quick else "full", out, plugin, machine,
        " ".join("%.2f" % v for v in os.getloadavg())))
    start = time.perf_counter()
    load0 = " ".join("%.2f" % v for v in os.getloadavg())
    if "approximation" in parts:
        approximation_rows = run_approximation(cfg)
        bench_report.write_csv(os.path.join(out, "approximation.csv"), bench_report.APPROXIMATION_COLUMNS,
                               approximation_rows)
        table = "# Wins and losses against the peers (generated by run_benchmarks.py)\n\nMachine: %s\n\n" \
                "Command: `pvpython --no-mpi Testing/Benchmarks/run_benchmarks.py %s`\n\n%s" % (
                    machine, " ".join(sys.argv[1:]), wins_losses(approximation_rows) + "\n" +
                    wins_losses_compact(approximation_rows))
        with open(os.path.join(out, "wins_losses.md"), "w") as f:
            f.write(table)
        log("\n" + table)
    if "sph" in parts:
        bench_report.write_csv(os.path.join(out, "sph.csv"), bench_report.SPH_COLUMNS, run_sph(cfg))
    if "solid" in parts:
        bench_report.write_csv(os.path.join(out, "solid.csv"), bench_report.SOLID_COLUMNS, run_solid(cfg))
    problems = bench_report.check_dir(out, [p + ".csv" for p in parts])
    for p in problems:
        log("ERROR: " + p)
    if not args.no_plots and "approximation" in parts:
        text = bench_report.report(out, "%s; load average at the start %s, at the end %s" % (
            machine, load0, " ".join("%.2f" % v for v in os.getloadavg())),
            "`pvpython --no-mpi Testing/Benchmarks/run_benchmarks.py %s`" % " ".join(sys.argv[1:]))
        log("\n" + text)
    log("total %.0f s, load average %s; results in %s" % (
        time.perf_counter() - start, " ".join("%.2f" % v for v in os.getloadavg()), out))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
