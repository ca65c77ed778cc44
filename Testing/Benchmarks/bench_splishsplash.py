"""Time to solution beside SPlisHSPlasH: the 3D dam break of BenchSPH (65,536 particles) with MeshFree's WCSPH and
DFSPH and with SPlisHSPlasH's DFSPH, one after the other in this process, on the same machine.

SPlisHSPlasH (Bender et al., https://github.com/InteractiveComputerGraphics/SPlisHSPlasH) is built beforehand by
setup_splishsplash.sh (never by the tests); give its SPHSimulator with --simulator. The scene is written here in
SPlisHSPlasH's JSON scene format (its doc/file_format.md), as close to BenchSPH's as that format allows:
  * the same tank and column: the closed tank [0, 3 L] x [0, W] x [0, 1.5 H] (a static wall box, SPlisHSPlasH's
    data/models/UnitBox.obj scaled and moved there, its faces half a spacing outside, where MeshFree's first layer
    of wall dummies is: with the faces on the tank's walls, half a spacing from the fluid's outer particles, the
    first steps of SPlisHSPlasH kicked them to ~20 m/s and ran at its minimum step, 0.1 ms, measured), the column
    [0, L] x [0, W] x [0, H] sampled on the same lattice (SPlisHSPlasH's regular fluid block places its first
    particle one spacing inside the block's start and leaves one spacing at its end, so the block is widened by half
    a spacing on each side: its particles then sit at (i + 1/2) dx, where BenchSPH's are), L x W x H = 64 x 32 x 32
    dx at dx = 1 cm, z up, g = 9.81 m/s^2;
  * the same spacing: particleRadius = dx / 2, so SPlisHSPlasH's support radius 4 r = 2 dx is MeshFree's h;
  * DFSPH with the same tolerances: average density error 0.01 %, divergence error 0.1 %, at most 100 iterations
    each (SPlisHSPlasH's minIterations = 2 is its default; MeshFree applies at least 2 corrections as well, and its
    density solve also requires the error's RMS to fall to 0.3 of its start, a stricter stop);
  * the same step rule: dt = 0.2 dx / v_max, at most 1 ms (MeshFree's CFLNumber 0.25 = SPlisHSPlasH's default
    cflFactor 0.5, cflMethod 1; cflMaxTimeStepSize set to MeshFree's TimeStep 1 ms);
  * the same fluid: rest density 1000, kinematic viscosity 1e-6 m^2/s (SPlisHSPlasH's "Standard" viscosity;
    MeshFree's Viscosity 1e-3 Pa s; MeshFree also applies its artificial viscosity alpha = 0.02, which has no
    SPlisHSPlasH counterpart set here);
  * no output files (no partio/VTK/state export; the boundary cache is off: --no-cache), no GUI.
What differs and cannot be set equal: the kernels (SPlisHSPlasH's cubic spline; MeshFree's poly6 density / spiky
gradient), the boundary model (--boundary akinci: Akinci et al. 2012 surface particles, the closest to MeshFree's
lattice dummy particles; --boundary volume-maps: SPlisHSPlasH's default, Bender et al. 2019), and the precision
(SPlisHSPlasH's default build is single precision with AVX; MeshFree computes in double).

Timing. MeshFree: BenchSPH --warmup 0 (the Advance() call from the initial state to the end time; set-up
excluded). SPlisHSPlasH: its own "Time sum: SimStep" (the time steps from the initial state to the end; scene
loading and boundary sampling excluded), and the simulated time is the sum of its step sizes as its "Time step size"
counter records them (it stops at the first step past stopAt). Both use the same threads (OMP_NUM_THREADS and
MESHFREE_NUM_THREADS, default: all CPUs; SPlisHSPlasH runs OpenMP, MeshFree oneTBB). The 1-minute load average is
read before and after each run and reported beside it.

SPHERIC Test 2 (--scene spheric2 --dx DX): the Test 2 scene of Data/Scripts/spheric_test2.py (bench_spheric2.py)
in the same two codes, 1 s (--time) from the initial state:
  * MeshFree: SPH Fluid With Obstacles from pvpython (spheric_test2.make_scene(): the 3.22 x 1 x 1 m tank, the
    column on the tank's lattice, round(1.228 / dx) x round(1 / dx) x round(0.55 / dx) particles at the far wall,
    the 0.161 x 0.403 x 0.161 m box as the Obstacles surface), each solver in its own pvpython process (this script
    under pvpython, --meshfree-spheric2), the proxy's defaults otherwise: Viscosity 1e-3 Pa s as the bench,
    CFLNumber 0.25, TimeStep 2 ms (the proxy's default step cap), DFSPH tolerances 0.01 % / 0.1 %, at most 100
    iterations; OutputInterval = the end time (one output: no landing steps on output times). Timed: the request
    of the end time after the initial state's (set-up, boundary dummies and the first output excluded), wall and
    CPU (the process' threads) seconds; steps from StepsTaken, iterations per step from the output's field data;
  * SPlisHSPlasH: the same column on the same lattice (particles at (i + 1/2) dx from the block's start, as
    MeshFree's: the block widened by half a spacing on each side, as for the dam break), the tank a static wall box
    (UnitBox.obj scaled, faces half a spacing outside the tank, as above), the box a static (non-wall) rigid body
    from an OBJ this script writes (its 12 triangles, outward normals, the specification's faces), the same step
    rule (cflFactor 0.5, cflMethod 1: 0.2 dx / v_max, at most cflMaxTimeStepSize = 2 ms, MeshFree's TimeStep),
    the same DFSPH tolerances, density 1000, kinematic viscosity 1e-6 m^2/s;
  * the particle counts of both are reported (fluid; SPlisHSPlasH's boundary particles with Akinci walls).
  What differs is as for the dam break (kernels, wall model, precision, MeshFree's stricter density stop).

Set-up (once; nothing is downloaded, the five git directories are local copies, e.g. from a mirror):
  Testing/Benchmarks/setup_splishsplash.sh --sph SPlisHSPlasH.git --compactnsearch CompactNSearch.git \
      --discregrid Discregrid.git --genericparameters GenericParameters.git --pbd PositionBasedDynamics.git \
      --commit 80b7284 --build SOMEWHERE
Run (from the repository root, after building BenchSPH):
  /usr/bin/python3 Testing/Benchmarks/bench_splishsplash.py --simulator PATH/TO/SPHSimulator --time 1.0 \\
      --out Testing/Benchmarks/results
  MESHFREE_PLUGIN=build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so /usr/bin/python3 \\
      Testing/Benchmarks/bench_splishsplash.py --simulator PATH/TO/SPHSimulator --scene spheric2 --dx 0.02 \\
      --time 1.0 --boundary volume-maps --out Testing/Benchmarks/results
Writes OUT/splishsplash.md (the table, appended as a new section) and OUT/splishsplash.json (all runs, appended).
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))

BLOCKS = {16384: (32, 16, 32), 65536: (64, 32, 32), 262144: (64, 64, 64)}  # as BenchSPH
DX = 0.01
# The DFSPH tolerances (0.01 % density, 0.1 % divergence, as MeshFree's defaults) and iteration bounds.
DFSPH_SETTINGS = {"minIterations": 2, "maxIterations": 100, "maxError": 0.01, "maxIterationsV": 100, "maxErrorV": 0.1,
                  "enableDivergenceSolver": True}


def static_body(geometry, translation, scale, wall, resolution):
    """A static boundary body of a SPlisHSPlasH scene: `wall` True for a container (its inside is the fluid's side,
    the volume map inverted), False for an obstacle; `resolution` the volume map's cells per axis."""
    return {
        "geometryFile": geometry,
        "translation": list(translation),
        "rotationAxis": [1, 0, 0],
        "rotationAngle": 0,
        "scale": list(scale),
        "isDynamic": False,
        "isWall": wall,
        "mapInvert": wall,
        "mapThickness": 0.0,
        "mapResolution": list(resolution),
        "samplingMode": 1,
    }


