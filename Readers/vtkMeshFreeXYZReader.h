/**
 * @class   vtkMeshFreeXYZReader
 * @brief   reads text point clouds (.xyz, .pts): x y z and value columns, one point per line
 *
 * Columns are separated by white space, commas or semicolons. Optional lines before the data: Leica's
 * point count (.pts), a header naming the columns (`x y z intensity`, CloudCompare's `//X Y Z R G B`),
 * comments (`#`, `//`). The columns named x, y, z (else the first three) are the points (double); every
 * other column is a double point array named by the header, or `Column<k>` (k counts from 1). Columns
 * named r, g, b (or red, green, blue) holding integers 0-255 become one unsigned-char array `RGB`.
 * Without a header, a .pts file follows Leica's layout: x y z [intensity] [r g b].
 * Output: a vtkPolyData with one vertex cell per point. Rows with a NaN coordinate are dropped with a
 * warning unless KeepInvalidPoints is on. A malformed file gives an error naming the line and an empty output.
 *
 * Pieces (MPI, see vtkMeshFreePointCloudReader): the lines after the header are cut into N byte ranges of equal
 * size, a line belonging to the piece whose range holds its first byte; each piece parses the lines before the
 * data (header, count, comments) and then its own lines only. The shares are contiguous, in file order, but not
 * floor(n/N) rows each; concatenated they are the whole output bit for bit. A Leica count line makes every piece
 * count the rows of the whole file (so a count that does not match fails on every piece); colour columns make
 * each piece read the others' rows too (RGB only when every kept row of the file holds integers 0-255), one at a
 * time, keeping none. A row that does not parse fails on the piece that holds it.
 *
 * CanReadFile accepts only text whose first lines are consistent rows of numbers, so that ParaView's
 * reader factory gives real PLOT3D grids (also ".xyz") and XMol molecules to their own readers.
 *
 * @sa vtkMeshFreePCDReader
 */
#ifndef vtkMeshFreeXYZReader_h
#define vtkMeshFreeXYZReader_h

#include "MeshFreeReadersModule.h"
#include "vtkMeshFreePointCloudReader.h"

class MESHFREEREADERS_EXPORT vtkMeshFreeXYZReader : public vtkMeshFreePointCloudReader
{
public:
  static vtkMeshFreeXYZReader* New();
  vtkTypeMacro(vtkMeshFreeXYZReader, vtkMeshFreePointCloudReader);

  /** 1 when the first 64 KB of the file read as a text point cloud, 0 otherwise. */
  int CanReadFile(const char* filename);

protected:
  vtkMeshFreeXYZReader() = default;
  ~vtkMeshFreeXYZReader() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkMeshFreeXYZReader(const vtkMeshFreeXYZReader&) = delete;
  void operator=(const vtkMeshFreeXYZReader&) = delete;
};

#endif
