"""Figure 5.8 (SPH dam break) at a CI size: 8,192 particles (the thesis' 65,536 block sampled twice as
coarsely) at t = 0.1 s. The script asserts that what it renders is the state at the requested time (time
stamp, colour range and rendered speeds equal to the data at t, speeds of the order of g t, all finite)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import figure_run  # noqa: E402

log = figure_run.run("sph", "fig_5_8_sph.py", ["--particles", "8192", "--end-time", "0.1"],
                     ["fig5_8_sph_8192.png"])
assert "t = 0.1 s: 8192 particles" in log, log
