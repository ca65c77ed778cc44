"""Normals benchmark of issue 23: MeshFree's Meshless Normals beside fixed-k PCA and CGAL's jet and PCA normals,
on clouds whose true normals are known, scored by scans_score.score_normals (angle to the true normal line: mean
and p99 in degrees; share consistently oriented; share outward).

    LD_PRELOAD=build/lib/libmeshfree_expat_compat.so \
    pvpython --no-mpi Testing/Benchmarks/bench_scans_normals.py [--points 150000] [--virtual DIR]
        [--levels 0,0.00125,0.006,0.012] [--shapes torus,sphere,cube] [--out DIR] [--work DIR] [--timeout 600]
        [--no-issue-torus] [--tools meshfree,pca,cgal]

Clouds: the torus R = 1, r = 0.35, the unit sphere and the cube [-1, 1]^3, --points uniform by area, Gaussian
noise per axis of sigma = level x the bounding-box diagonal (PCPNet's levels: 0, 0.125 %, 0.6 %, 1.2 %), the true
normal being the noise-free point's (the cube: its face's; edges and corners are where estimators smear); plus
each virtual scan of --virtual (virtual_scan.py; true normals in its .npz); plus issue 23's torus (150,000 points,
sigma = 0.002; PCA k 80 beside it) unless --no-issue-torus.
Estimators, each in its own process (wall time and peak memory by /usr/bin/time -v):
  MeshFree      MeshlessNormals with its defaults (surface_run_meshfree.py normals): oriented
  PCA k         k = 18, 112, 450 nearest neighbours, smallest-eigenvector of the covariance (numpy/scipy,
                scans_pca_normals below); unoriented, so only the angle is compared
  CGAL jet k    peers/cgal_peer normals --method jet, k = 18 and 112; unoriented
--tools: which estimators run (default all three; e.g. --tools meshfree to compare two builds of the plugin, with
MESHFREE_PLUGIN naming each). Writes OUT/scans_normals.md and OUT/scans_normals.json. The preload is the build's
expat shim (README, "Debian 12's expat and ParaView 5.11"): without it the .vtp files of the MeshFree runs cannot be
read back and every MeshFree row fails.
"""
import argparse
import datetime
import json
import math
import os
import shutil
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from bench_surface import _last_json, loadavg, run_process  # noqa: E402
import scans_score  # noqa: E402

PCA_K = (18, 112, 450)
JET_K = (18, 112)


def torus(n, rng):
    from virtual_scan import Torus
    t = Torus([0, 0, 0], 1.0, 0.35)
    p = t.sample(n, rng)
    return p, t.normal(p)


def sphere(n, rng):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return d.copy(), d


def cube(n, rng):
    face = rng.integers(0, 6, n)
    axis, sign = face // 2, np.where(face % 2 == 0, 1.0, -1.0)
    p = rng.uniform(-1, 1, (n, 3))
    p[np.arange(n), axis] = sign
    nrm = np.zeros((n, 3))
    nrm[np.arange(n), axis] = sign
    return p, nrm


SHAPES = dict(torus=torus, sphere=sphere, cube=cube)


def pca_normals(points, k, chunk=4000):
    """Unoriented PCA normals over the k nearest neighbours (the point itself included)."""
    from scipy.spatial import cKDTree
    tree = cKDTree(points)
    out = np.empty_like(points)
    for s in range(0, len(points), chunk):
        _, idx = tree.query(points[s:s + chunk], k=k)
        nb = points[idx]
        nb = nb - nb.mean(axis=1)[:, None, :]
        cov = np.einsum("nki,nkj->nij", nb, nb)
        _, vec = np.linalg.eigh(cov)
        out[s:s + chunk] = vec[:, :, 0]
    return out


def write_vtp(path, pts):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    vp = vtkPoints()
    vp.SetData(numpy_to_vtk(np.ascontiguousarray(pts), deep=1))
    pd = vtkPolyData()
    pd.SetPoints(vp)
    w = vtkXMLPolyDataWriter()
    w.SetFileName(path)
    w.SetInputData(pd)
    w.Write()


