#!/usr/bin/env python3
"""Regenerates every small data file of Data/ (seeded, byte-for-byte reproducible). Needs Python 3 and numpy
only (Debian: /usr/bin/python3 with python3-numpy, or pvpython).

  python3 Data/Scripts/make_data.py            # rewrite the files in Data/
  python3 Data/Scripts/make_data.py --out DIR  # write them elsewhere
  python3 Data/Scripts/make_data.py --check    # regenerate in memory, compare with Data/, exit 1 on a difference

Files (the thesis: M. G. Mero Barcia, "Metodos sin mallas", 2014):
  thesis_9points.xyz          sec. 3.4: the 9 points P with values f (z = f, for height-field fits; column f too)
  random_256.xyz              fig. 3.5: 256 random points in [-1, 1]^2 with random values z = f in [0, 1]
  octahedron_299.pcd          fig. 4.6: 299 phyxels filling the octahedron |x| + |y| + |z|/1.005 <= 1
  ellipsoid_568.pcd           fig. 4.7: 568 phyxels filling the ellipsoid of semi-axes 1, 0.6, 0.5
  ellipsoid_715.pcd           fig. 4.8: 715 phyxels filling the ellipsoid of semi-axes 1, 0.6, 0.4775 ...
  ellipsoid_715_surface.ply   ... and its closed surface: 990 vertices, 1976 triangles (binary PLY)
  scan_torus.pcd              a noisy scan-like cloud of a closed object (a torus seen by 4 scanners), for
                              surface reconstruction: x y z intensity scanner, binary .pcd
The phyxel lattices (cubic or body-centred, spacing below) were chosen to give the thesis' counts exactly.
"""
import argparse
import io
import os
import struct
import sys

import numpy as np

DATA = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def fmt(v):
    return "%.9g" % v


def xyz_text(header, rows, comment):
    out = io.StringIO()
    out.write("# %s\n" % comment)
    out.write(" ".join(header) + "\n")
    for r in rows:
        out.write(" ".join(fmt(v) for v in r) + "\n")
    return out.getvalue().encode()


def pcd_bytes(fields, columns, encoding="ascii", types=None, viewpoint=(0, 0, 0, 1, 0, 0, 0)):
    """A PCL .pcd v0.7 file. columns: one 1-D numpy array per field; types: 'F' (float32) or 'U1'."""
    types = types or ["F"] * len(fields)
    sizes = [4 if t == "F" else 1 for t in types]
    n = len(columns[0])
    head = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\nCOUNT %s\n"
            "WIDTH %d\nHEIGHT 1\nVIEWPOINT %s\nPOINTS %d\nDATA %s\n"
            % (" ".join(fields), " ".join(map(str, sizes)), " ".join(t[0] for t in types),
               " ".join("1" for _ in fields), n, " ".join(fmt(v) for v in viewpoint), n, encoding))
    if encoding == "ascii":
        body = "".join(" ".join(fmt(c[i]) if t == "F" else str(int(c[i])) for c, t in zip(columns, types)) + "\n"
                       for i in range(n))
        return head.encode() + body.encode()
    dtype = np.dtype([(f, "<f4" if t == "F" else "u1") for f, t in zip(fields, types)])
    rec = np.zeros(n, dtype=dtype)
    for f, c in zip(fields, columns):
        rec[f] = c
    return head.encode() + rec.tobytes()


def lattice(spacing, offset=0.0, bcc=False, extent=1.6):
    n = int(np.ceil(extent / spacing)) + 2
    g = (np.arange(-n, n + 1) + offset) * spacing
    p = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    if bcc:
        p = np.vstack([p, p + spacing / 2])
    return p


def phyxels(inside, expected, **kw):
    p = lattice(**kw)
    p = p[inside(p)]
    assert len(p) == expected, (len(p), expected)
    # A stable order (z, then y, then x) so that the file does not depend on the lattice's construction.
    return p[np.lexsort((p[:, 0], p[:, 1], p[:, 2]))].astype(np.float32)


def ellipsoid_surface(a, b, c, rings=26, segments=38):
    """A closed UV-ellipsoid: 2 poles + rings x segments vertices (990), 2 x segments x rings triangles
    (1976), outward (counter-clockwise) orientation."""
    verts = [(0.0, 0.0, c)]
    for i in range(1, rings + 1):
        theta = np.pi * i / (rings + 1)
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            verts.append((a * np.sin(theta) * np.cos(phi), b * np.sin(theta) * np.sin(phi), c * np.cos(theta)))
    verts.append((0.0, 0.0, -c))
    south = len(verts) - 1
    tris = []
    ring = lambda i, j: 1 + i * segments + (j % segments)
    for j in range(segments):
        tris.append((0, ring(0, j), ring(0, j + 1)))
    for i in range(rings - 1):
        for j in range(segments):
            tris.append((ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)))
            tris.append((ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)))
    for j in range(segments):
        tris.append((ring(rings - 1, j), south, ring(rings - 1, j + 1)))
    return np.array(verts, dtype=np.float32), np.array(tris, dtype=np.int32)


