"""Scan benchmark (issue 23): MeshFree's Meshless Surface beside PCL, CGAL, MeshLab and VTK on real multi-view
range scans, on virtual scans of known shapes and on single-view scans; every output scored by scans_score.py.

    sh Testing/Benchmarks/setup_peers.sh                                  # once: the peers (root)
    /usr/bin/python3 Testing/Benchmarks/scans_data.py prepare bunny SRC/bunny DATA     # once per data set
    /usr/bin/python3 Testing/Benchmarks/virtual_scan.py VIRTUAL [--points 150000]      # once
    pvpython --no-mpi Testing/Benchmarks/bench_scans.py --data DATA --virtual VIRTUAL \
        [--cases bunny,bunny_view,vscan_torus,...] [--tools meshfree,pcl,meshlab,cgal,vtk] [--timeout 900]
        [--out Testing/Benchmarks/results] [--work DIR] [--set-env NAME=VALUE]
    ... --merge --rescore      scores again the meshes left in --work by an earlier run (after a scorer change)

Nothing is downloaded: --data holds what scans_data.py prepared (NAME.xyz, NAME_view.xyz, NAME_ref.npz,
NAME.json), --virtual what virtual_scan.py wrote. Cases: each prepared real scan NAME (all views merged,
positions only) and NAME_view (its first view alone), scored against the authors' reconstruction; each virtual
scan, scored against the exact surface.

Tools, each case in its own process through /usr/bin/time -v (wall seconds, peak resident memory of the process),
every one from positions only:
  MeshFree MLS, WLS   MeshlessSurface (surface_run_meshfree.py) with its defaults and Method; when the proxy has
                      the property HoleFilling, MLS runs with HoleFilling 1 and 0 (and the table says so); the
                      output's DistanceToData array, when present, is summarised (max, share of vertices > delta)
  PCL                 pcl_normal_estimation -k 20 (oriented towards the viewpoint, PCL's only choice) then
                      pcl_poisson_reconstruction -depth 9: two processes, times added, memory the larger
  MeshLab             meshlabserver (xvfb-run) with peers/meshlab_screened_poisson.mlx: point-set normals
                      K 10 + screened Poisson depth 9
  CGAL Poisson        peers/cgal_peer poisson: jet normals k 18, MST orientation, Delaunay Poisson
  CGAL AFront         peers/cgal_peer afront: advancing front (interpolates the points)
  VTK                 scans_run_vtk.py signed: PCA normals k 20 + graph orientation, vtkSignedDistance (200
                      cells, radius 3 cells), vtkExtractSurface
The environment is the caller's plus OMP_WAIT_POLICY=passive (OpenMP's spinning barriers slow MeshLab and PCL
several-fold on a busy 2-core machine) and VTK_SMP_BACKEND_IN_USE=STDThread unless set; --set-env adds more.
The CGAL driver is $SCANS_CGAL_PEER, else <source>/build/scans-peers/cgal_peer (setup_peers.sh builds it).

Scores (scans_score.py): delta = 0.4 % of the cloud's bounding-box diagonal (1.1e-3 on the bunny) is the "has
data" radius; rms/p99/max over the mesh vertices within delta of a data point, to the reference (inner: without
those over the reference's holes; area: the same over an area-uniform sample of the mesh); coverage of the
reference where it has data; boundary edges, pieces, stray triangles, chi; border = p99 distance of the mesh's
boundary vertices to the nearest data point, in median data spacings h and, in parentheses, in the local spacing
of that data point (r_20 sqrt(pi / 20)) (open scans: the border should follow the data's).
Writes OUT/scans.md (tables) and OUT/scans_runs.json (every row, the commands, the load averages).
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from bench_surface import _last_json, _pcl_seconds, loadavg, run_process  # noqa: E402
import scans_score  # noqa: E402
from virtual_scan import Assembly  # noqa: E402

PLUGIN_REL = os.path.join("lib", "paraview-5.11", "plugins", "MeshFree", "MeshFree.so")
TOOLS = ("meshfree", "pcl", "meshlab", "cgal", "vtk")
PROBE = r"""
import json, sys
from paraview import simple
simple.LoadPlugin(sys.argv[1], remote=False)
src = simple.Sphere()
f = simple.MeshlessSurface(Input=src)
print(json.dumps(dict(properties=[str(p) for p in f.ListProperties()])))
"""


DATA_NOTE = """### Data: where each file came from

