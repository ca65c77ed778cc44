"""Surface-reconstruction benchmark (issue 13): MeshFree's MeshlessSurface and MeshlessNormals beside VTK, Open3D
and PCL on seeded analytic clouds, every output scored against the exact surface.

    pvpython --no-mpi Testing/Benchmarks/bench_surface.py [--quick] [--sizes 100000 1000000] [--out DIR]
        [--work DIR] [--only REGEX] [--peers meshfree,vtk,open3d,pcl] [--reps N] [--merge] [--list] [--no-render]
        [--set-env NAME=VALUE] [--render-only] [--report-only] [--require-meshfree]
    /usr/bin/python3 Testing/Benchmarks/bench_surface.py --peers vtk,open3d,pcl ...    (the peers alone)

The driver needs numpy, scipy and VTK's Python modules (pvpython, or Debian's python3 with python3-paraview).
Writes DIR/surface.csv (one row per case and peer), DIR/surface.md (tables) and, unless --no-render, one picture
per cloud of MeshFree's mesh (DIR/surface_<cloud>.png, 400 x 300, coloured by the signed distance to the true
surface; rendered by pvpython, under xvfb-run when there is no display). DIR defaults to
<build>/benchmark-results; the committed results are Testing/Benchmarks/results (--out there).
With --merge the rows of an earlier DIR/surface.csv that this run does not redo are kept (runs of different
sizes or peers add up; DIR/surface_runs.json lists the runs behind the tables).
The clouds and every tool's output go to --work (default $TMPDIR/meshfree-bench-surface; clouds are kept and
reused between runs).

Clouds (surface_clouds.py): sphere and torus (R = 1, r = 0.35), N points uniform by area for each N of --sizes
(default 100,000 and 1,000,000; --quick: 20,000), Gaussian noise sigma = 0 and 0.005 per axis, exact normals;
SPH particles (jittered cubic lattice, spacing H known): a ball and a resting block 2 x 1 x 0.5 of ~N particles
(--quick: 50,000).

Cases, each in its own process through /usr/bin/time -v (wall seconds, peak resident memory); the environment is
the caller's without any OMP_* variable (every tool on its default threads), plus VTK_SMP_BACKEND_IN_USE=
STDThread unless set, plus --set-env's (e.g. OMP_WAIT_POLICY=passive: on a busy 2-core machine OpenMP's spinning
barriers slow Open3D several-fold); the 1-minute load average is recorded before every run:
  normals   positions only -> oriented normals: MeshFree MeshlessNormals (ComputeCurvature 0, as the peers, and
            its default with Curvature); VTK vtkPCANormalEstimation k 20 +
            GRAPH_TRAVERSAL; Open3D PCA k 20 + orient_normals_consistent_tangent_plane; PCL pcl_normal_estimation
            k 20 (oriented towards the viewpoint only)
  smooth    noisy clouds, points moved onto the surface: MeshFree MeshlessNormals ProjectPoints=1; PCL
            pcl_mls_smoothing, radius 3 h (h = mean spacing sqrt(area / N)), order 2
  mesh+N    mesh from points with exact normals: MeshFree MeshlessSurface MLS and WLS; Open3D Poisson; PCL
            pcl_poisson_reconstruction (depth 8 up to 200k points, 9 above)
  mesh      mesh from positions only: MeshFree MeshlessSurface MLS and WLS; VTK vtkSurfaceReconstructionFilter
            (Hoppe) + flying edges at 0 (up to 200k points: 40-60 s per 100k); Open3D PCA + MST + Poisson
  sph       SPH particles: MeshFree MeshlessSurface SPH; VTK vtkSPHInterpolator colour field on a dense image of
            cell H/2 + vtkFlyingEdges3D at 0.5
MeshFree's filters keep their defaults (NeighborCount 20, SupportRadius and CellSize automatic) except Method and
ProjectPoints. Each case runs --reps times (default 3; once when the first run took more than --max-rep-s = 30 s)
and reports medians; the last run's output is scored (surface_score.py). --quick: 20k points, MeshFree and VTK
only (VTK's Hoppe on one cloud), one run each, MeshFree's cases in one pvpython process (the plugin loads once;
their wall time is then the runner's read + Update() + write): a smoke test of the program, not a measurement.
--require-meshfree fails at once (exit 1) when the plugin or its MeshlessSurface and MeshlessNormals proxies are
missing; without it MeshFree's rows say "not available".

surface.csv columns:
  case            group|peer|cloud (what --only matches, with the short key)
  key             short name of the peer's setting; group, peer, tool (meshfree, vtk, open3d, pcl), settings
  cloud, shape, n, sigma   the input (n = points or particles)
  status          ok, not available (the peer or proxy is missing: no numbers), failed (message in note)
  reps            timed runs behind the medians
  wall_s          median wall time of the whole process (start-up, reading, the algorithm, writing)
  algo_s          median of the tool's own time for the algorithm without file input/output: MeshFree: the
                  filter's Update(); VTK: its algorithms' Update(); Open3D: the calls; PCL: the times the tools
                  print (lines other than loading and saving)
  peak_mb         median peak resident memory of the process (MiB)
  algo_mb         median memory the algorithm took on top of its input (MiB): peak resident memory at its end
                  less resident memory at its start (surface_memory.py); not PCL (its tools read and write)
  cpu_pct         median CPU use of the process (100 = one core busy the whole time)
  load1           median 1-minute load average before the runs (the machine is shared: read times with it)
  rms, max, p99, bias     distances of the mesh vertices (mesh groups) or points (smooth) to the true surface;
                  bias = mean signed distance (positive outside)
  cov_mean, cov_max       distance from a dense true sample (200,000 points) to the nearest mesh vertex
  triangles, vertices, boundary_edges, nonmanifold_edges, euler (chi: 2 closed sphere or ball, 0 torus),
  components, watertight, nan_vertices    mesh topology after welding coincident vertices
  volume, volume_ref, volume_err   enclosed volume (divergence theorem), the reference (analytic volume; for SPH
                  the particles' volume N H^3) and (|volume| - volume_ref) / volume_ref
  ref_radius      SPH ball: radius of the volume-equivalent sphere, the reference surface
  mesh_normal_angle, mesh_normal_outward  the mesh's Normals array against the exact normals (degrees, share)
  ang_mean, ang_p95, consistent, outward  estimated normals: angle to the exact normal line (degrees), share on
                  the majority side (1 = consistently oriented), share pointing outward
  command         the timed command (WORK = the work folder); note: failures, batching
  run             when the run that measured the row started (its "id" in surface_runs.json)
"""
import argparse
import csv
import datetime
import json
import math
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bench_machine  # noqa: E402