def tank_body(unit_box, centre, tank, dx):
    """The tank: the unit box scaled to `tank` around `centre`, a volume-map cell per support radius (2 dx)."""
    return static_body(unit_box, centre, tank, True, [int(round(t / (2.0 * dx))) for t in tank])


def scene(size, end, boundary, box_obj):
    bx, by, bz = BLOCKS[size]
    half = 0.5 * DX
    # The wall box's faces where MeshFree's first layer of wall dummies is (half a spacing outside the tank): its
    # surface particles (Akinci) then sit one spacing from the fluid's outer layer, as MeshFree's dummies do.
    tank = (3.0 * bx * DX + DX, by * DX + DX, 1.5 * bz * DX + DX)
    centre = (1.5 * bx * DX, 0.5 * by * DX, 0.75 * bz * DX)
    return {
        "Configuration": {
            "pause": False,
            "stopAt": end,
            "sim2D": False,
            "particleRadius": half,
            "simulationMethod": 4,  # DFSPH
            "gravitation": [0.0, 0.0, -9.81],
            "timeStepSize": 0.001,
            "cflMethod": 1,
            "cflFactor": 0.5,
            "cflMaxTimeStepSize": 0.001,
            "boundaryHandlingMethod": 0 if boundary == "akinci" else 2,
            "enablePartioExport": False,
            "enableVTKExport": False,
            "enableStateExport": False,
            "enableRigidBodyExport": False,
            "enableRigidBodyVTKExport": False,
            # SPlisHSPlasH <= 2.15 reads the solver's settings from Configuration itself, 2.16 from a block named
            # after the method: both are written.
            **DFSPH_SETTINGS,
            "DFSPH": dict(DFSPH_SETTINGS),
        },
        "Materials": [
            {
                "id": "Fluid",
                "density0": 1000.0,
                "viscosityMethod": 1,
                "viscosity": 1e-6,  # <= 2.15
                "Standard viscosity": {"viscosity": 1e-6},  # 2.16
            }
        ],
        "RigidBodies": [tank_body(box_obj, centre, tank, DX)],
        "FluidBlocks": [
            {
                "denseMode": 0,
                "start": [-half, -half, -half],
                "end": [bx * DX + half, by * DX + half, bz * DX + half],
                "translation": [0.0, 0.0, 0.0],
                "scale": [1, 1, 1],
            }
        ],
    }


