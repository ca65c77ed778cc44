"""The thesis-figure scripts of Data/Scripts/figures run headless from Data/ and write their PNGs:
figs 3.1-3.4 (LS, WLS, MLS, SPH over the 9-point example) and 3.5 (MLS over 256 random points).
Figs 4.6-4.8 and 5.8 have tests of their own (test_readers_fig_solid_render, test_readers_fig_sph_render)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_run  # noqa: E402

figure_run.run("approximation", "fig_3_x_approximation.py", [],
               ["fig3_1_ls.png", "fig3_2_wls.png", "fig3_3_mls.png", "fig3_4_sph.png"])
figure_run.run("random256", "fig_3_5_random256.py", [], ["fig3_5_mls_256.png"])