Both real scans are from the Stanford 3D Scanning Repository (http://graphics.stanford.edu/data/3Dscanrep/,
Stanford University Computer Graphics Laboratory), read from copies in public GitHub repositories (the mirrored
git objects, `git --git-dir=MIRROR show COMMIT:PATH > FILE`), then merged by `scans_data.py prepare`:

| data | repository @ commit | paths | original |
|---|---|---|---|
| bunny range views (10) + alignment | somanshu25/GPU-Accelerated-Point-Cloud-Registration-Using-Hierarchical-GMM @ ff2ea430241dffa6175103802eac7e331ea8dcaa | data/bun.conf, data/bun000.ply, bun045, bun090, bun180, bun270, bun315, chin, ear_back, top2, top3 .ply | bunny.tar.gz, bunny/data (Turk & Levoy 1994; Cyberware 3030 MS; 362,272 points) |
| bunny reference | dengnantianjie/3dcoursework @ fdabb8f051a5e2b209fe9e5ac5fe989588413f3c | bunny/reconstruction/bun_zipper.ply | bunny.tar.gz, bunny/reconstruction/bun_zipper.ply (zippered, 35,947 vertices, 69,451 triangles; 5 holes in the base) |
| dragon range views (15, "stand" set) + alignment | bing-jian/gmmreg @ 86e4562a58ce2e6aa0397fafd8dd5262b3506508 | data/dragon_stand/dragonStandRight.conf, dragonStandRight_{0,24,...,336}.ply | the dragon range data, "stand" set (Cyberware 3030 MS with spacetime analysis, per its README; 469,193 points) |
| dragon reference | dengnantianjie/3dcoursework @ fdabb8f051a5e2b209fe9e5ac5fe989588413f3c | bunny/data/dragon_small.obj | Stanford's dragon reconstruction (VRIP, Curless & Levoy 1996) at its _res3 decimation (22,998 vertices, 47,794 triangles), re-saved by MeshLab as OBJ |

