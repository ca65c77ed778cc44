"""Open3D (Debian's python3-open3d 0.16) as a surface-reconstruction peer; one case per process (bench_surface.py).

    /usr/bin/python3 surface_run_open3d.py normals IN.ply OUT.ply [--k 20]
        estimate_normals (PCA of the k nearest neighbours) + orient_normals_consistent_tangent_plane(k) (MST)
    /usr/bin/python3 surface_run_open3d.py poisson IN.ply OUT.ply [--depth 8] [--estimate-normals [--k 20]]
        create_from_point_cloud_poisson (Kazhdan's screened Poisson) with the normals of IN.ply (exact), or
        with normals estimated and oriented as above

Open3D's defaults otherwise (its thread count included). Prints one JSON line: the seconds of each stage
without file input/output (algo_s = their sum) and the memory they took (algo_mb, surface_memory.py).
"""
import argparse
import json
import time

import numpy as np
import open3d as o3d

from surface_memory import AlgorithmMemory


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mode", choices=["normals", "poisson"])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--k", type=int, default=20)
    ap.add_argument("--depth", type=int, default=8)
    ap.add_argument("--estimate-normals", action="store_true")
    a = ap.parse_args()
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    cloud = o3d.io.read_point_cloud(a.inp)
    times = {}
    memory = AlgorithmMemory()
    memory.start()
    if a.mode == "normals" or a.estimate_normals:
        cloud.normals = o3d.utility.Vector3dVector(np.zeros((0, 3)))  # drop the exact ones
        t0 = time.perf_counter()
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=a.k))
        times["normals_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        cloud.orient_normals_consistent_tangent_plane(a.k)
        times["orient_s"] = time.perf_counter() - t0
    if a.mode == "normals":
        times["algo_mb"] = memory.stop()
        o3d.io.write_point_cloud(a.out, cloud)
    else:
        if not cloud.has_normals():
            raise SystemExit("poisson needs normals in %s (or --estimate-normals)" % a.inp)
        t0 = time.perf_counter()
        mesh, _density = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(cloud, depth=a.depth)
        times["poisson_s"] = time.perf_counter() - t0
        times["algo_mb"] = memory.stop()
        o3d.io.write_triangle_mesh(a.out, mesh, write_ascii=False, compressed=False)
    times["algo_s"] = sum(v for k, v in times.items() if k.endswith("_s"))
    print(json.dumps(times), flush=True)


if __name__ == "__main__":
    main()
