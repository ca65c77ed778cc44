"""Scores of a reconstructed surface against the analytic one (bench_surface.py, issue 13).

    python3 surface_score.py mesh    FILE --cloud CLOUD.json     (or --shape sphere|torus [--radius R])
    python3 surface_score.py normals FILE --cloud CLOUD.json
    python3 surface_score.py points  FILE --cloud CLOUD.json
prints one JSON object. Files: .vtp, .vtk (legacy), .ply, .obj (meshes and clouds), .pcd (ascii, binary,
binary_compressed clouds). Needs numpy, scipy and VTK's Python modules (pvpython, or Debian's python3).

Reference surfaces: the unit sphere (or a sphere of radius R: the SPH ball's volume-equivalent sphere), the torus
R = 1, r = 0.35 about z, and an axis-aligned box (the SPH block); signed distance positive outside.

mesh     the vertices used by a triangle: rms, max, p99 of the distance to the surface and bias = their mean
         signed distance; nan_vertices (left out of everything else). Coverage = distance from a dense, seeded
         sample of the true surface (200,000 points) to the nearest mesh vertex: cov_mean, cov_max (a one-sided
         Hausdorff distance; it sees holes and missing parts). Topology after welding coincident vertices
         (marching cubes outputs need not share them): triangles, vertices, boundary_edges (one triangle),
         nonmanifold_edges (three or more), euler = V - E + F (closed sphere 2, closed torus 0), components
         (connected pieces: spurious bubbles show here), watertight = triangles exist and every edge has exactly
         two. volume = the enclosed volume by the divergence theorem (sum over triangles of v0.(v1 x v2)/6,
         positive when the triangles face outward), only meaningful for a watertight mesh. When the mesh has a
         point array Normals: mesh_normal_angle (mean angle, degrees, to the exact normal at the vertex) and
         mesh_normal_outward (share pointing outward).
normals  angle between each estimated normal line and the exact normal (undirected: mean, p95, max), share of
         normals pointing outward, consistent = share on the majority side (1 = one orientation everywhere,
         outward or inward), bad_normals (NaN or zero length, left out).
points   rms, max, p99 distance and bias of the points to the surface (a smoothed or projected cloud).
"""
import json
import math
import os
import sys

import numpy as np

DENSE_SAMPLES = 200000


# ---------------------------------------------------------------------------------------------- reference
class Reference:
    """An analytic surface: signed distance, exact normal, dense area-uniform sample."""

    def __init__(self, shape, radius=1.0, R=1.0, r=0.35, lo=None, hi=None):
        self.shape, self.radius, self.R, self.r = shape, float(radius), float(R), float(r)
        self.lo = None if lo is None else np.asarray(lo, float)
        self.hi = None if hi is None else np.asarray(hi, float)

    @classmethod
    def from_cloud(cls, meta):
        return cls(**meta["reference"])

    def signed_distance(self, p):
        if self.shape == "sphere":
            return np.linalg.norm(p, axis=1) - self.radius
        if self.shape == "torus":
            return np.hypot(np.hypot(p[:, 0], p[:, 1]) - self.R, p[:, 2]) - self.r
        centre, half = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
        q = np.abs(p - centre) - half
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)

    def normal(self, p):
        """Exact outward unit normal at the closest surface point."""
        if self.shape == "sphere":
            d = p
        elif self.shape == "torus":
            rho = np.maximum(np.hypot(p[:, 0], p[:, 1]), 1e-300)
            d = p - np.column_stack([p[:, 0] * self.R / rho, p[:, 1] * self.R / rho, np.zeros(len(p))])
        else:  # box: the face of the largest normalised excursion
            centre, half = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
            q = (p - centre) / half
            axis = np.argmax(np.abs(q), axis=1)
            d = np.zeros_like(p)
            d[np.arange(len(p)), axis] = np.sign(q[np.arange(len(p)), axis])
        return d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]

    def dense_sample(self, m=DENSE_SAMPLES):
        rng = np.random.default_rng([4242, m])
        if self.shape == "sphere":
            v = rng.standard_normal((m, 3))
            return self.radius * v / np.linalg.norm(v, axis=1)[:, None]
        if self.shape == "torus":
            u, v, have = [], [], 0
            while have < m:
                k = 2 * m
                vv = rng.uniform(0.0, 2.0 * math.pi, k)
                keep = rng.uniform(0.0, self.R + self.r, k) <= self.R + self.r * np.cos(vv)
                v.append(vv[keep])
                u.append(rng.uniform(0.0, 2.0 * math.pi, int(keep.sum())))
                have += int(keep.sum())
            u, v = np.concatenate(u)[:m], np.concatenate(v)[:m]
            ring = self.R + self.r * np.cos(v)
            return np.column_stack([ring * np.cos(u), ring * np.sin(u), self.r * np.sin(v)])
        ext = self.hi - self.lo
        areas = np.array([ext[1] * ext[2], ext[0] * ext[2], ext[0] * ext[1]] * 2)
        face = rng.choice(6, size=m, p=areas / areas.sum())
        p = self.lo + rng.uniform(0.0, 1.0, (m, 3)) * ext
        axis = face % 3
        p[np.arange(m), axis] = np.where(face >= 3, self.hi[axis], self.lo[axis])
        return p