# SPHERIC Test 2 (Data/Scripts/spheric_test2.py's TANK, WATER, BOX; repeated here so that this script needs no
# ParaView when it only drives the runs; --meshfree-spheric2 checks them against spheric_test2's).
T2_TANK = (0.0, 3.22, 0.0, 1.0, 0.0, 1.0)
T2_WATER = (1.992, 3.22, 0.0, 1.0, 0.0, 0.55)
T2_BOX = (0.6635, 0.8245, 0.2955, 0.6985, 0.0, 0.161)
T2_TIME_STEP = 0.002  # SPH Fluid's TimeStep default (Plugin/xml/SPHFluid.xml), which spheric_test2 keeps


def t2_column(dx):
    """The layers (nx, ny, nz) and the lower corner of the column SPH Fluid builds in spheric_test2.make_scene():
    FluidBounds [3.22 - round(1.228 / dx) dx, 3.22] x [0, 1] x [0, 0.55], floor(extent / dx + 0.5) nodes per axis
    at lo + (i + 1/2) dx (SPHSetup.cxx)."""
    length = round((T2_WATER[1] - T2_WATER[0]) / dx) * dx
    lo = (T2_TANK[1] - length, T2_WATER[2], T2_WATER[4])
    ext = (length, T2_WATER[3] - T2_WATER[2], T2_WATER[5] - T2_WATER[4])
    return tuple(int(math.floor(e / dx + 0.5)) for e in ext), lo


def write_box_obj(path, box):
    """The box as a closed triangle mesh (12 triangles, counter-clockwise seen from outside: outward normals)."""
    x0, x1, y0, y1, z0, z1 = box
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1),
         (x0, y1, z1)]
    quads = [(1, 4, 3, 2), (5, 6, 7, 8), (1, 2, 6, 5), (3, 4, 8, 7), (1, 5, 8, 4), (2, 3, 7, 6)]
    with open(path, "w") as f:
        f.write("# SPHERIC Test 2 box (bench_splishsplash.py)\n")
        for p in v:
            f.write("v %r %r %r\n" % p)
        for a, b, c, d in quads:
            f.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))


