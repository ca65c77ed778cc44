"""The demo scripts of Data/Scripts that the README's demo command runs besides the figures run headless
and write their pictures: demo.py (kernel profiles and surface, neighbour cloud), demo_solid.py (the
deformable scenes of ch. 4), demo_scan.py (the shipped scan's normals and surface, and its surface with hole
filling on and off: the second warns, as it must, that the closed cloud's surface is left open) and
demo_spheric2.py (a coarse SPHERIC Test 2 with DFSPH, seconds). demo_dambreak.py (65,536 SPH particles, minutes)
is the SPH suite's."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_run  # noqa: E402

scripts = os.path.dirname(figure_run.FIGURES)
figure_run.run("demo", "demo.py", [], ["kernels.png", "kernel_wendland.png", "neighbors.png"], folder=scripts)
figure_run.run("demo_solid", "demo_solid.py", [],
               ["solid_octahedron.png", "solid_ellipsoid568.png", "solid_ellipsoid715.png"], folder=scripts)
figure_run.run("demo_scan", "demo_scan.py", [], ["scan_points.png", "scan_holes.png", "scan_surface.png"],
               folder=scripts, expected_warnings=["regions without samples leave the surface open"])
figure_run.run("demo_spheric2", "demo_spheric2.py", [], ["spheric2_%03d.png" % k for k in range(4)], folder=scripts)