# ---------------------------------------------------------------------------------------------- reading
def _vtk_polydata(path):
    ext = os.path.splitext(path)[1].lower()
    if ext == ".vtp":
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader as Reader
    elif ext == ".vtk":
        from vtkmodules.vtkIOLegacy import vtkPolyDataReader as Reader
    elif ext == ".ply":
        from vtkmodules.vtkIOPLY import vtkPLYReader as Reader
    elif ext == ".obj":
        from vtkmodules.vtkIOGeometry import vtkOBJReader as Reader
    else:
        raise ValueError("cannot read %s" % path)
    reader = Reader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def _points_and_normals(pd):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    if pd.GetPoints() is None or pd.GetNumberOfPoints() == 0:
        return np.zeros((0, 3)), None
    p = vtk_to_numpy(pd.GetPoints().GetData()).astype(float)
    arr = pd.GetPointData().GetArray("Normals")
    if arr is None:
        arr = pd.GetPointData().GetNormals()
    n = vtk_to_numpy(arr).astype(float) if arr is not None and arr.GetNumberOfComponents() == 3 else None
    return p, n


def read_mesh(path):
    """Vertices (n, 3), triangles (m, 3) (polygons fanned; vertices, lines and strips ignored) and the point
    array Normals if any."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    pd = _vtk_polydata(path)
    v, normals = _points_and_normals(pd)
    polys = pd.GetPolys()
    if polys is None or polys.GetNumberOfCells() == 0:
        return v, np.zeros((0, 3), np.int64), normals
    offsets = vtk_to_numpy(polys.GetOffsetsArray()).astype(np.int64)
    conn = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64)
    sizes = np.diff(offsets)
    if np.all(sizes == 3):
        return v, conn.reshape(-1, 3), normals
    tris = []
    for k in np.unique(sizes[sizes >= 3]):
        starts = offsets[:-1][sizes == k]
        for j in range(1, k - 1):  # fan (0, j, j + 1)
            tris.append(np.column_stack([conn[starts], conn[starts + j], conn[starts + j + 1]]))
    return v, np.concatenate(tris), normals


_PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4",
              ("U", 8): "<u8", ("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4", ("I", 8): "<i8"}


def lzf_decompress(src, size):
    """LZF (liblzf) decompression, as used by PCD's binary_compressed: control byte < 32 = a literal run of
    ctrl + 1 bytes; otherwise a back reference of length (ctrl >> 5) + 2 (7 = one more length byte) at
    distance ((ctrl & 31) << 8 | next byte) + 1."""
    out = bytearray(size)
    i, o, n = 0, 0, len(src)
    while i < n:
        ctrl = src[i]
        i += 1
        if ctrl < 32:
            run = ctrl + 1
            out[o:o + run] = src[i:i + run]
            i += run
            o += run
            continue
        length = ctrl >> 5
        if length == 7:
            length += src[i]
            i += 1
        ref = o - ((ctrl & 31) << 8) - src[i] - 1
        i += 1
        length += 2
        if ref + length <= o:
            out[o:o + length] = out[ref:ref + length]
        else:  # overlapping copy repeats the pattern
            for k in range(length):
                out[o + k] = out[ref + k]
        o += length
    if o != size:
        raise ValueError("LZF stream decoded to %d bytes, expected %d" % (o, size))
    return bytes(out)


def read_pcd(path):
    """Points and (if present) normals of a PCD file: ascii, binary or binary_compressed."""
    with open(path, "rb") as f:
        blob = f.read()
    head, pos = {}, 0
    while True:
        end = blob.index(b"\n", pos)
        line = blob[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, rest = line.partition(" ")
        head[key.upper()] = rest.split()
        if key.upper() == "DATA":
            break
    fields, sizes, types = head["FIELDS"], [int(s) for s in head["SIZE"]], head["TYPE"]
    counts = [int(c) for c in head.get("COUNT", ["1"] * len(fields))]
    n = int(head["POINTS"][0])
    names = ["%s_%d" % (f, i) if f == "_" else f for i, f in enumerate(fields)]
    mode = head["DATA"][0].lower()
    if mode == "ascii":
        flat = np.loadtxt(blob[pos:].decode("ascii").splitlines(), ndmin=2)
        cols, c = {}, 0
        for name, count in zip(names, counts):
            cols[name] = flat[:, c] if count == 1 else flat[:, c:c + count]
            c += count
    else:
        dtypes = [(name, _PCD_TYPES[(t, s)], (c,) if c > 1 else ()) for name, t, s, c in
                  zip(names, types, sizes, counts)]
        if mode == "binary":
            cols = np.frombuffer(blob, dtype=np.dtype(dtypes), count=n, offset=pos)
        elif mode == "binary_compressed":
            csize, usize = np.frombuffer(blob, "<u4", 2, pos)
            raw = lzf_decompress(blob[pos + 8:pos + 8 + int(csize)], int(usize))
            cols, off = {}, 0  # field after field (structure of arrays)
            for name, dt, shape in dtypes:
                width = np.dtype(dt).itemsize * (shape[0] if shape else 1)
                cols[name] = np.frombuffer(raw, dt, n * (shape[0] if shape else 1), off).reshape((n,) + shape)
                off += width * n
        else:
            raise ValueError("unknown PCD DATA %s" % mode)
    p = np.column_stack([np.asarray(cols[c], float) for c in ("x", "y", "z")])
    nrm = None
    if all(c in names for c in ("normal_x", "normal_y", "normal_z")):
        nrm = np.column_stack([np.asarray(cols[c], float) for c in ("normal_x", "normal_y", "normal_z")])
    return p, nrm


def read_cloud(path):
    if path.lower().endswith(".pcd"):
        return read_pcd(path)
    return _points_and_normals(_vtk_polydata(path))


# ---------------------------------------------------------------------------------------------- scores
def topology(v, tris):
    """Welds bit-identical vertices, drops triangles that collapse, counts edges by their triangles."""
    if len(tris) == 0:
        return dict(vertices_welded=0, edges=0, boundary_edges=0, nonmanifold_edges=0, euler=0, components=0,
                    degenerate_triangles=0, watertight=False, volume=0.0)
    used = np.unique(tris)
    key = np.ascontiguousarray(v[used]).view(np.dtype((np.void, 24))).ravel()
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    remap = np.empty(len(v), np.int64)
    remap[used] = inverse.ravel()
    t = remap[tris]
    ok = (t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])
    t = t[ok]
    nv = len(first)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    ekey = e[:, 0] * nv + e[:, 1]
    _, counts = np.unique(ekey, return_counts=True)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    graph = coo_matrix((np.ones(len(e), np.int8), (e[:, 0], e[:, 1])), shape=(nv, nv))
    ncomp, _ = connected_components(graph, directed=False)
    verts_used = len(np.unique(t)) if len(t) else 0
    pw = v[used][first]
    a, b, c = pw[t[:, 0]], pw[t[:, 1]], pw[t[:, 2]]
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
    return dict(vertices_welded=int(verts_used), edges=int(len(counts)), boundary_edges=int((counts == 1).sum()),
                nonmanifold_edges=int((counts > 2).sum()), euler=int(verts_used - len(counts) + len(t)),
                components=int(ncomp - (nv - verts_used)), degenerate_triangles=int((~ok).sum()),
                watertight=bool(len(t) > 0 and np.all(counts == 2)), volume=volume)


def score_mesh(path, ref, with_topology=True):
    from scipy.spatial import cKDTree
    v, tris, normals = read_mesh(path)
    out = dict(triangles=int(len(tris)))
    used = np.unique(tris) if len(tris) else np.arange(len(v))
    finite = np.isfinite(v[used]).all(axis=1)
    out["nan_vertices"] = int((~finite).sum())
    if len(tris):
        bad = ~np.isfinite(v).all(axis=1)
        tris = tris[~bad[tris].any(axis=1)]
    used = used[finite]
    out["vertices"] = int(len(used))
    if len(used) == 0:
        out["error"] = "no finite vertex"
        return out
    sd = ref.signed_distance(v[used])
    d = np.abs(sd)
    out.update(rms=float(np.sqrt(np.mean(d * d))), max=float(d.max()), p99=float(np.percentile(d, 99)),
               bias=float(sd.mean()))
    cov, _ = cKDTree(v[used]).query(ref.dense_sample(), workers=-1)
    out.update(cov_mean=float(cov.mean()), cov_max=float(cov.max()))
    if normals is not None and len(normals) == len(v):
        nn = normals[used]
        ok = np.isfinite(nn).all(axis=1) & (np.linalg.norm(nn, axis=1) > 0.5)
        if ok.any():
            nn = nn[ok] / np.linalg.norm(nn[ok], axis=1)[:, None]
            dot = np.einsum("ij,ij->i", nn, ref.normal(v[used][ok]))
            out.update(mesh_normal_angle=float(np.degrees(np.arccos(np.clip(dot, -1.0, 1.0))).mean()),
                       mesh_normal_outward=float((dot > 0).mean()))
    if with_topology:
        out.update(topology(v, tris))
    return out


def score_normals(path, ref):
    p, n = read_cloud(path)
    out = dict(points=int(len(p)))
    if n is None:
        out["error"] = "no normals in %s" % os.path.basename(path)
        return out
    length = np.linalg.norm(n, axis=1)
    ok = np.isfinite(n).all(axis=1) & np.isfinite(p).all(axis=1) & (length > 0.5)
    out["bad_normals"] = int((~ok).sum())
    if not ok.any():
        out["error"] = "no usable normal"
        return out
    dot = np.einsum("ij,ij->i", n[ok] / length[ok][:, None], ref.normal(p[ok]))
    angle = np.degrees(np.arccos(np.clip(np.abs(dot), 0.0, 1.0)))
    outward = float((dot > 0).mean())
    out.update(ang_mean=float(angle.mean()), ang_p95=float(np.percentile(angle, 95)), ang_max=float(angle.max()),
               outward=outward, consistent=max(outward, float((dot < 0).mean())))
    return out


def score_points(path, ref):
    p, _ = read_cloud(path)
    ok = np.isfinite(p).all(axis=1)
    out = dict(points=int(len(p)), nan_points=int((~ok).sum()))
    if not ok.any():
        out["error"] = "no finite point"
        return out
    sd = ref.signed_distance(p[ok])
    d = np.abs(sd)
    out.update(rms=float(np.sqrt(np.mean(d * d))), max=float(d.max()), p99=float(np.percentile(d, 99)),
               bias=float(sd.mean()))
    return out


def score(kind, path, ref):
    return {"mesh": score_mesh, "normals": score_normals, "points": score_points}[kind](path, ref)


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("kind", choices=["mesh", "normals", "points"])
    ap.add_argument("path")
    ap.add_argument("--cloud", help="the cloud's .json written by surface_clouds.py (gives the reference)")
    ap.add_argument("--shape", choices=["sphere", "torus"])
    ap.add_argument("--radius", type=float, default=1.0)
    a = ap.parse_args(argv)
    if a.cloud:
        with open(a.cloud) as f:
            ref = Reference.from_cloud(json.load(f))
    elif a.shape:
        ref = Reference(a.shape, radius=a.radius)
    else:
        ap.error("give --cloud or --shape")
    print(json.dumps(score(a.kind, a.path, ref)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
