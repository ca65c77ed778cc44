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

Set-up (once; nothing is downloaded, the five git directories are local copies, e.g. from a mirror):
  Testing/Benchmarks/setup_splishsplash.sh --sph SPlisHSPlasH.git --compactnsearch CompactNSearch.git \
      --discregrid Discregrid.git --genericparameters GenericParameters.git --pbd PositionBasedDynamics.git \
      --commit 80b7284 --build SOMEWHERE
Run (from the repository root, after building BenchSPH):
  /usr/bin/python3 Testing/Benchmarks/bench_splishsplash.py --simulator PATH/TO/SPHSimulator --time 1.0 \\
      --out Testing/Benchmarks/results
Writes OUT/splishsplash.md (the table, appended as a new section) and OUT/splishsplash.json (all runs, appended).
"""
import argparse
import json
import os
import re
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
        "RigidBodies": [
            {
                "geometryFile": box_obj,
                "translation": list(centre),
                "rotationAxis": [1, 0, 0],
                "rotationAngle": 0,
                "scale": list(tank),
                "isDynamic": False,
                "isWall": True,
                "mapInvert": True,
                "mapThickness": 0.0,
                "mapResolution": [int(round(t / (2.0 * DX))) for t in tank],  # a cell per support radius
                "samplingMode": 1,
            }
        ],
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


def run_splishsplash(simulator, size, end, boundary, env, work):
    models = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(simulator))), "data", "models")
    box = os.path.join(models, "UnitBox.obj")
    if not os.path.exists(box):
        return dict(code="SPlisHSPlasH DFSPH", rc=-1, error="no %s (SPlisHSPlasH's data/models)" % box)
    path = os.path.join(work, "dambreak_%d.json" % size)
    with open(path, "w") as f:
        json.dump(scene(size, end, boundary, box), f, indent=1)
    outdir = os.path.join(work, "output")
    cmd = [simulator, "--no-gui", "--no-cache", "--no-initial-pause", "--output-dir", outdir, "--stopAt", repr(end),
           path]
    rc, out, wall, l0, l1 = run(cmd, env=env, cwd=work)
    row = dict(code="SPlisHSPlasH DFSPH (%s)" % boundary, rc=rc, process_wall_s=wall, load_before=l0,
               load_after=l1, command="SPHSimulator --no-gui --no-cache --no-initial-pause --output-dir OUT "
               "--stopAt %r dambreak_%d.json" % (end, size), scene=scene(size, end, boundary, "UnitBox.obj"))

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
    ap.add_argument("--simulator", required=True, help="SPlisHSPlasH's SPHSimulator (setup_splishsplash.sh)")
    ap.add_argument("--bench-sph", default=os.path.join(ROOT, "build", "bin", "BenchSPH"))
    ap.add_argument("--size", type=int, default=65536, choices=sorted(BLOCKS))
    ap.add_argument("--time", type=float, default=1.0, help="simulated seconds (default 1)")
    ap.add_argument("--boundary", choices=("akinci", "volume-maps"), action="append",
                    help="SPlisHSPlasH boundary model(s) (default: akinci)")
    ap.add_argument("--solvers", default="wcsph,dfsph", help="MeshFree solvers to run (default wcsph,dfsph)")
    ap.add_argument("--threads", type=int, default=0, help="OMP_NUM_THREADS for all runs (default: all CPUs)")
    ap.add_argument("--out", default=None, help="folder for splishsplash.md / .json (default: print only)")
    ap.add_argument("--label", default="", help="a note for the results section")
    a = ap.parse_args()
    boundaries = a.boundary or ["akinci"]
    for exe in (a.simulator, a.bench_sph):
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
            sys.exit("bench_splishsplash.py: %s is not an executable" % exe)
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
            rows.append(run_meshfree(a.bench_sph, solver, a.size, a.time, env))
            print(json.dumps(rows[-1]), flush=True)
        for boundary in boundaries:
            rows.append(run_splishsplash(a.simulator, a.size, a.time, boundary, env, work))
            print(json.dumps({k: v for k, v in rows[-1].items() if k != "scene"}), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    head = "| code | particles | steps | simulated s | wall s | wall s / sim s | sim s / wall s | " \
           "iterations/step (density / divergence) | load 1-min before / after |"
    lines = [head, "|" + "---|" * 9]
    for r in rows:
        if r.get("wall_s") and r.get("sim_s"):
            lines.append("| %s | %s | %s | %.4f | %.1f | %.1f | %.5f | %s | %.2f / %.2f |" % (
                r["code"], r.get("particles"), r.get("steps"), r["sim_s"], r["wall_s"], r["wall_s"] / r["sim_s"],
                r["sim_s"] / r["wall_s"], r.get("iterations", "-"), r["load_before"], r["load_after"]))
        else:
            lines.append("| %s | failed (rc %s): see the JSON | | | | | | | |" % (r["code"], r.get("rc")))
    table = "\n".join(lines)
    print(table)
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        with open(os.path.join(a.out, "splishsplash.md"), "a") as f:
            f.write("\n## %s, %d particles, %g s simulated, %d threads%s\n\n" % (
                stamp, a.size, a.time, threads, (": " + a.label) if a.label else ""))
            f.write("Command: `/usr/bin/python3 Testing/Benchmarks/bench_splishsplash.py --simulator SPHSimulator "
                    "--size %d --time %g%s`\n\n" % (a.size, a.time,
                                                    "".join(" --boundary " + b for b in boundaries)))
            f.write(table + "\n")
        jpath = os.path.join(a.out, "splishsplash.json")
        old = []
        if os.path.exists(jpath):
            with open(jpath) as f:
                old = json.load(f)
        old.append(dict(stamp=stamp, size=a.size, time=a.time, threads=threads, label=a.label, runs=rows))
        with open(jpath, "w") as f:
            json.dump(old, f, indent=1)
    return 0 if all(r.get("wall_s") for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