The bunny views are identical, up to line ends, to the same files in dengnantianjie/3dcoursework; the .conf lines
"bmesh FILE tx ty tz qx qy qz qw" map a view's points p to R(q)^T p + t (scans_data.py; the merged bunny lies at a
median 6.4e-5 (rms 2.0e-4) from bun_zipper.ply, the dragon at a median 1.2e-4 from its reference). The dragon's
reference is coarse (edges about 2 mm on a 0.2 m model) and was made from more views than the 15 used here: its
scores measure agreement to about that resolution, and coverage counts only where the data are.
Terms of use: the Stanford repository asks that the source be acknowledged and allows research use; its page
(not retrievable from this machine, so not re-checked here) restricts commercial use. The copies above carry
Stanford's 1996 README without a licence of their own. No scan data are committed to this repository; the
benchmark reads them from the folder given on its command line.
"""


REFERENCE_NAMES = {"bunny_ref.npz": "bun_zipper.ply, the authors' zippered reconstruction",
                   "dragon_ref.npz": "the authors' VRIP reconstruction at its res3 decimation (coarse, see Data)"}


def log(*args):
    print(*args, flush=True)


def plugin_path():
    return os.environ.get("MESHFREE_PLUGIN") or os.path.join(SOURCE, "build", PLUGIN_REL)


def pvpython():
    return shutil.which("pvpython")


def probe_meshfree(env):
    exe, plugin = pvpython(), plugin_path()
    if not exe or not os.path.exists(plugin):
        return None
    script = os.path.join(os.environ.get("TMPDIR", "/tmp"), "bench_scans_probe.py")
    with open(script, "w") as f:
        f.write(PROBE)
    p = subprocess.run([exe, "--no-mpi", script, plugin], capture_output=True, text=True, env=env, timeout=300)
    info = _last_json(p.stdout)
    return info["properties"] if info else None


# ------------------------------------------------------------------------------------------------ cases
def real_cases(data):
    cases = []
    for name in sorted(os.listdir(data)):
        if not name.endswith("_ref.npz"):
            continue
        base = name[:-len("_ref.npz")]
        meta = json.load(open(os.path.join(data, base + ".json")))
        for key, xyz, label in ((base, base + ".xyz", "%s, %d views merged" % (base, len(meta["views"]))),
                                (base + "_view", base + "_view.xyz", "%s, one view (%s)" % (base, meta["view_file"]))):
            cases.append(dict(name=key, kind="real", xyz=os.path.join(data, xyz), label=label,
                              ref=os.path.join(data, base + "_ref.npz"), closed=key == base))
    return cases


def virtual_cases(vdir):
    cases = []
    for name in sorted(os.listdir(vdir)):
        if name.startswith("vscan_") and name.endswith(".json"):
            spec = json.load(open(os.path.join(vdir, name)))
            cases.append(dict(name=spec["name"], kind="virtual", xyz=os.path.join(vdir, spec["name"] + ".xyz"),
                              label="%s, %d view%s" % (spec["name"], spec["views"], "s" * (spec["views"] > 1)),
                              spec=spec, closed=spec["closed"]))
    return cases


def write_inputs(case, work):
    """NAME.vtp (VTK, MeshFree) and NAME.pcd (PCL) beside the .xyz."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    pts = np.loadtxt(case["xyz"], usecols=(0, 1, 2))
    case["points"] = pts
    base = os.path.join(work, case["name"])
    vp = vtkPoints()
    vp.SetData(numpy_to_vtk(np.ascontiguousarray(pts), deep=1))
    pd = vtkPolyData()
    pd.SetPoints(vp)
    verts = vtkCellArray()
    for i in range(len(pts)):
        verts.InsertNextCell(1)
        verts.InsertCellPoint(i)
    pd.SetVerts(verts)
    w = vtkXMLPolyDataWriter()
    w.SetFileName(base + ".vtp")
    w.SetInputData(pd)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.Write()
    with open(base + ".pcd", "w") as f:
        f.write("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %d\nHEIGHT 1\n"
                "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA ascii\n" % (len(pts), len(pts)))
        np.savetxt(f, pts, fmt="%.8g")
    shutil.copy(case["xyz"], base + ".xyz")
    case.update(vtp=base + ".vtp", pcd=base + ".pcd", xyz_in=base + ".xyz")


