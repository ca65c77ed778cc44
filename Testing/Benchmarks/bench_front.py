"""The timing of the SPHERIC Test 2 dam break (without its box) against the experiment and beside SPlisHSPlasH.

Why this exists (issue 25): on Test 2 the P1 impact comes 35-45 ms late in MeshFree's runs, because the water's
leading edge reaches the box late. This script separates what can cause that:
  * the reservoir's drainage: H4 (x = 2.638 m, in the reservoir, 0.65 m behind the gate) falls as the column
    collapses, independently of how the thin front tip is resolved; its lag behind the experiment is a lag of the
    whole flow (or of the experiment's time origin), not of the tip;
  * the flow's arrival at the gauge at x = 1.488 m (0.5 m from the gate) and at H2 (x = 0.992 m, 1 m from it), at
    depths of 1, 2 and 4 cm, and the tip's arrival at the box face (x = 0.8245 m) against the experiment's P1 arrival;
  * the same scene in SPlisHSPlasH (--simulator; built by setup_splishsplash.sh, see bench_splishsplash.py): DFSPH,
    its Akinci 2012 boundary particles (the closest to MeshFree's dummy particles), particleRadius dx / 2 (support
    2 dx), the same tolerances and step rule, exported every 25 ms (VTK), its front and gauges measured alike.
MeshFree runs through build/bin/BenchSPHFront (its header describes the scene, the front and the gauges).

Experiment (MARIN, Kleefsman et al. 2005; the SPHERIC Test 2 file as archived in github.com/vamseeachanta/
digitalmodel, docs/api/cfd/cases/kleefsman_impact/kleefsman_exp_data.csv, commit 665d901, 1 kHz): the samples below
were read from it by hand. Its column labelled H1 is wet from t = 0.185 s, long before the water can pass the box, and
its H3 column stays dry while H2 fills: the file's H1 column is the gauge at x = 1.488 m (0.5 m from the gate) and
its H3 the one at x = 0.496 m, behind the box (the positions in spheric_test2.py are those of the file's H3, H2, H1,
H4 columns in that order); bench_spheric2.py compares H2 and H4 only, which this does not touch. H4 starts at
0.5467 m (not 0.55) and oscillates by +-4 mm with a period of about 25 ms over the first 0.1 s: the reservoir's drop is
taken from its value at t = 0 and its early crossings are uncertain by about 10 ms.

Usage (from the repository root, after building BenchSPHFront):
  /usr/bin/python3 Testing/Benchmarks/bench_front.py --dim 2 --dx 0.02 0.01 0.005 [--solvers dfsph wcsph] \\
      [--simulator PATH/TO/SPHSimulator] [--end 0.45] [--out DIR]
  /usr/bin/python3 Testing/Benchmarks/bench_front.py --from FILE ...   (series written before by --out)
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
TANK_X, GATE_X, BOX_FACE_X = 3.22, 1.992, 0.8245
GAUGES = (0.992, 1.488, 2.638)  # H2, the gauge 0.5 m from the gate, H4

# (t [s], depth [m]) read from the experiment's file (see the docstring).
EXP_H4 = [(0.000, 0.5467), (0.010, 0.5507), (0.020, 0.5427), (0.030, 0.5490), (0.040, 0.5411), (0.050, 0.5417),
          (0.060, 0.5419), (0.070, 0.5372), (0.080, 0.5395), (0.090, 0.5353), (0.100, 0.5336), (0.110, 0.5331),
          (0.120, 0.5269), (0.130, 0.5287), (0.140, 0.5241), (0.150, 0.5223), (0.160, 0.5221), (0.170, 0.5154),
          (0.180, 0.5167), (0.190, 0.5129), (0.200, 0.5110), (0.210, 0.5094), (0.220, 0.5079), (0.230, 0.5047),
          (0.240, 0.5033), (0.354, 0.4710), (0.360, 0.4719), (0.370, 0.4671), (0.380, 0.4654), (0.390, 0.4629),
          (0.400, 0.4595), (0.410, 0.4563), (0.420, 0.4541), (0.430, 0.4490)]
EXP_G05 = [(0.180, 0.00067), (0.184, 0.00073), (0.185, 0.0014), (0.186, 0.0023), (0.187, 0.0031), (0.188, 0.0039),
           (0.190, 0.0053), (0.192, 0.0071), (0.194, 0.0103), (0.196, 0.0125), (0.198, 0.0139), (0.200, 0.0145),
           (0.205, 0.0159), (0.210, 0.0161), (0.215, 0.0173), (0.218, 0.0201), (0.220, 0.0241), (0.222, 0.0293),
           (0.225, 0.0333), (0.228, 0.0373), (0.230, 0.0394), (0.235, 0.0410), (0.240, 0.0426), (0.244, 0.0456)]
EXP_H2 = [(0.350, 0.0009), (0.353, 0.0049), (0.354, 0.0061), (0.358, 0.0101), (0.362, 0.0150), (0.365, 0.0179),
          (0.370, 0.0240), (0.375, 0.0311), (0.380, 0.0353), (0.385, 0.0371), (0.390, 0.0395), (0.395, 0.0423),
          (0.400, 0.0464), (0.405, 0.0499), (0.410, 0.0529), (0.415, 0.0557), (0.420, 0.0577), (0.425, 0.0600),
          (0.430, 0.0621)]
EXP_P1_ARRIVAL = 0.3945  # P1 first above 25 % of its peak (between the 1868 and 3675 Pa samples)


def first_cross(t, y, level, rising=True):
    for k in range(1, len(t)):
        a, b = y[k - 1], y[k]
        if (rising and a < level <= b) or (not rising and a > level >= b):
            return t[k - 1] + (t[k] - t[k - 1]) * (level - a) / (b - a)
    return float("nan")


def h4_shift(t, h4, t0=0.08, t1=0.39):
    """Least-squares time shift s of the simulated reservoir drop (H4 below its start) against the experiment's,
    over the experiment's samples in [t0, t1] (the simulation at t + s against the experiment at t); with the RMS
    misfit at that shift and unshifted. None when the series ends before t1 + 0.05."""
    et, eh = np.array(EXP_H4).T
    m = (et >= t0) & (et <= t1)
    if t[-1] < t1 + 0.05:
        return None
    target = eh[0] - eh[m]
    best = None
    for s in np.arange(-0.03, 0.06, 0.0005):
        err = float(np.sqrt(np.mean((h4[0] - np.interp(et[m] + s, t, h4) - target) ** 2)))
        if best is None or err < best[1]:
            best = (float(s), err)
    unshifted = float(np.sqrt(np.mean((h4[0] - np.interp(et[m], t, h4) - target) ** 2)))
    return best[0], best[1], unshifted


def lags(series):
    """The experiment's and the simulation's crossing times (s) of every event, from a series (dict of arrays: t,
    front_x, g2, g05, h4, t = 0 included)."""
    t, front, g2, g05, h4 = (series[k] for k in ("t", "front_x", "g2", "g05", "h4"))
    out = []
    et, eh = np.array(EXP_H4).T
    for drop in (0.020, 0.040, 0.075, 0.085):
        out.append(("H4 %d mm below its start" % round(drop * 1000), first_cross(et, eh[0] - eh, drop),
                    first_cross(t, h4[0] - h4, drop)))
    for name, exp, sim in (("x = 1.488 m (0.5 m from the gate)", EXP_G05, g05), ("H2, x = 0.992 m", EXP_H2, g2)):
        ex, ev = np.array(exp).T
        for level in (0.01, 0.02, 0.04):
            out.append(("%s %d cm deep" % (name, round(level * 100)), first_cross(ex, ev, level),
                        first_cross(t, sim, level)))
    out.append(("tip at the box face (experiment: P1 arrival)", EXP_P1_ARRIVAL,
                first_cross(t, -front, -BOX_FACE_X)))
    return out


def run_meshfree(bench, dim, dx, solver, end, every):
    cmd = [bench, "--dim", str(dim), "--dx", repr(dx), "--solver", solver, "--end", repr(end), "--every", repr(every)]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("bench_front.py: %s failed:\n%s" % (" ".join(cmd), p.stdout[-2000:]))
    rows = [[float(v) for v in line.split()] for line in p.stdout.splitlines() if line and not line.startswith("#")]
    head = p.stdout.splitlines()[0]
    a = np.array(rows)  # the first row is the initial state
    series = {"t": a[:, 0], "front_x": a[:, 1], "g2": a[:, 3], "g05": a[:, 4], "h4": a[:, 5]}
    return "MeshFree %s %dD dx=%g" % (solver.upper(), dim, dx), series, head


def splish_scene(dim, dx, end):
    """SPlisHSPlasH's JSON scene of the same dam break (its doc/file_format.md): DFSPH, Akinci boundary particles,
    the tank as an inverted static box whose faces lie half a spacing outside (where MeshFree's first dummies are),
    the column on the same lattice (the block widened by half a spacing on each side), exported every 25 ms."""
    half = 0.5 * dx
    length = round(1.228 / dx) * dx
    height = max(1, int(np.floor(0.55 / dx + 0.5))) * dx
    dfsph = {"minIterations": 2, "maxIterations": 100, "maxError": 0.01, "maxIterationsV": 100, "maxErrorV": 0.1,
             "enableDivergenceSolver": True}
    up = 2 if dim == 3 else 1
    g = [0.0, 0.0, 0.0]
    g[up] = -9.81
    box_scale = [TANK_X + dx, 1.0 + dx, 1.0 + dx] if dim == 3 else [TANK_X + dx, 1.0 + dx, 1.0]
    box_centre = [0.5 * TANK_X, 0.5, 0.5] if dim == 3 else [0.5 * TANK_X, 0.5, 0.0]
    start = [TANK_X - length - half, -half, -half] if dim == 3 else [TANK_X - length - half, -half, -1.0]
    stop = [TANK_X + half, 1.0 + half, height + half] if dim == 3 else [TANK_X + half, height + half, 1.0]
    return {
        "Configuration": {"pause": False, "stopAt": end, "sim2D": dim == 2, "particleRadius": half,
                          "simulationMethod": 4, "gravitation": g, "timeStepSize": 0.001, "cflMethod": 1,
                          "cflFactor": 0.5, "cflMaxTimeStepSize": 0.001, "boundaryHandlingMethod": 0,
                          "enablePartioExport": False, "enableVTKExport": True, "dataExportFPS": 40,
                          "particleAttributes": "velocity", "enableStateExport": False, **dfsph,
                          "DFSPH": dict(dfsph)},
        "Materials": [{"id": "Fluid", "density0": 1000.0, "viscosityMethod": 1, "viscosity": 1e-6,
                       "Standard viscosity": {"viscosity": 1e-6}}],
        "RigidBodies": [{"geometryFile": "UnitBox.obj", "translation": box_centre, "rotationAxis": [1, 0, 0],
                         "rotationAngle": 0, "scale": box_scale, "isDynamic": False, "isWall": True,
                         "mapInvert": True, "mapThickness": 0.0,
                         "mapResolution": [max(4, int(round(s / (2.0 * dx)))) for s in box_scale],
                         "samplingMode": 1}],
        "FluidBlocks": [{"denseMode": 0, "start": start, "end": stop, "translation": [0, 0, 0], "scale": [1, 1, 1]}],
    }, height


def read_vtk_points(path):
    data = open(path, "rb").read()
    m = re.search(rb"POINTS (\d+) float\n", data)
    n = int(m.group(1))
    return np.frombuffer(data[m.end():m.end() + 12 * n], dtype=">f4").reshape(n, 3).astype(float)


def measure(x, dx, dim):
    """Front and gauges of one particle set, as BenchSPHFront measures them."""
    from scipy.spatial import cKDTree
    up = 2 if dim == 3 else 1
    counts = np.array([len(v) - 1 for v in cKDTree(x).query_ball_point(x, 2.0 * dx * (1.0 - 1e-12))])
    floor = (x[:, up] < 2.0 * dx) & (counts >= 3)
    front = x[floor, 0].min() - 0.5 * dx if floor.any() else float("nan")
    depths = []
    for gx in GAUGES:
        w = np.clip(1.0 - np.abs(x[:, 0] - gx) / (2.0 * dx), 0.0, None)
        if dim == 3:
            w = w * np.clip(1.0 - np.abs(x[:, 1] - 0.5) / (2.0 * dx), 0.0, None)
        depths.append(float(w.sum()) * dx / (4.0 if dim == 3 else 2.0))
    return front, depths


def run_splishsplash(simulator, dim, dx, end):
    models = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(simulator))), "data", "models")
    work = tempfile.mkdtemp(prefix="bench_front_")
    scene, _ = splish_scene(dim, dx, end)
    scene["RigidBodies"][0]["geometryFile"] = os.path.join(models, "UnitBox.obj")
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    out = os.path.join(work, "output")
    p = subprocess.run([simulator, "--no-gui", "--no-cache", "--no-initial-pause", "--output-dir", out, path],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    vtk = os.path.join(out, "vtk")
    if p.returncode != 0 or not os.path.isdir(vtk):
        sys.exit("bench_front.py: SPlisHSPlasH failed:\n" + p.stdout[-2000:])
    frames = sorted(os.listdir(vtk), key=lambda f: int(re.findall(r"_(\d+)\.vtk", f)[0]))
    rows = []
    for name in frames:
        k = int(re.findall(r"_(\d+)\.vtk", name)[0])
        front, depths = measure(read_vtk_points(os.path.join(vtk, name)), dx, dim)
        rows.append([(k - 1) / 40.0, front] + depths)  # frame 1 is the initial state, then every 1/40 s
    a = np.array(rows)
    series = {"t": a[:, 0], "front_x": a[:, 1], "g2": a[:, 2], "g05": a[:, 3], "h4": a[:, 4]}
    return "SPlisHSPlasH DFSPH (Akinci) %dD dx=%g" % (dim, dx), series, "work folder " + work


def report(results):
    lines = []
    names = [r[0] for r in results]
    table = [r[1] for r in results]
    header = "| event | experiment (s) | " + " | ".join(names) + " |"
    lines += [header, "|" + "---|" * (2 + len(names))]
    events = lags(table[0])
    for k, (label, te, _) in enumerate(events):
        cells = []
        for series in table:
            ts = lags(series)[k][2]
            cells.append("%.3f (%+.0f ms)" % (ts, 1000 * (ts - te)) if np.isfinite(ts) else "-")
        lines.append("| %s | %.3f | %s |" % (label, te, " | ".join(cells)))
    cells = []
    for series in table:
        s = h4_shift(series["t"], series["h4"])
        cells.append("%+.1f ms (RMS %.1f mm; %.1f unshifted)" % (1000 * s[0], 1000 * s[1], 1000 * s[2]) if s else "-")
    lines.append("| H4 drop: least-squares lag over 0.08-0.39 s | 0 | %s |" % " | ".join(cells))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dim", type=int, default=2, choices=(2, 3))
    ap.add_argument("--dx", type=float, nargs="+", default=[0.01])
    ap.add_argument("--solvers", nargs="+", default=["dfsph"], choices=("dfsph", "wcsph"))
    ap.add_argument("--end", type=float, default=0.45)
    ap.add_argument("--every", type=float, default=0.005)
    ap.add_argument("--simulator", help="SPlisHSPlasH's SPHSimulator: the same scenes with it too")
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "bin", "BenchSPHFront"))
    ap.add_argument("--out", help="folder for the series (JSON) and the table (front.md)")
    ap.add_argument("--from", dest="from_files", nargs="+", help="series written by --out: no simulation")
    a = ap.parse_args()
    results = []
    if a.from_files:
        for path in a.from_files:
            d = json.load(open(path))
            results.append((d["name"], {k: np.array(v) for k, v in d["series"].items()}))
    else:
        for dx in a.dx:
            for solver in a.solvers:
                name, series, head = run_meshfree(a.bench, a.dim, dx, solver, a.end, a.every)
                print(head, flush=True)
                results.append((name, series))
            if a.simulator:
                name, series, note = run_splishsplash(a.simulator, a.dim, dx, a.end)
                print(name, note, flush=True)
                results.append((name, series))
    table = report(results)
    print(table)
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        for name, series in results:
            tag = re.sub(r"[^A-Za-z0-9.]+", "_", name)
            with open(os.path.join(a.out, "front_%s.json" % tag), "w") as f:
                json.dump({"name": name, "series": {k: v.tolist() for k, v in series.items()}}, f)
        with open(os.path.join(a.out, "front.md"), "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