def read_vtp_normals(path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    r = vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    out = r.GetOutput()
    arr = out.GetPointData().GetNormals() or out.GetPointData().GetArray("Normals")
    return vtk_to_numpy(out.GetPoints().GetData()).astype(float), vtk_to_numpy(arr).astype(float)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=150000)
    ap.add_argument("--levels", default="0,0.00125,0.006,0.012")
    ap.add_argument("--shapes", default="torus,sphere,cube")
    ap.add_argument("--virtual")
    ap.add_argument("--out", default=os.path.join(SOURCE, "build", "benchmark-results"))
    ap.add_argument("--work", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "meshfree-bench-normals"))
    ap.add_argument("--timeout", type=int, default=600)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--no-issue-torus", dest="issue_torus", action="store_false",
                    help="leave out issue 23's torus (150k points, sigma 0.002, PCA k 80 beside it)")
    ap.add_argument("--tools", default="meshfree,pca,cgal", help="comma-separated: meshfree, pca, cgal")
    a = ap.parse_args()
    tools = set(t for t in a.tools.split(",") if t)
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.work, exist_ok=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMP_")}
    env.update(OMP_WAIT_POLICY="passive")
    env.setdefault("VTK_SMP_BACKEND_IN_USE", "STDThread")
    clouds = []
    rng = np.random.default_rng(a.seed)
    for shape in [s for s in a.shapes.split(",") if s]:
        base_p, base_n = SHAPES[shape](a.points, rng)
        diag = float(np.linalg.norm(base_p.max(0) - base_p.min(0)))
        for level in [float(v) for v in a.levels.split(",")]:
            p = base_p + rng.normal(size=base_p.shape) * level * diag
            clouds.append(("%s, noise %.3g %%" % (shape, 100 * level), p, base_n))
    if a.issue_torus:
        # Issue 23's own cloud: the torus at 150,000 points, sigma = 0.002 per axis (PCA k 80 beside it).
        base_p, base_n = torus(150000, np.random.default_rng(a.seed + 1))
        clouds.append(("torus 150k, sigma 0.002 (issue 23)",
                       base_p + np.random.default_rng(a.seed + 2).normal(size=base_p.shape) * 0.002, base_n))
    if a.virtual:
        for name in sorted(os.listdir(a.virtual)):
            if name.startswith("vscan_") and name.endswith(".npz"):
                z = np.load(os.path.join(a.virtual, name))
                clouds.append((name[:-4], z["points"], z["normals"]))
    py = shutil.which("pvpython")
    plugin_runner = os.path.join(HERE, "surface_run_meshfree.py")
    cgal = os.environ.get("SCANS_CGAL_PEER") or os.path.join(SOURCE, "build", "scans-peers", "cgal_peer")
    rows = []
    for ci, (label, pts, true) in enumerate(clouds):
        stem = os.path.join(a.work, "c%02d" % ci)
        write_vtp(stem + ".vtp", pts)
        np.savetxt(stem + ".xyz", pts, fmt="%.9g")

        def add(tool, normals, run=None, oriented=True, why=""):
            row = dict(cloud=label, n=len(pts), tool=tool)
            if normals is None:
                text = why or (run["stderr"].strip().splitlines()[-1][:200] if run and run["stderr"].strip() else "")
                row["status"] = "failed" + (": " + text if text else "")
            else:
                row.update(scans_score.score_normals(normals, true, outward=oriented))
                if not oriented:  # an unoriented estimator: only the angle to the normal line means something
                    row.pop("consistent")
                row["status"] = "ok"
            if run:
                row.update(wall_s=run["wall_s"], peak_mb=run["peak_mb"], load1=run.get("load1"))
            rows.append(row)
            print(json.dumps(row), flush=True)

        if py and "meshfree" in tools:
            load = loadavg()[0]
            run = run_process([py, "--no-mpi", plugin_runner, "normals", stem + ".vtp", stem + "_mf.vtp"], env,
                              a.timeout)
            run["load1"] = load
            info = _last_json(run["stdout"]) or {}
            ok = run["rc"] == 0 and "error" not in info and os.path.exists(stem + "_mf.vtp")
            if ok:
                mp, mn = read_vtp_normals(stem + "_mf.vtp")
                ok = len(mp) == len(pts)
            add("MeshFree Meshless Normals", mn if ok else None, run, why=str(info.get("error", ""))[:200])
        for k in (PCA_K + ((80,) if "issue 23" in label else ())) if "pca" in tools else ():
            import time
            t0, load = time.perf_counter(), loadavg()[0]
            n = pca_normals(pts, min(k, len(pts)))
            add("PCA k %d (SciPy, in-process)" % k, n, dict(wall_s=time.perf_counter() - t0, peak_mb=None,
                                                            load1=load, stderr=""), oriented=False)
        if "cgal" in tools and os.path.exists(cgal):
            for k in JET_K:
                load = loadavg()[0]
                run = run_process([cgal, "normals", stem + ".xyz", stem + "_jet.xyz", "--k", str(k), "--method",
                                   "jet"], env, a.timeout)
                run["load1"] = load
                n = np.loadtxt(stem + "_jet.xyz")[:, 3:6] if run["rc"] == 0 else None
                add("CGAL jet k %d" % k, n, run, oriented=False)
        with open(os.path.join(a.out, "scans_normals.json"), "w") as f:
            json.dump(rows, f, indent=1, default=str)
    lines = ["## Normals benchmark (bench_scans_normals.py, issue 23)", "",
             "Run %s; %d points per synthetic cloud; angle to the true normal line (degrees); consistent: share "
             "on the majority side; outward: share pointing outward (only for oriented estimators); wall s: the "
             "process (PCA: in-process computation); 1-minute load averages before the runs: %s." % (
                 datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), a.points,
                 ", ".join("%.1f" % r["load1"] for r in rows if r.get("load1") is not None)), "",
             "| cloud | tool | mean | p99 | consistent | outward | wall s | peak MB |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "ok":
            lines.append("| %s | %s | %s | | | | | |" % (r["cloud"], r["tool"], r["status"]))
            continue
        lines.append("| %s | %s | %.2f | %.2f | %s | %s | %s | %s |" % (
            r["cloud"], r["tool"], r["ang_mean"], r["ang_p99"], "%.4f" % r["consistent"] if "consistent" in r else "-",
            "%.4f" % r["outward"] if "outward" in r else "-", "%.1f" % r["wall_s"] if r.get("wall_s") else "-",
            "%.0f" % r["peak_mb"] if r.get("peak_mb") else "-"))
    with open(os.path.join(a.out, "scans_normals.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote", os.path.join(a.out, "scans_normals.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
