"""Real multi-view range scans for the scan benchmark (bench_scans.py, issue 23): merge the raw views with the
alignment their authors published into one cloud (positions only), and keep the authors' reconstruction as the
reference to score against. Nothing is downloaded here: the files are read from a local directory.

    /usr/bin/python3 scans_data.py prepare bunny  SRC_DIR OUT_DIR    # SRC_DIR: bun.conf, bun*.ply, chin.ply, ...,
                                                            #          bun_zipper.ply (the reference)
    /usr/bin/python3 scans_data.py prepare dragon SRC_DIR OUT_DIR    # SRC_DIR: dragonStandRight.conf, the 15 views,
                                                            #          dragon_vrip_res3_meshlab.obj (reference)
    /usr/bin/python3 scans_data.py check OUT_DIR/NAME                # distances of the merged cloud to the reference

Writes OUT_DIR/NAME.xyz (all views merged, "x y z" per line), OUT_DIR/NAME_view.xyz (the first view alone: a
single-view scan), OUT_DIR/NAME_ref.npz (the reference: points (V, 3) float64, triangles (T, 3) int64) and
OUT_DIR/NAME.json (counts, bounding box, mean spacing, the files used). numpy only (any python3).

Where the files come from (Stanford 3D Scanning Repository, http://graphics.stanford.edu/data/3Dscanrep/, Stanford
Computer Graphics Laboratory; bunny: Turk & Levoy 1994, Cyberware 3030 MS, 10 views, 362,272 points, zippered
reconstruction bun_zipper.ply 35,947 vertices / 69,451 triangles; dragon: Cyberware 3030 MS
with spacetime analysis, reconstruction by VRIP, Curless & Levoy 1996), as copies kept in public GitHub repositories (see
results/scans.md for the commits and the terms of use):
  bunny views + bun.conf  github.com/somanshu25/GPU-Accelerated-Point-Cloud-Registration-Using-Hierarchical-GMM
                          data/*.ply, data/bun.conf (identical, up to line ends, to bunny.tar.gz's bunny/data)
  bun_zipper.ply          github.com/dengnantianjie/3dcoursework  bunny/reconstruction/bun_zipper.ply
  dragon views + .conf    github.com/bing-jian/gmmreg  data/dragon_stand/dragonStandRight_*.ply, .conf
  dragon reference        github.com/dengnantianjie/3dcoursework  bunny/data/dragon_small.obj: Stanford's
                          dragon_vrip_res3 (22,998 vertices, 47,794 triangles) re-saved by MeshLab as OBJ
The .conf files hold one line per view, "bmesh FILE tx ty tz qx qy qz qw": the view's points p go to R(q)^T p + t,
R(q) the rotation matrix of the unit quaternion q (checked here: so the merged bunny lies within the scanner's
noise of bun_zipper.ply; with R(q) p + t the views bun045 and bun090 land 1-3 cm off). "camera" and "mesh" lines
are not views and are skipped.
"""
import json
import os
import sys

import numpy as np

DATASETS = {
    "bunny": dict(conf="bun.conf", reference="bun_zipper.ply", view="bun000.ply"),
    "dragon": dict(conf="dragonStandRight.conf", reference="dragon_vrip_res3_meshlab.obj",
                   view="dragonStandRight_0.ply"),
}


def quaternion_matrix(qx, qy, qz, qw):
    q = np.array([qx, qy, qz, qw], dtype=float)
    q /= np.linalg.norm(q)
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def read_conf(path):
    """[(file, R, t)] for each "bmesh" line."""
    views = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) == 9 and parts[0] == "bmesh":
                t = np.array([float(v) for v in parts[2:5]])
                views.append((parts[1], quaternion_matrix(*[float(v) for v in parts[5:9]]), t))
    return views