def tool_runs(case, tools, work, surface_props, env):
    """[(tool, setting, [commands], output)]"""
    base = os.path.join(work, case["name"])
    py = pvpython()
    runs = []
    if "meshfree" in tools and surface_props is not None:
        runner = os.path.join(HERE, "surface_run_meshfree.py")
        fill = "HoleFilling" in surface_props
        settings = [("MLS", ["Method=MLS"])]
        if fill:
            settings = [("MLS, HoleFilling 1", ["Method=MLS", "HoleFilling=1"]),
                        ("MLS, HoleFilling 0", ["Method=MLS", "HoleFilling=0"])]
        settings.append(("WLS", ["Method=WLS"]))
        for label, props in settings:
            out = "%s_meshfree_%s.vtp" % (base, re.sub(r"[^A-Za-z0-9]+", "", label))
            runs.append(("MeshFree", label, [[py, "--no-mpi", runner, "surface", case["vtp"], out] + props], out))
    if "pcl" in tools and shutil.which("pcl_poisson_reconstruction"):
        nrm, out = base + "_pcl_normals.pcd", base + "_pcl.vtk"
        runs.append(("PCL", "normals k 20 + Poisson depth 9",
                     [["pcl_normal_estimation", case["pcd"], nrm, "-k", "20"],
                      ["pcl_poisson_reconstruction", nrm, out, "-depth", "9"]], out))
    if "meshlab" in tools and shutil.which("meshlabserver") and shutil.which("xvfb-run"):
        out = base + "_meshlab.ply"
        runs.append(("MeshLab", "normals K 10 + screened Poisson depth 9",
                     [["xvfb-run", "-a", "meshlabserver", "-i", case["xyz_in"], "-o", out, "-s",
                       os.path.join(HERE, "peers", "meshlab_screened_poisson.mlx")]], out))
    cgal = os.environ.get("SCANS_CGAL_PEER") or os.path.join(SOURCE, "build", "scans-peers", "cgal_peer")
    if "cgal" in tools and os.path.exists(cgal):
        runs.append(("CGAL", "jet k 18 + MST + Poisson", [[cgal, "poisson", case["xyz_in"], base + "_cgalp.off",
                                                            "--k", "18"]], base + "_cgalp.off"))
        runs.append(("CGAL", "advancing front", [[cgal, "afront", case["xyz_in"], base + "_cgalaf.off"]],
                     base + "_cgalaf.off"))
    if "vtk" in tools and py:
        out = base + "_vtk.vtp"
        runs.append(("VTK", "PCA k 20 + signed distance 200 + extract",
                     [[py, "--no-mpi", os.path.join(HERE, "scans_run_vtk.py"), "signed", case["vtp"], out]], out))
    return runs


def run_tool(commands, env, timeout):
    total = dict(wall_s=0.0, peak_mb=0.0, algo_s=0.0, rc=0, load1=loadavg()[0], notes=[])
    have_algo = True
    for cmd in commands:
        r = run_process(cmd, env, timeout)
        total["wall_s"] += r["wall_s"]
        total["peak_mb"] = max(total["peak_mb"], r["peak_mb"] or 0.0)
        info = _last_json(r["stdout"]) or {}
        algo = None
        if os.path.basename(cmd[0]).startswith("pcl_"):
            algo = _pcl_seconds(r["stdout"] + "\n" + r["stderr"])
        elif "update_s" in info:
            algo = info["update_s"]
        elif "algo_s" in info:
            algo = info["algo_s"]
        elif any(k.endswith("_s") for k in info):
            algo = sum(v for k, v in info.items() if k.endswith("_s"))
        if algo is None:
            have_algo = False
        else:
            total["algo_s"] += algo
        if "error" in info:
            r["rc"] = r["rc"] or 2
            total["notes"].append(info["error"][:200])
        if r["rc"] != 0:
            text = [l for l in (r["stderr"] + "\n" + r["stdout"]).splitlines() if l.strip()][-2:]
            total["notes"].append("exit %s: %s" % (r["rc"], " / ".join(text)[-240:]))
            total["rc"] = r["rc"]
            break
    if not have_algo:
        total["algo_s"] = None
    return total


# ------------------------------------------------------------------------------------------------ scoring
def reference_for(case):
    if case["kind"] == "virtual":
        return Assembly.from_spec(case["spec"]["shapes"])
    ref = np.load(case["ref"])
    return scans_score.TriangleDistance(ref["points"], ref["triangles"])


