/**
 * @class   vtkMeshFreePCDReader
 * @brief   reads the Point Cloud Library's .pcd files (v0.7: ascii, binary, binary_compressed)
 *
 * Output: a vtkPolyData with one vertex cell per point.
 * - The fields `x`, `y`, `z` are the points (float when all three are 4-byte floats, else double; a missing
 *   one is 0).
 * - PCL's `normal_x`, `normal_y`, `normal_z` (one floating type, COUNT 1) become one 3-component array
 *   `Normals`, the active normals of the point data (so that glyphs and surface filters use them).
 * - Every other field is a point array named as in the file, of the field's own type (SIZE 1/2/4/8, TYPE
 *   I/U/F), with COUNT components (`curvature` stays `curvature`). PCL's packed colour fields `rgb` (float)
 *   and `rgba` (uint32) become unsigned-char arrays `rgb` (3 components) and `rgba` (4). Padding fields
 *   (`_`) are skipped.
 * - binary data may be followed by zero bytes (PCL's writers pad files up to a page); any other bytes after
 *   the POINTS records mean that the header does not describe the data, and the file is refused.
 * - Field data: `Viewpoint` (tx ty tz qw qx qy qz) and `OrganizedDimensions` (WIDTH, HEIGHT).
 * - Points with a NaN (or infinite) x, y or z, PCL's marker of invalid points, are dropped with a warning
 *   giving their count, unless KeepInvalidPoints is on. When points of an organised cloud (HEIGHT > 1) are
 *   dropped, the point array `PixelIndex` keeps each point's row-major index in the WIDTH x HEIGHT grid.
 *
 * A file that does not parse (truncated data, counts that do not match, unknown types, compressed sizes
 * that lie, ...) gives an error naming the problem and an empty output.
 *
 * Pieces (MPI, see vtkMeshFreePointCloudReader): piece p of N is a contiguous share of the points in file order,
 * the pieces concatenated being the whole output bit for bit; every piece has the same arrays and field data.
 * - binary: the points [floor(p n / N), floor((p+1) n / N)); only their records are read.
 * - binary_compressed: the same share, but the LZF blob (all fields, column-major) cannot be split: each piece
 *   decompresses the whole of it, copies its share out and frees the rest.
 * - ascii: the data section is cut into N byte ranges of equal size, a line belonging to the piece whose range
 *   holds its first byte (not floor(n/N) points each). Each piece counts the lines of the whole section, so that a
 *   POINTS that does not match fails on every piece; a value that does not parse fails on its piece only.
 * - an organised cloud (HEIGHT > 1) whose invalid points are dropped: whether PixelIndex is there depends on the
 *   whole file, so each piece also reads the others' points (ascii: parses their lines), keeping none of them;
 *   PixelIndex is the index in the file's grid, and the dropped-points warning counts the piece's points.
 *
 * @sa vtkMeshFreePCDWriter vtkMeshFreeXYZReader
 */
#ifndef vtkMeshFreePCDReader_h
#define vtkMeshFreePCDReader_h

#include "MeshFreeReadersModule.h"
#include "vtkMeshFreePointCloudReader.h"

class MESHFREEREADERS_EXPORT vtkMeshFreePCDReader : public vtkMeshFreePointCloudReader
{
public:
  static vtkMeshFreePCDReader* New();
  vtkTypeMacro(vtkMeshFreePCDReader, vtkMeshFreePointCloudReader);

  /** 1 when the file starts with a valid .pcd header, 0 otherwise (reads the first 64 KB only). */
  int CanReadFile(const char* filename);

protected:
  vtkMeshFreePCDReader() = default;
  ~vtkMeshFreePCDReader() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkMeshFreePCDReader(const vtkMeshFreePCDReader&) = delete;
  void operator=(const vtkMeshFreePCDReader&) = delete;
};

#endif
