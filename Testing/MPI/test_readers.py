"""The PCD and XYZ readers under MPI: each rank reads its own contiguous share of the points (ParaView asks piece =
rank of N), and the pieces gathered in rank order equal the serial read bit for bit — coordinates and every array,
in file order, every point once (an `idx` column holds each point's index in the file). PCD ascii, binary and
binary_compressed, and text clouds; CRLF line ends, no final newline, comments and blank lines; a 1-point file
(empty pieces keep the arrays, no hang); a bad file fails on every rank.

Each rank writes the same files into its own temporary directory (no rank waits for another's files)."""
import os
import shutil
import struct
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_mpi as mm  # noqa: E402
from vtkmodules.util import numpy_support as ns  # noqa: E402
from vtkmodules.vtkCommonCore import VTK_STRING  # noqa: E402

mm.load(globals())
READERS = {"pcd": globals()["PCDReader"], "xyz": globals()["PointCloudXYZReader"]}
DIR = tempfile.mkdtemp(prefix=f"meshfree_mpi_readers_{mm.RANK}_")


def write(name, data):
    path = os.path.join(DIR, name)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return path


# --- the files ------------------------------------------------------------------------------------------------
FIELDS = [("x", "F", 4, 1), ("y", "F", 4, 1), ("z", "F", 4, 1), ("normal_x", "F", 4, 1), ("normal_y", "F", 4, 1),
          ("normal_z", "F", 4, 1), ("rgb", "U", 4, 1), ("idx", "I", 4, 1), ("label", "I", 2, 3), ("range", "F", 8, 1)]
DTYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("I", 2): "<i2", ("I", 4): "<i4", ("U", 4): "<u4"}


def make_cloud(n, seed):
    rng = np.random.default_rng(seed)
    columns = {}
    for name, kind, size, count in FIELDS:
        shape = (n, count) if count > 1 else (n,)
        if name == "idx":
            values = np.arange(n)
        elif name == "rgb":
            values = rng.integers(0, 1 << 24, size=shape)
        elif kind == "I":
            values = rng.integers(-30000, 30000, size=shape)
        else:
            values = rng.uniform(-10, 10, size=shape) * (1e-3 if size == 8 else 1)
        columns[name] = np.asarray(values).astype(DTYPES[(kind, size)])
    return columns


def pcd_header(n, data, width=None, height=1):
    return ("# .PCD v0.7\nVERSION 0.7\nFIELDS " + " ".join(f[0] for f in FIELDS) +
            "\nSIZE " + " ".join(str(f[2]) for f in FIELDS) + "\nTYPE " + " ".join(f[1] for f in FIELDS) +
            "\nCOUNT " + " ".join(str(f[3]) for f in FIELDS) +
            f"\nWIDTH {n if width is None else width}\nHEIGHT {height}\nVIEWPOINT 1 2 3 1 0 0 0\nPOINTS {n}\n"
            f"DATA {data}\n")


def pcd_ascii(columns, n, newline="\n", final=True):
    lines = []
    for i in range(n):
        values = []
        for name, kind, size, count in FIELDS:
            v = np.atleast_1d(columns[name][i])
            values += [repr(float(x)) if kind == "F" and size == 8 else
                       (np.format_float_positional(x, unique=True, trim="-") if kind == "F" else str(int(x)))
                       for x in v]
        lines.append(" ".join(values))
    text = newline.join(lines) + (newline if final and lines else "")
    return pcd_header(n, "ascii") + text


def pcd_binary(columns, n):
    record = np.empty(n, dtype=[(f[0], DTYPES[(f[1], f[2])], (f[3],) if f[3] > 1 else ()) for f in FIELDS])
    for f in FIELDS:
        record[f[0]] = columns[f[0]]
    return pcd_header(n, "binary").encode() + record.tobytes()


def lzf_literals(raw):
    """A valid LZF stream of literal runs only (control byte L-1, then L <= 32 bytes): what lzf_decompress reads."""
    out = bytearray()
    for k in range(0, len(raw), 32):
        chunk = raw[k:k + 32]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)


def pcd_compressed(columns, n):
    raw = b"".join(np.ascontiguousarray(columns[f[0]]).tobytes() for f in FIELDS)  # one block per field
    packed = lzf_literals(raw)
    return pcd_header(n, "binary_compressed").encode() + struct.pack("<II", len(packed), len(raw)) + packed


def xyz_text(columns, n, newline="\n", final=True, decorated=False):
    lines = ["# a text cloud", "", "x y z idx value"] if decorated else []
    for i in range(n):
        lines.append(" ".join(repr(float(columns[c][i])) for c in ("x", "y", "z")) +
                     f" {int(columns['idx'][i])} {float(columns['range'][i])!r}")
        if decorated and i % 7 == 3:
            lines += ["// comment", "   "]
    return newline.join(lines) + (newline if final else "")


