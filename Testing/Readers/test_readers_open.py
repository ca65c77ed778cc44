"""The readers through paraview.simple: OpenDataFile picks MeshFree's readers for .pcd and for text .xyz/.pts
clouds, still gives real PLOT3D .xyz grids to ParaView's PLOT3D reader, and the PCD
writer proxy round-trips a cloud with SaveData in every encoding."""
import os
import struct
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.environ["MESHFREE_SOURCE_DIR"], "Testing", "Python"))
import meshfree_test  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from paraview import simple  # noqa: E402

meshfree_test.load(globals())
out = os.path.join(os.environ["MESHFREE_TEST_OUTPUT"], "open")
os.makedirs(out, exist_ok=True)


def path(name):
    return os.path.join(out, name)


def write(name, data):
    with open(path(name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return path(name)


def opened(name):
    reader = simple.OpenDataFile(path(name))
    assert reader is not None, name
    return reader, reader.GetXMLName()


rng = np.random.default_rng(7)
xyz = rng.uniform(-5, 5, size=(50, 3))
value = rng.uniform(size=50)
write("cloud.xyz", "".join("%r %r %r %r\n" % (a, b, c, v) for (a, b, c), v in zip(xyz, value)))
write("cloud.pts", "%d\n" % len(xyz) + "".join("%r %r %r %d %d %d %d\n" % (a, b, c, -5, 10, 20, 30)
                                                for a, b, c in xyz))
write("named.xyz", "//X Y Z Temperature\n" + "".join("%r, %r, %r, %r\n" % (a, b, c, v)
                                                       for (a, b, c), v in zip(xyz, value)))

# A real PLOT3D grid (binary, Fortran records): 3 x 2 x 2 points.
ni, nj, nk = 3, 2, 2
gx = np.array([[[(i, j * 2.0, k * 3.0) for i in range(ni)] for j in range(nj)] for k in range(nk)],
              dtype=np.float32).reshape(-1, 3)
dims = struct.pack("<3i", ni, nj, nk)
coords = gx[:, 0].tobytes() + gx[:, 1].tobytes() + gx[:, 2].tobytes()
write("grid.xyz", struct.pack("<i", len(dims)) + dims + struct.pack("<i", len(dims)) +
      struct.pack("<i", len(coords)) + coords + struct.pack("<i", len(coords)))

reader, name = opened("cloud.xyz")
assert name == "MeshFreeXYZReader", name
data = meshfree_test.fetch(reader)
assert data.GetNumberOfPoints() == 50 and data.GetNumberOfVerts() == 50
assert np.allclose(np.asarray(data.Points), xyz, rtol=0, atol=0)
assert np.array_equal(np.asarray(data.PointData["Column4"]), value)

reader, name = opened("cloud.pts")
assert name == "MeshFreeXYZReader", name
data = meshfree_test.fetch(reader)
assert np.all(np.asarray(data.PointData["Intensity"]) == -5)
assert np.all(np.asarray(data.PointData["RGB"]) == [10, 20, 30])

reader, name = opened("named.xyz")
data = meshfree_test.fetch(reader)
assert np.array_equal(np.asarray(data.PointData["Temperature"]), value)

# The GUI's File > Open lists every reader that accepts the file ("Open Data With..."): ours comes first,
# in the reader factory's order, and is what OpenDataFile takes.
factory = sm.vtkSMProxyManager.GetProxyManager().GetReaderFactory()
session = sm.ActiveConnection.Session
readers = factory.GetReaders(path("cloud.xyz"), session)
names = [readers.GetString(i) for i in range(1, readers.GetLength(), 3)]
print("readers offered for a text .xyz cloud:", names)
assert names[0] == "MeshFreeXYZReader", names

reader, name = opened("grid.xyz")
assert name == "P3DReader", "a PLOT3D grid must stay with ParaView's PLOT3D reader, got %s" % name
readers = factory.GetReaders(path("grid.xyz"), session)
names = [readers.GetString(i) for i in range(1, readers.GetLength(), 3)]
assert "MeshFreeXYZReader" not in names, names
grid = sm.Fetch(reader)
block = grid.GetBlock(0)
assert block.GetNumberOfPoints() == ni * nj * nk, block.GetNumberOfPoints()
pts = np.array([block.GetPoint(i) for i in range(block.GetNumberOfPoints())])
assert np.allclose(pts, gx), pts

# (XMol molecules, the other ".xyz", are refused by the reader's CanReadFile: see TestXYZFormat. Opening
# one here would make ParaView's PLOT3D reader print an error while it probes the text file.)

# PCD: PCL's files and the writer proxy, every encoding.
fixture = os.path.join(os.environ["MESHFREE_READERS_TEST_DATA"], "pcl_xyzrgb_ascii.pcd")
reader = simple.OpenDataFile(fixture)
assert reader.GetXMLName() == "MeshFreePCDReader"
reader.KeepInvalidPoints = 1
data = meshfree_test.fetch(reader)
assert data.GetNumberOfPoints() == 4
reader.KeepInvalidPoints = 0
data = meshfree_test.fetch(reader)
assert data.GetNumberOfPoints() == 3
assert np.asarray(data.PointData["rgb"]).tolist()[0] == [255, 0, 0]

# PCL's PointNormal: normal_x normal_y normal_z become the active normals, named Normals.
fixture = os.path.join(os.environ["MESHFREE_READERS_TEST_DATA"], "pcl_pointnormal_binary.pcd")
data = meshfree_test.fetch(simple.OpenDataFile(fixture))
normals = data.VTKObject.GetPointData().GetNormals()
assert normals is not None and normals.GetName() == "Normals", normals
assert np.array_equal(np.asarray(data.PointData["Normals"])[1], np.float32([0.6, 0.8, 0.0]))
assert "curvature" in data.PointData.keys() and "normal_x" not in data.PointData.keys()

# The writer: x y z as 4-byte floats by default (what PCL reads), doubles with WriteDoubleCoordinates.
source = simple.OpenDataFile(path("cloud.pts"))
for encoding in ("ascii", "binary", "binary_compressed"):
    for double in (0, 1):
        target = path("roundtrip_%s_%d.pcd" % (encoding, double))
        simple.SaveData(target, proxy=source, Encoding=encoding, WriteDoubleCoordinates=double)
        with open(target, "rb") as f:
            text = f.read(400)
        assert ("DATA %s\n" % encoding).encode() in text, text
        assert (b"SIZE 8 8 8 " if double else b"SIZE 4 4 4 ") in text, text
        back = meshfree_test.fetch(simple.OpenDataFile(target))
        assert np.array_equal(np.asarray(back.Points), xyz if double else xyz.astype(np.float32))
        assert np.array_equal(np.asarray(back.PointData["Intensity"]), np.full(50, -5.0))
        assert np.array_equal(np.asarray(back.PointData["RGB"]), np.tile([10, 20, 30], (50, 1)))
print("OK")
