"""The plugin loads with LoadPlugin and its proxies appear in paraview.simple."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())
# paraview.simple names a proxy after its label without spaces.
for name in ("PointNeighbors", "MeshFreeKernel"):
    assert name in globals(), "proxy %s missing after LoadPlugin" % name
# The plugin is registered under its contract name.
from paraview.modules.vtkRemotingCore import vtkPVPluginTracker  # noqa: E402
tracker = vtkPVPluginTracker.GetInstance()
names = [tracker.GetPluginName(i) for i in range(tracker.GetNumberOfPlugins())]
assert "MeshFree" in names, names
assert os.path.basename(meshfree_test.plugin_path()) == "MeshFree.so"
print("loaded", meshfree_test.plugin_path())