def scene_spheric2(dx, end, boundary, unit_box, box_obj):
    """Test 2 in SPlisHSPlasH's JSON format (see the module docstring)."""
    (nx, ny, nz), lo = t2_column(dx)
    half = 0.5 * dx
    tank = tuple(T2_TANK[2 * a + 1] - T2_TANK[2 * a] + dx for a in range(3))
    centre = tuple(0.5 * (T2_TANK[2 * a] + T2_TANK[2 * a + 1]) for a in range(3))
    box = tuple(T2_BOX[2 * a + 1] - T2_BOX[2 * a] for a in range(3))
    dam = scene(65536, end, boundary, unit_box)  # its configuration and materials, then Test 2's geometry
    config = dam["Configuration"]
    config.update(particleRadius=half, timeStepSize=T2_TIME_STEP, cflMaxTimeStepSize=T2_TIME_STEP)
    return {
        "Configuration": config,
        "Materials": dam["Materials"],
        "RigidBodies": [
            tank_body(unit_box, centre, tank, dx),
            # the box's mesh is already in place: no translation, unit scale; a map cell per half spacing
            static_body(box_obj, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), False,
                        [max(8, int(math.ceil(b / half))) for b in box]),
        ],
        "FluidBlocks": [
            {
                "denseMode": 0,
                "start": [lo[0] - half, lo[1] - half, lo[2] - half],
                "end": [lo[0] + nx * dx + half, lo[1] + ny * dx + half, lo[2] + nz * dx + half],
                "translation": [0.0, 0.0, 0.0],
                "scale": [1, 1, 1],
            }
        ],
    }


def meshfree_spheric2_child(solver, dx, end):
    """Run under pvpython: one Test 2 run of SPH Fluid With Obstacles, its measurements as one JSON line."""
    sys.path.insert(0, os.path.join(ROOT, "Data", "Scripts"))
    import spheric_test2
    from paraview import servermanager as sm
    from vtkmodules.numpy_interface import dataset_adapter as dsa
    assert (tuple(spheric_test2.TANK), tuple(spheric_test2.WATER), tuple(spheric_test2.BOX)) == \
        (T2_TANK, T2_WATER, T2_BOX), "bench_splishsplash.py's Test 2 geometry differs from spheric_test2.py's"
    ns = {}
    spheric_test2.load_plugin(ns)
    fluid = spheric_test2.make_scene(ns, dx, end, end, solver)  # one output interval: the whole run
    fluid.UpdatePipelineInformation()
    assert abs(fluid.GetPropertyValue("TimeStep") - T2_TIME_STEP) < 1e-12, "TimeStep default is not 2 ms"
    settings = {k: fluid.GetPropertyValue(k) for k in ("CFLNumber", "TimeStep", "DensityTolerance",
                                                       "DivergenceTolerance", "MaximumIterations", "Viscosity",
                                                       "ArtificialViscosity")}
    fluid.UpdatePipeline(0.0)  # set-up and the initial state, not timed
    first = dsa.WrapDataObject(sm.Fetch(fluid))
    fluid.UpdatePropertyInformation()
    steps0 = fluid.GetProperty("StepsTaken").GetElement(0)
    t0, c0 = time.perf_counter(), time.process_time()
    fluid.UpdatePipeline(end)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = dsa.WrapDataObject(sm.Fetch(fluid))
    fluid.UpdatePropertyInformation()
    row = dict(particles=first.GetNumberOfPoints(), particles_end=out.GetNumberOfPoints(),
               steps=fluid.GetProperty("StepsTaken").GetElement(0) - steps0, sim_s=end, wall_s=wall, cpu_s=cpu,
               settings=settings)
    if solver == "DFSPH":
        its = []
        for name in ("DensityIterations", "DivergenceIterations"):
            a = out.FieldData[name] if name in out.FieldData.keys() else None
            its.append(float(a[1]) if a is not None and len(a) > 1 else float("nan"))
        row["iterations"] = "%.2f / %.2f" % tuple(its)
    print("RESULT " + json.dumps(row), flush=True)