PLUGIN_REL = os.path.join("lib", "paraview-5.11", "plugins", "MeshFree", "MeshFree.so")
TOOLS = ("meshfree", "vtk", "open3d", "pcl")
PCL_TOOLS = ("pcl_normal_estimation", "pcl_mls_smoothing", "pcl_poisson_reconstruction")

COLUMNS = ["case", "key", "group", "peer", "tool", "settings", "cloud", "shape", "n", "sigma", "status", "reps",
           "wall_s", "algo_s", "peak_mb", "algo_mb", "cpu_pct", "load1", "rms", "max", "p99", "bias", "cov_mean",
           "cov_max", "triangles", "vertices", "boundary_edges", "nonmanifold_edges", "euler", "components", "watertight",
           "nan_vertices", "volume", "volume_ref", "volume_err", "ref_radius", "mesh_normal_angle",
           "mesh_normal_outward", "ang_mean", "ang_p95", "consistent", "outward", "command", "note", "run"]
GROUPS = [("mesh+N", "Meshes from points with exact normals"), ("mesh", "Meshes from positions only"),
          ("sph", "SPH fluid surfaces"), ("normals", "Normals from positions only (estimated and oriented)"),
          ("smooth", "Points moved onto the surface (noisy clouds)")]


def log(*args):
    print(*args, flush=True)


def loadavg():
    try:
        return os.getloadavg()
    except OSError:
        return (float("nan"),) * 3


# ---------------------------------------------------------------------------------------------- peers
def _imports(python, module):
    try:
        return subprocess.run([python, "-c", "import %s" % module], capture_output=True, timeout=120).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def _python_with(module):
    for python in ("/usr/bin/python3", sys.executable):
        if python and os.path.exists(python) and _imports(python, module):
            return python
    return None


def find_plugin():
    path = os.environ.get("MESHFREE_PLUGIN")
    if path:
        return path
    return os.path.join(SOURCE, "build", PLUGIN_REL)


def find_peers(wanted, env):
    """Which peers exist here, with the interpreter or programs they run with; nothing is installed."""
    found, notes = {}, {}
    if "vtk" in wanted:
        python = _python_with("vtkmodules.vtkFiltersPoints")
        if python:
            found["vtk"] = dict(python=python)
        else:
            notes["vtk"] = "no Python with vtkmodules.vtkFiltersPoints"
    if "open3d" in wanted:
        python = _python_with("open3d")
        if python:
            found["open3d"] = dict(python=python)
        else:
            notes["open3d"] = "no Python with open3d (Debian: python3-open3d, /usr/bin/python3)"
    if "pcl" in wanted:
        progs = {t: shutil.which(t) for t in PCL_TOOLS}
        if all(progs.values()):
            found["pcl"] = progs
        else:
            notes["pcl"] = "missing " + ", ".join(t for t, p in progs.items() if not p)
    if "meshfree" in wanted:
        pvpython = shutil.which("pvpython")
        plugin = find_plugin()
        if not pvpython:
            notes["meshfree"] = "pvpython not found"
        elif not os.path.exists(plugin):
            notes["meshfree"] = "plugin not found at %s (set MESHFREE_PLUGIN)" % plugin
        else:
            p = subprocess.run([pvpython, "--no-mpi", os.path.join(HERE, "surface_run_meshfree.py"), "probe"],
                               capture_output=True, text=True, env=dict(env, MESHFREE_PLUGIN=plugin), timeout=300)
            probe = _last_json(p.stdout) or {}
            proxies = [name for name in ("MeshlessSurface", "MeshlessNormals") if probe.get(name)]
            if proxies:
                found["meshfree"] = dict(pvpython=pvpython, plugin=plugin, proxies=proxies)
            missing = [name for name in ("MeshlessSurface", "MeshlessNormals") if not probe.get(name)]
            if missing:
                notes["meshfree"] = "%s not available in %s%s" % (
                    " and ".join(missing), plugin, (": " + probe["reason"]) if probe.get("reason") else "")
    return found, notes


def versions(found):
    out = {}
    try:
        from vtkmodules.vtkCommonCore import vtkVersion
        out["vtk"] = "VTK " + vtkVersion.GetVTKVersion()
    except ImportError:
        pass
    if "open3d" in found:
        p = subprocess.run([found["open3d"]["python"], "-c", "import open3d; print(open3d.__version__)"],
                           capture_output=True, text=True)
        out["open3d"] = "Open3D " + p.stdout.strip()
    if "pcl" in found and shutil.which("dpkg-query"):
        p = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "pcl-tools"], capture_output=True, text=True)
        out["pcl"] = "pcl-tools " + (p.stdout.strip() or "?")
    if "meshfree" in found:
        out["meshfree"] = "MeshFree %s (%s)" % (os.path.relpath(found["meshfree"]["plugin"], SOURCE),
                                                 plugin_build(found["meshfree"]["plugin"]))
    return out


