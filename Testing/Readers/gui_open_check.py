# Runs inside the real ParaView GUI (paraview --script=...): File > Open offers MeshFree's readers, first
# for a text .xyz cloud (the "Open Data With..." list is the reader factory's list, in this order), and
# OpenDataFile in the GUI's session picks them; a .pcd shows as points.
import os

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403

out = os.environ.get("MESHFREE_TEST_OUTPUT", ".")
cloud = os.path.join(out, "gui_cloud.xyz")
with open(cloud, "w") as f:
    for i in range(200):
        f.write("%g %g %g %d\n" % (i % 20 * 0.1, i // 20 * 0.1, 0.05 * ((i % 7) - 3), i))
session = sm.ActiveConnection.Session
factory = sm.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
types = factory.GetSupportedFileTypes(session)
assert "Point Cloud Text Files (MeshFree) (*.xyz *.pts)" in types, types
assert "PCL Point Cloud Data (MeshFree) (*.pcd)" in types, types
offered = factory.GetReaders(cloud, session)
names = [offered.GetString(i) for i in range(1, offered.GetLength(), 3)]
print("File > Open offers for a text .xyz cloud:", names)
assert names and names[0] == "MeshFreeXYZReader", names

reader = OpenDataFile(cloud)
assert reader.GetXMLName() == "MeshFreeXYZReader", reader.GetXMLName()
pcd = OpenDataFile(os.path.join(os.environ["MESHFREE_READERS_TEST_DATA"], "pcl_xyzrgb_ascii.pcd"))
assert pcd.GetXMLName() == "MeshFreePCDReader"
display = Show(reader)
assert display.Representation == "Points", display.Representation
Render()
png = os.path.join(out, "gui_readers.png")
SaveScreenshot(png, ImageResolution=[400, 300])
assert os.path.getsize(png) > 1000
print("GUI readers check passed")
