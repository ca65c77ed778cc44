"""Virtual range scanner for the scan benchmark (bench_scans.py, issue 23), after Berger et al., "A benchmark for
surface reconstruction", ACM TOG 32(2), 2013: range images of analytic shapes from several viewpoints, so the true
surface - and every output's distance to it - is known exactly.

    /usr/bin/python3 virtual_scan.py OUT_DIR [--points 150000] [--seed 7] [--only NAME ...]

Cases (each OUT_DIR/NAME.xyz: positions only, "x y z" per line; NAME.npz: points, normals = the true outward
normal at each sample's noise-free surface point, view = the view index; NAME.json: the shapes, the scanner's
settings and the counts):
  vscan_sphere     unit sphere, 6 views
  vscan_torus      torus R = 1, r = 0.35 (axis z), 6 views
  vscan_assembly   three disjoint solids - a sphere, a torus and a capsule - that occlude one another, 8 views
  vscan_single     the torus from one view only: an open scan (its border is the silhouette and the
                   grazing-angle cut-off)
The scanner: a pinhole camera per view on a ring around the object at elevations of 20-45 degrees above the
object's middle, none below, so the underside is never seen (each closed case has an unseen region to close);
rays cast on the exact signed distance (sphere tracing, converged to 1e-9 of the object size); returns at grazing
incidence (|cos| < 0.15) are dropped, as a triangulation scanner loses them; depth-dependent noise along the ray,
sigma = noise x size x (depth / mean depth)^2 (triangulation error grows with the square of the range; noise =
0.0005 by default, size = the bounding-box diagonal); per-view misregistration: each view's points are moved by
a small random rigid motion (rotation N(0, 0.05 deg) about a random axis through the object's centre,
translation N(0, 0.0003 x size) per axis), as after an imperfect alignment. The pixel grid is sized so that all
views together return about --points points.

Shapes give exact unsigned distance (distance), outward normal (normal), and an area-uniform sample (sample):
Assembly(shapes) is a union of disjoint solids, so the distance to its surface is the least distance to any part.
"""
import argparse
import json
import math
import os
import sys

import numpy as np


class Sphere:
    def __init__(self, centre, radius):
        self.c, self.r = np.asarray(centre, float), float(radius)

    def sdf(self, p):
        return np.linalg.norm(p - self.c, axis=1) - self.r

    def normal(self, p):
        d = p - self.c
        return d / np.linalg.norm(d, axis=1)[:, None]

    def area(self):
        return 4 * math.pi * self.r ** 2

    def sample(self, n, rng):
        d = rng.normal(size=(n, 3))
        return self.c + self.r * d / np.linalg.norm(d, axis=1)[:, None]

    def spec(self):
        return dict(type="sphere", centre=self.c.tolist(), radius=self.r)


class Torus:
    """Axis z through centre; major radius R, tube radius r."""

    def __init__(self, centre, R, r):
        self.c, self.R, self.r = np.asarray(centre, float), float(R), float(r)

    def _q(self, p):
        d = p - self.c
        rho = np.hypot(d[:, 0], d[:, 1])
        return d, rho, np.stack([rho - self.R, d[:, 2]], axis=1)

    def sdf(self, p):
        _, _, q = self._q(p)
        return np.linalg.norm(q, axis=1) - self.r

    def normal(self, p):
        d, rho, q = self._q(p)
        rho = np.maximum(rho, 1e-300)
        qn = q / np.linalg.norm(q, axis=1)[:, None]
        return np.stack([qn[:, 0] * d[:, 0] / rho, qn[:, 0] * d[:, 1] / rho, qn[:, 1]], axis=1)

    def area(self):
        return 4 * math.pi ** 2 * self.R * self.r

    def sample(self, n, rng):
        out = []
        while sum(len(o) for o in out) < n:  # tube angle by rejection: density proportional to R + r cos(phi)
            phi = rng.uniform(0, 2 * math.pi, 2 * n)
            keep = rng.uniform(0, self.R + self.r, 2 * n) < self.R + self.r * np.cos(phi)
            phi = phi[keep]
            theta = rng.uniform(0, 2 * math.pi, len(phi))
            w = self.R + self.r * np.cos(phi)
            out.append(np.stack([w * np.cos(theta), w * np.sin(theta), self.r * np.sin(phi)], axis=1))
        return self.c + np.concatenate(out)[:n]

    def spec(self):
        return dict(type="torus", centre=self.c.tolist(), R=self.R, r=self.r)


