# Runs inside the real ParaView GUI (paraview --script=...): the plugin's proxies exist and render.
import os

from paraview.simple import *  # noqa: F401,F403

src = MeshFreeKernel(Kernel="Wendland", Dimension=2)
Show(src)
Render()
out = os.path.join(os.environ.get("MESHFREE_TEST_OUTPUT", "."), "gui_check.png")
SaveScreenshot(out, ImageResolution=[400, 300])
assert os.path.getsize(out) > 1000
print("GUI check passed")