def plugin_build(plugin):
    """When the plugin was built and from which commit (with '+' when Filters/ or Plugin/ have local changes)."""
    built = datetime.datetime.fromtimestamp(os.path.getmtime(plugin)).strftime("%Y-%m-%d %H:%M")
    try:
        head = subprocess.run(["git", "-C", SOURCE, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", SOURCE, "status", "--porcelain", "--", "Filters", "Plugin"],
                               capture_output=True, text=True).stdout.strip()
    except OSError:
        head, dirty = "", ""
    return "built %s%s" % (built, (", source %s%s" % (head, "+" if dirty else "")) if head else "")


# ---------------------------------------------------------------------------------------------- cases
def build_cases(clouds, found, cfg, work):
    """Every (group, peer, cloud) of the matrix, for the peers in cfg.peers (found or not)."""
    out_dir = os.path.join(work, "out")
    cases = []
    runner = {t: os.path.join(HERE, "surface_run_%s.py" % t) for t in ("vtk", "open3d", "meshfree")}

    def add(group, key, peer, tool, cloud, kind, settings, cmd=None, job=None, ext="vtp"):
        if tool not in cfg.peers:
            return
        out = os.path.join(out_dir, "%s__%s.%s" % (cloud["name"], key, ext))
        case = dict(id="%s|%s|%s" % (group, peer, cloud["name"]), key=key, group=group, peer=peer, tool=tool,
                    cloud=cloud, kind=kind, settings=settings, out=out)
        if tool == "meshfree":
            job = dict(job, output=out)
            case["job"] = job
            mf = found.get("meshfree", {})
            case["cmd"] = [mf.get("pvpython", "pvpython"), "--no-mpi", runner["meshfree"], job["mode"], job["input"],
                           out] + ["%s=%s" % kv for kv in job.get("properties", {}).items()]
        elif tool == "pcl":  # program, input, output, options
            case["cmd"] = [found.get("pcl", {}).get(cmd[0]) or cmd[0], cmd[1], out] + cmd[2:]
        else:  # our runner: mode, input, output, options
            python = found.get(tool, {}).get("python", "python3")
            case["cmd"] = [python, runner[tool], cmd[0], cmd[1], out] + cmd[2:]
        if cfg.only and not (re.search(cfg.only, case["id"]) or re.search(cfg.only, key)):
            return
        cases.append(case)

    for c in clouds:
        f = {k: c["files"].get(k, "") for k in ("vtp", "xyz_vtp", "ply", "pcd", "xyz_pcd")}  # per peer's needs
        if c["kind"] == "sph":
            add("sph", "mf_sph", "MeshFree MeshlessSurface SPH", "meshfree", c, "mesh", "Method=SPH",
                job=dict(mode="surface", input=f["vtp"], properties=dict(Method="SPH")))
            add("sph", "vtk_sph", "VTK SPHInterpolator colour field H/2 + FlyingEdges 0.5", "vtk", c, "mesh",
                "Wendland quintic, step H, dense grid cell H/2, level 0.5",
                cmd=["sph", f["vtp"], "--spacing", repr(c["spacing"]), "--cell", "0.5", "--level", "0.5"])
            continue
        n, h = c["n"], c["mean_spacing"]
        depth = 8 if n <= 200000 else 9
        # normals
        # What the peers compute (normals and their orientation), then the filter's default (with Curvature).
        add("normals", "mf_normals", "MeshFree MeshlessNormals", "meshfree", c, "normals",
            "ComputeCurvature=0", job=dict(mode="normals", input=f["xyz_vtp"], properties=dict(ComputeCurvature=0)))
        add("normals", "mf_normals_k", "MeshFree MeshlessNormals + Curvature", "meshfree", c, "normals",
            "defaults (ComputeCurvature=1)", job=dict(mode="normals", input=f["xyz_vtp"], properties={}))
        add("normals", "vtk_normals", "VTK PCA k20 + graph traversal", "vtk", c, "normals",
            "vtkPCANormalEstimation SampleSize 20, GRAPH_TRAVERSAL", cmd=["normals", f["xyz_vtp"], "--k", "20"])
        add("normals", "o3d_normals", "Open3D PCA k20 + tangent-plane MST", "open3d", c, "normals",
            "estimate_normals KNN 20 + orient_normals_consistent_tangent_plane(20)",
            cmd=["normals", f["ply"], "--k", "20"], ext="ply")
        add("normals", "pcl_normals", "PCL NormalEstimation k20 (viewpoint)", "pcl", c, "normals", "-k 20",
            cmd=["pcl_normal_estimation", f["xyz_pcd"], "-k", "20"], ext="pcd")
        # smoothing / projection
        if c["sigma"] > 0:
            add("smooth", "mf_project", "MeshFree MeshlessNormals ProjectPoints", "meshfree", c, "points+normals",
                "ProjectPoints=1", job=dict(mode="normals", input=f["xyz_vtp"], properties=dict(ProjectPoints=1)))
            r = 3.0 * h
            add("smooth", "pcl_mls", "PCL MLS r=3h order 2", "pcl", c, "points",
                "-radius %.5f -sqr_gauss_param %.7f -polynomial_order 2" % (r, r * r),
                cmd=["pcl_mls_smoothing", f["xyz_pcd"], "-radius", "%.5f" % r, "-sqr_gauss_param", "%.7f" % (r * r),
                     "-polynomial_order", "2"], ext="pcd")
        # meshes with the exact normals
        for method in ("MLS", "WLS"):
            add("mesh+N", "mf_%s_n" % method.lower(), "MeshFree MeshlessSurface %s" % method, "meshfree", c, "mesh",
                "Method=%s, Normals given" % method,
                job=dict(mode="surface", input=f["vtp"], properties=dict(Method=method)))
        add("mesh+N", "o3d_poisson", "Open3D Poisson d%d" % depth, "open3d", c, "mesh", "depth %d" % depth,
            cmd=["poisson", f["ply"], "--depth", str(depth)], ext="ply")
        add("mesh+N", "pcl_poisson", "PCL Poisson d%d" % depth, "pcl", c, "mesh", "-depth %d" % depth,
            cmd=["pcl_poisson_reconstruction", f["pcd"], "-depth", str(depth)], ext="vtk")
        # meshes from positions only
        for method in ("MLS", "WLS"):
            add("mesh", "mf_%s" % method.lower(), "MeshFree MeshlessSurface %s" % method, "meshfree", c, "mesh",
                "Method=%s, positions only" % method,
                job=dict(mode="surface", input=f["xyz_vtp"], properties=dict(Method=method)))
        if n <= 200000 and (not cfg.quick or (c["shape"] == "torus" and c["sigma"] > 0)):
            add("mesh", "vtk_hoppe", "VTK Hoppe (SurfaceReconstructionFilter) k20", "vtk", c, "mesh",
                "NeighborhoodSize 20, default grid, FlyingEdges at 0", cmd=["hoppe", f["xyz_vtp"], "--k", "20"])
        add("mesh", "o3d_est_poisson", "Open3D PCA k20 + MST + Poisson d%d" % depth, "open3d", c, "mesh",
            "estimate_normals KNN 20 + tangent-plane MST + Poisson depth %d" % depth,
            cmd=["poisson", f["ply"], "--depth", str(depth), "--estimate-normals", "--k", "20"], ext="ply")
    return cases


# ---------------------------------------------------------------------------------------------- running
def _last_json(text):
    for line in reversed(text.strip().splitlines()):
        line = line.strip()
        if line.startswith("{"):
            try:
                return json.loads(line)
            except ValueError:
                continue
    return None


def _pcl_seconds(text):
    """PCL's tools print '[done, 123.4 ms : N points]' or 'in 123.4 ms' per stage: all but loading and saving."""
    clean = re.sub(r"\x1b\[[0-9;]*m", "", text)
    ms = [float(v) for line in clean.splitlines() if "Loading" not in line and "Saving" not in line
          for v in re.findall(r"([0-9.]+) ms", line)]
    return sum(ms) / 1000.0 if ms else None


def run_process(cmd, env, timeout):
    """One run through /usr/bin/time -v: wall seconds, peak RSS (MiB), CPU %, the tool's output."""
    report = tempfile.NamedTemporaryFile(prefix="bench_surface_time", suffix=".txt", delete=False)
    report.close()
    timer = ["/usr/bin/time", "-v", "-o", report.name] if os.path.exists("/usr/bin/time") else []
    t0 = time.perf_counter()
    try:
        p = subprocess.run(timer + cmd, capture_output=True, text=True, env=env, timeout=timeout)
        rc, stdout, stderr = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired as e:
        rc, stdout, stderr = "timeout", e.stdout or "", "timed out after %d s" % timeout
        stdout = stdout.decode() if isinstance(stdout, bytes) else stdout
    wall = time.perf_counter() - t0
    with open(report.name) as f:
        rep = f.read()
    os.unlink(report.name)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", rep)
    cpu = re.search(r"Percent of CPU this job got: (\d+)%", rep)
    return dict(rc=rc, wall_s=wall, peak_mb=int(rss.group(1)) / 1024.0 if rss else None,
                cpu_pct=float(cpu.group(1)) if cpu else None, stdout=stdout, stderr=stderr)


def _failure(run):
    text = (run["stderr"] + "\n" + run["stdout"]).strip().splitlines()
    tail = [l for l in text if l.strip() and "Command exited with non-zero status" not in l][-3:]
    msg = " / ".join(l.strip() for l in tail)[-300:]
    return "exit %s: %s" % (run["rc"], msg.replace("Traceback", "traceback"))


def run_case(case, cfg):
    runs = []
    for _ in range(cfg.reps):
        load = loadavg()[0]
        r = run_process(case["cmd"], cfg.env, cfg.timeout)
        r["load1"] = load
        info = _last_json(r["stdout"]) or {}
        if case["tool"] == "pcl":
            r["algo_s"] = _pcl_seconds(r["stdout"] + "\n" + r["stderr"])
        elif case["tool"] == "meshfree":
            r["algo_s"] = info.get("update_s")
            r["algo_mb"] = info.get("algo_mb")
            if "error" in info:
                r["rc"], r["stderr"] = r["rc"] or 2, info["error"]
        else:
            r["algo_s"] = info.get("algo_s")
            r["algo_mb"] = info.get("algo_mb")
        runs.append(r)
        if r["rc"] != 0 or r["wall_s"] > cfg.max_rep_s:
            break
    return runs


def run_meshfree_batch(cases, cfg):
    """--quick: every MeshFree case in one pvpython process (the plugin loads once); per-case times are the
    runner's read + Update() + write, the memory is the whole process's."""
    jobs = [c["job"] for c in cases]
    spec = os.path.join(cfg.work, "meshfree_jobs.json")
    with open(spec, "w") as f:
        json.dump(jobs, f, indent=1)
    mf = cfg.found["meshfree"]
    load = loadavg()[0]
    r = run_process([mf["pvpython"], "--no-mpi", os.path.join(HERE, "surface_run_meshfree.py"), "jobs", spec],
                    cfg.env, cfg.timeout)
    results = {}
    for line in r["stdout"].splitlines():
        info = _last_json(line)
        if info and "job" in info:
            results[info["job"]] = info
    out = []
    for i, case in enumerate(cases):
        info = results.get(i, {"error": "no result (runner exit %s)" % r["rc"]})
        one = dict(rc=2 if "error" in info else 0, load1=load, peak_mb=r["peak_mb"], cpu_pct=r["cpu_pct"],
                   algo_s=info.get("update_s"), algo_mb=info.get("algo_mb"), stdout="", stderr=info.get("error", ""),
                   wall_s=sum(info.get(k, 0.0) for k in ("read_s", "update_s", "write_s")))
        out.append([one])
    log("  MeshFree batch: %d cases in one process, %.1f s, peak %.0f MB" % (len(cases), r["wall_s"],
                                                                            r["peak_mb"] or -1))
    return out


# ---------------------------------------------------------------------------------------------- scoring
def reference_volume(cloud):
    ref = cloud["reference"]
    if cloud["kind"] == "sph":
        return cloud["particle_volume"]
    if ref["shape"] == "sphere":
        return 4.0 / 3.0 * math.pi * ref["radius"] ** 3
    return 2.0 * math.pi ** 2 * ref["R"] * ref["r"] ** 2


def score_case(case):
    import surface_score
    ref = surface_score.Reference.from_cloud(case["cloud"])
    kind, path = case["kind"], case["out"]
    if kind == "mesh":
        s = surface_score.score_mesh(path, ref)
        vref = reference_volume(case["cloud"])
        s["volume_ref"] = vref
        if "volume" in s:
            s["volume_err"] = (abs(s["volume"]) - vref) / vref
        return s
    if kind == "points+normals":
        s = surface_score.score_points(path, ref)
        s.update({k: v for k, v in surface_score.score_normals(path, ref).items() if k not in ("points",)})
        return s
    return surface_score.score(kind, path, ref)


def make_row(case, runs, status, note=""):
    c = case["cloud"]
    row = {k: None for k in COLUMNS}
    row.update(case=case["id"], key=case["key"], group=case["group"], peer=case["peer"], tool=case["tool"],
               settings=case["settings"], cloud=c["name"], shape=c["shape"], n=c["n"], sigma=c["sigma"],
               status=status, note=note, command=" ".join(case["cmd"]).replace(os.path.dirname(case["out"]) + "/",
                                                                                  "WORK/out/"))
    row["command"] = row["command"].replace(os.path.dirname(c["files"]["vtp"]) + "/", "WORK/").replace(
        HERE + "/", "Testing/Benchmarks/")
    if c["kind"] == "sph" and c["reference"]["shape"] == "sphere":
        row["ref_radius"] = c["reference"]["radius"]
    ok = [r for r in runs if r["rc"] == 0]
    if ok:
        row["reps"] = len(ok)
        for key in ("wall_s", "algo_s", "peak_mb", "algo_mb", "cpu_pct", "load1"):
            values = [r[key] for r in ok if r.get(key) is not None]
            row[key] = statistics.median(values) if values else None
    return row


# ---------------------------------------------------------------------------------------------- output
def _fmt(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return "%.6g" % v
    return str(v)


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([_fmt(r.get(c)) for c in COLUMNS])


def check_csv(path):
    problems = []
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
        header = rows and list(rows[0].keys())
    if header != COLUMNS:
        problems.append("%s: columns differ from %s" % (path, COLUMNS))
    if not any(r["status"] == "ok" for r in rows):
        problems.append("%s: no case ran" % path)
    for r in rows:
        if r["status"] == "ok":
            needed = ["wall_s"] + (["rms", "max", "cov_mean", "euler"] if r["group"] in ("mesh", "mesh+N", "sph")
                                   else ["rms", "max"] if r["group"] == "smooth" else ["ang_mean", "consistent"])
            for k in needed:
                try:
                    if not math.isfinite(float(r[k])):
                        raise ValueError
                except ValueError:
                    problems.append("%s: %s has no finite %s" % (path, r["case"], k))
    return problems


def _num(v, fmt="%.2e"):
    return "—" if v is None else fmt % v


def _wall(r):
    return "—" if r["wall_s"] is None else "%.2f (%d)" % (r["wall_s"], r["reps"] or 0)


def _watertight(r):
    if r.get("watertight") is None:
        return "—"
    extra = []
    if r.get("boundary_edges") or r.get("nonmanifold_edges"):
        extra.append("%d boundary, %d non-manifold edges" % (r["boundary_edges"], r["nonmanifold_edges"]))
    if r.get("nan_vertices"):
        extra.append("%d NaN vertices" % r["nan_vertices"])
    return ("yes" if r["watertight"] else "no") + (" (%s)" % ", ".join(extra) if extra else "")


def read_csv(path):
    """Rows of an earlier surface.csv, with numbers and flags converted back."""
    ints = {"n", "reps", "triangles", "vertices", "boundary_edges", "nonmanifold_edges", "euler", "components",
            "nan_vertices"}
    text = {"case", "key", "group", "peer", "tool", "settings", "cloud", "shape", "status", "command", "note", "run"}
    rows = []
    with open(path, newline="") as f:
        for raw in csv.DictReader(f):
            row = {k: None for k in COLUMNS}
            for k, v in raw.items():
                if k not in row or v in ("", None):
                    continue
                if k in text:
                    row[k] = v
                elif k == "watertight":
                    row[k] = v == "yes"
                else:
                    row[k] = int(float(v)) if k in ints else float(v)
            rows.append(row)
    return rows


def _cloud_order(name):
    kind = 1 if name.startswith("sph_") else 0
    m = re.search(r"_(\d+)([kM]?)(_|$)", name)
    n = int(m.group(1)) * {"": 1, "k": 1000, "M": 1000000}[m.group(2)] if m else 0
    return (kind, n, name)


def _status_cell(r):
    if r is None or r["status"] == "not available":
        return "—"
    return "failed" if r["status"] != "ok" else None


def write_markdown(path, rows, header_lines):
    lines = ["# Surface reconstruction: MeshFree beside VTK, Open3D and PCL (issue 13)", ""] + header_lines + [""]
    clouds = sorted({r["cloud"] for r in rows}, key=_cloud_order)
    for group, title in GROUPS:
        grows = [r for r in rows if r["group"] == group]
        if not grows:
            continue
        gclouds = [c for c in clouds if any(r["cloud"] == c for r in grows)]
        peers = []
        for r in grows:
            if r["peer"] not in peers:
                peers.append(r["peer"])
        mesh = group in ("mesh+N", "mesh", "sph")
        what = ("rms / wall s / watertight" if mesh else "rms / wall s" if group == "smooth" else
                "mean angle ° / wall s / consistent")
        lines += ["## %s" % title, "", "Overview (%s; — = not run or not available):" % what, "",
                  "| peer | " + " | ".join(gclouds) + " |", "|---|" + "---|" * len(gclouds)]
        for peer in peers:
            cells = []
            for cl in gclouds:
                r = next((x for x in grows if x["peer"] == peer and x["cloud"] == cl), None)
                cell = _status_cell(r)
                if cell is None and mesh:
                    cell = "%s / %s / %s" % (_num(r["rms"]), _num(r["wall_s"], "%.2f"),
                                             "yes" if r["watertight"] else "no")
                elif cell is None and group == "smooth":
                    cell = "%s / %s" % (_num(r["rms"]), _num(r["wall_s"], "%.2f"))
                elif cell is None:
                    cell = "%s / %s / %s" % (_num(r["ang_mean"], "%.2f"), _num(r["wall_s"], "%.2f"),
                                             _num(r["consistent"], "%.3f"))
                cells.append(cell)
            lines.append("| %s | %s |" % (peer, " | ".join(cells)))
        lines.append("")
        for cl in gclouds:
            crows = [r for r in grows if r["cloud"] == cl and r["status"] != "not available"]
            if not crows:
                continue
            lines += ["#### %s — %s" % (group, cl), ""]
            if mesh:
                head = ["peer", "wall s (runs)", "algo s", "peak MB", "algo MB", "load", "rms", "max", "bias", "cov mean",
                        "cov max", "triangles", "watertight", "χ", "pieces", "volume err"]
            else:
                head = ["peer", "wall s (runs)", "algo s", "peak MB", "algo MB", "load"] + (
                    ["rms", "max", "p99", "bias"] if group == "smooth" else []) + [
                    "mean angle °", "p95 °", "consistent", "outward"]
            lines += ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
            for r in crows:
                if r["status"] != "ok":
                    lines.append("| %s | %s |" % (r["peer"], r["status"] + (": " + r["note"] if r["note"] else ""))
                                 + " |" * (len(head) - 2))
                    continue
                cells = [r["peer"], _wall(r), _num(r["algo_s"], "%.2f"), _num(r["peak_mb"], "%.0f"),
                         _num(r.get("algo_mb"), "%.0f"), _num(r["load1"], "%.1f")]
                if mesh:
                    cells += [_num(r["rms"]), _num(r["max"]), _num(r["bias"]), _num(r["cov_mean"]),
                              _num(r["cov_max"]), _num(r["triangles"], "%d"), _watertight(r), _num(r["euler"], "%d"),
                              _num(r["components"], "%d"), _num(r["volume_err"], "%+.4f")]
                else:
                    if group == "smooth":
                        cells += [_num(r["rms"]), _num(r["max"]), _num(r["p99"]), _num(r["bias"])]
                    cells += [_num(r["ang_mean"], "%.2f"), _num(r["ang_p95"], "%.2f"), _num(r["consistent"], "%.3f"),
                              _num(r["outward"], "%.3f")]
                lines.append("| " + " | ".join(cells) + " |")
            lines.append("")
    missing = {}
    for r in rows:
        if r["status"] == "not available":
            missing.setdefault(r["note"] or "?", []).append(r)
    if missing:
        lines += ["## Not available", ""]
        for why, rs in missing.items():
            peers = sorted({r["peer"] for r in rs})
            lines.append("- %s (%d cases): %s" % (", ".join(peers), len(rs), why))
        lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines).rstrip() + "\n")


