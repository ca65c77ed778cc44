#!/usr/bin/env python3
"""Writes the binary .pcd fixtures byte by byte, laid out exactly as PCL's writers lay them out
(PCDWriter::writeBinary / writeBinaryCompressed), without PCL and without our own writer, so that the
reader is checked against the format rather than against itself. The ascii fixtures beside this script
are hand-written text. Run: python3 make_fixtures.py (deterministic; no third-party modules)."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def header(fields, sizes, types, counts, width, height, data, viewpoint="0 0 0 1 0 0 0"):
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
            "FIELDS %s\nSIZE %s\nTYPE %s\nCOUNT %s\nWIDTH %d\nHEIGHT %d\nVIEWPOINT %s\nPOINTS %d\nDATA %s\n"
            % (" ".join(fields), " ".join(map(str, sizes)), " ".join(types), " ".join(map(str, counts)),
               width, height, viewpoint, width * height, data)).encode()


def lzf_literals(data):
    """A valid LZF stream made of literal runs only (control byte L-1, then L <= 32 bytes)."""
    out = bytearray()
    for i in range(0, len(data), 32):
        chunk = data[i:i + 32]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)


def points():
    # PointNormal-like values: x y z, normal, curvature; point 2 is PCL's invalid (NaN) point.
    nan = float("nan")
    return [((0.5, -1.25, 2.0), (0.0, 0.0, 1.0), 0.125),
            ((1.5, 0.25, -3.0), (0.6, 0.8, 0.0), 0.25),
            ((nan, nan, nan), (nan, nan, nan), nan),
            ((-2.0, 4.0, 8.0), (1.0, 0.0, 0.0), 0.0)]


def pointnormal_binary_with_padding():
    # Old PCL (1.x) writes the SSE padding of PointNormal as "_" fields of 4 unsigned bytes.
    fields = ["x", "y", "z", "_", "normal_x", "normal_y", "normal_z", "_", "curvature"]
    sizes = [4, 4, 4, 1, 4, 4, 4, 1, 4]
    types = ["F", "F", "F", "U", "F", "F", "F", "U", "F"]
    counts = [1, 1, 1, 4, 1, 1, 1, 4, 1]
    body = b""
    for p, n, c in points():
        body += struct.pack("<3f", *p) + b"\xAA" * 4 + struct.pack("<3f", *n) + b"\xBB" * 4 + struct.pack("<f", c)
    return header(fields, sizes, types, counts, 4, 1, "binary") + body


def xyzrgba_binary_compressed_organised():
    # A 2 x 2 organised PointXYZRGBA cloud; PCL's compressed layout is one block per field (xxxx yyyy ...),
    # padding left out of the blocks, the rgba field an uint32 0xAARRGGBB.
    fields = ["x", "y", "z", "_", "rgba"]
    sizes = [4, 4, 4, 1, 4]
    types = ["F", "F", "F", "U", "U"]
    counts = [1, 1, 1, 4, 1]
    xs = [(0.0, 0.0, 1.0), (1.0, 0.0, 1.0), (0.0, 1.0, 1.5), (1.0, 1.0, 2.0)]
    colors = [0xFF102030, 0x80FF0000, 0x0000FF00, 0xFF0000FF]
    blocks = b""
    for k in range(3):
        blocks += struct.pack("<4f", *[p[k] for p in xs])
    blocks += struct.pack("<4I", *colors)
    packed = lzf_literals(blocks)
    return (header(fields, sizes, types, counts, 2, 2, "binary_compressed", "1 2 3 0.5 0.5 0.5 0.5")
            + struct.pack("<II", len(packed), len(blocks)) + packed)


def main():
    with open(os.path.join(HERE, "pcl_pointnormal_binary.pcd"), "wb") as f:
        f.write(pointnormal_binary_with_padding())
    with open(os.path.join(HERE, "pcl_xyzrgba_organised_compressed.pcd"), "wb") as f:
        f.write(xyzrgba_binary_compressed_organised())


if __name__ == "__main__":
    main()
