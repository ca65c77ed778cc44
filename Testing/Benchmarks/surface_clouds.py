"""Seeded test clouds for the surface-reconstruction benchmark (bench_surface.py, issue 13), and their files.

Surfaces (exact outward normals known):
  sphere   unit sphere, points uniform by area (normalised Gaussian vectors)
  torus    ring radius R = 1, tube radius r = 0.35, axis z; uniform by area: the area element is
           (R + r cos v) du dv, so v is drawn by rejection against (R + r cos v) / (R + r)
  each with isotropic Gaussian noise of standard deviation sigma per axis (0 or 0.005) added to the positions;
  the clean and the noisy cloud of one shape and size share the same surface points.
SPH particles (spacing H known; the fluid's volume is N H^3, one lattice cell per particle):
  ball     cubic lattice of spacing H = (4/3 pi / N)^(1/3), the cells whose centre lies in the unit ball,
           centres jittered uniformly by +-0.1 H per axis. Reference: the sphere of the
           volume-equivalent radius, 4/3 pi R^3 = N H^3.
  block    a resting fluid block 2 x 1 x 0.5 (on the floor z = 0): nx x ny x nz lattice cells of spacing
           H = (1 / N)^(1/3), jittered the same way. Reference: the box of the lattice cells, whose volume
           is exactly N H^3.

Files written per cloud into the work folder (float32 everywhere, so that every tool sees the same points):
  NAME.vtp       vertices + point array Normals (exact)    MeshFree, VTK       (SPH clouds: no Normals)
  NAME_xyz.vtp   vertices only                             MeshFree, VTK
  NAME.ply       binary PLY x y z nx ny nz                 Open3D
  NAME.pcd       binary PCD x y z normal_x normal_y normal_z curvature      PCL (normals given)
  NAME_xyz.pcd   binary PCD x y z                          PCL (positions only)
  NAME.json      what the scorer needs: shape, reference radius / box, spacing, particle volume
"""
import json
import math
import os

import numpy as np

TORUS_R, TORUS_r = 1.0, 0.35
NOISE_SIGMA = 0.005
BLOCK_SIZE = (2.0, 1.0, 0.5)
JITTER = 0.1        # SPH lattice jitter, in spacings (uniform, per axis)
FORMAT_VERSION = 2  # bump when the clouds change: cached files of another version are rewritten
_SHAPE_SEED = {"sphere": 1, "torus": 2, "ball": 3, "block": 4}