def write_report(out, rows, runs):
    """surface.md from the rows and the runs behind them."""
    header = ["Runs behind these tables (the machine is shared: each row's `load` is the 1-minute load average "
              "before its runs; read times with it):", ""]
    for run in runs:
        header.append("- `%s` — %s, %d cases, %d s; load average %s; %s; %s." % (
            run["command"].strip(), run["date"], run["cases"], run["seconds"], run["load"], run["setup"],
            run["peers"]))
    header += ["", "Machine: %s. Every case in its own process through `/usr/bin/time -v` (wall time, peak "
               "memory), with no OMP_* variable set (each tool's default threads); medians of the runs. "
               "'wall s' is the whole process (start-up and file input/output included), 'algo s' the tool's own "
               "computation (MeshFree: the filter's Update()); 'peak MB' the whole process's peak memory (pvpython "
               "with ParaView's libraries and the plugin starts at 320 MB, python3 with VTK at 95 MB, with Open3D at 80 MB), "
               "'algo MB' what the computation took on top of its input (peak at its end less resident memory "
               "at its start, surface_memory.py); 'load' the 1-minute load average." % (
                   runs[-1]["machine"]),
               "",
               "Scores (surface_score.py; every column is described in bench_surface.py): distances of the mesh "
               "vertices to the true surface (rms, max, bias = mean signed distance, positive outside); coverage "
               "(cov) = distance from 200,000 true surface points to the nearest vertex (mean, max); watertight = "
               "every edge in exactly two triangles; χ = Euler characteristic (2 closed sphere, ball or block, "
               "0 torus); pieces = connected components; volume err = (enclosed volume − reference) / reference, "
               "the reference being the analytic volume, or for SPH particles N H³. SPH reference surfaces: the "
               "ball's volume-equivalent sphere, the block's lattice box. Normals: angle to the exact normal line, "
               "consistent = share on the majority side, outward = share pointing out."]
    pictures_here = sorted(p for p in os.listdir(out) if p.startswith("surface_") and p.endswith(".png"))
    if pictures_here:
        header += ["", "Pictures of MeshFree's meshes (coloured by the signed distance to the true surface): " +
                   ", ".join("`%s`" % p for p in pictures_here) + "."]
    write_markdown(os.path.join(out, "surface.md"), rows, header)