class Capsule:
    """Points within r of the segment a-b."""

    def __init__(self, a, b, radius):
        self.a, self.b, self.r = np.asarray(a, float), np.asarray(b, float), float(radius)
        self.axis = self.b - self.a
        self.length = float(np.linalg.norm(self.axis))

    def _foot(self, p):
        s = np.clip((p - self.a) @ self.axis / self.length ** 2, 0, 1)
        return self.a + s[:, None] * self.axis

    def sdf(self, p):
        return np.linalg.norm(p - self._foot(p), axis=1) - self.r

    def normal(self, p):
        d = p - self._foot(p)
        return d / np.linalg.norm(d, axis=1)[:, None]

    def area(self):
        return 2 * math.pi * self.r * self.length + 4 * math.pi * self.r ** 2

    def sample(self, n, rng):
        u = self.axis / self.length
        e1 = np.cross(u, [1.0, 0, 0] if abs(u[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(u, e1)
        side = rng.random(n) < 2 * math.pi * self.r * self.length / self.area()
        out = np.empty((n, 3))
        m = int(side.sum())
        t, a = rng.random(m), rng.uniform(0, 2 * math.pi, m)
        out[side] = self.a + t[:, None] * self.axis + self.r * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)
        caps = Sphere([0, 0, 0], self.r).sample(n - m, rng)
        ends = np.where(((caps @ u) < 0)[:, None], self.a, self.b)
        out[~side] = ends + caps
        return out

    def spec(self):
        return dict(type="capsule", a=self.a.tolist(), b=self.b.tolist(), radius=self.r)


class Assembly:
    """A union of disjoint solids."""

    def __init__(self, shapes):
        self.shapes = list(shapes)

    @staticmethod
    def from_spec(specs):
        make = dict(sphere=lambda s: Sphere(s["centre"], s["radius"]), torus=lambda s: Torus(s["centre"], s["R"], s["r"]),
                    capsule=lambda s: Capsule(s["a"], s["b"], s["radius"]))
        return Assembly([make[s["type"]](s) for s in specs])

    def sdf(self, p):
        return np.min([s.sdf(p) for s in self.shapes], axis=0)

    def distance(self, p):
        return np.abs(self.sdf(np.asarray(p, float)))

    def normal(self, p):
        d = np.stack([np.abs(s.sdf(p)) for s in self.shapes])
        which = np.argmin(d, axis=0)
        out = np.empty_like(p)
        for i, s in enumerate(self.shapes):
            sel = which == i
            if sel.any():
                out[sel] = s.normal(p[sel])
        return out

    def sample(self, n, rng):
        areas = np.array([s.area() for s in self.shapes])
        counts = rng.multinomial(n, areas / areas.sum())
        return np.concatenate([s.sample(int(c), rng) for s, c in zip(self.shapes, counts)])

    def spec(self):
        return [s.spec() for s in self.shapes]


CASES = {
    "vscan_sphere": dict(shapes=[Sphere([0, 0, 0], 1.0)], views=6),
    "vscan_torus": dict(shapes=[Torus([0, 0, 0], 1.0, 0.35)], views=6),
    "vscan_assembly": dict(shapes=[Sphere([-1.0, 0.1, 0.5], 0.5), Torus([0.65, 0.35, 0.2], 0.6, 0.2),
                                   Capsule([0.2, -0.95, 0.25], [1.3, -0.95, 0.6], 0.25)], views=8),
    "vscan_single": dict(shapes=[Torus([0, 0, 0], 1.0, 0.35)], views=1),
}


def cast(shape, origin, dirs, far, eps):
    """Sphere tracing: hit distance along each ray (inf where none)."""
    t = np.zeros(len(dirs))
    alive = np.ones(len(dirs), bool)
    hit = np.zeros(len(dirs), bool)
    for _ in range(600):
        idx = np.nonzero(alive)[0]
        if len(idx) == 0:
            break
        d = shape.sdf(origin + t[idx, None] * dirs[idx])
        t[idx] += d
        done = d < eps
        hit[idx[done]] = True
        gone = t[idx] > far
        alive[idx[done | gone]] = False
    t[~hit] = np.inf
    return t


def rotation(axis, angle):
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def scan(name, points, seed, noise=0.0005, rot_deg=0.05, shift=0.0003, grazing=0.15):
    case = CASES[name]
    shape = Assembly(case["shapes"])
    rng = np.random.default_rng(seed)
    dense = shape.sample(200000, rng)
    lo, hi = dense.min(0), dense.max(0)
    centre, size = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    views = case["views"]
    distance = 1.6 * size
    fov = 2 * math.atan(0.55 * size / distance)
    # a first pass at low resolution measures how many rays hit, to size the pixel grid for ~points in total
    res = 64
    for attempt in range(2):
        clouds, normals, ids = [], [], []
        for v in range(views):
            azimuth = 2 * math.pi * v / views + 0.3
            elevation = math.radians(20 + 25 * ((v * 0.618) % 1.0)) if views > 1 else math.radians(30)
            eye = centre + distance * np.array([math.cos(elevation) * math.cos(azimuth),
                                                math.cos(elevation) * math.sin(azimuth), math.sin(elevation)])
            fwd = (centre - eye) / np.linalg.norm(centre - eye)
            right = np.cross(fwd, [0, 0, 1.0])
            right /= np.linalg.norm(right)
            up = np.cross(right, fwd)
            s = np.tan(fov / 2) * np.linspace(-1, 1, res)
            u, w = np.meshgrid(s, s)
            dirs = fwd + u.reshape(-1, 1) * right + w.reshape(-1, 1) * up
            dirs /= np.linalg.norm(dirs, axis=1)[:, None]
            t = cast(shape, eye, dirs, 3 * distance, 1e-9 * size)
            ok = np.isfinite(t)
            p = eye + t[ok, None] * dirs[ok]
            n = shape.normal(p)
            keep = np.abs(np.einsum("ij,ij->i", n, dirs[ok])) > grazing
            p, n, depth, d = p[keep], n[keep], t[ok][keep], dirs[ok][keep]
            clouds.append((p, n, depth, d))
        hits = sum(len(c[0]) for c in clouds)
        if attempt == 0:
            res = max(16, int(round(res * math.sqrt(points / max(hits, 1)))))
    mean_depth = float(np.mean(np.concatenate([c[2] for c in clouds])))
    out_p, out_n, out_v = [], [], []
    for v, (p, n, depth, d) in enumerate(clouds):
        sigma = noise * size * (depth / mean_depth) ** 2
        q = p + (rng.normal(size=len(p)) * sigma)[:, None] * d
        R = rotation(rng.normal(size=3), math.radians(rng.normal(0, rot_deg)))
        q = (q - centre) @ R.T + centre + rng.normal(0, shift * size, 3)
        out_p.append(q)
        out_n.append(n @ R.T)  # the true normal, carried with the view's misregistration
        out_v.append(np.full(len(q), v))
    pts, nrm, view = np.concatenate(out_p), np.concatenate(out_n), np.concatenate(out_v)
    spec = dict(name=name, shapes=shape.spec(), views=views, pixels=res, points=int(len(pts)), diagonal=size,
                noise=noise, rot_deg=rot_deg, shift=shift, grazing=grazing, seed=seed,
                closed=views > 1, mean_depth=mean_depth)
    return pts, nrm, view, spec


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--points", type=int, default=150000)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--only", nargs="*")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    for i, name in enumerate(CASES):
        if a.only and name not in a.only:
            continue
        pts, nrm, view, spec = scan(name, a.points, a.seed + i)
        from scipy.spatial import cKDTree
        d, _ = cKDTree(pts).query(pts[:: max(1, len(pts) // 20000)], k=2)
        spec["spacing"] = float(np.median(d[:, 1]))
        base = os.path.join(a.out, name)
        np.savetxt(base + ".xyz", pts, fmt="%.8g")
        np.savez(base + ".npz", points=pts, normals=nrm, view=view)
        with open(base + ".json", "w") as f:
            json.dump(spec, f, indent=1)
        print(json.dumps({k: spec[k] for k in ("name", "points", "views", "pixels", "spacing", "diagonal")}),
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
