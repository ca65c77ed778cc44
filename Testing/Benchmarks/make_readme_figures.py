#!/usr/bin/env python3
"""Montages of the demo's pictures for the README (small PNGs): the thesis figures, and surface reconstruction.

Usage: python3 Testing/Benchmarks/make_readme_figures.py [DEMO_DIR] [OUT_PNG]
DEMO_DIR defaults to build/demo (written by ./run.sh demo); OUT_PNG to Testing/Benchmarks/results/demo_figures.png;
the surface montage goes beside it as surface_figures.png. Needs Debian's python3-matplotlib.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

PANELS = [
    ("fig3_1_ls.png", "3.1 LS"),
    ("fig3_2_wls.png", "3.2 WLS"),
    ("fig3_3_mls.png", "3.3 MLS"),
    ("fig3_4_sph.png", "3.4 SPH"),
    ("fig3_5_mls_256.png", "3.5 MLS, 256 random points"),
    ("fig4_6_solid.png", "4.6 octahedron solid"),
    ("fig4_7_solid.png", "4.7 ellipsoid solid"),
    ("fig4_8_solid.png", "4.8 ellipsoid with its surface"),
    ("fig5_8_sph_65536.png", "5.8 SPH dam break, 65,536 particles"),
    ("dambreak_005.png", "3D dam break (demo)"),
]

SURFACE_PANELS = [
    ("scan_points.png", "scan: 3,000 points, estimated outward normals"),
    ("scan_holes.png", "from below: HoleFilling Auto / Off, coloured by DistanceToData"),
    ("scan_surface.png", "its surface, coloured by the scan's intensity"),
    ("dambreak_surface_005.png", "3D dam break as an SPH surface, coloured by speed"),
    ("spheric2_001.png", "SPHERIC Test 2 (DFSPH, dx 0.05 m) at 0.5 s"),
    ("spheric2_003.png", "... at 1 s"),
]


def montage(demo, panels, out, rows, columns, size):
    missing = [f for f, _ in panels if not os.path.isfile(os.path.join(demo, f))]
    if missing:
        sys.exit("missing demo pictures in %s (run ./run.sh demo first): %s" % (demo, ", ".join(missing)))
    fig, axes = plt.subplots(rows, columns, figsize=size)
    for ax, (name, title) in zip(axes.flat, panels):
        ax.imshow(mpimg.imread(os.path.join(demo, name)))
        ax.set_title(title, fontsize=9)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    print("wrote", out)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    demo = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build", "demo")
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "results", "demo_figures.png")
    montage(demo, PANELS, out, 2, 5, (15, 5.4))
    montage(demo, SURFACE_PANELS, os.path.join(os.path.dirname(out), "surface_figures.png"), 2, 3, (15, 7.2))


if __name__ == "__main__":
    main()