def render_pictures(rows, cfg):
    """One picture per cloud of MeshFree's default mesh (MLS with the exact normals; SPH for particles), from the
    meshes in the work folder."""
    items, seen = [], set()
    for key in ("mf_mls_n", "mf_sph", "mf_mls"):
        for r in rows:
            mesh = os.path.join(cfg.work, "out", "%s__%s.vtp" % (r["cloud"], key))
            if r["key"] == key and r["status"] == "ok" and r["cloud"] not in seen and os.path.exists(mesh):
                seen.add(r["cloud"])
                items.append(dict(mesh=mesh, png=os.path.join(cfg.out, "surface_%s.png" % r["cloud"]),
                                  cloud=os.path.join(cfg.work, "data", r["cloud"] + ".json"),
                                  title="MeshFree %s, %s: rms %.1e, %s s" % (
                                      r["settings"].split(",")[0], r["cloud"], r["rms"] or float("nan"),
                                      _num(r["wall_s"], "%.2f"))))
    if not items:
        return []
    spec = os.path.join(cfg.work, "render.json")
    with open(spec, "w") as f:
        json.dump(items, f, indent=1)
    pvpython = cfg.found["meshfree"]["pvpython"]
    cmd = [pvpython, "--no-mpi", os.path.join(HERE, "surface_render.py"), spec]
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"] + cmd
    p = subprocess.run(cmd, capture_output=True, text=True, env=cfg.env, timeout=600)
    made = [i["png"] for i in items if os.path.exists(i["png"])]
    if len(made) < len(items):
        log("  warning: %d of %d pictures rendered (%s)" % (len(made), len(items), _failure(
            dict(rc=p.returncode, stdout=p.stdout, stderr=p.stderr))))
    return made