def ply_bytes(verts, tris):
    head = ("ply\nformat binary_little_endian 1.0\ncomment MeshFree Data/Scripts/make_data.py\n"
            "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(tris)))
    body = verts.astype("<f4").tobytes()
    face = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"] = 3
    face["i"] = tris
    return head.encode() + body + face.tobytes()


def scan_torus(points=3000, seed=20140611):
    """A torus (R = 1, r = 0.35) seen by 4 scanners around it: visible surface samples, noise along each
    scanner's ray (sigma 0.004), intensity = cos(incidence)."""
    rng = np.random.default_rng(seed)
    big, small = 1.0, 0.35
    scanners = np.array([[3.0, 0.0, 1.5], [0.0, 3.0, 1.5], [-3.0, 0.0, 1.5], [0.0, -3.0, 1.5]])
    out = []
    per = points // len(scanners)
    for k, eye in enumerate(scanners):
        got = []
        while sum(len(g) for g in got) < per:
            # Area-uniform samples of the torus (rejection on the (R + r cos v) area factor).
            u = rng.uniform(0, 2 * np.pi, 4 * per)
            v = rng.uniform(0, 2 * np.pi, 4 * per)
            keep = rng.uniform(0, big + small, 4 * per) < big + small * np.cos(v)
            u, v = u[keep], v[keep]
            p = np.stack([(big + small * np.cos(v)) * np.cos(u), (big + small * np.cos(v)) * np.sin(u),
                          small * np.sin(v)], -1)
            normal = np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)], -1)
            ray = p - eye
            dist = np.linalg.norm(ray, axis=1)
            ray /= dist[:, None]
            cosine = -(normal * ray).sum(1)
            facing = cosine > 0.1
            p, ray, dist, cosine = p[facing], ray[facing], dist[facing], cosine[facing]
            p = p + ray * rng.normal(0, 0.004, len(p))[:, None]
            got.append(np.column_stack([p, cosine, np.full(len(p), k)]))
        out.append(np.vstack(got)[:per])
    cloud = np.vstack(out)
    return [cloud[:, 0], cloud[:, 1], cloud[:, 2], cloud[:, 3], cloud[:, 4]]


def build():
    files = {}
    p9 = [(1, 1), (1, -1), (-1, 1), (-1, -1), (0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]
    f9 = [1, -1, 0, 0, 1, 0, -1, -1, 1]
    files["thesis_9points.xyz"] = xyz_text(["x", "y", "z", "f"], [(x, y, f, f) for (x, y), f in zip(p9, f9)],
                                           "thesis sec. 3.4: 9 points with values f, placed at z = f")
    rng = np.random.default_rng(35)
    xy = rng.uniform(-1, 1, size=(256, 2))
    f = rng.uniform(0, 1, size=256)
    files["random_256.xyz"] = xyz_text(["x", "y", "z", "f"], [(a, b, v, v) for (a, b), v in zip(xy, f)],
                                       "thesis fig. 3.5: 256 random points, random values f placed at z = f")

    octa = phyxels(lambda p: np.abs(p[:, 0]) + np.abs(p[:, 1]) + np.abs(p[:, 2]) / 1.005 <= 1 + 1e-9, 299,
                   spacing=0.20061, bcc=True)
    files["octahedron_299.pcd"] = pcd_bytes(["x", "y", "z"], [octa[:, 0], octa[:, 1], octa[:, 2]])
    e568 = phyxels(lambda p: (p[:, 0] / 1.0) ** 2 + (p[:, 1] / 0.6) ** 2 + (p[:, 2] / 0.5) ** 2 <= 1, 568,
                   spacing=0.12990663554518173, offset=0.5)
    files["ellipsoid_568.pcd"] = pcd_bytes(["x", "y", "z"], [e568[:, 0], e568[:, 1], e568[:, 2]])
    axes715 = (1.0, 0.6, 0.4775)
    s715 = 0.11856
    e715 = phyxels(lambda p: sum((p[:, k] / axes715[k]) ** 2 for k in range(3)) <= 1, 715, spacing=s715)
    files["ellipsoid_715.pcd"] = pcd_bytes(["x", "y", "z"], [e715[:, 0], e715[:, 1], e715[:, 2]])
    # The surface encloses the phyxels by half a lattice spacing.
    verts, tris = ellipsoid_surface(*(a + s715 / 2 for a in axes715))
    assert len(verts) == 990 and len(tris) == 1976
    files["ellipsoid_715_surface.ply"] = ply_bytes(verts, tris)

    files["scan_torus.pcd"] = pcd_bytes(["x", "y", "z", "intensity", "scanner"], scan_torus(), "binary",
                                        types=["F", "F", "F", "F", "U1"])
    return files


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=DATA, help="folder for the files (default: Data/)")
    parser.add_argument("--check", action="store_true", help="compare with the files in --out, write nothing")
    args = parser.parse_args()
    files = build()
    bad = 0
    for name, data in sorted(files.items()):
        path = os.path.join(args.out, name)
        if args.check:
            same = os.path.exists(path) and open(path, "rb").read() == data
            print("%-28s %s" % (name, "same" if same else "DIFFERS"))
            bad += not same
        else:
            os.makedirs(args.out, exist_ok=True)
            with open(path, "wb") as fh:
                fh.write(data)
            print("wrote %-28s %7d bytes" % (name, len(data)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