def size_label(n):
    """100000 -> '100k', 1000000 -> '1M', 20000 -> '20k', 12345 -> '12345'."""
    if n >= 1000000 and n % 1000000 == 0:
        return "%dM" % (n // 1000000)
    if n >= 1000 and n % 1000 == 0:
        return "%dk" % (n // 1000)
    return str(n)


def noise_label(sigma):
    return "n0" if sigma == 0 else "n" + ("%g" % sigma).split(".")[1]  # 0.005 -> n005


def cloud_name(shape, n, sigma=0.0):
    if shape in ("ball", "block"):
        return "sph_%s_%s" % (shape, size_label(n))
    return "%s_%s_%s" % (shape, size_label(n), noise_label(sigma))


def _rng(shape, n, salt=0):
    return np.random.default_rng([20240513, _SHAPE_SEED[shape], n, salt])


# ---------------------------------------------------------------------------------------------- shapes
def sample_sphere(n, rng, radius=1.0):
    v = rng.standard_normal((n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    return radius * v, v.copy()


def sample_torus(n, rng):
    us, vs, have = [], [], 0
    while have < n:
        m = (n - have) * 3 // 2 + 64
        v = rng.uniform(0.0, 2.0 * math.pi, m)
        keep = rng.uniform(0.0, 1.0, m) * (TORUS_R + TORUS_r) <= TORUS_R + TORUS_r * np.cos(v)
        vs.append(v[keep])
        us.append(rng.uniform(0.0, 2.0 * math.pi, int(keep.sum())))
        have += int(keep.sum())
    u, v = np.concatenate(us)[:n], np.concatenate(vs)[:n]
    normal = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
    centre = np.column_stack([TORUS_R * np.cos(u), TORUS_R * np.sin(u), np.zeros(n)])
    return centre + TORUS_r * normal, normal


def sample_surface_box(n, rng, lo, hi):
    """Points uniform by area on the boundary of the box [lo, hi] (for the scorer's coverage sample)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    ext = hi - lo
    areas = np.array([ext[1] * ext[2], ext[0] * ext[2], ext[0] * ext[1]] * 2)
    face = rng.choice(6, size=n, p=areas / areas.sum())
    p = lo + rng.uniform(0.0, 1.0, (n, 3)) * ext
    axis, upper = face % 3, face >= 3
    p[np.arange(n), axis] = np.where(upper, hi[axis], lo[axis])
    return p


def lattice_ball(n, rng):
    h = (4.0 / 3.0 * math.pi / n) ** (1.0 / 3.0)
    m = int(math.ceil(1.0 / h)) + 1
    g = (np.arange(-m, m) + 0.5) * h
    c = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    c = c[np.einsum("ij,ij->i", c, c) <= 1.0]
    c += rng.uniform(-JITTER * h, JITTER * h, c.shape)
    return c, h


def lattice_block(n, rng):
    h = (BLOCK_SIZE[0] * BLOCK_SIZE[1] * BLOCK_SIZE[2] / n) ** (1.0 / 3.0)
    counts = [max(1, int(round(s / h))) for s in BLOCK_SIZE]
    lo = np.array([-0.5 * counts[0] * h, -0.5 * counts[1] * h, 0.0])
    axes = [lo[i] + (np.arange(counts[i]) + 0.5) * h for i in range(3)]
    c = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    c += rng.uniform(-JITTER * h, JITTER * h, c.shape)
    return c, h, lo, lo + np.array(counts) * h


# ---------------------------------------------------------------------------------------------- writers
def write_ply(path, points, normals=None):
    cols = [points] if normals is None else [points, normals]
    data = np.ascontiguousarray(np.hstack(cols), dtype="<f4")
    names = ["x", "y", "z"] + ([] if normals is None else ["nx", "ny", "nz"])
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n%send_header\n" % (
        len(points), "".join("property float %s\n" % c for c in names))
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(data.tobytes())


def write_pcd(path, points, normals=None):
    if normals is None:
        fields, data = ["x", "y", "z"], points
    else:
        fields = ["x", "y", "z", "normal_x", "normal_y", "normal_z", "curvature"]
        data = np.hstack([points, normals, np.zeros((len(points), 1))])
    k = len(fields)
    header = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\nCOUNT %s\n"
              "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n") % (
        " ".join(fields), " ".join(["4"] * k), " ".join(["F"] * k), " ".join(["1"] * k), len(points), len(points))
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(data, dtype="<f4").tobytes())


def write_vtp(path, points, normals=None):
    """A vtkPolyData of one vertex cell per point (what a reader of a point cloud gives), raw appended data."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    n = len(points)
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float32), deep=True))
    verts = vtkCellArray()
    verts.SetData(numpy_to_vtkIdTypeArray(np.arange(n + 1, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.arange(n, dtype=np.int64), deep=True))
    pd = vtkPolyData()
    pd.SetPoints(pts)
    pd.SetVerts(verts)
    if normals is not None:
        arr = numpy_to_vtk(np.ascontiguousarray(normals, dtype=np.float32), deep=True)
        arr.SetName("Normals")
        pd.GetPointData().AddArray(arr)
    w = vtkXMLPolyDataWriter()
    w.SetFileName(path)
    w.SetInputData(pd)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.SetCompressorTypeToNone()
    if not w.Write():
        raise RuntimeError("could not write " + path)


# ---------------------------------------------------------------------------------------------- clouds
def make_cloud(folder, shape, n, sigma=0.0, formats=("vtp", "ply", "pcd")):
    """Writes the cloud's files into folder (unless already there in this version); returns its description."""
    name = cloud_name(shape, n, sigma)
    base = os.path.join(folder, name)
    meta_path = base + ".json"
    if os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
        if meta.get("version") == FORMAT_VERSION and all(
                os.path.exists(base + s) for s in _suffixes(meta["kind"], formats)):
            return meta
    meta = dict(version=FORMAT_VERSION, name=name, shape=shape, n_requested=n, sigma=sigma,
                files={_file_key(s): base + s for s in _suffixes(
                    "sph" if shape in ("ball", "block") else "surface", formats)})
    if shape in ("sphere", "torus"):
        meta["kind"] = "surface"
        points, normals = (sample_sphere if shape == "sphere" else sample_torus)(n, _rng(shape, n))
        if sigma > 0:
            points = points + _rng(shape, n, 1).normal(scale=sigma, size=points.shape)
        area = 4.0 * math.pi if shape == "sphere" else 4.0 * math.pi ** 2 * TORUS_R * TORUS_r
        meta.update(n=len(points), reference=dict(shape=shape, radius=1.0) if shape == "sphere" else dict(
            shape="torus", R=TORUS_R, r=TORUS_r), mean_spacing=math.sqrt(area / n))
        if "vtp" in formats:
            write_vtp(base + ".vtp", points, normals)
            write_vtp(base + "_xyz.vtp", points)
        if "ply" in formats:
            write_ply(base + ".ply", points, normals)
        if "pcd" in formats:
            write_pcd(base + ".pcd", points, normals)
            write_pcd(base + "_xyz.pcd", points)
    else:
        meta["kind"] = "sph"
        if shape == "ball":
            points, h = lattice_ball(n, _rng(shape, n))
            radius = (3.0 * len(points) / (4.0 * math.pi)) ** (1.0 / 3.0) * h
            meta["reference"] = dict(shape="sphere", radius=radius)
        else:
            points, h, lo, hi = lattice_block(n, _rng(shape, n))
            meta["reference"] = dict(shape="box", lo=lo.tolist(), hi=hi.tolist())
        meta.update(n=len(points), spacing=h, particle_volume=len(points) * h ** 3)
        write_vtp(base + ".vtp", points)
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=1)
    return meta


def _file_key(suffix):
    """'.vtp' -> 'vtp', '_xyz.pcd' -> 'xyz_pcd'."""
    return suffix.lstrip("_").replace(".", "_").lstrip("_")


def _suffixes(kind, formats):
    if kind == "sph":
        return [".vtp"]
    out = []
    if "vtp" in formats:
        out += [".vtp", "_xyz.vtp"]
    if "ply" in formats:
        out += [".ply"]
    if "pcd" in formats:
        out += [".pcd", "_xyz.pcd"]
    return out


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description="write the benchmark's clouds into a folder")
    ap.add_argument("folder")
    ap.add_argument("--sizes", type=int, nargs="+", default=[20000])
    a = ap.parse_args()
    os.makedirs(a.folder, exist_ok=True)
    for size in a.sizes:
        for shp in ("sphere", "torus"):
            for s in (0.0, NOISE_SIGMA):
                print(make_cloud(a.folder, shp, size, s)["name"])
        for shp in ("ball", "block"):
            m = make_cloud(a.folder, shp, size)
            print(m["name"], m["n"], "particles, spacing %.5g" % m["spacing"])