# ---------------------------------------------------------------------------------------------- main
def default_out():
    plugin = find_plugin()
    d = os.path.dirname(os.path.abspath(plugin))
    for _ in range(4):
        d = os.path.dirname(d)
    return os.path.join(d, "benchmark-results") if os.path.isdir(d) else os.path.join(
        tempfile.gettempdir(), "meshfree-benchmark-results")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="20k points, MeshFree and VTK only (a smoke run)")
    ap.add_argument("--sizes", type=int, nargs="+", help="point counts (default 100000 1000000; quick 20000)")
    ap.add_argument("--sph-sizes", type=int, nargs="+", help="SPH particle counts (default: --sizes; quick 50000)")
    ap.add_argument("--out", help="results folder (default <build>/benchmark-results)")
    ap.add_argument("--work", default=os.path.join(tempfile.gettempdir(), "meshfree-bench-surface"),
                    help="clouds and tool outputs (default %(default)s)")
    ap.add_argument("--only", help="regular expression on 'group|peer|cloud' or the short key")
    ap.add_argument("--peers", help="comma list of %s (default all; quick: meshfree,vtk)" % ",".join(TOOLS))
    ap.add_argument("--reps", type=int, help="timed runs per case (default 3; quick 1)")
    ap.add_argument("--max-rep-s", type=float, default=30.0, help="one run only when the first takes longer")
    ap.add_argument("--timeout", type=int, default=3600, help="seconds before a run is killed")
    ap.add_argument("--list", action="store_true", help="print the cases and exit")
    ap.add_argument("--no-render", action="store_true", help="no pictures")
    ap.add_argument("--report-only", action="store_true",
                    help="only rewrite --out's surface.md from its surface.csv and surface_runs.json")
    ap.add_argument("--render-only", action="store_true",
                    help="only redraw the pictures of --out's surface.csv from the meshes kept in --work")
    ap.add_argument("--require-meshfree", action="store_true",
                    help="fail at once when MeshFree's plugin or surface proxies are missing")
    ap.add_argument("--set-env", action="append", metavar="NAME=VALUE",
                    help="an environment variable for every tool (e.g. OMP_WAIT_POLICY=passive on a busy machine; "
                    "by default no OMP_* variable is set); repeatable")
    ap.add_argument("--merge", action="store_true",
                    help="keep the rows of an earlier surface.csv in --out that this run does not redo")
    ap.add_argument("--meshfree-batch", action="store_true",
                    help="all MeshFree cases in one process (default in --quick)")
    cfg = ap.parse_args()
    cfg.sizes = cfg.sizes or ([20000] if cfg.quick else [100000, 1000000])
    cfg.sph_sizes = cfg.sph_sizes or ([50000] if cfg.quick else cfg.sizes)
    cfg.peers = [p.strip() for p in (cfg.peers or ("meshfree,vtk" if cfg.quick else ",".join(TOOLS))).split(",")]
    unknown = [p for p in cfg.peers if p not in TOOLS]
    if unknown:
        ap.error("unknown peer(s) %s; choose from %s" % (", ".join(unknown), ", ".join(TOOLS)))
    cfg.reps = cfg.reps or (1 if cfg.quick else 3)
    cfg.meshfree_batch = cfg.meshfree_batch or cfg.quick
    cfg.out = cfg.out or default_out()
    try:
        import numpy  # noqa: F401
        import scipy.spatial  # noqa: F401
        import vtkmodules.vtkIOXML  # noqa: F401
    except ImportError as e:
        sys.exit("bench_surface.py needs numpy, scipy and VTK's Python modules (%s): run it with pvpython or "
                 "Debian's /usr/bin/python3" % e)
    import surface_clouds

    cfg.env = {k: v for k, v in os.environ.items() if not k.startswith("OMP_")}
    cfg.env.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")
    cfg.env["MESHFREE_PLUGIN"] = find_plugin()
    for assignment in cfg.set_env or []:
        name, _, value = assignment.partition("=")
        cfg.env[name] = value
    if cfg.report_only:
        with open(os.path.join(cfg.out, "surface_runs.json")) as f:
            write_report(cfg.out, read_csv(os.path.join(cfg.out, "surface.csv")), json.load(f))
        log("wrote %s" % os.path.join(cfg.out, "surface.md"))
        return 0
    if cfg.render_only:
        cfg.found = {"meshfree": dict(pvpython=shutil.which("pvpython") or "pvpython")}
        made = render_pictures(read_csv(os.path.join(cfg.out, "surface.csv")), cfg)
        log("wrote %d pictures into %s" % (len(made), cfg.out))
        return 0 if made else 1
    start, load_start = time.perf_counter(), loadavg()
    run_id = datetime.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
    found, notes = find_peers(cfg.peers, cfg.env)
    cfg.found = found
    plugin_mtime = os.path.getmtime(found["meshfree"]["plugin"]) if "meshfree" in found else None
    log("bench_surface (%s): sizes %s, SPH %s, peers %s, reps %d; load average %s" % (
        "quick" if cfg.quick else "full", cfg.sizes, cfg.sph_sizes, ",".join(cfg.peers), cfg.reps,
        " ".join("%.2f" % v for v in load_start)))
    for tool in cfg.peers:
        if tool in found:
            state = "found: " + ", ".join(str(v) for v in found[tool].values())
            if tool in notes:
                state += "; but " + notes[tool]
        else:
            state = "not available: " + notes.get(tool, "?")
        log("  %-8s %s" % (tool, state))
    if cfg.require_meshfree and "meshfree" in cfg.peers and (
            "meshfree" not in found or "meshfree" in notes):
        log("ERROR: MeshFree's surface proxies are not available (%s)" % notes.get("meshfree"))
        return 1

    os.makedirs(os.path.join(cfg.work, "data"), exist_ok=True)
    os.makedirs(os.path.join(cfg.work, "out"), exist_ok=True)
    formats = ("vtp", "ply", "pcd") if ({"open3d", "pcl"} & set(cfg.peers)) else ("vtp",)
    clouds = []
    t0 = time.perf_counter()
    for n in cfg.sizes:
        for shape in ("sphere", "torus"):
            for sigma in (0.0, surface_clouds.NOISE_SIGMA):
                clouds.append(surface_clouds.make_cloud(os.path.join(cfg.work, "data"), shape, n, sigma, formats))
    for n in cfg.sph_sizes:
        for shape in ("ball", "block"):
            clouds.append(surface_clouds.make_cloud(os.path.join(cfg.work, "data"), shape, n))
    log("clouds ready in %s (%.1f s): %s" % (os.path.join(cfg.work, "data"), time.perf_counter() - t0,
                                             ", ".join("%s (%d)" % (c["name"], c["n"]) for c in clouds)))
    cases = build_cases(clouds, found, cfg, cfg.work)
    if cfg.list:
        for c in cases:
            log("%-70s %s" % (c["id"], " ".join(c["cmd"])))
        return 0

    def available(case):
        if case["tool"] not in found:
            return False, notes.get(case["tool"], "not found")
        if case["tool"] == "meshfree":
            proxy = "MeshlessSurface" if case["job"]["mode"] == "surface" else "MeshlessNormals"
            if proxy not in found["meshfree"]["proxies"]:
                return False, "%s not available in this build" % proxy
        return True, ""

    results = {}
    runnable = []
    for case in cases:
        ok, why = available(case)
        if ok:
            runnable.append(case)
        else:
            results[case["id"]] = make_row(case, [], "not available", why)
    batch = [c for c in runnable if c["tool"] == "meshfree" and cfg.meshfree_batch]
    batch_runs = {}
    if batch:
        for case in batch:
            if os.path.exists(case["out"]):
                os.unlink(case["out"])
        batch_runs = dict(zip((c["id"] for c in batch), run_meshfree_batch(batch, cfg)))
    problems = []
    for i, case in enumerate(runnable):
        if case["id"] in batch_runs:
            runs = batch_runs[case["id"]]
        else:
            if os.path.exists(case["out"]):
                os.unlink(case["out"])
            runs = run_case(case, cfg)
        if runs[-1]["rc"] == 0 and os.path.exists(case["out"]):
            try:
                row = make_row(case, runs, "ok")
                row.update({k: v for k, v in score_case(case).items() if k in COLUMNS})
                if cfg.meshfree_batch and case["tool"] == "meshfree":
                    row["note"] = "batched: wall_s = read + Update() + write; peak_mb = the whole process"
            except Exception as e:  # a scorer failure is reported with the case
                row = make_row(case, runs, "failed", "scoring: %s: %s" % (type(e).__name__, e))
        else:
            why = _failure(runs[-1]) if runs[-1]["rc"] != 0 else "no output file"
            row = make_row(case, runs, "failed", why)
        if row["status"] == "failed":
            problems.append("%s: %s" % (case["id"], row["note"]))
        results[case["id"]] = row
        log("[%d/%d] %-72s %s" % (i + 1, len(runnable), case["id"], summary(row)))
    rows = [results[c["id"]] for c in cases]
    for r in rows:
        r["run"] = run_id

    os.makedirs(cfg.out, exist_ok=True)
    csv_path, md_path = os.path.join(cfg.out, "surface.csv"), os.path.join(cfg.out, "surface.md")
    runs_path = os.path.join(cfg.out, "surface_runs.json")
    runs_before = []
    if cfg.merge and os.path.exists(csv_path):  # keep the earlier rows this run did not redo
        ids = {r["case"] for r in rows}
        rows = [r for r in read_csv(csv_path) if r["case"] not in ids] + rows
        if os.path.exists(runs_path):
            with open(runs_path) as f:
                runs_before = json.load(f)
    write_csv(csv_path, rows)
    pictures = [] if cfg.no_render or "meshfree" not in found else render_pictures(rows, cfg)
    load_end = loadavg()
    loads = [results[c["id"]]["load1"] for c in cases if results[c["id"]]["load1"] is not None]
    vers = versions(found)
    rebuilt = plugin_mtime is not None and os.path.getmtime(found["meshfree"]["plugin"]) != plugin_mtime
    if rebuilt:
        log("warning: the MeshFree plugin was rebuilt during this run: its rows mix two builds")
        vers["meshfree"] += ", REBUILT DURING THE RUN"
    this_run = dict(
        command="pvpython --no-mpi Testing/Benchmarks/bench_surface.py " + " ".join(
            shlex.quote(os.path.relpath(a, SOURCE) if os.path.isabs(a) and a.startswith(SOURCE + os.sep) else a)
            for a in sys.argv[1:]),
        id=run_id, date=run_id[:16], seconds=round(time.perf_counter() - start),
        cases=len(runnable), machine=bench_machine.describe(),
        load="%.2f at the start, %.2f at the end, %s before the runs" % (
            load_start[0], load_end[0], "%.2f–%.2f" % (min(loads), max(loads)) if loads else "—"),
        peers="; ".join("%s: %s" % (t, vers.get(t, "found") if t in found and t not in notes else
                                    ("partly, " + notes[t]) if t in found else "not available")
                        for t in cfg.peers),
        setup="reps %d (one run when the first took more than %.0f s)%s, VTK_SMP_BACKEND_IN_USE=%s%s" % (
            cfg.reps, cfg.max_rep_s, ", MeshFree batched in one process" if cfg.meshfree_batch else "",
            cfg.env.get("VTK_SMP_BACKEND_IN_USE"), "".join(", " + a for a in cfg.set_env or [])))
    used = {r["run"] for r in rows}
    all_runs = [run for run in runs_before if run.get("id") in used] + [this_run]  # runs still behind a row
    with open(runs_path, "w") as f:
        json.dump(all_runs, f, indent=1)
    write_report(cfg.out, rows, all_runs)
    problems += check_csv(csv_path)
    for p in problems:
        log("ERROR: " + p)
    log("wrote %s, %s%s; total %.0f s, load average %s" % (
        csv_path, md_path, (" and %d pictures" % len(pictures)) if pictures else "", time.perf_counter() - start,
        " ".join("%.2f" % v for v in load_end)))
    return 1 if problems else 0


def summary(row):
    if row["status"] != "ok":
        return row["status"] + (": " + row["note"] if row["note"] else "")
    parts = ["%.2fs" % row["wall_s"] if row["wall_s"] is not None else "-"]
    if row["algo_s"] is not None:
        parts.append("algo %.2fs" % row["algo_s"])
    if row["peak_mb"] is not None:
        parts.append("%.0fMB" % row["peak_mb"])
    if row.get("rms") is not None:
        parts.append("rms %.2e max %.2e" % (row["rms"], row["max"]))
    if row.get("ang_mean") is not None:
        parts.append("%.2f° cons %.3f out %.3f" % (row["ang_mean"], row["consistent"], row["outward"]))
    if row.get("watertight") is not None:
        parts.append("wt %s chi %s" % ("yes" if row["watertight"] else "no", row["euler"]))
    return " ".join(parts)


if __name__ == "__main__":
    sys.exit(main())