def spacing(points):
    from scipy.spatial import cKDTree
    idx = np.arange(0, len(points), max(1, len(points) // 20000))
    d, _ = cKDTree(points).query(points[idx], k=2)
    return float(np.median(d[:, 1]))


LOCAL_K = 20  # the local spacing of a sample: r_k sqrt(pi / k) over its k nearest (Meshless Surface's own measure)


def border_p99(points, triangles, data_tree, h):
    """(p99 of the boundary vertices' distance to the nearest data point in median spacings h, p99 of the same
    distance in the local spacing of that data point); None without a border. A scan's border is where it grazes
    the surface, 2-8 times sparser than its median: the local figure says how far past the data's own spacing there
    the surface runs on."""
    v, t, _ = scans_score.clean_mesh(points, triangles)
    if len(t) == 0:
        return None
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    b = np.unique(edges[counts == 1])
    if len(b) == 0:
        return None  # no border
    d, nearest = data_tree.query(v[b])
    rk, _ = data_tree.query(data_tree.data[nearest], k=LOCAL_K + 1)
    local = np.maximum(rk[:, -1] * np.sqrt(np.pi / LOCAL_K), 1e-300)
    return float(np.percentile(d, 99) / h), float(np.percentile(d / local, 99))


def distance_to_data_summary(path, delta):
    if not path.endswith(".vtp"):
        return None
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    r = vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    arr = r.GetOutput().GetPointData().GetArray("DistanceToData")
    if arr is None:
        return None
    d = vtk_to_numpy(arr).astype(float)
    return dict(dtd_max=float(np.nanmax(d)) if len(d) else None, dtd_far_share=float((d > delta).mean()) if len(d) else None)


def score(case, out, ref, delta):
    from scipy.spatial import cKDTree
    pts, tri = scans_score.read_mesh(out)
    row = scans_score.score_mesh(pts, tri, case["points"], ref, delta)
    border = border_p99(pts, tri, cKDTree(case["points"]), case["spacing"]) if len(tri) else None
    row["border_p99_h"], row["border_p99_local"] = border if border else (None, None)
    extra = distance_to_data_summary(out, delta)
    if extra:
        row.update(extra)
    return row


# ------------------------------------------------------------------------------------------------ report
def fmt(v, f="%.2e"):
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "-"
    return f % v if isinstance(v, float) else str(v)


def border_cell(r):
    if not r.get("boundary_edges") or r.get("border_p99_h") is None:
        return "-"
    local = r.get("border_p99_local")
    return "%.1f" % r["border_p99_h"] + (" (%.1f)" % local if local is not None else "")


def write_report(out, rows, header):
    lines = list(header)
    for case_name in dict.fromkeys(r["case"] for r in rows):
        rs = [r for r in rows if r["case"] == case_name]
        c = dict(rs[0])
        c["reference"] = REFERENCE_NAMES.get(c["reference"], c["reference"])
        lines += ["", "### %s" % c["label"], "",
                  "%d points, spacing %.2e, delta %.2e; reference: %s." % (c["n"], c["spacing"], c["delta"], c["reference"]),
                  "",
                  "| tool | setting | rms | p99 | max | scored | inner rms | inner p99 | area rms | area p99 | cov rms | "
                  "cov p99 | cov far | boundary edges | pieces (stray tri.) | chi | border p99 / h (local) | triangles | wall s | "
                  "tool s | peak MB |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rs:
            if r.get("status") != "ok":
                lines.append("| %s | %s | %s |%s" % (r["tool"], r["setting"], r.get("status"), " |" * 18))
                continue
            lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s (%s) | %s | %s | %s | "
                         "%s | %s | %s |" % (
                r["tool"], r["setting"], fmt(r.get("rms")), fmt(r.get("p99")), fmt(r.get("max")),
                fmt(r.get("scored_share"), "%.3f"), fmt(r.get("inner_rms")), fmt(r.get("inner_p99")),
                fmt(r.get("area_rms")), fmt(r.get("area_p99")), fmt(r.get("cov_rms")), fmt(r.get("cov_p99")),
                fmt(r.get("cov_far_share"), "%.4f"), fmt(r.get("boundary_edges")), fmt(r.get("pieces")),
                fmt(r.get("stray_triangles")), fmt(r.get("euler")), border_cell(r),
                fmt(r.get("triangles")), fmt(r.get("wall_s"), "%.1f"), fmt(r.get("algo_s"), "%.1f"),
                fmt(r.get("peak_mb"), "%.0f")))
        notes = [r for r in rs if r.get("notes")]
        for r in notes:
            lines.append("")
            lines.append("- %s %s: %s" % (r["tool"], r["setting"], "; ".join(r["notes"])[:400]))
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", help="folder prepared by scans_data.py")
    ap.add_argument("--virtual", help="folder written by virtual_scan.py")
    ap.add_argument("--cases", help="comma-separated case names (default: all found)")
    ap.add_argument("--tools", default=",".join(TOOLS))
    ap.add_argument("--timeout", type=int, default=900)
    ap.add_argument("--out", default=os.path.join(SOURCE, "build", "benchmark-results"))
    ap.add_argument("--work", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "meshfree-bench-scans"))
    ap.add_argument("--set-env", action="append", default=[])
    ap.add_argument("--note", default="", help="a line for the report's header (e.g. the machine's state)")
    ap.add_argument("--merge", action="store_true",
                    help="keep the rows of OUT/scans_runs.json that this run does not redo (runs add up)")
    ap.add_argument("--merge-from", action="append", default=[],
                    help="also keep the rows of this scans_runs.json (another run's) that this run does not redo; "
                         "where several sources have the same case, tool and setting, the last one given wins")
    ap.add_argument("--report-only", action="store_true", help="run nothing: rewrite OUT/scans.md from the rows kept")
    ap.add_argument("--rescore", action="store_true",
                    help="run no tool: score again the meshes an earlier run left in WORK, for the rows kept (OUT's "
                         "with --merge, or --merge-from's) of the same case, tool and setting (e.g. after a change of "
                         "the scorer); their times and memory stay as measured")
    a = ap.parse_args()
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMP_")}
    env["OMP_WAIT_POLICY"] = "passive"
    env.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")
    for kv in a.set_env:
        k, v = kv.split("=", 1)
        env[k] = v
    tools = [t for t in a.tools.split(",") if t]
    cases = (real_cases(a.data) if a.data else []) + (virtual_cases(a.virtual) if a.virtual else [])
    if a.cases:
        wanted = a.cases.split(",")
        cases = [c for c in cases if c["name"] in wanted]
    if not cases and not a.report_only:
        log("bench_scans: no cases (give --data and/or --virtual; see --help)")
        return 1
    os.makedirs(a.work, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    props = probe_meshfree(env) if "meshfree" in tools and not a.report_only else None
    if "meshfree" in tools and not a.report_only:
        log("MeshFree plugin %s: %s" % (plugin_path(), "HoleFilling present" if props and "HoleFilling" in props
                                         else ("loaded, no HoleFilling" if props else "not available")))
    started = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    rows, kept = [], []
    runs_json = os.path.join(a.out, "scans_runs.json")
    sources = ([runs_json] if a.merge and os.path.exists(runs_json) else []) + a.merge_from
    if sources:
        starts = []
        for src in sources:
            earlier = json.load(open(src))
            kept += earlier["rows"]
            starts.append(earlier.get("started", "?"))
        started = " and ".join(starts + ([] if a.report_only or a.rescore else [started]))
        latest = {}  # the same case, tool and setting in several sources: the later source's row
        for r in kept:
            latest[(r["case"], r["tool"], r["setting"])] = r
        kept = list(latest.values())
    if a.report_only:
        cases = []
    for case in cases:
        write_inputs(case, a.work)
        case["spacing"] = spacing(case["points"])
        lo, hi = case["points"].min(0), case["points"].max(0)
        delta = 0.004 * float(np.linalg.norm(hi - lo))
        ref = reference_for(case)
        refname = ("the exact surface (%s)" % ", ".join(s["type"] for s in case["spec"]["shapes"])
                   if case["kind"] == "virtual" else REFERENCE_NAMES.get(os.path.basename(case["ref"]),
                                                                       os.path.basename(case["ref"])))
        for tool, setting, commands, out in tool_runs(case, tools, a.work, props, env):
            if a.rescore:
                earlier = [r for r in kept if (r["case"], r["tool"], r["setting"]) == (case["name"], tool, setting)]
                if earlier and earlier[-1].get("status") == "ok" and os.path.exists(out):
                    log("%s: %s %s: scored again" % (case["name"], tool, setting))
                    rows.append(dict(earlier[-1], **score(case, out, ref, delta)))
                continue
            if os.path.exists(out):
                os.unlink(out)
            log("%s: %s %s ..." % (case["name"], tool, setting))
            run = run_tool(commands, env, a.timeout)
            row = dict(case=case["name"], label=case["label"], n=int(len(case["points"])), spacing=case["spacing"],
                       delta=delta, reference=refname, tool=tool, setting=setting, wall_s=run["wall_s"],
                       algo_s=run["algo_s"], peak_mb=run["peak_mb"], load1=run["load1"], notes=run["notes"],
                       commands=[" ".join(c).replace(a.work, "WORK").replace(SOURCE, "SOURCE") for c in commands])
            if run["rc"] == 0 and os.path.exists(out):
                try:
                    row.update(score(case, out, ref, delta))
                    row["status"] = "ok" if row.get("triangles") else "empty mesh"
                except Exception as e:  # a mesh the scorer cannot read is reported, not raised
                    row["status"] = "unscored: %s" % e
            else:
                row["status"] = "timeout" if run["rc"] == "timeout" else "failed"
            log("  %s" % json.dumps({k: row.get(k) for k in ("status", "rms", "inner_rms", "area_rms", "cov_far_share", "boundary_edges",
                                                              "pieces", "euler", "wall_s", "peak_mb")}))
            rows.append(row)
            redone = {(r["case"], r["tool"], r["setting"]) for r in rows}
            merged = [r for r in kept if (r["case"], r["tool"], r["setting"]) not in redone] + rows
            with open(runs_json, "w") as f:
                json.dump(dict(started=started, rows=merged), f, indent=1, default=str)
    if kept:
        redone = {(r["case"], r["tool"], r["setting"]) for r in rows}
        rows = [r for r in kept if (r["case"], r["tool"], r["setting"]) not in redone] + rows
        order = {}
        for r in rows:
            order.setdefault(r["case"], len(order))
        tools = ["MeshFree", "PCL", "MeshLab", "CGAL", "VTK"]
        rows.sort(key=lambda r: (order[r["case"]], tools.index(r["tool"]) if r["tool"] in tools else 9))
        with open(runs_json, "w") as f:
            json.dump(dict(started=started, rows=rows), f, indent=1, default=str)
    versions = subprocess.run(["dpkg-query", "-W", "-f", "${Package} ${Version}; ", "pcl-tools", "libcgal-dev",
                               "meshlab", "paraview"], capture_output=True, text=True).stdout
    head = subprocess.run(["git", "-C", SOURCE, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    header = ["## Scan benchmark results (bench_scans.py, issue 23)", "",
              "Run %s on %s (%d cores), benchmark scripts at commit %s (see the note below for the plugin), peers: %s" % (started, platform.node() or "this machine",
                                                                         os.cpu_count() or 0, head or "?", versions),
              "Environment: OMP_WAIT_POLICY=passive, VTK_SMP_BACKEND_IN_USE=%s; 1-minute load averages before the "
              "runs: %s." % (env["VTK_SMP_BACKEND_IN_USE"], ", ".join("%.1f" % r["load1"] for r in rows)),
              "rms / p99 / max: mesh vertices within delta of a data point, to the reference; scored: their share; "
              "inner: the same vertices but those whose closest reference point is on the reference's border (over "
              "its holes); area: the inner scores over an area-uniform sample of the mesh within delta of the data "
              "instead of its vertices (independent of the tessellation); "
              "cov: reference samples where the data are, to the mesh (far: share farther than delta); border: p99 "
              "distance of boundary vertices to the data in spacings h (in parentheses: in the local spacing of the "
              "nearest data point, r_20 sqrt(pi / 20)); wall s: the whole process(es); tool s: the "
              "tool's own algorithm time where it reports one; peak MB: the process's peak resident memory."]
    if a.note:
        header += ["", a.note]
    header += ["", DATA_NOTE.strip()]
    write_report(os.path.join(a.out, "scans.md"), rows, header)
    log("wrote %s" % os.path.join(a.out, "scans.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