def run_meshfree_spheric2(pvpython, solver, dx, end, env):
    cmd = [pvpython, "--no-mpi", os.path.abspath(__file__), "--meshfree-spheric2", solver, "--dx", repr(dx),
           "--time", repr(end)]
    rc, out, wall, l0, l1 = run(cmd, env=env)
    row = dict(code="MeshFree " + solver, rc=rc, process_wall_s=wall, load_before=l0, load_after=l1,
               command="pvpython --no-mpi Testing/Benchmarks/bench_splishsplash.py --meshfree-spheric2 %s --dx %r "
               "--time %r" % (solver, dx, end))
    for line in out.splitlines():
        if line.startswith("RESULT "):
            row.update(json.loads(line[len("RESULT "):]))
    if "wall_s" not in row:
        row["error"] = out[-3000:]
    return row


def load1():
    return os.getloadavg()[0]


def run(cmd, env=None, cwd=None):
    before = load1()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=cwd)
    wall = time.perf_counter() - t0
    return p.returncode, p.stdout, wall, before, load1()


def run_meshfree(bench, solver, size, end, env):
    rc, out, wall, l0, l1 = run([bench, "--solver", solver, "--sizes", str(size), "--warmup", "0", repr(end)],
                                env=env)
    row = dict(code="MeshFree " + solver.upper(), rc=rc, process_wall_s=wall, load_before=l0, load_after=l1,
               command=" ".join([os.path.relpath(bench, ROOT), "--solver", solver, "--sizes", str(size),
                                 "--warmup", "0", repr(end)]))
    backend = out.splitlines()[0] if out else ""
    row["threads"] = backend
    for line in out.splitlines():
        f = line.split()
        if len(f) >= 7 and f[0] == str(size):
            row.update(particles=int(f[0]), steps=int(f[1]), sim_s=float(f[2]), wall_s=float(f[3]))
            if solver == "dfsph" and len(f) >= 10:
                row["iterations"] = "%s / %s" % (f[7], f[9])
    if "wall_s" not in row:
        row["error"] = out[-2000:]
    return row