N = 997
cloud = make_cloud(N, 5)
one = make_cloud(1, 6)
FILES = [  # (label, reader, path, points, binary: floor shares)
    ("pcd ascii", "pcd", write("cloud_ascii.pcd", pcd_ascii(cloud, N)), N, False),
    ("pcd ascii CRLF", "pcd", write("cloud_ascii_crlf.pcd", pcd_ascii(cloud, N, "\r\n")), N, False),
    ("pcd ascii no final newline", "pcd", write("cloud_ascii_nofinal.pcd", pcd_ascii(cloud, N, final=False)), N,
     False),
    ("pcd binary", "pcd", write("cloud_binary.pcd", pcd_binary(cloud, N)), N, True),
    ("pcd binary_compressed", "pcd", write("cloud_compressed.pcd", pcd_compressed(cloud, N)), N, True),
    ("xyz", "xyz", write("cloud.xyz", xyz_text(cloud, N)), N, False),
    ("xyz CRLF, comments, no final newline", "xyz",
     write("cloud_crlf.xyz", xyz_text(cloud, N, "\r\n", final=False, decorated=True)), N, False),
    ("pts with a count line", "xyz", write("cloud.pts", f"{N}\n" + xyz_text(cloud, N)), N, False),
    ("pcd ascii, 1 point", "pcd", write("one_ascii.pcd", pcd_ascii(one, 1)), 1, False),
    ("pcd binary, 1 point", "pcd", write("one_binary.pcd", pcd_binary(one, 1)), 1, True),
    ("pcd binary_compressed, 1 point", "pcd", write("one_compressed.pcd", pcd_compressed(one, 1)), 1, True),
    ("xyz, 1 point, no final newline", "xyz", write("one.xyz", xyz_text(one, 1, final=False)), 1, False),
]


# --- reading and comparing ----------------------------------------------------------------------------------------
def table(polydata):
    """(n, w) float64 table of the points and every point array (exact: no value here needs more than a double),
    and the arrays' names and types."""
    n = polydata.GetNumberOfPoints()
    cols = [ns.vtk_to_numpy(polydata.GetPoints().GetData()).reshape(n, 3).astype(np.float64)] if n else \
        [np.zeros((0, 3))]
    layout = [("points", polydata.GetPoints().GetDataType() if polydata.GetPoints() else -1, 3)]
    pd = polydata.GetPointData()
    for a in range(pd.GetNumberOfArrays()):
        array = pd.GetArray(a)
        k = array.GetNumberOfComponents()
        layout.append((array.GetName(), array.GetDataType(), k))
        cols.append(ns.vtk_to_numpy(array).reshape(n, k).astype(np.float64) if n else np.zeros((0, k)))
    fd = polydata.GetFieldData()
    for a in range(fd.GetNumberOfArrays()):
        layout.append(("field " + fd.GetArray(a).GetName(), tuple(ns.vtk_to_numpy(fd.GetArray(a)).tolist())))
    return np.hstack(cols), layout


class Errors:
    """Collects the ErrorEvent messages of an algorithm (an observer also keeps them off the output window)."""

    def __init__(self, algorithm):
        self.text = ""

        def caught(caller, event, data=None):
            self.text += str(data)

        caught.CallDataType = VTK_STRING  # the message arrives as call data
        algorithm.AddObserver("ErrorEvent", caught)


def serial_and_local(kind, path):
    """(serial whole table, its layout, this rank's piece table, its layout, errors of both)."""
    serial = READERS[kind](FileName=path)
    local = READERS[kind](FileName=path)
    algorithms = serial.GetClientSideObject(), local.GetClientSideObject()
    errors = [Errors(a) for a in algorithms]
    algorithms[0].UpdatePiece(0, 1, 0)
    local.UpdatePipeline()
    whole, whole_layout = table(algorithms[0].GetOutputDataObject(0))
    piece, piece_layout = table(algorithms[1].GetOutputDataObject(0))
    return whole, whole_layout, piece, piece_layout, errors[0].text + errors[1].text


for label, kind, path, n, binary in FILES:
    whole, whole_layout, piece, piece_layout, errors = serial_and_local(kind, path)
    mm.check(errors == "", f"{label}: errors on rank {mm.RANK}: {errors}")
    mm.check(len(whole) == n, f"{label}: the serial read has {len(whole)} of {n} points")
    mm.check(piece_layout == whole_layout, f"{label}: rank {mm.RANK}'s piece has other arrays than serial")
    sizes = mm.all_gather(np.array([[len(piece)]]))[:, 0].astype(int)
    mm.check(sizes.sum() == n, f"{label}: the pieces hold {sizes.tolist()} points, not {n} in all")
    mm.check(n < mm.RANKS or mm.RANKS == 1 or sizes.max() < n, f"{label}: one rank holds all {n} points")
    if binary:
        want = [(n * (p + 1)) // mm.RANKS - (n * p) // mm.RANKS for p in range(mm.RANKS)]
        mm.check(sizes.tolist() == want, f"{label}: shares {sizes.tolist()}, floor shares {want}")
    got = mm.all_gather(piece) if piece.shape[1] else piece
    idx = [k for k, entry in enumerate(whole_layout) if entry[0] == "idx"]
    if idx:
        column = 3 + sum(entry[2] for entry in whole_layout[1:idx[0]])
        mm.check(np.array_equal(got[:, column], np.arange(n)), f"{label}: not every point once, in file order")
    mm.check(got.shape == whole.shape and np.array_equal(got.view(np.int64), whole.view(np.int64)),
             f"{label}: the gathered pieces differ from the serial read")
    if mm.RANK == 0:
        mm.log(f"{label}: {n} points as {sizes.tolist()} on {mm.RANKS} ranks = serial, bit for bit")

# A bad file: every rank reports it (the count of points does not match), none hangs, every output is empty.
bad = write("bad.pcd", pcd_ascii(cloud, 20).replace("POINTS 20", "POINTS 21").replace("WIDTH 20", "WIDTH 21"))
bad_pts = write("bad.pts", "21\n" + xyz_text(cloud, 20))
for kind, path in (("pcd", bad), ("xyz", bad_pts)):
    whole, _, piece, _, errors = serial_and_local(kind, path)
    mm.check("Cannot read" in errors and len(piece) == 0 and len(whole) == 0,
             f"{path}: rank {mm.RANK} gave {len(piece)} points and the errors {errors!r}")
if mm.RANK == 0:
    mm.log("bad files: an error and an empty output on every rank")

shutil.rmtree(DIR, ignore_errors=True)
mm.finish()
