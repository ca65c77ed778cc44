"""Figures 4.6-4.8 (MLS deformable solids: octahedron, ellipsoid, ellipsoid with its closed surface from
Data/ellipsoid_715_surface.ply), all three in one pvpython process as the demo runs them. The script
asserts the phyxel counts against the lattice rule, finite values, the fall, the container, and that the
embedded surface follows the phyxels; this test checks it ran cleanly. Running the figures one after the
other once made the 4.7 solid take the previous figure's points as its input surface ("The input must be a
closed surface"): the error filter below catches that."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_run  # noqa: E402

log = figure_run.run("solid", "fig_4_x_deformable.py", [],
                     ["fig4_6_solid.png", "fig4_7_solid.png", "fig4_8_solid.png"])
for figure in ("4.6", "4.7", "4.8"):
    assert ("fig %s:" % figure) in log, "figure %s printed no check line" % figure