def run_splishsplash(simulator, size, end, boundary, env, work, dx=None):
    """SPlisHSPlasH's DFSPH on BenchSPH's dam break at `size` particles, or on Test 2 at spacing `dx` (not None)."""
    models = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(simulator))), "data", "models")
    box = os.path.join(models, "UnitBox.obj")
    if not os.path.exists(box):
        return dict(code="SPlisHSPlasH DFSPH", rc=-1, error="no %s (SPlisHSPlasH's data/models)" % box)
    if dx is None:
        name = "dambreak_%d.json" % size
        content, recorded = scene(size, end, boundary, box), scene(size, end, boundary, "UnitBox.obj")
    else:
        name = "spheric2_dx%g.json" % dx
        obj = os.path.join(work, "spheric2_box.obj")
        write_box_obj(obj, T2_BOX)
        content = scene_spheric2(dx, end, boundary, box, obj)
        recorded = scene_spheric2(dx, end, boundary, "UnitBox.obj", "spheric2_box.obj")
    path = os.path.join(work, name)
    with open(path, "w") as f:
        json.dump(content, f, indent=1)
    outdir = os.path.join(work, "output")
    cmd = [simulator, "--no-gui", "--no-cache", "--no-initial-pause", "--output-dir", outdir, "--stopAt", repr(end),
           path]
    # CPU seconds of the child (all its threads), from the children's resource usage before and after.
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rc, out, wall, l0, l1 = run(cmd, env=env, cwd=work)
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = dict(code="SPlisHSPlasH DFSPH (%s)" % boundary, rc=rc, process_wall_s=wall, load_before=l0,
               load_after=l1, command="SPHSimulator --no-gui --no-cache --no-initial-pause --output-dir OUT "
               "--stopAt %r %s" % (end, name), scene=recorded,
               process_cpu_s=(cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime))

    def grab(pattern, cast=float):
        m = re.search(pattern, out)
        return cast(m.group(1)) if m else None
    row["particles"] = grab(r"Number of fluid particles: (\d+)", int)
    row["boundary_particles"] = grab(r"Number of boundary particles: (\d+)", int)
    simstep = grab(r"Time sum: SimStep: ([0-9.eE+-]+) ms")
    row["sim_s"] = grab(r"Total number: Time step size: ([0-9.eE+-]+)")
    row["steps"] = None
    avg_dt = grab(r"Average number: Time step size: ([0-9.eE+-]+)")
    if row["sim_s"] and avg_dt:
        row["steps"] = int(round(row["sim_s"] / avg_dt))
    it = grab(r"Average number: DFSPH - iterations: ([0-9.eE+-]+)")
    itv = grab(r"Average number: DFSPH - iterationsV: ([0-9.eE+-]+)")
    if it is not None and itv is not None:
        row["iterations"] = "%.2f / %.2f" % (it, itv)
    if simstep is not None:
        row["wall_s"] = simstep / 1000.0
    else:
        row["error"] = out[-3000:]
    shutil.rmtree(outdir, ignore_errors=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--simulator", help="SPlisHSPlasH's SPHSimulator (setup_splishsplash.sh)")
    ap.add_argument("--scene", choices=("dambreak", "spheric2"), default="dambreak",
                    help="BenchSPH's dam break (default) or SPHERIC Test 2 at --dx")
    ap.add_argument("--dx", type=float, default=0.04, help="Test 2 particle spacing, m (--scene spheric2)")
    ap.add_argument("--bench-sph", default=os.path.join(ROOT, "build", "bin", "BenchSPH"))
    ap.add_argument("--pvpython", default=shutil.which("pvpython") or "pvpython",
                    help="pvpython for the Test 2 runs of MeshFree (plugin from $MESHFREE_PLUGIN)")
    ap.add_argument("--size", type=int, default=65536, choices=sorted(BLOCKS))
    ap.add_argument("--time", type=float, default=1.0, help="simulated seconds (default 1)")
    ap.add_argument("--boundary", choices=("akinci", "volume-maps"), action="append",
                    help="SPlisHSPlasH boundary model(s) (default: akinci)")
    ap.add_argument("--solvers", default="wcsph,dfsph", help="MeshFree solvers to run (default wcsph,dfsph)")
    ap.add_argument("--threads", type=int, default=0, help="OMP_NUM_THREADS for all runs (default: all CPUs)")
    ap.add_argument("--out", default=None, help="folder for splishsplash.md / .json (default: print only)")
    ap.add_argument("--label", default="", help="a note for the results section")
    ap.add_argument("--omp-wait-policy", choices=("default", "passive", "active"), action="append",
                    help="OMP_WAIT_POLICY for SPlisHSPlasH's runs, one run per value given (default: unset, its "
                         "own default: libgomp's threads spin at a barrier before they sleep, which a shared, "
                         "loaded machine penalises; MeshFree's oneTBB threads yield)")
    ap.add_argument("--meshfree-spheric2", choices=("WCSPH", "DFSPH"), default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.meshfree_spheric2:  # the child run under pvpython
        meshfree_spheric2_child(a.meshfree_spheric2, a.dx, a.time)
        return 0
    t2 = a.scene == "spheric2"
    boundaries = a.boundary or ["akinci"]
    if not a.simulator:
        sys.exit("bench_splishsplash.py: --simulator is required")
    for exe in (a.simulator,) + ((shutil.which(a.pvpython) or a.pvpython,) if t2 else (a.bench_sph,)):
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
            sys.exit("bench_splishsplash.py: %s is not an executable" % exe)
    if t2 and not os.path.exists(os.environ.get("MESHFREE_PLUGIN", "")):
        sys.exit("bench_splishsplash.py: set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
    env = dict(os.environ)
    threads = a.threads or os.cpu_count()
    env["OMP_NUM_THREADS"] = str(threads)
    env["MESHFREE_NUM_THREADS"] = str(threads)
    stamp = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    print("%s; %d CPUs, %d threads; load average %s" % (stamp, os.cpu_count(), threads,
                                                      " ".join("%.2f" % x for x in os.getloadavg())), flush=True)
    rows = []
    work = tempfile.mkdtemp(prefix="bench_splishsplash_")
    try:
        for solver in [s for s in a.solvers.split(",") if s]:
            if t2:
                rows.append(run_meshfree_spheric2(a.pvpython, solver.upper(), a.dx, a.time, env))
            else:
                rows.append(run_meshfree(a.bench_sph, solver, a.size, a.time, env))
            print(json.dumps(rows[-1]), flush=True)
        for boundary in boundaries:
            for policy in a.omp_wait_policy or ["default"]:
                splish_env = dict(env)
                if policy != "default":
                    splish_env["OMP_WAIT_POLICY"] = policy.upper()
                rows.append(run_splishsplash(a.simulator, a.size, a.time, boundary, splish_env, work,
                                             a.dx if t2 else None))
                if policy != "default":
                    rows[-1]["code"] = rows[-1]["code"][:-1] + ", OMP_WAIT_POLICY=%s)" % policy.upper()
                print(json.dumps({k: v for k, v in rows[-1].items() if k != "scene"}), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    head = "| code | particles (fluid + boundary) | steps | simulated s | wall s | CPU s | wall s / sim s | " \
           "sim s / wall s | iterations/step (density / divergence) | load 1-min before / after |"
    lines = [head, "|" + "---|" * 10]
    for r in rows:
        if r.get("wall_s") and r.get("sim_s"):
            cpu = r.get("cpu_s")
            if cpu is None and r.get("process_cpu_s") is not None:
                cpu_text = "(%.0f)" % r["process_cpu_s"]  # the whole process, loading included
            else:
                cpu_text = "%.1f" % cpu if cpu is not None else "-"
            parts = "%s" % r.get("particles")
            if r.get("boundary_particles"):
                parts += " + %d" % r["boundary_particles"]
            lines.append("| %s | %s | %s | %.4f | %.1f | %s | %.1f | %.5f | %s | %.2f / %.2f |" % (
                r["code"], parts, r.get("steps"), r["sim_s"], r["wall_s"], cpu_text, r["wall_s"] / r["sim_s"],
                r["sim_s"] / r["wall_s"], r.get("iterations", "-"), r["load_before"], r["load_after"]))
        else:
            lines.append("| %s | failed (rc %s): see the JSON | | | | | | | | |" % (r["code"], r.get("rc")))
    table = "\n".join(lines)
    print(table)
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        with open(os.path.join(a.out, "splishsplash.md"), "a") as f:
            what = ("SPHERIC Test 2 at dx = %g m" % a.dx) if t2 else ("%d particles" % a.size)
            f.write("\n## %s, %s, %g s simulated, %d threads%s\n\n" % (
                stamp, what, a.time, threads, (": " + a.label) if a.label else ""))
            f.write("Command: `/usr/bin/python3 Testing/Benchmarks/bench_splishsplash.py --simulator SPHSimulator "
                    "%s--time %g --solvers %s%s%s`\n\n" % (
                        ("--scene spheric2 --dx %g " % a.dx) if t2 else ("--size %d " % a.size), a.time, a.solvers,
                        "".join(" --boundary " + b for b in boundaries),
                        "".join(" --omp-wait-policy " + w for w in a.omp_wait_policy or [])))
            f.write(table + "\n")
        jpath = os.path.join(a.out, "splishsplash.json")
        old = []
        if os.path.exists(jpath):
            with open(jpath) as f:
                old = json.load(f)
        old.append(dict(stamp=stamp, scene=a.scene, dx=a.dx if t2 else None, size=None if t2 else a.size,
                        time=a.time, threads=threads, label=a.label, runs=rows))
        with open(jpath, "w") as f:
            json.dump(old, f, indent=1)
    return 0 if all(r.get("wall_s") for r in rows) else 1

if __name__ == "__main__":
    sys.exit(main())
