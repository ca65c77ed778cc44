"""One scorer for every tool of the scan benchmark (bench_scans.py, issue 23): meshes against a reference surface
(a triangle mesh or an analytic shape) and estimated normals against true ones.

Mesh scores (score_mesh):
  vertices, triangles, nan_vertices        after welding coincident vertices (marching-cubes outputs repeat
                                           them) and dropping degenerate triangles and NaN vertices
  boundary_edges, nonmanifold_edges        edges used by one triangle / by more than two
  euler                                    chi = V - E + F (2: one closed sphere-like piece; 0: a torus)
  pieces, stray_triangles                  connected pieces; triangles outside the largest piece
  scored_share                             share of the vertices within `delta` of a data point: "where the
                                           reference has data" - only those are scored against the reference
  rms, p99, max                            their distance to the reference surface
  inner_rms, inner_p99, inner_share        the vertex scores over the vertices whose closest reference point is
                                           not on the reference's border (a reference with holes, e.g. a
                                           scanner's unseen base, has no surface over them: a vertex there
                                           measures its distance to the hole's rim); inner_share = their share
  area_rms, area_p99                       the inner scores over an area-uniform sample of the mesh (within
                                           `delta` of a data point, closest reference point not on its border)
                                           instead of its vertices: independent of the tessellation (an adaptive
                                           mesher, e.g. screened Poisson's octree, puts fewer vertices where the
                                           data are sparse)
  cov_rms, cov_p99, cov_far_share          coverage: a dense area-uniform sample of the reference surface, kept
                                           where the data are (within `delta` of a data point), to the mesh;
                                           cov_far_share = share of those samples farther than `delta` from
                                           the mesh (holes, missing parts)
Distances from points to a triangle mesh are exact: a KD-tree (scipy cKDTree) over the triangle centroids (long
triangles contribute the centroids of n x n similar sub-triangles) gives k candidate triangles per point and the
exact point-triangle distance (closest point by Voronoi region of the triangle; Ericson, Real-Time Collision
Detection, 2005, sec. 5.1.5) is taken over them; the result is certified when the k-th site is farther than the
best distance plus the largest centroid-to-corner distance of any (sub-)triangle (no other triangle can then be
closer); uncertified points are redone with 4k candidates and finally with every triangle having a site within
that bound. Analytic references (virtual_scan.py)
give their exact distance directly.

Normal scores (score_normals): angle between the estimated and the true normal line (degrees; mean, p99), the
share on the majority side (1 = consistently oriented) and the share pointing outward (true normals outward).
numpy + scipy only; reading meshes (read_mesh) uses VTK for .vtp/.vtk/.ply (pvpython) and numpy for .off/.xyz.
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


# ---------------------------------------------------------------------------------------- point-triangle
def closest_on_triangles(p, a, b, c):
    """Closest points on triangles (a, b, c) to points p, all (m, 3), row by row."""
    ab, ac, ap = b - a, c - a, p - a
    d1 = np.einsum("ij,ij->i", ab, ap)
    d2 = np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3 = np.einsum("ij,ij->i", ab, bp)
    d4 = np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5 = np.einsum("ij,ij->i", ab, cp)
    d6 = np.einsum("ij,ij->i", ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v = vb / denom
        w = vc / denom
        out = a + ab * v[:, None] + ac * w[:, None]  # inside the face
        wbc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        sel = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
        out[sel] = (b + (c - b) * wbc[:, None])[sel]
        wac = d2 / (d2 - d6)
        sel = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        out[sel] = (a + ac * wac[:, None])[sel]
        sel = (d6 >= 0) & (d5 <= d6)
        out[sel] = c[sel]
        vab = d1 / (d1 - d3)
        sel = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        out[sel] = (a + ab * vab[:, None])[sel]
        sel = (d3 >= 0) & (d4 <= d3)
        out[sel] = b[sel]
        sel = (d1 <= 0) & (d2 <= 0)
        out[sel] = a[sel]
    bad = ~np.isfinite(out).all(axis=1)  # degenerate triangle: nearest of its corners
    if bad.any():
        corners = np.stack([a[bad], b[bad], c[bad]], axis=1)
        k = np.argmin(np.linalg.norm(corners - p[bad][:, None, :], axis=2), axis=1)
        out[bad] = corners[np.arange(len(k)), k]
    return out


class TriangleDistance:
    """Exact unsigned distance from points to a triangle mesh (see the module's note)."""

    def __init__(self, points, triangles):
        self.v = np.asarray(points, dtype=float)
        self.t = np.asarray(triangles, dtype=np.int64)
        a, b, c = (self.v[self.t[:, j]] for j in range(3))
        # Triangles larger than the median are split (for the search only) into n x n similar sub-triangles
        # so that one bound - the largest centroid-to-corner distance of any piece - stays at the median
        # triangle's and the certification succeeds with few candidates.
        centre = (a + b + c) / 3.0
        reach = np.linalg.norm(np.stack([a, b, c], axis=1) - centre[:, None, :], axis=2).max(axis=1)
        n = np.clip(np.ceil(reach / max(np.median(reach), 1e-300)), 1, 64).astype(np.int64)
        self.reach = float((reach / n).max())
        sites, owner = [centre[n == 1]], [np.nonzero(n == 1)[0]]
        for m in np.unique(n[n > 1]):
            sel = np.nonzero(n == m)[0]
            uv = [((3 * i + 1) / (3.0 * m), (3 * j + 1) / (3.0 * m)) for i in range(m) for j in range(m - i)]
            uv += [((3 * i + 2) / (3.0 * m), (3 * j + 2) / (3.0 * m)) for i in range(m) for j in range(m - 1 - i)]
            uv = np.array(uv)
            ab, ac = (b - a)[sel], (c - a)[sel]
            pts = a[sel][:, None, :] + uv[None, :, 0, None] * ab[:, None, :] + uv[None, :, 1, None] * ac[:, None, :]
            sites.append(pts.reshape(-1, 3))
            owner.append(np.repeat(sel, len(uv)))
        self.sites = np.concatenate(sites)
        self.owner = np.concatenate(owner)
        self.tree = cKDTree(self.sites)

    def _exact(self, p, cand):
        """Min distance of each p[i] to the triangles cand[i, :] (cand (m, k))."""
        m, k = cand.shape
        rep = np.repeat(p, k, axis=0)
        tri = self.t[cand.ravel()]
        q = closest_on_triangles(rep, self.v[tri[:, 0]], self.v[tri[:, 1]], self.v[tri[:, 2]])
        return np.linalg.norm(rep - q, axis=1).reshape(m, k).min(axis=1)

    def distance(self, points, k=16, chunk=40000):
        p = np.asarray(points, dtype=float)
        out = np.empty(len(p))
        k = min(k, len(self.sites))
        for s in range(0, len(p), chunk):
            out[s:s + chunk] = self._certified(p[s:s + chunk], k)
        return out

    def _certified(self, p, k):
        dc, near = self.tree.query(p, k=k)
        if k == 1:
            dc, near = dc[:, None], near[:, None]
        d = self._exact(p, self.owner[near])
        if k >= len(self.sites):
            return d
        todo = np.nonzero(dc[:, -1] - self.reach < d)[0]
        if len(todo) == 0:
            return d
        if 4 * k <= 256 and 4 * k < len(self.sites):
            d[todo] = self._certified(p[todo], 4 * k)
            return d
        for i in todo:  # every triangle with a search site within the bound
            idx = np.unique(self.owner[self.tree.query_ball_point(p[i], d[i] + self.reach)])
            if len(idx):
                d[i] = min(d[i], self._exact(p[i:i + 1], idx[None, :])[0])
        return d

    def border_distance(self, points):
        """Exact distance from points to the mesh's border (edges used by one triangle); +inf without a border."""
        if not hasattr(self, "_border"):
            e = np.sort(np.concatenate([self.t[:, [0, 1]], self.t[:, [1, 2]], self.t[:, [2, 0]]]), axis=1)
            edges, counts = np.unique(e, axis=0, return_counts=True)
            self._border = edges[counts == 1]
        p = np.asarray(points, dtype=float)
        out = np.full(len(p), np.inf)
        if len(self._border) == 0:
            return out
        a, b = self.v[self._border[:, 0]], self.v[self._border[:, 1]]
        ab = b - a
        len2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
        chunk = max(1, 2000000 // len(ab))  # points x edges x 3 doubles per step: about 50 MB
        for s in range(0, len(p), chunk):
            q = p[s:s + chunk, None, :] - a[None, :, :]
            t = np.clip(np.einsum("ijk,jk->ij", q, ab) / len2[None, :], 0.0, 1.0)
            out[s:s + chunk] = np.linalg.norm(q - t[:, :, None] * ab[None, :, :], axis=2).min(axis=1)
        return out

    def sample(self, n, rng):
        """n points uniform by area on the mesh."""
        a, b, c = (self.v[self.t[:, j]] for j in range(3))
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        tri = rng.choice(len(self.t), n, p=area / area.sum())
        r1, r2 = rng.random(n), rng.random(n)
        s = np.sqrt(r1)
        return (1 - s)[:, None] * a[tri] + (s * (1 - r2))[:, None] * b[tri] + (s * r2)[:, None] * c[tri]


# ---------------------------------------------------------------------------------------------- topology
def clean_mesh(points, triangles, weld=1e-9):
    """Weld vertices closer than weld x (bounding-box diagonal) on a grid, drop NaN vertices' and degenerate
    triangles, keep only used vertices. Returns points, triangles, the number of NaN vertices."""
    p = np.asarray(points, dtype=float)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    finite = np.isfinite(p).all(axis=1)
    nan_vertices = int((~finite).sum())
    t = t[finite[t].all(axis=1)]
    if len(t) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), nan_vertices
    good = p[finite]
    diag = float(np.linalg.norm(good.max(0) - good.min(0))) or 1.0
    key = np.zeros((len(p), 3), dtype=np.int64)
    key[finite] = np.round(good / (weld * diag)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    t = inverse[t]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    used, t = np.unique(t, return_inverse=True)
    return p[first][used], t.reshape(-1, 3), nan_vertices


def topology(points, triangles):
    v, t = points, triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    n = len(v)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    used = np.unique(t)  # vertices no triangle uses count neither as vertices nor as pieces
    tri_label = label[t[:, 0]]
    largest = np.bincount(tri_label).max() if len(t) else 0
    return dict(vertices=int(len(used)), triangles=int(len(t)), edges=int(len(edges)),
                boundary_edges=int((counts == 1).sum()), nonmanifold_edges=int((counts > 2).sum()),
                euler=int(len(used) - len(edges) + len(t)), pieces=int(len(np.unique(label[used]))),
                stray_triangles=int(len(t) - largest))


def _stats(d, prefix=""):
    if len(d) == 0:
        return {prefix + "rms": float("nan"), prefix + "p99": float("nan"), prefix + "max": float("nan")}
    return {prefix + "rms": float(np.sqrt(np.mean(d * d))), prefix + "p99": float(np.percentile(d, 99)),
            prefix + "max": float(d.max())}


def score_mesh(points, triangles, data, reference, delta, cover_samples=200000, seed=1):
    """All mesh scores (module note). data: the input cloud (n, 3); reference: an object with distance(P) and
    sample(n, rng) (TriangleDistance or an analytic shape); delta: the 'has data' radius."""
    v, t, nan_vertices = clean_mesh(points, triangles)
    result = dict(nan_vertices=nan_vertices)
    if len(t) == 0:
        result.update(vertices=0, triangles=0, status="empty mesh")
        return result
    result.update(topology(v, t))
    data_tree = cKDTree(np.asarray(data, dtype=float))
    near, _ = data_tree.query(v, distance_upper_bound=delta)
    scored = np.isfinite(near)
    result["scored_share"] = float(scored.mean())
    d = reference.distance(v[scored])
    result.update(_stats(d))
    border = getattr(reference, "border_distance", None)
    inner = border(v[scored]) > d * (1.0 + 1e-9) + 1e-15 if border else np.ones(len(d), dtype=bool)
    s = _stats(d[inner], "inner_")
    result.update(inner_rms=s["inner_rms"], inner_p99=s["inner_p99"],
                  inner_share=float(inner.mean()) if len(d) else float("nan"))
    mesh = TriangleDistance(v, t)
    on_mesh = mesh.sample(cover_samples, np.random.default_rng(seed + 1))
    on_mesh = on_mesh[np.isfinite(data_tree.query(on_mesh, distance_upper_bound=delta)[0])]
    da = reference.distance(on_mesh)
    s = _stats(da[border(on_mesh) > da * (1.0 + 1e-9) + 1e-15] if border else da, "area_")
    result.update(area_rms=s["area_rms"], area_p99=s["area_p99"])
    rng = np.random.default_rng(seed)
    ref_pts = reference.sample(cover_samples, rng)
    has_data = np.isfinite(data_tree.query(ref_pts, distance_upper_bound=delta)[0])
    cov = mesh.distance(ref_pts[has_data])
    s = _stats(cov, "cov_")
    result.update(cov_rms=s["cov_rms"], cov_p99=s["cov_p99"],
                  cov_far_share=float((cov > delta).mean()) if len(cov) else float("nan"))
    return result


# ----------------------------------------------------------------------------------------------- normals
def score_normals(estimated, true, outward=True):
    n = np.asarray(estimated, dtype=float)
    g = np.asarray(true, dtype=float)
    ok = np.isfinite(n).all(axis=1) & (np.linalg.norm(n, axis=1) > 0)
    n = n[ok] / np.linalg.norm(n[ok], axis=1)[:, None]
    g = g[ok] / np.linalg.norm(g[ok], axis=1)[:, None]
    dot = np.einsum("ij,ij->i", n, g)
    ang = np.degrees(np.arccos(np.clip(np.abs(dot), 0.0, 1.0)))
    plus = float((dot > 0).mean())
    out = dict(ang_mean=float(ang.mean()), ang_p99=float(np.percentile(ang, 99)), consistent=max(plus, 1 - plus),
               invalid=int((~ok).sum()))
    if outward:
        out["outward"] = plus
    return out


# ------------------------------------------------------------------------------------------------ reading
def read_off(path):
    with open(path) as f:
        words = f.read().split()
    i = 1 if words[0].upper().endswith("OFF") else 0
    nv, nf = int(words[i]), int(words[i + 1])
    i += 3
    pts = np.array(words[i:i + 3 * nv], dtype=float).reshape(nv, 3)
    i += 3 * nv
    tri = []
    for _ in range(nf):
        m = int(words[i])
        idx = [int(x) for x in words[i + 1:i + 1 + m]]
        i += 1 + m
        tri.extend((idx[0], idx[k], idx[k + 1]) for k in range(1, m - 1))
    return pts, np.array(tri, dtype=np.int64).reshape(-1, 3)


def polydata_arrays(pd):
    """points (n, 3), triangles (t, 3) of a vtkPolyData (polygons fan-triangulated, other cells ignored)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    pts = vtk_to_numpy(pd.GetPoints().GetData()).astype(float) if pd.GetPoints() else np.zeros((0, 3))
    polys = pd.GetPolys()
    tri = []
    if polys.GetNumberOfCells():
        offsets = vtk_to_numpy(polys.GetOffsetsArray()).astype(np.int64)
        conn = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64)
        sizes = np.diff(offsets)
        if (sizes == 3).all():
            return pts, conn.reshape(-1, 3)
        for s, m in zip(offsets[:-1], sizes):
            tri.extend((conn[s], conn[s + k], conn[s + k + 1]) for k in range(1, m - 1))
    return pts, np.array(tri, dtype=np.int64).reshape(-1, 3)


def read_bin(path):
    """points, triangles, DistanceToData of BenchSurfaceScan's --out file (int64 counts, then float64 points,
    int64 triangles, float64 distances)."""
    raw = open(path, "rb").read()
    nv, nt = (int(c) for c in np.frombuffer(raw[:16], dtype=np.int64))
    o = 16
    pts = np.frombuffer(raw[o:o + 24 * nv], dtype=np.float64).reshape(nv, 3)
    o += 24 * nv
    tri = np.frombuffer(raw[o:o + 24 * nt], dtype=np.int64).reshape(nt, 3)
    o += 24 * nt
    return pts, tri, np.frombuffer(raw[o:o + 8 * nv], dtype=np.float64)


def read_mesh(path):
    """points, triangles of a .off (numpy), .bin (BenchSurfaceScan), .vtp, .vtk (legacy) or .ply (VTK readers)."""
    low = path.lower()
    if low.endswith(".off"):
        return read_off(path)
    if low.endswith(".bin"):
        return read_bin(path)[:2]
    if low.endswith(".vtp"):
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader as Reader
    elif low.endswith(".vtk"):
        from vtkmodules.vtkIOLegacy import vtkPolyDataReader as Reader
    elif low.endswith(".ply"):
        from vtkmodules.vtkIOPLY import vtkPLYReader as Reader
    else:
        raise ValueError("unknown mesh format: " + path)
    r = Reader()
    r.SetFileName(path)
    r.Update()
    return polydata_arrays(r.GetOutput())