def read_ply(path):
    """Vertices (and faces when the file has an element "face") of an ASCII PLY; x y z are the first three
    vertex properties in every file used here."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii", "replace").strip()
            header.append(line)
            if line == "end_header":
                break
            if not line and len(header) > 200:
                raise ValueError("%s: no end_header" % path)
        if not any(h.startswith("format ascii") for h in header):
            raise ValueError("%s: only ASCII PLY is read here" % path)
        elements, current = [], None
        for h in header:
            p = h.split()
            if p and p[0] == "element":
                current = [p[1], int(p[2]), []]
                elements.append(current)
            elif p and p[0] == "property" and current is not None:
                current[2].append(p[-1])
        body = f.read().decode("ascii", "replace").splitlines()
    points, faces, row = None, None, 0
    for name, count, props in elements:
        lines = body[row:row + count]
        row += count
        if name == "vertex":
            points = np.array([[float(v) for v in line.split()[:3]] for line in lines], dtype=float)
        elif name == "face":
            tri = []
            for line in lines:
                v = [int(x) for x in line.split()]
                for k in range(1, v[0] - 1):  # fan-triangulate polygons
                    tri.append((v[1], v[1 + k], v[2 + k]))
            faces = np.array(tri, dtype=np.int64).reshape(-1, 3)
    return points, faces


def read_obj(path):
    pts, tri = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                pts.append([float(v) for v in line.split()[1:4]])
            elif line.startswith("f "):
                idx = [int(v.split("/")[0]) - 1 for v in line.split()[1:]]
                for k in range(1, len(idx) - 1):
                    tri.append((idx[0], idx[k], idx[k + 1]))
    return np.array(pts, dtype=float), np.array(tri, dtype=np.int64).reshape(-1, 3)


def read_mesh(path):
    return read_obj(path) if path.lower().endswith(".obj") else read_ply(path)


def mean_spacing(points, sample=20000, seed=0):
    """Median distance to the nearest other point over a random sample."""
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(seed)
    idx = rng.choice(len(points), min(sample, len(points)), replace=False)
    d, _ = cKDTree(points).query(points[idx], k=2)
    return float(np.median(d[:, 1]))


def merge(src, name):
    spec = DATASETS[name]
    views = read_conf(os.path.join(src, spec["conf"]))
    clouds, used = [], []
    for file, R, t in views:
        pts, _ = read_ply(os.path.join(src, file))
        clouds.append(pts @ R + t)  # row vectors: (R^T p)^T = p^T R
        used.append(dict(file=file, points=len(pts)))
    return clouds, used, views


def write_xyz(path, points):
    np.savetxt(path, points, fmt="%.7g")


def prepare(name, src, out):
    os.makedirs(out, exist_ok=True)
    clouds, used, views = merge(src, name)
    cloud = np.concatenate(clouds)
    first = [i for i, (file, _, _) in enumerate(views) if file == DATASETS[name]["view"]][0]
    ref_pts, ref_tri = read_mesh(os.path.join(src, DATASETS[name]["reference"]))
    used_ref = np.unique(ref_tri)
    base = os.path.join(out, name)
    write_xyz(base + ".xyz", cloud)
    write_xyz(base + "_view.xyz", clouds[first])
    np.savez(base + "_ref.npz", points=ref_pts, triangles=ref_tri)
    meta = dict(name=name, points=int(len(cloud)), view_points=int(len(clouds[first])),
                view_file=DATASETS[name]["view"], views=used, reference=DATASETS[name]["reference"],
                reference_vertices=int(len(used_ref)), reference_triangles=int(len(ref_tri)),
                bounds=[cloud.min(0).tolist(), cloud.max(0).tolist()],
                diagonal=float(np.linalg.norm(cloud.max(0) - cloud.min(0))), spacing=mean_spacing(cloud))
    with open(base + ".json", "w") as f:
        json.dump(meta, f, indent=1)
    print(json.dumps({k: v for k, v in meta.items() if k != "views"}))


def check(base):
    """Distance of the merged cloud to the reference (the scorer's exact point-to-triangle distance)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from scans_score import TriangleDistance
    cloud = np.loadtxt(base + ".xyz")
    ref = np.load(base + "_ref.npz")
    d = TriangleDistance(ref["points"], ref["triangles"]).distance(cloud)
    print(json.dumps(dict(points=len(cloud), median=float(np.median(d)), rms=float(np.sqrt(np.mean(d * d))),
                          p90=float(np.percentile(d, 90)), p99=float(np.percentile(d, 99)))))


def main(argv):
    if len(argv) == 4 and argv[0] == "prepare" and argv[1] in DATASETS:
        prepare(argv[1], argv[2], argv[3])
        return 0
    if len(argv) == 2 and argv[0] == "check":
        check(argv[1])
        return 0
    print(__doc__)
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
